#!/usr/bin/python3
"""volref-mpi against the single-process `volref render` (cli/mpi/CMakeLists.txt registers each mode).

equal --np N [--compositing direct|swap]
             : every supported projection (first hit included) and order, orthographic and
               perspective, unshaded and shaded, crop and clip planes, on a procedural field:
               `mpirun -np N volref-mpi render` equals `volref render` within 1e-12 (conventions §14),
               with binary swap or direct send compositing; closed forms for constant media and f = z.
raw          : a raw file read as bricks (sub-box reads) by 2, 3 and 4 ranks equals `volref render`.
memory       : a raw volume over one rank's --max-memory: refused in one line by 1 rank, rendered by 4
               (and equal to `volref render` without the limit).
failed       : a truncated raw file whose last brick cannot be read: exit status != 0, exactly one
               `volref: error:` line naming the file, no image.
formats      : NRRD (attached and detached), MetaImage (.mha, .mhd), NIfTI-1 (.nii, scaled) read as bricks
               by 2, 3 and 4 ranks equal `volref render`; gzip data and a flipped NIfTI are one-line errors.
volumes      : mesh bounds; several volumes (different grids, overlapping, one cropped and clipped, transformed) on every
               projection and order, orthographic and perspective, shaded and unshaded, by 2, 3 and
               4 ranks equal `volref render`; a constant medium beside a second one has a closed form.
adaptive     : render.integrator "adaptive" on every projection, one volume and three (the composite's
               state handed from rank to rank, the others' independent parts), by 2, 3 and 4 ranks:
               every channel, the error channel included, equals `volref render` within 1e-12; the
               chain's bricks cut by work by default, by cells when asked (--timing names the cut).
refusals     : scenes outside the first version's scope are refused in one line naming the key.
"""
import argparse, json, os, shutil, struct, subprocess, sys, math

ap = argparse.ArgumentParser()
ap.add_argument("--mpirun", required=True)
ap.add_argument("--volref", required=True)
ap.add_argument("--volref-mpi", required=True)
ap.add_argument("--dump", required=True, help="volref_image_dump (tests/identity): the reference as doubles")
ap.add_argument("--work", required=True)
ap.add_argument("mode")
ap.add_argument("--np", type=int, default=2)
ap.add_argument("--compositing", choices=("direct", "swap"), help="volref-mpi's --compositing (default: its default)")
a = ap.parse_args()
comp = ["--compositing", a.compositing] if a.compositing else []

# ctest sets these (cli/mpi/CMakeLists.txt); the defaults let the script run by hand too. Root (CI) needs
# the first two; 4 ranks on a 2-core machine need oversubscription; containers often forbid the
# shared-memory transport's cross-memory attach (ptrace), which would only add warnings.
for k, v in (("OMPI_ALLOW_RUN_AS_ROOT", "1"), ("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1"),
             ("OMPI_MCA_rmaps_base_oversubscribe", "1"), ("OMPI_MCA_btl_vader_single_copy_mechanism", "none")):
    os.environ.setdefault(k, v)
shutil.rmtree(a.work, ignore_errors=True)
os.makedirs(a.work)
failures = []


def run(cmd, **kw):
    return subprocess.run(cmd, capture_output=True, text=True, timeout=600, **kw)


def mpirun(np, args):
    return run([a.mpirun, "-q", "--oversubscribe", "-np", str(np), a.volref_mpi] + args)


def write_scene(name, scene):
    path = os.path.join(a.work, name + ".json")
    with open(path, "w") as f:
        json.dump(scene, f)
    return path


def read_img(path):
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"\n")
    head = data[:end].decode().split()
    w, h, channels = int(head[0]), int(head[1]), head[2:]
    n = w * h * len(channels)
    return w, h, channels, struct.unpack("<%dd" % n, data[end + 1:end + 1 + 8 * n])


references = {}  # scene path -> the single process's .img, rendered once per scene


def reference(name, scene_path):
    """volref_image_dump's render_scene doubles for the scene (None, with a failure, if it failed)."""
    if scene_path in references:
        return references[scene_path]
    cases = os.path.join(a.work, name + ".cases")
    with open(cases, "w") as f:
        f.write("%s|%s||threads=1\n" % (name, scene_path))
    r = run([a.dump, cases, a.work])
    ref = os.path.join(a.work, name + ".img")
    if r.returncode != 0 or not os.path.exists(ref):
        err = os.path.join(a.work, name + ".err")
        failures.append("%s: the single-process render failed: %s %s" % (
            name, r.stderr.strip(), open(err).read().strip() if os.path.exists(err) else ""))
        ref = None
    references[scene_path] = ref
    return ref


def check_equal(name, scene_path, np, extra=(), tolerance=1e-12):
    """volref-mpi's doubles (.img) against volref_image_dump's render_scene doubles: max abs <= 1e-12."""
    ref = reference(name, scene_path)
    if ref is None:
        return
    out = os.path.join(a.work, name + ".np%d.img" % np)
    r = mpirun(np, ["render", scene_path, "-o", out, "--threads", "1"] + comp + list(extra))
    if r.returncode != 0 or not os.path.exists(out):
        failures.append("%s np=%d: volref-mpi failed (%d): %s" % (name, np, r.returncode, r.stderr.strip()))
        return
    w0, h0, c0, p0 = read_img(ref)
    w1, h1, c1, p1 = read_img(out)
    if (w0, h0, c0) != (w1, h1, c1):
        failures.append("%s np=%d: image %s differs from the reference's %s" % (name, np, (w1, h1, c1), (w0, h0, c0)))
        return
    # Equal values (the first hit's Z = +inf on a miss) differ by 0.
    diff = max((0.0 if x == y else abs(x - y) for x, y in zip(p0, p1)), default=0.0)
    covered = sum(1 for i in range(c0.index("A"), len(p0), len(c0)) if p0[i] != 0.0)
    if not diff <= tolerance:
        failures.append("%s np=%d: max abs difference %.3e over %g" % (name, np, diff, tolerance))
    elif covered == 0:
        failures.append("%s: the reference image is empty (the case tests nothing)" % name)
    else:
        print("ok %s np=%d: max abs difference %.3e (%d pixels covered)" % (name, np, diff, covered))


def check_exr(name, scene_path, np):
    """The user's path: an EXR written by rank 0 and `volref compare` (floats: 1e-6)."""
    ref = os.path.join(a.work, name + ".ref.exr")
    out = os.path.join(a.work, name + ".np%d.exr" % np)
    r = run([a.volref, "render", scene_path, "-o", ref])
    r2 = mpirun(np, ["render", scene_path, "-o", out] + comp)
    if r.returncode != 0 or r2.returncode != 0:
        failures.append("%s: EXR renders failed: %s %s" % (name, r.stderr.strip(), r2.stderr.strip()))
        return
    c = run([a.volref, "compare", ref, out, "--tolerance", "1e-6"])
    if c.returncode != 0:
        failures.append("%s np=%d: EXR differs: %s" % (name, np, c.stdout.strip()[-300:]))
    else:
        print("ok %s np=%d: EXR within 1e-6 (float storage)" % (name, np))


def base_scene(projection, camera, shaded=False, order="front-to-back"):
    vol = {
        "source": {"field": "marschner-lobb", "dims": [21, 17, 25]},
        "spacing": [1.0, 1.25, 0.8],
        "origin": [-3.0, 1.0, 0.5],
        "transfer": {"color": [[0.0, 0.1, 0.3, 0.9], [0.5, 1.0, 0.8, 0.4], [1.0, 0.9, 0.1, 0.1]],
                     "opacity": [[0.0, 0.0], [0.45, 0.0], [0.5, 0.6], [1.0, 0.3]]},
    }
    if shaded:
        vol["shading"] = {"model": "blinn-phong", "ka": 0.15, "kd": 0.7, "ks": 0.4, "n": 30}
    cams = {
        "ortho": {"type": "orthographic", "eye": [40, -30, 45], "target": [7, 11, 10], "up": [0, 0, 1], "height": 40},
        "persp": {"type": "perspective", "eye": [35, 40, -25], "target": [7, 11, 10], "up": [0, 1, 0], "fov_y": 40},
        # The eye inside the volume: rays start inside a brick.
        "inside": {"type": "perspective", "eye": [6, 9, 8], "target": [14, 18, 1], "up": [0, 0, 1], "fov_y": 70},
    }
    render = {"projection": projection, "step": 0.37}
    if projection == "composite":
        render["order"] = order
    if projection == "first-hit":
        render["isovalue"] = 0.5
    return {"volume": vol, "camera": cams[camera], "image": {"width": 33, "height": 27}, "render": render}


if a.mode == "equal":
    cases = []
    for cam in ("ortho", "persp", "inside"):
        cases.append(("composite-ftb-" + cam, base_scene("composite", cam)))
        cases.append(("composite-btf-" + cam, base_scene("composite", cam, order="back-to-front")))
        cases.append(("shaded-ftb-" + cam, base_scene("composite", cam, shaded=True)))
        for p in ("mip", "minip", "average", "xray", "first-hit"):
            cases.append((p + "-" + cam, base_scene(p, cam)))
        cases.append(("shaded-first-hit-" + cam, base_scene("first-hit", cam, shaded=True)))
    # First hit by bisection (tricubic: no exact cell-cubic search) and with a step of 2.6 voxels (the
    # ghost layer reaches half a step beyond the brick).
    s = base_scene("first-hit", "persp", shaded=True)
    s["volume"]["interpolation"] = "tricubic-bspline"
    cases.append(("first-hit-tricubic-persp", s))
    s = base_scene("first-hit", "ortho")
    s["render"]["step"] = 2.6
    s["volume"]["crop"] = {"planes": [0, 8, 4, 14, 3, 12], "regions": 134217727 ^ (1 << 13)}
    s["volume"]["clip_planes"] = [{"point": [7, 11, 10], "normal": [1, 1, 0]}]
    cases.append(("first-hit-step-crop-clip-ortho", s))
    s = base_scene("composite", "persp", shaded=True, order="back-to-front")
    s["volume"]["interpolation"] = "tricubic-catmull-rom"
    cases.append(("shaded-btf-tricubic-persp", s))
    s = base_scene("composite", "ortho")
    s["volume"]["crop"] = {"planes": [0, 8, 4, 14, 3, 12], "regions": 134217727 ^ (1 << 13)}
    s["volume"]["clip_planes"] = [{"point": [7, 11, 10], "normal": [1, 1, 0]}]
    cases.append(("composite-crop-clip-ortho", s))
    s = base_scene("xray", "persp")
    s["render"]["gain"] = 0.01
    s["volume"]["transfer"]["domain"] = "normalized"
    cases.append(("xray-normalized-persp", s))
    # Binary swap asked for with a rank count that is not a power of two is direct send (cli/mpi/main.cpp
    # `run`: the same path as --compositing direct, whose test renders these cases): only the closed
    # forms below run, and check the note.
    swap_falls_back = a.compositing == "swap" and a.np & (a.np - 1)
    for name, scene in ([] if swap_falls_back else cases):
        check_equal(name, write_scene(name, scene), a.np)
    # --balance work (cli/mpi/Balance.h): the bricks cut where the probe's sample counts balance, read
    # again; the image is the single process's as with any cut. The two composite scenes get other cuts
    # than the cells' rule at 2 and 3 ranks (--timing says "bricks": "work"), the mip one the same cut
    # ("work-same-cut": its samples balance there).
    for name in ("composite-ftb-persp", "shaded-btf-tricubic-persp", "mip-ortho"):
        path = os.path.join(a.work, name + ".json")
        if os.path.exists(path):
            check_equal(name + "-balanced", path, a.np, extra=["--balance", "work"])
    # The fast profile (conventions §9b, §14): float positions relative to each brick's origin, so a
    # rank's samples round differently from the single process's; the termination (Tr <= 2^-10) may then
    # fall one sample apart. Within the profile's own bound against the reference, 2^-10 times the
    # brightest colour (1 unshaded, 2.4 with these lights) plus float rounding, twice (both renders).
    for cam in (() if swap_falls_back else ("ortho", "persp", "inside")):
        for name, scene, bound in (("fast-composite-" + cam, base_scene("composite", cam), 2 ** -10 + 2e-5),
                                   ("fast-shaded-" + cam, base_scene("composite", cam, shaded=True), 2.4 * 2 ** -10 + 1e-4),
                                   ("fast-mip-" + cam, base_scene("mip", cam), 2e-5)):
            scene["render"]["profile"] = "fast"
            check_equal(name, write_scene(name, scene), a.np, tolerance=2 * bound)
            if a.np == 2 and cam == "persp":  # one rank: the parts' path (Chain.h chained), the single process's bytes
                check_equal(name + "-np1", os.path.join(a.work, name + ".json"), 1, tolerance=0.0)
    if not swap_falls_back:
        check_exr("composite-ftb-persp", os.path.join(a.work, "composite-ftb-persp.json"), a.np)
    # Hand-checkable: a constant medium (value 1, opacity a = 0.5 per unit length, colour c) 32 units
    # deep along z, seen by an orthographic camera along -z: every pixel is C = c A, A = 1 - 0.5^32
    # (the opacity correction telescopes); x-ray = gain 32; average = 1. Split along z (the longest
    # axis) into N bricks, so the combination across bricks is what is checked.
    closed = {
        "composite": lambda ch: ([1.0, 0.5, 0.25][ch] if ch < 3 else 1.0) * (1.0 - 0.5 ** 32),
        "xray": lambda ch: 32.0 * 0.125 if ch < 3 else 1.0,
        "average": lambda ch: 1.0,
    }
    # First hit on f = z (world), seen from above along -z: the hit is z = 10.3 exactly in the lowest
    # bricks (the first ones the ray meets hold no crossing), Z = 100 - 10.3, colour (1, 0.5, 0.25), A = 1.
    closed["first-hit"] = lambda ch: [1.0, 0.5, 0.25, 1.0, 100.0 - 10.3][ch]
    for projection, expect in closed.items():
        name = "constant-" + projection
        scene = {"volume": {"source": {"field": "constant", "value": 1.0, "dims": [9, 9, 33]},
                            "transfer": {"color": [[0.0, 1.0, 0.5, 0.25], [2.0, 1.0, 0.5, 0.25]],
                                         "opacity": [[0.0, 0.5], [2.0, 0.5]]}},
                 "camera": {"type": "orthographic", "eye": [4, 4, 100], "target": [4, 4, 16], "up": [0, 1, 0], "height": 4},
                 "image": {"width": 16, "height": 12},
                 "render": {"projection": projection, "step": 0.37, "gain": 0.125}}
        if projection == "first-hit":
            scene["volume"]["source"] = {"field": "linear", "coefficients": [0, 0, 1, 0], "dims": [9, 9, 33]}
            scene["volume"]["transfer"]["color"] = [[0.0, 1.0, 0.5, 0.25], [40.0, 1.0, 0.5, 0.25]]
            scene["volume"]["transfer"]["opacity"] = [[0.0, 0.5], [40.0, 0.5]]
            scene["render"]["isovalue"] = 10.3
        path = write_scene(name, scene)
        out = os.path.join(a.work, name + ".np%d.img" % a.np)
        r = mpirun(a.np, ["render", path, "-o", out, "--threads", "1"] + comp)
        if r.returncode != 0:
            failures.append("%s: volref-mpi failed: %s" % (name, r.stderr.strip()))
            continue
        _, _, chans, px = read_img(out)
        worst = max(abs(px[i] - expect(i % len(chans))) for i in range(len(px)))
        if not worst <= 1e-12:
            failures.append("%s np=%d: %.3e from the closed form" % (name, a.np, worst))
        else:
            print("ok %s np=%d: closed form within %.3e" % (name, a.np, worst))
        # Binary swap asked for with a rank count that is not a power of two: direct send, said once.
        if a.compositing == "swap" and a.np & (a.np - 1):
            note = "volref-mpi: note: binary swap needs a power-of-two rank count; %d ranks used direct send" % a.np
            if r.stderr.strip() != note:
                failures.append("%s np=%d: expected the note %r on stderr, got %r" % (name, a.np, note, r.stderr))


def write_raw(name, dims, fmt, value, truncate_to=None):
    path = os.path.join(a.work, name + ".raw")
    nx, ny, nz = dims
    data = bytearray()
    for k in range(nz):
        for j in range(ny):
            data += struct.pack("<%d%s" % (nx, fmt), *[value(i, j, k) for i in range(nx)])
    if truncate_to is not None:
        data = data[:truncate_to]
    with open(path, "wb") as f:
        f.write(data)
    with open(path + ".json", "w") as f:
        json.dump({"dims": dims, "type": {"f": "f32", "d": "f64", "B": "u8"}[fmt], "spacing": [1.0, 0.9, 1.1]}, f)
    return path


def smooth(i, j, k):
    return 0.5 + 0.25 * math.sin(0.3 * i + 0.1 * j) * math.cos(0.2 * k) + 0.01 * ((i * 7 + j * 3 + k) % 5)


def raw_scene(path, projection="composite", shaded=False):
    s = base_scene(projection, "persp", shaded=shaded)
    s["volume"] = {"source": {"file": path},
                   "transfer": {"color": [[0.0, 0.2, 0.3, 0.9], [1.0, 1.0, 0.6, 0.2]],
                                "opacity": [[0.0, 0.0], [0.6, 0.0], [0.8, 0.5]]}}
    if shaded:
        s["volume"]["shading"] = {"model": "phong"}
    s["camera"] = {"type": "perspective", "eye": [60, 50, -40], "target": [12, 10, 14], "up": [0, 1, 0], "fov_y": 35}
    return s


if a.mode == "raw":
    path = write_raw("field", [26, 22, 30], "f", smooth)
    for np in (2, 3, 4):
        check_equal("raw-composite", write_scene("raw-composite", raw_scene(path)), np)
        check_equal("raw-shaded", write_scene("raw-shaded", raw_scene(path, shaded=True)), np)
        check_equal("raw-mip", write_scene("raw-mip", raw_scene(path, "mip")), np)
    # The shader's zero-gradient tolerance (conventions §8: 1e-9 max |v| / voxel) is the whole volume's on
    # every rank (Volume::whole_range): a ramp of 1e-8 per voxel in x < 20 beside values of 1000 in
    # x >= 24 has |grad f| = 1e-8 below the whole volume's tolerance 1e-6, so the single-process render
    # leaves those samples unlit (colour 0.5), while a brick holding only the ramp (its own tolerance
    # ~2e-16) would light them (0.2 0.5 + 0.7 0.5 + 0.3 = 0.75 under the headlight along +x). At 3 and 4
    # ranks some bricks hold only the ramp: with each brick's own range they were 0.12 and 0.10 off.
    ramp = write_raw("zero-gradient", [40, 6, 6], "d",
                     lambda i, j, k: 1e-8 * i if i < 20 else (1000.0 if i >= 24 else 1e-8 * 19 + (i - 19) * 200.0))
    zg = raw_scene(ramp, shaded=True)
    zg["volume"]["transfer"] = {"color": [[0.0, 0.5, 0.5, 0.5], [2000.0, 0.5, 0.5, 0.5]],
                                "opacity": [[0.0, 0.05], [2000.0, 0.05]]}
    zg["volume"]["shading"] = {"model": "blinn-phong", "ka": 0.2, "kd": 0.7, "ks": 0.3, "n": 10}
    zg["camera"] = {"type": "orthographic", "eye": [-30, 2.7, 2.75], "target": [20, 2.7, 2.75], "up": [0, 0, 1],
                    "height": 6}
    zg_path = write_scene("zero-gradient", zg)
    for np in (2, 3, 4):
        check_equal("zero-gradient", zg_path, np)

def field_bytes(dims, fmt):
    """smooth() at every voxel, x fastest, packed with struct format `fmt` ("<f", ">f", "<d", ...)."""
    nx, ny, nz = dims
    values = [smooth(i, j, k) for k in range(nz) for j in range(ny) for i in range(nx)]
    return struct.pack("%s%d%s" % (fmt[0], len(values), fmt[1]), *values)


def write_nifti(path, dims, spacing, origin, slope=0.0, inter=0.0, flip_x=False):
    """NIfTI-1 (.nii), sform_code 1 with an axis-aligned sform, float32 data after vox_offset 352."""
    nx, ny, nz = dims
    h = bytearray(348)
    struct.pack_into("<i", h, 0, 348)
    struct.pack_into("<8h", h, 40, 3, nx, ny, nz, 1, 1, 1, 1)
    struct.pack_into("<hh", h, 70, 16, 32)  # DT_FLOAT32, bitpix
    struct.pack_into("<8f", h, 76, 1.0, spacing[0], spacing[1], spacing[2], 1, 1, 1, 1)
    struct.pack_into("<fff", h, 108, 352.0, slope, inter)
    struct.pack_into("<hh", h, 252, 0, 1)  # qform_code 0, sform_code 1
    sx = -spacing[0] if flip_x else spacing[0]
    struct.pack_into("<4f", h, 280, sx, 0, 0, origin[0])
    struct.pack_into("<4f", h, 296, 0, spacing[1], 0, origin[1])
    struct.pack_into("<4f", h, 312, 0, 0, spacing[2], origin[2])
    h[344:348] = b"n+1\0"
    with open(path, "wb") as f:
        f.write(bytes(h) + b"\0\0\0\0" + field_bytes(dims, "<f"))


def one_error(name, scene, expect):
    out = os.path.join(a.work, name + ".exr")
    r = mpirun(2, ["render", write_scene(name, scene), "-o", out])
    lines = [l for l in r.stderr.splitlines() if l.startswith("volref: error:")]
    if r.returncode == 0 or len(lines) != 1 or expect not in lines[0] or os.path.exists(out):
        failures.append("%s: expected one error line with %r and no image, got %d %r" % (name, expect, r.returncode, r.stderr))
    else:
        print("ok %s: %s" % (name, lines[0]))


if a.mode == "formats":
    # The same field in every format volref-mpi reads as a sub-box; each rendered by 2, 3 and 4 ranks
    # against `volref render` (which reads the whole file with the same reader).
    dims = [26, 22, 30]
    files = {}
    # NRRD, attached header, raw encoding, big endian, with a byte skip.
    p = os.path.join(a.work, "field.nrrd")
    with open(p, "wb") as f:
        f.write(("NRRD0004\ntype: float\ndimension: 3\nsizes: %d %d %d\nspacings: 1 0.9 1.1\n"
                 "space origin: (-2,1.5,0.25)\nendian: big\nencoding: raw\nbyte skip: 7\n\n" % tuple(dims)).encode())
        f.write(b"skipped" + field_bytes(dims, ">f"))
    files["nrrd"] = p
    # NRRD, detached header (.nhdr) naming a data file; little endian f64.
    with open(os.path.join(a.work, "field-data.bin"), "wb") as f:
        f.write(field_bytes(dims, "<d"))
    p = os.path.join(a.work, "field.nhdr")
    with open(p, "w") as f:
        f.write("NRRD0004\ntype: double\ndimension: 3\nsizes: %d %d %d\nspacings: 1 0.9 1.1\nendian: little\n"
                "encoding: raw\ndata file: field-data.bin\n" % tuple(dims))
    files["nhdr"] = p
    # MetaImage, inline (.mha, ElementDataFile = LOCAL), big endian.
    p = os.path.join(a.work, "field.mha")
    with open(p, "wb") as f:
        f.write(("ObjectType = Image\nNDims = 3\nDimSize = %d %d %d\nElementType = MET_FLOAT\n"
                 "ElementSpacing = 1 0.9 1.1\nOffset = 3 -1 2\nBinaryDataByteOrderMSB = True\n"
                 "ElementDataFile = LOCAL\n" % tuple(dims)).encode())
        f.write(field_bytes(dims, ">f"))
    files["mha"] = p
    # MetaImage, detached (.mhd + data file), samples at the end of the file (HeaderSize = -1).
    with open(os.path.join(a.work, "field-mhd.raw"), "wb") as f:
        f.write(b"some leading bytes" + field_bytes(dims, "<f"))
    p = os.path.join(a.work, "field.mhd")
    with open(p, "w") as f:
        f.write("NDims = 3\nDimSize = %d %d %d\nElementType = MET_FLOAT\nElementSpacing = 1 0.9 1.1\n"
                "HeaderSize = -1\nElementDataFile = field-mhd.raw\n" % tuple(dims))
    files["mhd"] = p
    # NIfTI-1 (.nii), sform with an origin, scaled by scl_slope / scl_inter.
    p = os.path.join(a.work, "field.nii")
    write_nifti(p, dims, [1.0, 0.75, 1.25], [-3.5, 2.0, 0.5], slope=1.5, inter=-0.25)
    files["nii"] = p
    for np_ in (2, 3, 4):
        for name, path in files.items():
            scene = raw_scene(path)
            if name == "nii":  # scaled values: 1.5 v - 0.25
                scene["volume"]["transfer"]["opacity"] = [[0.0, 0.0], [0.65, 0.0], [0.95, 0.5]]
            check_equal("fmt-" + name, write_scene("fmt-" + name, scene), np_)
        check_equal("fmt-nrrd-shaded", write_scene("fmt-nrrd-shaded", raw_scene(files["nrrd"], shaded=True)), np_)
    # Data that cannot be read as a sub-box: one line naming the file, no image.
    p = os.path.join(a.work, "gz.nrrd")
    import gzip
    with open(p, "wb") as f:
        f.write(("NRRD0004\ntype: float\ndimension: 3\nsizes: %d %d %d\nendian: little\nencoding: gzip\n\n"
                 % tuple(dims)).encode())
        f.write(gzip.compress(field_bytes(dims, "<f")))
    one_error("fmt-gzip", raw_scene(p), "gz.nrrd: volref-mpi reads bricks as sub-boxes of uncompressed samples stored in the volume's axis order; "
              "this file has gzip encoding")
    p = os.path.join(a.work, "flipped.nii")
    write_nifti(p, dims, [1.0, 0.75, 1.25], [20.0, 2.0, 0.5], flip_x=True)
    one_error("fmt-flipped-nifti", raw_scene(p), "flipped.nii: volref-mpi reads bricks as sub-boxes of uncompressed samples "
              "stored in the volume's axis order; this file has a flipped or permuted orientation")

if a.mode == "memory":
    # 64^3 f64 = 2 MiB: over a 1.5 MiB limit on one rank; a quarter (+ ghost) fits on each of 4.
    path = write_raw("big", [64, 64, 64], "d", smooth)
    scene = write_scene("big", raw_scene(path))
    out1 = os.path.join(a.work, "big.np1.exr")
    r = mpirun(1, ["--max-memory", "1536K", "render", scene, "-o", out1, "--threads", "1"])
    lines = [l for l in r.stderr.splitlines() if l.startswith("volref: error:")]
    if r.returncode == 0 or len(lines) != 1 or "memory" not in lines[0] or os.path.exists(out1):
        failures.append("1 rank under --max-memory 1536K: expected one error line about memory and no image, got %d: %r"
                        % (r.returncode, r.stderr))
    else:
        print("ok refused by 1 rank: " + lines[0])
    check_equal("big", scene, 4, extra=["--max-memory", "1536K"])
    # The adaptive chain's arrays count too (cli/mpi/Chain.h chain_bytes), by hand for rank 0 of 2 at
    # 512 x 512: per pixel its key and both ranks' (3 doubles), its place among the ranks (4 ints), the
    # state (15 doubles) and the error sums (5): 20 doubles x 5 (the array, received, sent, collect's
    # copy, rank 0's sum), and the pixels (R G B A error: 5 doubles): 24 + 16 + 800 + 40 = 880 bytes,
    # x 262144 pixels = 220.0 MiB; the bricks (5 x 5 x 9 voxels) add kilobytes. The merged parts' count
    # (what was checked before) is 58 MiB, under the 120 MiB limit.
    chain = write_scene("chain-memory", {
        "volume": {"source": {"field": "constant", "value": 1.0, "dims": [5, 5, 9]},
                   "transfer": {"color": [[0.0, 1.0, 0.5, 0.25], [2.0, 1.0, 0.5, 0.25]], "opacity": [[0.0, 0.5], [2.0, 0.5]]}},
        "camera": {"type": "orthographic", "eye": [2, 2, 100], "target": [2, 2, 4], "up": [0, 1, 0], "height": 4},
        "image": {"width": 512, "height": 512},
        "render": {"projection": "composite", "integrator": "adaptive", "tolerance": 1e-3}})
    out2 = os.path.join(a.work, "chain-memory.img")
    r = mpirun(2, ["--max-memory", "120M", "render", chain, "-o", out2, "--threads", "1"])
    lines = [l for l in r.stderr.splitlines() if l.startswith("volref: error:")]
    if r.returncode == 0 or len(lines) != 1 or "chain's states" not in lines[0] or "220 MiB" not in lines[0] or os.path.exists(out2):
        failures.append("2 ranks, adaptive chain under --max-memory 120M: expected one error line naming the chain's "
                        "220 MiB and no image, got %d: %r" % (r.returncode, r.stderr))
    else:
        print("ok refused by 2 ranks: " + lines[0])

if a.mode == "failed":
    # 16 x 16 x 64 u8, split along z; the file holds 40 of the 64 slices. Every rank checks the file's size
    # before reading its brick (issue 32: a rank once read only its own brick and a short file could pass),
    # so all refuse it; one error line comes out.
    path = write_raw("short", [16, 16, 64], "B", lambda i, j, k: (i + j + k) % 200, truncate_to=16 * 16 * 40)
    scene = write_scene("short", raw_scene(path))
    out = os.path.join(a.work, "short.exr")
    r = mpirun(2, ["render", scene, "-o", out])
    lines = [l for l in r.stderr.splitlines() if l.startswith("volref: error:")]
    # mpirun -q: stderr is that one line and nothing else (no line per rank, no launcher notice).
    if r.returncode == 0 or len(lines) != 1 or "short.raw: truncated: expected 16384 bytes of data, found 10240" not in lines[0] \
            or r.stderr.strip().splitlines() != lines or os.path.exists(out):
        failures.append("truncated brick: expected exit != 0, one error line, no image; got %d, %r, image %s"
                        % (r.returncode, r.stderr, os.path.exists(out)))
    else:
        print("ok failed brick: " + lines[0])

def two_volumes(projection, camera, shaded=False, order="front-to-back"):
    """base_scene's volume and a second one on another grid (coarser, shifted, partly overlapping it),
    the second cropped and clipped, tricubic; a third, small constant one in front of both."""
    s = base_scene(projection, camera, shaded=shaded, order=order)
    v0 = s.pop("volume")
    v1 = {"source": {"field": "marschner-lobb", "dims": [13, 15, 11], "alpha": 0.5, "fm": 3},
          "spacing": [1.7, 1.1, 2.05], "origin": [4.2, -2.5, 3.3],
          "interpolation": "tricubic-catmull-rom",
          "transfer": {"color": [[0.0, 0.9, 0.2, 0.1], [1.0, 0.2, 0.9, 0.3]],
                       "opacity": [[0.0, 0.0], [0.4, 0.05], [0.7, 0.4], [1.0, 0.1]]},
          "crop": {"planes": [5, 20, -1, 12, 4, 22], "regions": 134217727 ^ (1 << 13)},
          "clip_planes": [{"point": [10, 5, 12], "normal": [1, -1, 0.5]}]}
    v2 = {"source": {"field": "constant", "value": 0.5, "dims": [4, 5, 3]},
          "spacing": [2.0, 1.5, 2.5], "origin": [8.0, 6.0, 6.0],
          "transfer": {"color": [[0.0, 0.3, 0.3, 1.0], [1.0, 0.3, 0.3, 1.0]], "opacity": [[0.0, 0.2], [1.0, 0.2]]}}
    if shaded:
        v1["shading"] = {"model": "phong"}
    s["volumes"] = [v0, v1, v2]
    if projection == "first-hit":
        s["render"]["step"] = 0.45  # and volume 2 (constant 0.5 = the isovalue) hits at its face
    return s


if a.mode == "volumes":
    cases = []
    for cam in ("ortho", "persp", "inside"):
        cases.append(("vols-composite-ftb-" + cam, two_volumes("composite", cam)))
        cases.append(("vols-composite-btf-" + cam, two_volumes("composite", cam, order="back-to-front")))
        for p in ("mip", "minip", "average", "xray", "first-hit"):
            cases.append(("vols-" + p + "-" + cam, two_volumes(p, cam)))
    cases.append(("vols-shaded-ftb-persp", two_volumes("composite", "persp", shaded=True)))
    cases.append(("vols-shaded-first-hit-persp", two_volumes("first-hit", "persp", shaded=True)))
    # Transforms: the second volume rotated, scaled and moved; the first (whose lattice is split) turned
    # too; and the reference scene of two volumes (a shaded shell cut by a clip plane, a transformed
    # Gaussian), made small.
    for cam in ("ortho", "persp"):
        for p in ("composite", "mip", "first-hit"):
            s = two_volumes(p, cam, shaded=p != "mip")
            s["volumes"][1]["transform"] = {"scale": [1.3, 0.8, 1], "rotate": {"axis": [1, 1, 0], "degrees": 35},
                                            "translate": [2, -1, 3]}
            s["volumes"][0]["transform"] = {"rotate": {"axis": [0, 0, 1], "degrees": 20}, "translate": [1, 0, 0]}
            cases.append(("vols-transform-%s-%s" % (p, cam), s))
    s = base_scene("composite", "persp", shaded=True)
    s["volume"]["transform"] = {"scale": [1, 1.5, 0.7], "rotate": {"axis": [1, 0, 1], "degrees": 50}, "translate": [3, 0, -2]}
    cases.append(("one-volume-transform-shaded-persp", s))
    # Pre-classification (the RGBA volume, Levoy's pre-shading with shading) and a gradient cache:
    # per voxel, so a brick's (with its ghost layer) equals the whole volume's there.
    for cam in ("ortho", "persp"):
        for shaded in (False, True):
            s = base_scene("composite", cam, shaded=shaded)
            s["volume"]["classify"] = "pre"
            cases.append(("pre-classified-%s%s" % (cam, "-shaded" if shaded else ""), s))
        s = base_scene("composite", cam, shaded=True)
        s["volume"]["gradient"] = {"cache": True}
        cases.append(("gradient-cache-shaded-" + cam, s))
    s = base_scene("composite", "persp", shaded=True)
    s["volume"].update({"interpolation": "tricubic-bspline", "gradient": {"cache": True}})  # analytic, cached
    cases.append(("gradient-cache-tricubic-shaded-persp", s))
    s = two_volumes("composite", "persp", shaded=True)
    s["volumes"][1]["gradient"] = {"cache": True}
    s["volumes"][0]["classify"] = "pre"
    cases.append(("vols-pre-classified-gradient-cache-persp", s))
    # Mesh bounds: two disjoint boxes (one closed OBJ), so rays enter and leave the shape twice.
    obj = os.path.join(a.work, "two-boxes.obj")
    with open(obj, "w") as f:
        quads = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
        for base, (lo, hi) in enumerate((((-2.5, 2.0, 1.0), (6.0, 20.0, 18.0)), ((10.0, 4.0, 5.0), (16.5, 19.0, 19.5)))):
            for c in range(8):
                f.write("v %g %g %g\n" % tuple(hi[i] if c >> i & 1 else lo[i] for i in range(3)))
        for base in (0, 8):
            for q in quads:  # corner c = x + 2 y + 4 z; outward faces
                v = [base + 1 + (0, 1, 3, 2, 4, 5, 7, 6)[i] for i in q]
                f.write("f %d %d %d\nf %d %d %d\n" % (v[0], v[1], v[2], v[0], v[2], v[3]))
    for cam in ("ortho", "persp"):
        for p in ("composite", "mip", "first-hit"):
            s = base_scene(p, cam, shaded=p == "composite")
            s["volume"]["bounds"] = {"type": "mesh", "file": obj}
            cases.append(("mesh-bounds-%s-%s" % (p, cam), s))
    # Early termination (front to back): the ray's state handed from rank to rank, so a ray stops
    # where the single process's does; one volume and the mix of three, low thresholds so that most
    # rays stop inside some brick.
    for cam in ("ortho", "persp"):
        s = base_scene("composite", cam, shaded=True)
        s["render"]["early_termination"] = 0.3
        cases.append(("early-termination-" + cam, s))
        s = two_volumes("composite", cam)
        s["render"]["early_termination"] = 0.25
        cases.append(("vols-early-termination-" + cam, s))
    s = json.load(open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "reference_scenes",
                                    "two-volumes-clipped.json")))
    s["image"] = {"width": 40, "height": 32}
    cases.append(("vols-two-volumes-clipped", s))
    for name, scene in cases:
        path = write_scene(name, scene)
        # (Early termination at one rank: the parts' path, not the chain; Chain.h chained.)
        for np_ in ((1, 2, 3, 4) if "early-termination" in name else (2, 3, 4)):
            check_equal(name, path, np_)
    # Closed form: two constant media along z, one above the other (z in [0, 16] and [16, 32]), with
    # opacities 0.5 and 0.25 per unit and colours c0, c1, seen from above along -z: the upper medium
    # first, C = c1 (1 - 0.75^16) + 0.75^16 c0 (1 - 0.5^16), A = 1 - 0.75^16 0.5^16; where they overlap
    # (z in [14, 18] here: the second spans [14, 32]) the extinctions add (conventions §6a), so the
    # scene below keeps them apart: the second starts at z = 16.
    c0, c1 = [1.0, 0.5, 0.25], [0.2, 0.4, 0.8]
    t1, t0 = 0.75 ** 16, 0.5 ** 16
    expect = [c1[i] * (1 - t1) + t1 * c0[i] * (1 - t0) for i in range(3)] + [1 - t1 * t0]
    scene = {"volumes": [
        {"source": {"field": "constant", "value": 1.0, "dims": [9, 9, 17]},
         "transfer": {"color": [[0.0] + c0, [2.0] + c0], "opacity": [[0.0, 0.5], [2.0, 0.5]]}},
        {"source": {"field": "constant", "value": 1.0, "dims": [5, 5, 9]}, "spacing": [2.0, 2.0, 2.0],
         "origin": [0.0, 0.0, 16.0],
         "transfer": {"color": [[0.0] + c1, [2.0] + c1], "opacity": [[0.0, 0.25], [2.0, 0.25]]}}],
        "camera": {"type": "orthographic", "eye": [4, 4, 100], "target": [4, 4, 16], "up": [0, 1, 0], "height": 4},
        "image": {"width": 16, "height": 12}, "render": {"projection": "composite", "step": 0.37}}
    path = write_scene("vols-constant", scene)
    for np_ in (2, 3, 4):
        out = os.path.join(a.work, "vols-constant.np%d.img" % np_)
        r = mpirun(np_, ["render", path, "-o", out, "--threads", "1"] + comp)
        if r.returncode != 0:
            failures.append("vols-constant np=%d: volref-mpi failed: %s" % (np_, r.stderr.strip()))
            continue
        _, _, chans, px = read_img(out)
        worst = max(abs(px[i] - expect[i % 4]) for i in range(len(px)))
        if not worst <= 1e-12:
            failures.append("vols-constant np=%d: %.3e from the closed form" % (np_, worst))
        else:
            print("ok vols-constant np=%d: closed form within %.3e" % (np_, worst))

if a.mode == "adaptive":
    # render.integrator "adaptive", composite: each pixel's state passed from rank to rank in ray order.
    cases = []
    for cam in ("ortho", "persp", "inside"):
        s = base_scene("composite", cam)
        s["render"]["integrator"] = "adaptive"
        s["render"]["tolerance"] = 1e-4
        cases.append(("adaptive-" + cam, s))
    s = base_scene("composite", "persp", shaded=True)
    s["render"].update({"integrator": "adaptive", "tolerance": 1e-3})
    cases.append(("adaptive-shaded-persp", s))
    s = base_scene("composite", "ortho")
    s["render"].update({"integrator": "adaptive", "tolerance": 1e-4})
    s["volume"]["interpolation"] = "tricubic-bspline"
    s["volume"]["crop"] = {"planes": [0, 8, 4, 14, 3, 12], "regions": 134217727 ^ (1 << 13)}
    s["volume"]["clip_planes"] = [{"point": [7, 11, 10], "normal": [1, 1, 0]}]
    cases.append(("adaptive-tricubic-crop-clip-ortho", s))
    # Opacity 1 above f = 0.7: rays end inside some brick (the opaque piece), the ranks behind add nothing.
    s = base_scene("composite", "persp")
    s["render"].update({"integrator": "adaptive", "tolerance": 1e-4})
    s["volume"]["transfer"]["opacity"] = [[0.0, 0.0], [0.45, 0.0], [0.5, 0.3], [0.7, 1.0], [1.0, 1.0]]
    cases.append(("adaptive-opaque-persp", s))
    # Several volumes' adaptive mix (MultiVolumeIntegrator::adaptive_composite), the state handed on
    # the same way; one orthographic, one perspective with shading, one with an opaque run.
    for cam, shaded in (("ortho", False), ("persp", True)):
        s = two_volumes("composite", cam, shaded=shaded)
        s["render"].update({"integrator": "adaptive", "tolerance": 1e-3})
        cases.append(("adaptive-vols-composite-%s%s" % (cam, "-shaded" if shaded else ""), s))
    s = two_volumes("composite", "inside")
    s["render"].update({"integrator": "adaptive", "tolerance": 1e-3})
    s["volumes"][0]["transfer"]["opacity"] = [[0.0, 0.0], [0.45, 0.0], [0.5, 0.3], [0.7, 1.0], [1.0, 1.0]]
    cases.append(("adaptive-vols-composite-opaque-inside", s))
    # The other projections: each rank's pieces as independent parts (one volume and several).
    for cam in ("ortho", "persp"):
        for p in ("mip", "minip", "average", "xray", "first-hit"):
            s = base_scene(p, cam)
            s["render"].update({"integrator": "adaptive", "tolerance": 1e-5})
            cases.append(("adaptive-%s-%s" % (p, cam), s))
            s = two_volumes(p, cam)
            s["render"].update({"integrator": "adaptive", "tolerance": 1e-5})
            s["volumes"][1]["interpolation"] = "trilinear"  # adaptive mip / first hit: trilinear or nearest
            cases.append(("adaptive-vols-%s-%s" % (p, cam), s))
    s = base_scene("mip", "inside")
    s["render"].update({"integrator": "adaptive"})
    s["volume"]["interpolation"] = "nearest"
    cases.append(("adaptive-mip-nearest-inside", s))
    s = base_scene("first-hit", "persp", shaded=True)
    s["render"].update({"integrator": "adaptive"})
    cases.append(("adaptive-shaded-first-hit-persp", s))
    for name, scene in cases:
        path = write_scene(name, scene)
        for np_ in (2, 3, 4):
            check_equal(name, path, np_)
    # The chain's bricks are cut by work unless asked otherwise (--balance auto, conventions §14): the
    # cell cut too, and --timing names the cut each way (the fixed step's default stays cells).
    for name in ("adaptive-persp", "adaptive-vols-composite-persp-shaded"):
        for np_ in (2, 3):
            check_equal(name + "-cells", os.path.join(a.work, name + ".json"), np_, extra=["--balance", "cells"])
    fixed = write_scene("fixed-persp", base_scene("composite", "persp"))
    for scene_path, extra, expect in ((os.path.join(a.work, "adaptive-persp.json"), [], "work"),
                                      (os.path.join(a.work, "adaptive-persp.json"), ["--balance", "cells"], "cells"),
                                      (fixed, [], "cells")):
        r = mpirun(2, ["render", scene_path, "-o", os.path.join(a.work, "timing.img"), "--threads", "1", "--timing"] + extra)
        said = [l for l in r.stderr.splitlines() if l.startswith("volref: timing ")]
        timing = json.loads(said[0][len("volref: timing "):]) if said else {}
        cut = timing.get("bricks")
        # render_s_ranks: each rank's own integration; render_s is the largest of them (the same doubles printed).
        each = timing.get("render_s_ranks", [])
        if len(each) != 2 or min(each) < 0.0 or max(each) != timing.get("render_s"):
            failures.append("%s %s: render_s_ranks %r against render_s %r" % (
                os.path.basename(scene_path), extra, each, timing.get("render_s")))
        if r.returncode != 0 or cut not in (expect, expect + "-same-cut"):
            failures.append("%s %s: expected bricks %r in --timing, got %r (%d) %r" % (
                os.path.basename(scene_path), extra, expect, cut, r.returncode, r.stderr[-300:]))
        else:
            print("ok %s %s: bricks %s" % (os.path.basename(scene_path), " ".join(extra) or "(default)", cut))

if a.mode == "refusals":
    cases = {
        "render.profile": ("render", "profile", "vtk-gpu"),
    }
    def expect_refusal(key, scene):
        out = os.path.join(a.work, "refused.exr")
        r = mpirun(2, ["render", write_scene("refused", scene), "-o", out])
        lines = [l for l in r.stderr.splitlines() if l.startswith("volref: error:")]
        if r.returncode == 0 or len(lines) != 1 or not lines[0].startswith("volref: error: " + key) or os.path.exists(out):
            failures.append("%s: expected one error line naming it, got %d %r" % (key, r.returncode, r.stderr))
        else:
            print("ok " + lines[0])

    for key, (section, k, v) in cases.items():
        s = base_scene("composite", "ortho")
        s[section][k] = v
        expect_refusal(key, s)
    # The fast profile's pre-integrated segments (each rank would build its own table).
    s = base_scene("composite", "ortho")
    s["render"]["profile"] = "fast"
    s["render"]["profile_options"] = {"preintegration": 64}
    expect_refusal("render.profile_options.preintegration", s)
    # Several volumes: the key names the volume at fault.
    s = two_volumes("composite", "ortho")
    s["volumes"][1]["gradient"] = {"cache": "auto"}
    s["volumes"][1]["shading"] = {"model": "phong"}
    expect_refusal("volumes[1].gradient.cache", s)

for f in failures:
    print("FAIL " + f)
sys.exit(1 if failures else 0)
