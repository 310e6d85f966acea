"""Issue 29: a renderer written outside volref (tests/python/external_caster.py, a numpy float32 caster
written from the docs) with other conventions is matched by a user-written render.profile, and
`volref.fit` / `volref compare --fit --scene` name its rules, while planted bugs stay unexplained.
Also the Python helpers: heatmap, write_image, profiles, _repr_png_, numpy volumes in memory, the
trace's interval and segment.

Run: PYTHONPATH=build/python /usr/bin/python3 -m pytest -q -p no:cacheprovider tests/python/test_convention_search.py
"""
import copy
import json
import os
import random
import subprocess
import sys
import zlib

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import external_caster as ec  # noqa: E402
import test_external_caster as tec  # noqa: E402
import volref  # noqa: E402

SCENES = tec.SCENES
MATCH = 2e-5  # a user-written profile against the float32 caster (test_external_caster.py's bound)


def with_profile(scene_name, rules):
    scene = copy.deepcopy(SCENES[scene_name])
    scene["render"]["profile"] = {"base": "reference", **rules}
    return scene


def caster_rules(kw):
    """The caster's switches as render.profile rules."""
    rules = {}
    for k, v in kw.items():
        if k == "termination":
            rules[k] = {v[0]: v[1]}
        elif k in ("placement", "first", "step_count", "ray_box", "correction", "table", "compositing", "correction_floor",
                   "gradient", "normal", "gradient_offset", "clamp_shaded"):
            rules[k] = v
    return rules


# (scene, caster switches, the rules fit must name, the image model it must name)
VARIANTS = [
    ("hazy", dict(placement="from-entry", first=0.0), {"placement": "from-entry", "first": 0.0}, "identity"),
    ("hazy", dict(placement="from-entry", first=1.0), {"placement": "from-entry", "first": 1.0}, "identity"),
    ("hazy", dict(ray_box="texel"), {"ray_box": "texel"}, "identity"),
    ("hazy", dict(correction="none"), {"correction": "none"}, "identity"),
    ("hazy", dict(correction="extinction"), {"correction": "extinction"}, "identity"),
    ("hazy", dict(table=256), {"table": 256}, "identity"),
    ("clear", dict(termination=("alpha_above", 1 - 1 / 255)), {"termination": {"alpha_above": 1 - 1 / 255}}, "identity"),
    ("hazy", dict(placement="from-entry", first=1.0, correction="none"),
     {"placement": "from-entry", "first": 1.0, "correction": "none"}, "identity"),
    ("clear", dict(placement="from-entry", first=0.0, ray_box="texel"),
     {"placement": "from-entry", "first": 0.0, "ray_box": "texel"}, "identity"),
    ("axis", dict(placement="from-entry", first=1.0, step_count="before-exit"),
     {"placement": "from-entry", "first": 1.0, "step_count": "before-exit"}, "identity"),
    ("hazy", dict(output=("flip",)), {}, "vertical flip"),
    ("hazy", dict(output=("unpremultiplied",)), {}, "unpremultiplied"),
    ("hazy", dict(output=("double-premultiplied",)), {}, "double-premultiplied"),
    ("hazy", dict(output=("bgra",)), {}, "BGRA"),
    ("hazy", dict(output=("srgb",)), {}, "sRGB-encoded"),
    ("hazy", dict(ray_box="texel", output=("flip",)), {"ray_box": "texel"}, "vertical flip"),
    # Shaded (section 8): the gradient scheme, its offset and the normal's sign.
    ("shaded", dict(gradient="central"), {"gradient": "central"}, "identity"),
    ("shaded", dict(gradient="forward", normal="+gradient"), {"gradient": "forward", "normal": "+gradient"}, "identity"),
    ("shaded", dict(gradient_offset=0.5), {"gradient_offset": 0.5}, "identity"),
    ("shaded-phong-two-lights", dict(gradient="central", placement="from-entry", first=1.0),
     {"gradient": "central", "placement": "from-entry", "first": 1.0}, "identity"),
]


@pytest.mark.parametrize("case", VARIANTS, ids=lambda c: f"{c[0]}-{'-'.join(f'{k}={v}' for k, v in c[1].items())}")
def test_user_profile_matches_and_fit_names_the_rules(case):
    scene_name, kw, expected, model = case
    image = ec.render(SCENES[scene_name], **kw)
    # 1. The renderer's rules written as a profile give its image to its float32 rounding.
    if "output" not in kw:
        ours = volref.render(with_profile(scene_name, caster_rules(kw))).rgba
        assert np.abs(ours - image).max() <= MATCH
    # 2. fit names them (and no other rule).
    r = volref.fit(image, SCENES[scene_name])
    assert r["explained"], r["verdict"]
    assert r["rules"] == expected, r["verdict"]
    assert r["image_model"] == model
    assert r["unexplained_pixels"] <= 0.001 * r["pixels"]
    assert r["residual"].shape == image.shape[:2]


def test_unseen_combinations_are_explained():
    """Random pairs and triples of rules the list above does not hold: fit explains each, and a render
    with the rules it names gives the caster's image."""
    rng = random.Random(29)
    choices = {
        "placement": [dict(placement="from-entry", first=0.0), dict(placement="from-entry", first=0.5),
                      dict(placement="from-entry", first=1.0)],
        "ray_box": [dict(ray_box="texel")],
        "correction": [dict(correction="none"), dict(correction="extinction")],
        "table": [dict(table=256), dict(table=1024)],
        "termination": [dict(termination=("alpha_above", 0.99)), dict(termination=("alpha_at_least", 0.999))],
    }
    for trial in range(5):
        dims = rng.sample(sorted(choices), 2 if trial < 3 else 3)
        kw = {}
        for d in dims:
            kw.update(rng.choice(choices[d]))
        scene_name = rng.choice(["hazy", "clear"])
        image = ec.render(SCENES[scene_name], **kw)
        r = volref.fit(image, SCENES[scene_name])
        assert r["explained"], (kw, r["verdict"])
        named = volref.render(with_profile(scene_name, r["rules"])).rgba
        assert np.abs(named - image).max() <= 1e-4, (kw, r["rules"])


@pytest.mark.parametrize("bug", ["half-texel-shift", "colour-missing-correction", "wrong-order", "double-premultiply",
                                 "flip-data-z"])
@pytest.mark.parametrize("scene_name", ["hazy", "clear"])
def test_planted_bugs_stay_unexplained(bug, scene_name):
    r = volref.fit(ec.render(SCENES[scene_name], bug=bug), SCENES[scene_name])
    assert not r["explained"], r["verdict"]
    assert r["rules"] == {} and r["image_model"] is None
    assert r["unexplained_pixels"] > 0.05 * r["pixels"]
    assert "a bug, or a convention volref does not model" in r["verdict"]


def test_reference_rules_are_the_reference():
    """The reference preset's rules (central-in-domain gradients, optical depth) rendered by the profile
    integrator give the reference integrators' image to rounding, shaded or not; the caster with a clamped
    central gradient and clamped shading is matched by those rules written as a profile."""
    for name in ("shaded", "shaded-phong-two-lights", "hazy"):
        scene = SCENES[name]
        ref = volref.render(scene).rgba
        rules = {k: v for k, v in volref.profiles()["reference"].items()}
        assert np.abs(volref.render(with_profile(name, rules)).rgba - ref).max() <= 1e-12
    kw = dict(gradient="central", clamp_shaded=True, normal="+gradient")
    ours = volref.render(with_profile("shaded", caster_rules(kw))).rgba
    assert np.abs(ours - ec.render(SCENES["shaded"], **kw)).max() <= MATCH


def test_alpha_agrees_colour_differs():
    image = ec.render(SCENES["hazy"], bug="colour-missing-correction")
    r = volref.fit(image, SCENES["hazy"])
    assert not r["explained"]
    assert r["alpha_agrees_colour_differs"]
    assert "alpha agrees, colour differs" in r["verdict"]


def write_scene_files(tmp_path, scene_name):
    """The dict scene as files: the numpy volume as raw + sidecar, the scene as JSON."""
    scene = copy.deepcopy(SCENES[scene_name])
    vol = scene["volume"]["source"]
    vol.astype("<f4").tofile(tmp_path / "vol.raw")
    (tmp_path / "vol.raw.json").write_text(json.dumps({"dims": [vol.shape[2], vol.shape[1], vol.shape[0]], "type": "f32"}))
    scene["volume"]["source"] = {"file": "vol.raw", "format": "raw"}
    (tmp_path / "scene.json").write_text(json.dumps(scene))
    return tmp_path / "scene.json"


def test_cli_fit_with_scene(tmp_path):
    cli = os.environ.get("VOLREF_CLI")
    if not cli:
        pytest.skip("VOLREF_CLI not set (ctest sets it)")
    scene = write_scene_files(tmp_path, "hazy")
    volref.write_image(tmp_path / "gpu.exr", ec.render(SCENES["hazy"], placement="from-entry", first=0.0, ray_box="texel"))
    p = subprocess.run([cli, "compare", str(tmp_path / "gpu.exr"), "--fit", "--scene", str(scene), "--json",
                        "--heatmap", str(tmp_path / "res.png")], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    j = json.loads(p.stdout)
    assert j["explained"] is True
    assert j["rules"] == {"placement": "from-entry", "first": 0.0, "ray_box": "texel"}
    assert j["unexplained_pixels"] == 0 and j["residual_max"] <= 1e-4
    assert (tmp_path / "res.png").stat().st_size > 0
    # A bug: exit 1, explained false, no rules named.
    volref.write_image(tmp_path / "bug.exr", ec.render(SCENES["hazy"], bug="wrong-order"))
    p = subprocess.run([cli, "compare", str(tmp_path / "bug.exr"), "--fit", "--scene", str(scene), "--json"],
                       capture_output=True, text=True)
    assert p.returncode == 1, p.stderr
    j = json.loads(p.stdout)
    assert j["explained"] is False and j["rules"] == {}
    # Text: the verdict line.
    p = subprocess.run([cli, "compare", str(tmp_path / "gpu.exr"), "--fit", "--scene", str(scene)], capture_output=True, text=True)
    assert "placement from-entry, first 0, ray_box texel explain 100.00% of pixels; 0 pixels unexplained" in p.stdout, p.stdout


def test_heatmap_is_the_max_abs_difference(tmp_path):
    a = volref.render(SCENES["hazy"]).rgba
    b = ec.render(SCENES["hazy"], correction="none")
    h = volref.heatmap(a, b, path=tmp_path / "h.png")
    assert h.shape == a.shape[:2]
    assert np.array_equal(h, np.abs(a - b.astype(np.float64)).max(axis=2))
    assert (tmp_path / "h.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_write_image_round_trips(tmp_path):
    r = volref.render(SCENES["hazy"])
    volref.write_image(tmp_path / "r.exr", r)
    c = volref.compare(tmp_path / "r.exr", r.rgba.astype(np.float32))
    assert c["overall"]["max_abs"] == 0.0
    volref.write_image(tmp_path / "n.exr", r.rgba)
    assert volref.compare(tmp_path / "n.exr", r.rgba.astype(np.float32))["overall"]["max_abs"] == 0.0
    with pytest.raises(volref.Error, match="image"):
        volref.write_image(tmp_path / "x.exr", np.zeros((4, 4)))


def test_profiles_are_presets_as_rules():
    p = volref.profiles()
    assert set(p) >= {"reference", "vtk-gpu", "glsl-basic", "ospray", "cuda-curvilinear", "vtk-cpu", "vtk-js", "fast"}
    assert p["vtk-gpu"]["placement"] == "from-entry" and p["vtk-gpu"]["first"] == 1.0 and p["vtk-gpu"]["table"] == 1024
    assert p["vtk-js"] == {"base": "vtk-js"}
    # Every rule dict is a valid render.profile, and renders its preset's image.
    for name in ("reference", "vtk-gpu", "ospray"):
        by_name = copy.deepcopy(SCENES["hazy"])
        by_name["render"]["profile"] = name
        by_rules = copy.deepcopy(SCENES["hazy"])
        by_rules["render"]["profile"] = p[name]
        a, b = volref.render(by_name), volref.render(by_rules)
        assert np.abs(a.rgba - b.rgba).max() <= 1e-12, name
        assert volref.render(b.scene).rgba.tobytes() == b.rgba.tobytes()  # the resolved scene renders again


def test_repr_png():
    r = volref.render(SCENES["hazy"])
    png = r._repr_png_()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    assert int.from_bytes(png[16:20], "big") == r.width and int.from_bytes(png[20:24], "big") == r.height
    # The IDAT: filter byte 0 then RGBA8 = round(255 clamp(c / a)), alpha round(255 a) (background transparent).
    n = int.from_bytes(png[33:37], "big")
    assert png[37:41] == b"IDAT"
    raw = np.frombuffer(zlib.decompress(png[41:41 + n]), np.uint8).reshape(r.height, 1 + 4 * r.width)
    assert (raw[:, 0] == 0).all()
    px = raw[:, 1:].reshape(r.height, r.width, 4)
    a = r.rgba[..., 3]
    assert np.array_equal(px[..., 3], np.round(np.clip(a, 0, 1) * 255).astype(np.uint8))


def test_numpy_volumes_write_no_file(tmp_path, monkeypatch):
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    monkeypatch.setenv("TMPDIR", str(tmp))
    r = volref.render(SCENES["hazy"])
    assert list(tmp.iterdir()) == []
    monkeypatch.setenv("TMPDIR", str(tmp_path / "does-not-exist"))  # no temporary folder is needed
    assert volref.render(SCENES["hazy"]).rgba.tobytes() == r.rgba.tobytes()
    assert r.scene["volume"]["source"] is SCENES["hazy"]["volume"]["source"]


def test_trace_rows_line_up_with_skipping_on_and_off():
    n = 32
    z, y, x = np.mgrid[0:n, 0:n, 0:n].astype(np.float32)
    vol = np.exp(-((x - 20) ** 2 + (y - 16) ** 2 + (z - 16) ** 2) / 12).astype(np.float32)
    scene = {"volume": {"source": vol, "transfer": {"color": [[0, 1, 1, 1]], "opacity": [[0, 0], [0.3, 0], [1, 0.8]]}},
             "camera": {"type": "orthographic", "eye": [15.5, 15.5, 60], "target": [15.5, 15.5, 0], "up": [0, 1, 0], "height": 40},
             "image": {"width": 16, "height": 16}, "render": {"step": 0.5}}
    on = volref.trace(scene, (10, 8), skipping=True)
    off = volref.trace(scene, (10, 8), skipping=False)
    assert len(on) < len(off)  # skipping passes over empty macrocells
    rows = {(int(r["interval"]), int(r["segment"])): float(r["t"]) for r in off}
    for r in on:
        key = (int(r["interval"]), int(r["segment"]))
        assert rows[key] == float(r["t"])
    # The segment index is floor((t - t_entry) / h): midpoints sit half a step into their segment.
    t_entry = float(off[0]["t0"])
    for r in off[:-1]:
        assert int(r["segment"]) == int(np.floor((float(r["t"]) - t_entry) / 0.5 + 1e-9))
