"""The Python module `volref` (python/, docs/python.md) against the command line and closed forms.

Run by ctest (tests/CMakeLists.txt: python_module) as
    PYTHONPATH=BUILD/python VOLREF_CLI=BUILD/cli/volref /usr/bin/python3 -m pytest tests/python
"""
import json
import os
import pathlib
import pydoc
import subprocess
import sys
import threading
import time
import _thread

import numpy as np
import OpenImageIO as oiio
import pytest

import volref

SOURCE = pathlib.Path(os.environ.get("VOLREF_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
CLI = os.environ.get("VOLREF_CLI", str(SOURCE / "build" / "cli" / "volref"))
SCENES = SOURCE / "reference_scenes"
SMALL = ["image.width=48", "image.height=40"]  # keeps each reference scene fast, non-square on purpose


def cli(*args, check=True):
    r = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True)
    if check and r.returncode != 0:
        raise AssertionError(f"volref {' '.join(map(str, args))}: {r.returncode}\n{r.stderr}")
    return r


def read_exr(path):
    inp = oiio.ImageInput.open(str(path))
    assert inp, oiio.geterror()
    spec = inp.spec()
    pixels = inp.read_image(oiio.FLOAT)
    inp.close()
    return list(spec.channelnames), pixels


def bits(a):
    """float32 values as their bit patterns (so that -0 != 0 and NaN == NaN compare as stored)."""
    return np.ascontiguousarray(a, dtype=np.float32).view(np.uint32)


def cli_render(scene, out, *sets, flags=()):
    args = ["render", scene, "-o", out, *flags]
    for s in sets:
        args += ["--set", s]
    cli(*args)
    return read_exr(out)


def write_raw(path, array, **sidecar):
    """A raw file + JSON sidecar (docs/formats.md) holding `array` indexed [k, j, i]."""
    types = {"uint8": "u8", "int8": "i8", "uint16": "u16", "int16": "i16", "uint32": "u32", "int32": "i32",
             "float32": "f32", "float64": "f64"}
    a = np.ascontiguousarray(array)
    a.tofile(path)
    nz, ny, nx = a.shape
    meta = {"dims": [nx, ny, nz], "type": types[a.dtype.name],
            "endian": "big" if a.dtype.byteorder == ">" else "little", **sidecar}
    pathlib.Path(str(path) + ".json").write_text(json.dumps(meta))
    return path


def toy_volume(dtype, shape=(5, 6, 7), seed=1):
    """A volume that differs along every axis, in the dtype's range."""
    rng = np.random.default_rng(seed)
    if np.dtype(dtype).kind == "f":
        return rng.uniform(-1, 2, size=shape).astype(dtype)
    info = np.iinfo(dtype)
    return rng.integers(max(info.min, -1000), min(info.max, 1000), size=shape, endpoint=True).astype(dtype)


def volume_scene(source, **extra):
    lo, hi = (-1.0, 2.0)
    transfer = {"color": [[lo, 0.1, 0.2, 0.9], [hi, 1.0, 0.6, 0.1]], "opacity": [[lo, 0.0], [hi, 0.6]],
                "opacity_unit_distance": 2.0}
    scene = {"volume": {"source": source, "transfer": transfer},
             "camera": {"type": "perspective", "eye": [14, -9, 17], "target": [3, 2.5, 2], "up": [0, 0, 1], "fov_y": 40},
             "image": {"width": 36, "height": 30}, "render": {"step": 0.37}}
    scene["volume"].update(extra)
    return scene


# ---- render equals the CLI's EXR -------------------------------------------------------------------

@pytest.mark.parametrize("name", ["default", "levoy-lecture", "constant-box", "gaussian-mip", "sphere-first-hit",
                                  "linear-xray", "nrrd-gaussian", "two-volumes-clipped", "shaded-composite",
                                  "region-boundaries", "radar-sweep"])
def test_render_equals_cli_exr_bit_for_bit(tmp_path, name):
    scene = SCENES / f"{name}.json"
    channels, exr = cli_render(scene, tmp_path / "cli.exr", *SMALL)
    r = volref.render(scene, overrides=SMALL)
    assert r.channels == channels
    assert r.pixels.shape == exr.shape == (40, 48, len(channels))
    assert np.array_equal(bits(r.pixels), bits(exr))
    assert np.array_equal(r.rgba, r.pixels[:, :, :4])
    if "Z" in channels:
        assert np.array_equal(bits(r.depth), bits(exr[:, :, channels.index("Z")]))
    else:
        assert r.depth is None


def test_render_error_channel_equals_cli(tmp_path):
    scene = SCENES / "default.json"
    channels, exr = cli_render(scene, tmp_path / "cli.exr", *SMALL, flags=["--error"])
    r = volref.render(str(scene), overrides={"image.width": 48, "image.height": 40}, error=True, threads=2)
    assert r.channels == channels == ["R", "G", "B", "A", "error"]
    assert np.array_equal(bits(r.pixels), bits(exr))
    assert np.array_equal(r.error, r.pixels[:, :, 4])


def test_any_thread_count_and_no_skipping_give_the_same_bits():
    scene = SCENES / "shaded-composite.json"
    a = volref.render(scene, overrides=SMALL, threads=1)
    b = volref.render(scene, overrides=SMALL, skipping=False)
    assert np.array_equal(a.pixels, b.pixels)


def test_scene_as_dict_and_json_text_equal_the_file():
    text = (SCENES / "levoy-lecture.json").read_text()
    a = volref.render(SCENES / "levoy-lecture.json")
    b = volref.render(json.loads(text))
    c = volref.render(text)
    assert np.array_equal(a.pixels, b.pixels) and np.array_equal(a.pixels, c.pixels)


def test_result_views_share_one_buffer_row_0_on_top():
    r = volref.render(SCENES / "linear-xray.json", overrides=SMALL)
    assert r.rgba.dtype == np.float64 and r.rgba.shape == (r.height, r.width, 4)
    assert np.shares_memory(r.rgba, r.pixels)
    # linear-xray: a field increasing with y seen along -z; rows further down see smaller values.
    assert r.rgba[0, :, 0].mean() != r.rgba[-1, :, 0].mean()


@pytest.mark.parametrize("name", ["default", "two-volumes-clipped", "radar-sweep", "levoy-isosurfaces"])
def test_resolved_scene_renders_the_same(name):
    r = volref.render(SCENES / f"{name}.json", overrides=SMALL)
    s = r.scene
    assert s["image"]["width"] == 48 and "render" in s and "lights" in s
    again = volref.render(s)
    assert np.array_equal(again.pixels, r.pixels)
    assert again.scene == s


# ---- numpy volumes ---------------------------------------------------------------------------------

DTYPES = ["uint8", "int8", "uint16", "int16", "uint32", "int32", "float32", "float64"]


@pytest.mark.parametrize("dtype", DTYPES)
def test_numpy_volume_equals_the_same_volume_read_from_a_file(tmp_path, dtype):
    a = toy_volume(dtype)
    lo, hi = float(a.min()), float(a.max())
    extra = {"spacing": [1.0, 0.8, 1.3], "origin": [0.5, -0.25, 0.0],
             "transfer": {"color": [[lo, 0.1, 0.2, 0.9], [hi, 1.0, 0.6, 0.1]], "opacity": [[lo, 0.0], [hi, 0.6]],
                          "opacity_unit_distance": 2.0}}
    from_file = volref.render(volume_scene(str(write_raw(tmp_path / "v.raw", a)), **extra))
    from_array = volref.render(volume_scene(a, **extra))
    assert from_array.rgba[..., 3].max() > 0.05  # something is drawn
    assert np.array_equal(from_array.pixels, from_file.pixels)
    assert from_array.scene["volume"]["source"] is a


def test_numpy_volume_on_a_shell_equals_the_same_file(tmp_path):
    # A shell places the samples itself (beam space): the array is its data as a file's would be.
    a = toy_volume("float32", shape=(6, 5, 7))
    shell = {"type": "cylindrical", "center": [3, 2.5, 0], "radius": [1, 4], "angle": [0, 120], "height": [0, 5]}
    from_file = volref.render(volume_scene(str(write_raw(tmp_path / "s.raw", a)), bounds=shell))
    from_array = volref.render(volume_scene(a, bounds=shell))
    assert from_array.rgba[..., 3].max() > 0.05  # something is drawn
    assert np.array_equal(from_array.pixels, from_file.pixels)


def test_numpy_volume_in_any_layout_and_byte_order(tmp_path):
    a = toy_volume("float32", shape=(6, 5, 7))
    reference = volref.render(volume_scene(a)).pixels
    fortran = np.asfortranarray(a)
    big = a.astype(">f4")
    strided = np.zeros((6, 10, 7), np.float32)
    strided[:, ::2, :] = a
    for variant in (fortran, big, strided[:, ::2, :], a.transpose(2, 1, 0).copy().transpose(2, 1, 0)):
        assert np.array_equal(volref.render(volume_scene(variant)).pixels, reference)


def test_numpy_axis_order_is_k_j_i():
    # array[k, j, i] = i + 10 j + 100 k is the linear field x + 10 y + 100 z on the unit grid.
    nz, ny, nx = 4, 5, 6
    k, j, i = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
    a = (i + 10 * j + 100 * k).astype(np.float64)
    field = {"field": "linear", "coefficients": [1, 10, 100, 0], "dims": [nx, ny, nz]}
    scene = lambda src: {"volume": {"source": src, "transfer": {"opacity": [[0, 0], [600, 0.5]]}},
                         "image": {"width": 24, "height": 20}, "render": {"projection": "mip"}}
    assert np.array_equal(volref.render(scene(a)).pixels, volref.render(scene(field)).pixels)
    t = volref.trace(scene(a), (12, 10))
    assert len(t) > 0
    np.testing.assert_allclose(t["value"], t["x"] + 10 * t["y"] + 100 * t["z"], rtol=0, atol=1e-9)


def test_numpy_constant_volume_closed_form():
    # reference_scenes/constant-box.json with the constant field as an array: a 10-unit box seen along -z,
    # opacity 0.2 per unit length: alpha = 1 - 0.8^10 at every pixel, colour (1, 0.5, 0.25) alpha, whatever the step.
    scene = json.loads((SCENES / "constant-box.json").read_text())
    scene["volume"]["source"] = np.ones((11, 11, 11), np.uint8)
    alpha = 1 - 0.8 ** 10
    for step in (0.3, 1.0, 0.07):
        r = volref.render(scene, overrides={"render.step": step})
        np.testing.assert_allclose(r.rgba[..., 3], alpha, rtol=0, atol=1e-14)
        np.testing.assert_allclose(r.rgba[..., :3], np.broadcast_to([alpha, 0.5 * alpha, 0.25 * alpha], (64, 64, 3)),
                                   rtol=0, atol=1e-14)


def test_numpy_nan_volume_is_transparent_and_counted():
    a = np.ones((6, 6, 6), np.float32)
    a[2, 3, 1] = np.nan
    a[4, 0, 5] = np.inf
    with pytest.warns(RuntimeWarning, match="2 non-finite voxels"):
        r = volref.render(volume_scene(a))
    assert r.non_finite_voxels == 2 and np.isfinite(r.pixels).all()
    with pytest.warns(RuntimeWarning):
        empty = volref.render(volume_scene(np.full((3, 3, 3), np.nan)))
    assert empty.non_finite_voxels == 27 and not empty.rgba.any()


def test_several_numpy_volumes():
    a, b = toy_volume("float32"), toy_volume("int16", seed=2).astype(np.float32) / 1000
    vol = lambda src, t: {"source": src, "transfer": {"opacity": [[-1, 0], [2, 0.5]]}, "transform": {"translate": t}}
    scene = {"volumes": [vol(a, [0, 0, 0]), vol(b, [2, 1, 0])], "image": {"width": 24, "height": 24}}
    r = volref.render(scene)
    assert r.rgba[..., 3].max() > 0
    assert r.scene["volumes"][0]["source"] is a and r.scene["volumes"][1]["source"] is b


# ---- compare equals `volref compare --json` --------------------------------------------------------

def test_compare_equals_cli_json(tmp_path):
    ref, half = tmp_path / "ref.exr", tmp_path / "half.exr"
    cli_render(SCENES / "default.json", ref, *SMALL)
    cli_render(SCENES / "default.json", half, *SMALL, "volume.transfer.opacity_unit_distance=0.5")
    png = tmp_path / "ref.png"
    cli("render", SCENES / "default.json", "-o", png, "--set", SMALL[0], "--set", SMALL[1])
    for a, b, tol in ((ref, half, 0.002), (ref, ref, 0.0), (ref, png, 0.0)):
        expected = json.loads(cli("compare", a, b, "--tolerance", tol, "--json", check=False).stdout)
        got = volref.compare(str(a), str(b), tolerance=tol)
        assert got == expected
    # numpy inputs: the same metrics as the files (only the inputs' names differ)
    _, ea = read_exr(ref)
    _, eb = read_exr(half)
    got = volref.compare(ea, eb, tolerance=0.002)
    expected = json.loads(cli("compare", ref, half, "--tolerance", 0.002, "--json", check=False).stdout)
    for key in ("channels", "overall", "pixels", "pixels_over", "fraction_over", "within_tolerance", "tolerance"):
        assert got[key] == expected[key], key
    assert got["within_tolerance"] is False and got["overall"]["ssim"] < 1


def test_compare_error_channel_equals_cli(tmp_path):
    a, b = tmp_path / "a.exr", tmp_path / "b.exr"
    cli_render(SCENES / "default.json", a, *SMALL, flags=["--error"])
    cli_render(SCENES / "default.json", b, *SMALL, "render.step=0.25")
    expected = json.loads(cli("compare", a, b, "--tolerance-from-error", "--json", check=False).stdout)
    assert volref.compare(a, b, error=True) == expected
    # numpy inputs with the error channel given as an array
    channels, exr = read_exr(a)
    got = volref.compare(exr[..., :4], b, error=(exr[..., channels.index("error")], None))
    assert got["overall"] == expected["overall"] and got["tolerance"] == expected["tolerance"]
    # a RenderResult carries its own error channel
    ra = volref.render(SCENES / "default.json", overrides=SMALL, error=True)
    got = volref.compare(ra, b, error=True)
    assert got["overall"] == volref.compare(ra.rgba, b, error=(ra.error, None))["overall"]
    assert got["a"]["description"] == "48x40, float, premultiplied, error channel"


def test_compare_numpy_quantization_and_identity():
    rng = np.random.default_rng(3)
    x = rng.uniform(0, 1, size=(16, 20, 4))
    same = volref.compare(x, x)
    assert same["within_tolerance"] and same["overall"]["max_abs"] == 0 and same["overall"]["psnr_db"] is None
    q = np.round(x * 255) / 255  # an RGBA8 framebuffer read back as float
    assert not volref.compare(x, q)["within_tolerance"]
    r = volref.compare(x, q, quantization=(None, 8))
    assert r["within_tolerance"] and r["tolerance"] == "0 + 8-bit quantisation of B"
    u8 = np.round(x * 255).astype(np.uint8)
    assert volref.compare(x, u8)["within_tolerance"]


# ---- trace ------------------------------------------------------------------------------------------

@pytest.mark.parametrize("name,pixel,sets", [("levoy-lecture", (32, 32), []), ("default", (20, 22), SMALL),
                                             ("shaded-composite", (24, 20), SMALL), ("gaussian-mip", (24, 20), SMALL),
                                             ("linear-xray", (10, 30), SMALL)])
def test_trace_last_row_is_the_rendered_pixel(name, pixel, sets):
    scene = SCENES / f"{name}.json"
    r = volref.render(scene, overrides=sets)
    t = volref.trace(scene, pixel, overrides=sets)
    assert len(t) > 0
    last = t[-1]
    x, y = pixel
    traced = np.array([last["acc_r"], last["acc_g"], last["acc_b"], last["acc_a"]])
    # bit for bit on the scalar path; the SIMD packet path agrees to its documented rounding (docs/trace.md)
    np.testing.assert_allclose(traced, r.rgba[y, x], rtol=0, atol=1e-12)


def test_trace_equals_cli_csv(tmp_path):
    scene = SCENES / "levoy-lecture.json"
    text = cli("trace", scene, "--pixel", "32,32").stdout.splitlines()
    t = volref.trace(scene, (32, 32))
    assert list(t.dtype.names) == text[0].split(",")
    for row, line in zip(t, text[1:]):
        for name, cell in zip(t.dtype.names, line.split(",")):
            assert row[name] == (int(cell) if name in ("sample", "cell_i", "cell_j", "cell_k") else float(cell))
    assert t["acc_a"][-1] == 0.6253600714236399  # docs/trace.md
    as_json = volref.trace(scene, (32, 32), format="json")
    assert as_json == json.loads(cli("trace", scene, "--pixel", "32,32", "--format", "json").stdout)


def test_trace_numpy_scene():
    scene = volume_scene(toy_volume("float32"))
    r = volref.render(scene, overrides={"render.order": "back-to-front"})
    t = volref.trace(scene, (18, 15), overrides={"render.order": "back-to-front"})
    assert t["acc_a"][-1] == pytest.approx(r.rgba[15, 18, 3], abs=1e-12)


# ---- explain ----------------------------------------------------------------------------------------

def test_explain_equals_cli_json():
    cases = [
        (("opacity-correction",), dict(opacity=0.5, length=0.25),
         ["--opacity", "0.5", "--length", "0.25"]),
        (("trilinear",), dict(corners=[5.0, 5.1, 5.2, 4.6, 4.9, 5.1, 5.3, 4.7], point=(0.2, 0.3, 0.8)),
         ["--corners", "5.0,5.1,5.2,4.6,4.9,5.1,5.3,4.7", "--point", "0.2,0.3,0.8"]),
        (("composite",), dict(samples=[(1, 0, 0, 0.5), (0, 0, 1, 0.5)], order="back-to-front", step=0.5),
         ["--samples", "1,0,0,0.5", "0,0,1,0.5", "--order", "back-to-front", "--step", "0.5"]),
        (("shade",), dict(normal=(0, 0, 1), light=["headlight", "1,0,1:1,0.5,0.5"], two_sided=True),
         ["--normal", "0,0,1", "--light", "headlight", "1,0,1:1,0.5,0.5", "--two-sided"]),
        (("ray",), dict(scene=str(SCENES / "levoy-lecture.json"), pixel=(32, 32)),
         ["--scene", SCENES / "levoy-lecture.json", "--pixel", "32,32"]),
        (("ray",), dict(scene=SCENES / "default.json", pixel=(3, 4), set=["image.width=8", "image.height=8"], no_skipping=True),
         ["--scene", SCENES / "default.json", "--pixel", "3,4", "--set", "image.width=8", "--set", "image.height=8", "--no-skipping"]),
    ]
    for (topic,), kwargs, args in cases:
        expected = json.loads(cli("explain", topic, *args, "--json").stdout)
        assert volref.explain(topic, **kwargs) == expected, topic


def test_explain_with_a_dict_scene_equals_the_file(tmp_path):
    path = SCENES / "levoy-lecture.json"
    expected = volref.explain("ray", scene=path, pixel=(32, 32))
    assert volref.explain("ray", scene=json.loads(path.read_text()), pixel=(32, 32)) == expected
    # trilinear at a point of a numpy volume = of the same volume read from a raw file by the CLI
    a = toy_volume("float32")
    scene_file = tmp_path / "scene.json"
    scene_file.write_text(json.dumps(volume_scene(str(write_raw(tmp_path / "v.raw", a)))))
    expected = json.loads(cli("explain", "trilinear", "--scene", scene_file, "--at", "2.5,1.25,3", "--json").stdout)
    assert volref.explain("trilinear", scene=volume_scene(a), at=(2.5, 1.25, 3.0)) == expected


# ---- errors: volref.Error, one line, nothing written ------------------------------------------------

def self_referencing_scene(ok_volume):
    d = {"volume": ok_volume}
    d["description"] = d  # issue 32: a dict that contains itself once recursed until the stack overflowed
    return d


def deep_list_scene(ok_volume, depth=200000):
    deep = []
    for _ in range(depth):
        deep = [deep]
    return {"volume": ok_volume, "description": deep}


def bad_inputs():
    ok_volume = {"source": np.zeros((4, 5, 6), np.float32), "transfer": {"opacity": [[0, 0], [1, 1]]}}
    return [
        ("self reference", lambda: volref.render(self_referencing_scene(ok_volume)), "contains itself"),
        ("deep list", lambda: volref.render(deep_list_scene(ok_volume)), "nested deeper than 256"),
        ("extreme number", lambda: volref.render({"volume": ok_volume, "render": {"step": 1e-300}}),
         "scene: render.step: the number 1e-300 is beyond volref's range"),
        ("device scene", lambda: volref.render("/dev/zero"), "it is a character device"),
        ("unknown key", lambda: volref.render({"volume": ok_volume, "bogus": 1}), "scene: bogus: unknown key"),
        ("missing key", lambda: volref.render({"image": {"width": 8}}), "scene: volume: required"),
        ("missing file", lambda: volref.render({"volume": {"source": "no-such-volume.nrrd"}}), "no-such-volume.nrrd"),
        ("missing scene file", lambda: volref.render("no-such-scene.json"), "no-such-scene.json"),
        ("2-D array", lambda: volref.render({"volume": {"source": np.zeros((4, 5))}}),
         "volume.source: expected a 3-D numpy array (shape (nz, ny, nx), x fastest), got 2 dimensions"),
        ("complex dtype", lambda: volref.render({"volume": {"source": np.zeros((2, 2, 2), np.complex128)}}),
         "volume.source: numpy dtype complex128 is not a volume type"),
        ("int64 dtype", lambda: volref.render({"volumes": [ok_volume, {"source": np.zeros((2, 2, 2), np.int64)}]}),
         "volumes[1].source: numpy dtype int64"),
        ("empty array", lambda: volref.render({"volume": {"source": np.zeros((0, 2, 2), np.float32)}}), "empty"),
        ("NaN number", lambda: volref.render({"volume": ok_volume, "render": {"step": float("nan")}}),
         "scene: render.step: expected a finite number"),
        ("out of range", lambda: volref.render({"volume": ok_volume, "render": {"step": 0}}),
         "scene: render.step: expected a number > 0, got 0"),
        ("bad JSON", lambda: volref.render('{"volume": }'), "scene: line 1"),
        ("not a scene", lambda: volref.render(42), "scene: expected"),
        ("object in scene", lambda: volref.render({"volume": ok_volume, "camera": object()}), "scene: camera"),
        ("bad override", lambda: volref.render({"volume": ok_volume}, overrides=["render.stepp=1"]), "render.stepp"),
        ("threads", lambda: volref.render({"volume": ok_volume}, threads=0), "threads:"),
        ("max_memory", lambda: volref.render({"volume": {"source": np.zeros((64, 64, 64)), "transfer": {}}},
                                             max_memory="1M"),
         "scene: volume.source (numpy array): a volume of 64 x 64 x 64: needs 2 MiB, more than the memory limit"),
        ("bad max_memory", lambda: volref.render({"volume": ok_volume}, max_memory="lots"), "max_memory"),
        ("pixel outside", lambda: volref.trace({"volume": ok_volume}, (300, 2)), "pixel: (300, 2) is outside"),
        ("pixel type", lambda: volref.trace({"volume": ok_volume}, "3,4"), "pixel: expected (x, y)"),
        ("first-hit trace", lambda: volref.trace(SCENES / "sphere-first-hit.json", (1, 1)), "first-hit"),
        ("explain topic", lambda: volref.explain("nope"), 'unknown topic "nope"'),
        ("explain option", lambda: volref.explain("opacity-correction", opacity=0.5, lenght=1), "--lenght"),
        ("explain value", lambda: volref.explain("opacity-correction", opacity=2, length=1), "--opacity"),
        ("compare sizes", lambda: volref.compare(np.zeros((4, 4, 4)), np.zeros((5, 4, 4))), "same size"),
        ("compare shape", lambda: volref.compare(np.zeros((4, 4)), np.zeros((4, 4, 4))), "a: expected a numpy array"),
        ("compare dtype", lambda: volref.compare(np.zeros((4, 4, 4), np.complex64), np.zeros((4, 4, 4))), "complex64"),
        ("compare error", lambda: volref.compare(np.zeros((4, 4, 4)), np.zeros((4, 4, 4)), error=True), "error:"),
        ("compare file", lambda: volref.compare(np.zeros((4, 4, 4)), "no-such-image.exr"), "no-such-image.exr"),
        ("tolerance", lambda: volref.compare(np.zeros((4, 4, 4)), np.zeros((4, 4, 4)), tolerance=-1), "tolerance:"),
    ]


@pytest.mark.parametrize("case", bad_inputs(), ids=lambda c: c[0])
def test_bad_input_raises_volref_error_and_writes_nothing(tmp_path, monkeypatch, case):
    _, call, needle = case
    tmp, cwd = tmp_path / "tmp", tmp_path / "cwd"
    tmp.mkdir()
    cwd.mkdir()
    monkeypatch.setenv("TMPDIR", str(tmp))  # where numpy volumes' temporary files go
    monkeypatch.chdir(cwd)
    with pytest.raises(volref.Error) as e:
        call()
    assert isinstance(e.value, ValueError)
    message = str(e.value)
    assert needle in message and "\n" not in message
    assert list(tmp.iterdir()) == [] and list(cwd.iterdir()) == []


def test_memory_limit_is_restored_after_a_call():
    scene = {"volume": {"source": np.zeros((64, 64, 64)), "transfer": {}}, "image": {"width": 4, "height": 4}}
    with pytest.raises(volref.Error):
        volref.render(scene, max_memory=1 << 20)
    volref.render(scene)  # the machine's limit again
    volref.render(scene, max_memory="1G")


# ---- GIL, Ctrl-C, help --------------------------------------------------------------------------------

SLOW = (SCENES / "shaded-composite.json", ["image.width=700", "image.height=700", "render.step=0.05"])


def test_render_releases_the_gil():
    ticks, done = [0], threading.Event()
    def count():
        while not done.is_set():
            ticks[0] += 1
            time.sleep(0.001)
    t = threading.Thread(target=count)
    t.start()
    volref.render(SCENES / "default.json", overrides=["image.width=160", "image.height=160"])
    done.set()
    t.join()
    assert ticks[0] > 5


def test_ctrl_c_cancels_a_render_and_the_next_render_works():
    timer = threading.Timer(0.5, _thread.interrupt_main)  # as Ctrl-C: SIGINT's handler in the main thread
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        volref.render(SLOW[0], overrides=SLOW[1], threads=1)
    elapsed = time.monotonic() - start
    timer.cancel()
    assert elapsed < 20, elapsed
    r = volref.render(SCENES / "levoy-lecture.json")  # the cancel request was forgotten
    assert r.rgba[32, 32, 3] == pytest.approx(0.6253600714236399, abs=1e-12)


@pytest.mark.skipif("VOLREF_BUILD_DIR" not in os.environ, reason="needs the build folder (run by ctest)")
def test_installed_module_imports_and_finds_its_libraries(tmp_path):
    prefix = tmp_path / "prefix"
    subprocess.run([os.environ.get("VOLREF_CMAKE", "cmake"), "--install", os.environ["VOLREF_BUILD_DIR"],
                    "--prefix", prefix], check=True, capture_output=True)
    site = prefix / os.environ.get("VOLREF_PYTHON_INSTALL_DIR", "lib/python3.11/dist-packages")
    assert (site / "volref.pyi").exists()
    env = {k: v for k, v in os.environ.items() if k not in ("LD_LIBRARY_PATH", "PYTHONPATH")}
    env["PYTHONPATH"] = str(site)
    code = ("import volref; r = volref.render(%r); print(volref.__file__, r.rgba[32, 32, 3])"
            % str(SCENES / "levoy-lecture.json"))
    out = subprocess.run([sys.executable, "-c", code], env=env, check=True, capture_output=True, text=True).stdout
    assert out.startswith(str(site)) and float(out.split()[1]) == pytest.approx(0.6253600714236399, abs=1e-15)


def test_help_explains_the_arguments():
    text = pydoc.render_doc(volref.render)
    for word in ("scene", "threads", "overrides", "error", "max_memory", "numpy", "KeyboardInterrupt", "volref.Error"):
        assert word in text, word
    for f in (volref.compare, volref.trace, volref.explain):
        assert len(pydoc.render_doc(f)) > 400
    stub = pathlib.Path(volref.__file__).with_name("volref.pyi")
    assert stub.exists() and "def render(" in stub.read_text()


def test_compare_returns_the_rays_the_program_does_not_finish(tmp_path):
    """Issue 28: seed 001's float32 kernel faults where the real program hangs (tests/gpu/h100/seed001:
    sphere-composite, 3 rays its guard marked); compare lists them and leaves them out, as the CLI does."""
    scene = SOURCE / "tests" / "gpu" / "h100" / "seed001" / "sphere-composite.json"
    r = volref.render(scene)
    got = volref.compare(r, r)
    gpu = SOURCE / "tests" / "gpu" / "h100" / "seed001" / "sphere-composite.h100.exr"
    _, px = read_exr(gpu)
    marked = sorted([int(x), int(y)] for y, x in zip(*np.nonzero((px[..., 0] == -1) & (px[..., 3] == -1))))
    assert sorted(got["fault"]) == marked and len(marked) == 3
    assert got["within_tolerance"] is True and got["non_finite"]["a"] == 0
    out = tmp_path / "k.exr"
    cli("render", scene, "-o", out)
    expected = json.loads(cli("compare", out, gpu, "--json", check=False).stdout)
    assert sorted(expected["fault"]) == marked
    assert sorted(volref.compare(str(out), str(gpu))["fault"]) == marked
