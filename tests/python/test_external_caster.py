"""An external float32 ray caster (tests/python/external_caster.py, written from the docs only) against
volref's presets (docs/conventions.md section 9): with the switches of a preset it must give volref's
image to float32 rounding, each preset rule must be needed (changing it alone moves the image well past
that), and each planted shader bug and each output model must be clearly visible.

Run: PYTHONPATH=build/python /usr/bin/python3 -m pytest -q -p no:cacheprovider tests/python/test_external_caster.py
"""
import copy
import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import external_caster as ec  # noqa: E402
import volref  # noqa: E402

# float32 against double: measured at most 3.3e-6 on every case below (samples per ray <= 60). The
# documented bound of docs/python.md (N samples x 32 roundings x 2^-24) would be 1.1e-4 here; 2e-5
# keeps a 6x margin over what is measured while staying far below any convention slip (>= 2.9e-5,
# and >= 2e-4 for every rule checked in test_each_preset_rule_is_needed).
TOLERANCE = 2e-5
NEEDED = 1e-4  # a changed rule must move the image at least this far from volref's
VISIBLE = 1e-3  # a planted bug or an output model must change the image at least this far

N = 16
_z, _y, _x = np.mgrid[0:N, 0:N, 0:N].astype(np.float32)  # indexed [k, j, i]: x fastest
# Two blobs, off centre in x, y and z (so flips and shifts show), small (< 0.15) on the domain's faces.
VOLUME = (np.exp(-((_x - 7) ** 2 + (_y - 8.5) ** 2 + (_z - 9) ** 2) / 16)
          + 0.6 * np.exp(-((_x - 10) ** 2 + (_y - 5) ** 2 + (_z - 5) ** 2) / 6)).astype(np.float32)
COLOUR = [[0, .1, .2, .9], [.5, .9, .5, .2], [1, 1, .9, .6]]
# CLEAR: transparent below 0.15 (so near the faces), opaque from 0.6: rays terminate.
CLEAR = [[0, 0], [.15, 0], [.6, 1], [1, 1]]
# HAZY: opacity 0.05 on the faces (the entry and exit samples count), a shell of 5e-5 (below vtk-gpu's
# 1e-4 correction floor), 0.9 inside.
HAZY = [[0, .05], [.05, .05], [.1, 5e-5], [.2, 5e-5], [.6, .9], [1, .9]]
OBLIQUE = {"type": "perspective", "eye": [24, 19, 30], "target": [7.5, 7.5, 7.5], "up": [0, 1, 0], "fov_y": 30}
# Along -z: every chord through the volume is 15 = 30 steps exactly (an integer L / h).
AXIS = {"type": "orthographic", "eye": [7.5, 7.5, 30], "target": [7.5, 7.5, 0], "up": [0, 1, 0], "height": 18}


def make_scene(opacity=CLEAR, camera=OBLIQUE, **changes):
    scene = {"volume": {"source": VOLUME, "transfer": {"color": COLOUR, "opacity": opacity}},
             "camera": camera, "image": {"width": 48, "height": 40}, "render": {"step": 0.5}}
    for path, value in changes.items():  # "volume.shading" -> scene["volume"]["shading"]
        *keys, last = path.split(".")
        node = scene
        for key in keys:
            node = node[key]
        node[last] = value
    return scene


SCENES = {
    "clear": make_scene(),
    "hazy": make_scene(HAZY),
    "axis": make_scene(HAZY, AXIS),
    "clear-mip": make_scene(**{"render.projection": "mip"}),
    "hazy-unit-0.5": make_scene(HAZY, **{"volume.transfer.opacity_unit_distance": 0.5}),
    "shaded": make_scene(**{"volume.shading": {"model": "blinn-phong"}}),
    "shaded-phong-two-lights": make_scene(HAZY, **{
        "volume.shading": {"model": "phong", "ka": .2, "kd": .6, "ks": .4, "n": 7, "kl": .02},
        "lights": [{"type": "headlight", "color": [1, .9, .8]},
                   {"type": "directional", "direction": [1, 2, .5], "color": [.3, .3, .5]}]}),
    "shaded-two-sided-phong": make_scene(HAZY, **{"volume.shading": {"model": "phong", "two_sided": True},
                                                  "lights": [{"type": "directional", "direction": [1, 2, .5]}]}),
    "shaded-two-sided-blinn-phong": make_scene(HAZY, **{"volume.shading": {"two_sided": True, "ks": .5}}),
    "default-transfer": make_scene(**{"volume.transfer": {}}),
    "moved-anisotropic-grid": make_scene(**{"volume.origin": [-3, 2, 1], "volume.spacing": [.8, 1, .9],
                                            "render.step": .7}),
    "early-termination-0.9": make_scene(**{"render.early_termination": 0.9}),
}

_volref_images = {}


def volref_image(scene_name, profile):
    key = (scene_name, profile)
    if key not in _volref_images:
        scene = copy.deepcopy(SCENES[scene_name])
        scene["render"]["profile"] = profile
        _volref_images[key] = volref.render(scene).rgba
    return _volref_images[key]


def caster_image(scene_name, profile, **changes):
    return ec.render(SCENES[scene_name], **{**ec.PRESETS[profile], **changes})


def max_diff(a, b):
    return float(np.max(np.abs(np.asarray(a, np.float64) - np.asarray(b, np.float64))))


MATCHES = [
    ("reference", "clear", {}), ("reference", "hazy", {}), ("reference", "axis", {}),
    ("reference", "clear-mip", {}), ("reference", "hazy-unit-0.5", {}), ("reference", "shaded", {}),
    ("reference", "shaded-phong-two-lights", {}), ("reference", "shaded-two-sided-phong", {}),
    ("reference", "shaded-two-sided-blinn-phong", {}), ("reference", "default-transfer", {}),
    ("reference", "moved-anisotropic-grid", {}),
    # section 4: early termination "after the segment where A first exceeds A_max"
    ("reference", "early-termination-0.9", {"termination": ("alpha_above", 0.9)}),
    ("vtk-gpu", "clear", {}), ("vtk-gpu", "hazy", {}), ("vtk-gpu", "axis", {}), ("vtk-gpu", "clear-mip", {}),
    ("vtk-gpu", "hazy-unit-0.5", {}), ("vtk-gpu", "moved-anisotropic-grid", {}),
    ("ospray", "clear", {}), ("ospray", "hazy", {}), ("ospray", "axis", {}), ("ospray", "clear-mip", {}),
    # ospray's alpha = 1 - exp(-a d) has no l: the scene's opacity_unit_distance does not change its image
    ("ospray", "hazy-unit-0.5", {}),
]


@pytest.mark.parametrize("profile, scene_name, changes", MATCHES,
                         ids=[f"{p}-{s}" for p, s, _ in MATCHES])
def test_caster_matches_volref_preset(profile, scene_name, changes):
    reference = volref_image(scene_name, profile)
    image = caster_image(scene_name, profile, **changes)
    assert image.dtype == np.float32 and image.shape == (40, 48, 4)
    diff = max_diff(image, reference)
    print(f"{profile} {scene_name}: max abs {diff:.3g}")
    assert diff < TOLERANCE, f"{profile} on {scene_name}: max abs difference {diff:.3g}"
    assert reference[..., 3].max() > 0.5 and (reference[..., 3] > 0).mean() > 0.25  # not a vacuous image


def test_the_scenes_exercise_termination():
    # vtk-gpu's and ospray's termination rules stop rays that would otherwise add more than NEEDED
    for profile in ("vtk-gpu", "ospray"):
        assert max_diff(caster_image("clear", profile, termination=None), volref_image("clear", profile)) > NEEDED


# Each rule of a preset changed alone, on a scene where it shows: it must move the image past NEEDED.
RULES = [
    ("vtk-gpu", "hazy", {"first": 0}),  # one step inside, not at the entry
    ("vtk-gpu", "hazy", {"placement": "midpoints"}),
    ("vtk-gpu", "axis", {"step_count": "before-exit"}),  # the sample at t1 when L / h is an integer
    ("vtk-gpu", "hazy", {"step_count": "before-exit"}),  # at least one sample on chords shorter than h
    ("vtk-gpu", "clear", {"table": 0}),
    ("vtk-gpu", "clear", {"table": 256}),
    ("vtk-gpu", "hazy", {"correction_floor": 0}),  # entries <= 1e-4 uncorrected
    ("vtk-gpu", "clear", {"termination": None}),
    ("vtk-gpu", "clear", {"ray_box": "texel"}),
    ("ospray", "clear", {"correction": "pow"}),
    ("ospray", "hazy", {"placement": "from-entry", "first": 0.5}),
    ("ospray", "clear", {"termination": None}),
    ("reference", "hazy", {"placement": "from-entry", "first": 0.5}),
    ("reference", "hazy", {"placement": "from-exit", "first": 0.5}),
    ("reference", "clear", {"table": 1024}),
    ("reference", "clear", {"ray_box": "texel"}),
    ("reference", "clear", {"correction": "none"}),
    ("reference", "clear", {"correction": "extinction"}),
]


@pytest.mark.parametrize("profile, scene_name, changes", RULES,
                         ids=[f"{p}-{s}-{'-'.join(f'{k}={v}' for k, v in c.items())}" for p, s, c in RULES])
def test_each_preset_rule_is_needed(profile, scene_name, changes):
    diff = max_diff(caster_image(scene_name, profile, **changes), volref_image(scene_name, profile))
    print(f"{profile} {scene_name} {changes}: max abs {diff:.3g}")
    assert diff > NEEDED


def _constant_scene(opacity):
    volume = np.ones((6, 6, 6), np.float32)
    camera = {"type": "orthographic", "eye": [2.5, 2.5, 20], "target": [2.5, 2.5, 0], "up": [0, 1, 0], "height": 2}
    return {"volume": {"source": volume, "transfer": {"color": [[0, 1, 1, 1]], "opacity": [[0, opacity]]}},
            "camera": camera, "image": {"width": 4, "height": 4}, "render": {"step": 0.5}}


@pytest.mark.parametrize("placement, first, step_count, samples", [
    ("from-entry", 0, "through-exit", 11),  # L / h = 10: t0, t0 + h, ..., t1
    ("from-entry", 1, "through-exit", 10),  # t0 + h .. t1 (vtk-gpu)
    ("from-entry", 0.5, "through-exit", 10),
    ("from-entry", 0, "before-exit", 10),
    ("from-entry", 1, "before-exit", 9),
    ("from-entry", 0.5, "before-exit", 10),
    ("from-exit", 0, "through-exit", 11),
    ("midpoints", 0, "through-exit", 10),
])
def test_sample_counts_closed_form(placement, first, step_count, samples):
    # a constant medium, chord 5 along z, uncorrected a = 0.1: A = 1 - 0.9^samples
    image = ec.render(_constant_scene(0.1), placement=placement, first=first, step_count=step_count,
                      correction="none")
    assert np.allclose(image[..., 3], 1 - 0.9 ** samples, rtol=0, atol=2e-6)


def test_ray_box_texel_and_corrections_closed_form():
    scene = _constant_scene(0.5)
    # pow over the chord: A = 1 - 0.5^L (l = 1), L = 5 (domain) or 6 (texel: half a voxel more at each end)
    assert np.allclose(ec.render(scene)[..., 3], 1 - 0.5 ** 5, atol=2e-6)
    assert np.allclose(ec.render(scene, ray_box="texel")[..., 3], 1 - 0.5 ** 6, atol=2e-6)
    assert np.allclose(ec.render(scene, correction="extinction")[..., 3], 1 - np.exp(-0.5 * 5), atol=2e-6)
    # volref agrees with the domain box
    assert max_diff(ec.render(scene), volref.render(scene).rgba) < TOLERANCE


@pytest.mark.parametrize("bug", ec.BUGS)
def test_planted_bug_is_visible(bug):
    clean = caster_image("clear", "reference")
    buggy = caster_image("clear", "reference", bug=bug)
    diff = max_diff(buggy, clean)
    print(f"bug {bug}: max abs {diff:.3g}")
    assert diff > VISIBLE
    assert max_diff(buggy, volref_image("clear", "reference")) > VISIBLE


@pytest.mark.parametrize("model", ec.OUTPUT_MODELS)
def test_output_model_is_visible(model):
    clean = caster_image("clear", "reference")
    image = caster_image("clear", "reference", output=model)
    diff = max_diff(image, clean)
    print(f"output {model}: max abs {diff:.3g}")
    assert diff > VISIBLE
    assert np.array_equal(ec.apply_output_model(clean, model), image)


def test_output_models_invert():
    clean = caster_image("clear", "reference")
    assert np.array_equal(ec.apply_output_model(ec.apply_output_model(clean, "flip"), "flip"), clean)
    assert np.array_equal(ec.apply_output_model(ec.apply_output_model(clean, "bgra"), "bgra"), clean)
    un = ec.apply_output_model(clean, "unpremultiplied")
    assert np.allclose(un[..., :3] * un[..., 3:], clean[..., :3], atol=1e-6)


@pytest.mark.parametrize("scene_name", [name for name in SCENES if name.startswith("shaded")])
def test_shading_is_visible(scene_name):
    # the shaded matches above are not vacuous: shading (and one- vs two-sided lighting) shows
    scene = SCENES[scene_name]
    flipped = copy.deepcopy(scene)
    flipped["volume"]["shading"]["two_sided"] = not scene["volume"]["shading"].get("two_sided", False)
    shaded = ec.render(scene)
    assert max_diff(shaded, ec.render(scene, shading=False)) > VISIBLE
    assert max_diff(shaded, ec.render(flipped)) > VISIBLE
