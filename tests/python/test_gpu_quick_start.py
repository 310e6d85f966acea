"""The pytest examples of docs/gpu-quick-start.md, run as they are printed there.

"Your renderer" is tests/python/external_caster.py: a numpy float32 ray caster written from the docs
alone, standing in for a CUDA, GLSL, Vulkan or PyTorch shader. Its keyword switches have the names of
render.profile's rules, so one dict describes the shader to both.

Run: PYTHONPATH=build/python /usr/bin/python3 -m pytest -q -p no:cacheprovider tests/python/test_gpu_quick_start.py
"""
import copy
import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import external_caster as ec  # noqa: E402  "your renderer"
import volref  # noqa: E402

N = 16
_z, _y, _x = np.mgrid[0:N, 0:N, 0:N].astype(np.float32)  # indexed [k, j, i]: x fastest
VOLUME = (np.exp(-((_x - 7) ** 2 + (_y - 8.5) ** 2 + (_z - 9) ** 2) / 16)
          + 0.6 * np.exp(-((_x - 10) ** 2 + (_y - 5) ** 2 + (_z - 5) ** 2) / 6)).astype(np.float32)
SCENE = {
    "volume": {"source": VOLUME,  # voxel (i, j, k) at origin + (i, j, k) spacing: default [0, 0, 0], [1, 1, 1]
               "transfer": {"color": [[0, .1, .2, .9], [.5, .9, .5, .2], [1, 1, .9, .6]],
                            "opacity": [[0, 0], [.15, 0], [.6, 1], [1, 1]]}},
    "camera": {"type": "perspective", "eye": [24, 19, 30], "target": [7.5, 7.5, 7.5], "up": [0, 1, 0], "fov_y": 30},
    "image": {"width": 48, "height": 40},
    "render": {"step": 0.5},  # voxels
}

# float32 against volref's double: measured at most 3.3e-6 at up to 60 samples per ray
# (tests/python/test_external_caster.py); 2e-5 leaves a 6x margin and is below every convention slip.
FLOAT32_TOLERANCE = 2e-5

# How my shader marches: from the entry, first sample at the entry, on the texture's box [-0.5, n - 0.5].
MY_RULES = {"placement": "from-entry", "first": 0.0, "ray_box": "texel"}


def with_profile(scene, rules):
    scene = copy.deepcopy(scene)
    scene["render"]["profile"] = {"base": "reference", **rules}
    return scene


def test_my_renderer_matches_volref():
    mine = ec.render(SCENE, **MY_RULES)                     # your renderer: float32 RGBA (H, W, 4)
    expected = volref.render(with_profile(SCENE, MY_RULES))  # volref with the same rules, in double
    report = volref.compare(mine, expected, tolerance=FLOAT32_TOLERANCE)
    assert report["within_tolerance"], report["overall"]
    assert expected.rgba[..., 3].max() > 0.5  # the image is not empty


def test_my_renderer_within_the_step_error():
    # Against volref's own rules (midpoints, domain box): allow volref's step-doubling error estimate.
    expected = volref.render(SCENE, error=True)  # expected.error: (H, W)
    report = volref.compare(ec.render(SCENE, **MY_RULES), expected, tolerance=FLOAT32_TOLERANCE, error=True)
    assert report["within_tolerance"], report["overall"]


def test_my_rules_over_a_preset():
    # My shader is VTK's loop, but it evaluates the transfer function exactly instead of a 1024-entry table.
    rules = {**volref.profiles()["vtk-gpu"], "table": 0}  # a preset's dict is a valid render.profile as it is
    scene = copy.deepcopy(SCENE)
    scene["render"]["profile"] = rules
    expected = volref.render(scene)
    mine = ec.render(SCENE, **{**ec.PRESETS["vtk-gpu"], "table": 0})
    assert volref.compare(mine, expected, tolerance=FLOAT32_TOLERANCE)["within_tolerance"]
    assert volref.render(expected.scene).rgba.tobytes() == expected.rgba.tobytes()  # the resolved scene renders again


def test_rules_the_scene_does_not_read_or_cannot_honour():
    mip = with_profile(SCENE, {"correction": "none"})
    mip["render"]["projection"] = "mip"  # a MIP does not composite: the correction is never read
    with pytest.warns(UserWarning, match="render.profile.correction: not read by this scene"):
        volref.render(mip)
    with pytest.raises(volref.Error, match='render.profile.placement: placement "from-exit" .* "lerp"'):
        volref.render(with_profile(SCENE, {"placement": "from-exit"}))  # back to front needs lerp compositing


def test_fit_names_my_conventions():
    result = volref.fit(ec.render(SCENE, **MY_RULES), SCENE)  # SCENE has the reference profile
    assert result["explained"], result["verdict"]
    assert result["rules"]["placement"] == "from-entry"
    assert result["rules"]["ray_box"] == "texel"
    assert result["image_model"] == "identity"


def test_fit_leaves_a_bug_unexplained():
    buggy = ec.render(SCENE, bug="half-texel-shift")  # reads the volume half a voxel off in x
    result = volref.fit(buggy, SCENE)
    assert not result["explained"]
    assert result["unexplained_pixels"] > 0.1 * result["pixels"]
    assert result["residual"].shape == (40, 48)  # per pixel: what the closest set leaves (a heat map)


# A sparser scene for the trace: a 32^3 volume with one blob, so that empty-space skipping has empty
# 8^3-cell blocks to skip (the 16^3 scene above has none).
_z, _y, _x = np.mgrid[0:32, 0:32, 0:32].astype(np.float32)
SPARSE = copy.deepcopy(SCENE)
SPARSE["volume"]["source"] = np.exp(-((_x - 18) ** 2 + (_y - 16) ** 2 + (_z - 14) ** 2) / 16).astype(np.float32)
SPARSE["camera"].update(eye=[48, 38, 60], target=[15.5, 15.5, 15.5])


def my_sample_dump(scene, pixel):
    """A shader's debug printf for one pixel: {k: (t, value, alpha, acc_a)}, float32, volref's placement
    (midpoints of segments of h, the last one shorter). Built from external_caster's parts."""
    vol = ec._Volume(scene["volume"], None)
    opacity = ec._TransferFunction(scene["volume"]["transfer"]["opacity"], 1)
    width = scene["image"]["width"]
    origins, dirs = ec._camera_rays(scene["camera"], width, scene["image"]["height"])
    ray = pixel[1] * width + pixel[0]
    o, d = origins[ray:ray + 1], dirs[ray:ray + 1]
    t0, t1, hit = ec._slab(o, d, vol.lo, vol.hi)
    h = np.float32(scene["render"]["step"])  # spacing 1: voxels = world units
    n = max(1, int(np.ceil((t1[0] - t0[0]) / h - np.float32(1e-9))))
    T, rows = np.float32(1), {}
    for k in range(n):
        start = t0[0] + np.float32(k) * h
        end = t1[0] if k == n - 1 else t0[0] + np.float32(k + 1) * h
        t = start + np.float32(0.5) * (end - start)
        v = vol.sample((o + t * d).astype(np.float32))[0]
        a = opacity(v)[0]
        alpha = np.float32(1) - (np.float32(1) - a) ** (end - start)  # opacity_unit_distance 1
        T = T * (np.float32(1) - alpha)
        rows[k] = (t, v, alpha, np.float32(1) - T)
    return rows


def test_trace_lines_up_with_my_dump():
    pixel = (32, 16)
    mine = my_sample_dump(SPARSE, pixel)
    for skipping in (True, False):
        trace = volref.trace(SPARSE, pixel, skipping=skipping)
        for row in trace:
            assert row["interval"] == 0  # one box: one interval
            t, value, alpha, acc_a = mine[row["segment"]]  # segment = my loop's k
            assert abs(row["t"] - t) < 1e-4
            assert abs(row["value"] - value) < 1e-5
            assert abs(row["alpha"] - alpha) < 1e-5
            assert abs(row["acc_a"] - acc_a) < FLOAT32_TOLERANCE
        # the segments skipped are the ones my shader found transparent
        skipped = set(mine) - set(trace["segment"].tolist())
        assert all(mine[k][2] == 0 for k in skipped)
        assert len(skipped) > 0 if skipping else len(skipped) == 0


def test_the_doc_shows_this_file():
    # Every Python block of docs/gpu-quick-start.md section 7 is this file's code, verbatim.
    doc = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "docs", "gpu-quick-start.md")
    with open(doc, encoding="utf-8") as f:
        section = f.read().split("## 7. pytest examples", 1)[1]
    with open(os.path.abspath(__file__), encoding="utf-8") as f:
        source = f.read()
    blocks = [b.split("```", 1)[0] for b in section.split("```python\n")[1:]]
    assert len(blocks) >= 4
    for block in blocks:
        assert block in source, block
