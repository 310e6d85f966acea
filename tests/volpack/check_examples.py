#!/usr/bin/python3
"""Checks run_case.py's scene -> VolPack translation against VolPack's own example programs (issue 55).

    check_examples.py VOLPACK_RENDER CC VOLPACK_INCLUDE_DIR VOLPACK_LIBRARY WORKDIR

Debian's libvolpack1-dev ships the 1994 examples (/usr/share/doc/libvolpack1-dev/examples: makevolume,
makeoctree, classifyvolume, rendervolume, K&R C) and their input brainsmall.den. They are compiled as they
are into WORKDIR (CC -std=gnu89 -w) and run as the examples' test.sh does: rendervolume on the unclassified
volume (vpRenderRawVolume), with the min-max octree, and -classified on classifyvolume's output
(vpRenderClassifiedVolume); each writes a 256 x 256 VP_LUMINANCE image. scenes/brain_examples_raw.json and
scenes/brain_examples_classified.json, translated by run_case.py and rendered by volpack_render, must give
the same bytes (their luminance channel; volpack_render renders VP_LUMINANCEA). Exit 0 when every image
agrees byte for byte, 1 otherwise.
"""
import gzip
import os
import shutil
import subprocess
import sys

import numpy as np

sys.dont_write_bytecode = True  # run_case is imported from the source tree
import run_case  # noqa: E402

EXAMPLES = "/usr/share/doc/libvolpack1-dev/examples"
HERE = os.path.dirname(os.path.abspath(__file__))


def copy_example(name, workdir):
    """An example file into WORKDIR (Debian may ship it gzipped)."""
    src = os.path.join(EXAMPLES, name)
    dst = os.path.join(workdir, name)
    if os.path.exists(src):
        shutil.copyfile(src, dst)
    elif os.path.exists(src + ".gz"):
        with gzip.open(src + ".gz", "rb") as f, open(dst, "wb") as g:
            g.write(f.read())
    else:
        sys.exit(f"check_examples: {src} not found (install libvolpack1-dev: scripts/install-deps.sh)")


def run(cmd, cwd):
    r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.stderr.write(r.stdout + r.stderr)
        sys.exit(f"check_examples: failed (exit status {r.returncode}): {' '.join(cmd)}")
    return r


def read_pgm(path):
    with open(path, "rb") as f:
        data = f.read()
    # StorePGM: "P5\n%d %d\n%d\n" then width * height bytes
    magic, size, maxval, body = data.split(b"\n", 3)
    width, height = map(int, size.split())
    if magic != b"P5" or maxval != b"255" or len(body) != width * height:
        sys.exit(f"check_examples: {path}: not the examples' PGM")
    return np.frombuffer(body, np.uint8).reshape(height, width)


def main(argv):
    if len(argv) != 5:
        print(__doc__, file=sys.stderr)
        return 2
    volpack_render, cc, include_dir, library, workdir = argv
    shutil.rmtree(workdir, ignore_errors=True)
    os.makedirs(workdir)
    for name in ("volume.h", "makevolume.c", "makeoctree.c", "classifyvolume.c", "rendervolume.c",
                 "brainsmall.den"):
        copy_example(name, workdir)
    for program in ("makevolume", "makeoctree", "classifyvolume", "rendervolume"):
        run([cc, "-std=gnu89", "-w", "-O2", "-I", include_dir, f"{program}.c", "-o", program, library, "-lm"], workdir)

    # examples/test.sh, in its order: brainsmall.rv; raw render; octree + raw render; classified render.
    images = {}
    run(["./makevolume"], workdir)
    run(["./rendervolume"], workdir)
    images["rendervolume"] = read_pgm(os.path.join(workdir, "brainsmall.ppm"))
    run(["./makeoctree"], workdir)
    run(["./rendervolume", "-octree"], workdir)
    images["rendervolume -octree"] = read_pgm(os.path.join(workdir, "brainsmall.ppm"))
    run(["./classifyvolume"], workdir)
    run(["./rendervolume", "-classified"], workdir)
    images["rendervolume -classified"] = read_pgm(os.path.join(workdir, "brainsmall.ppm"))

    ok = True
    for scene, example in (("brain_examples_raw", "rendervolume"), ("brain_examples_raw", "rendervolume -octree"),
                           ("brain_examples_classified", "rendervolume -classified")):
        try:
            args, _ = run_case.volpack_args(os.path.join(HERE, "scenes", f"{scene}.json"), workdir)
        except run_case.SceneError as e:
            sys.exit(f"check_examples: {scene}: {e}")
        pam = os.path.join(workdir, f"{scene}.pam")
        r = run([volpack_render, *args, "--output", pam], workdir)
        ours = run_case.read_pam(pam)[..., 0]
        theirs = images[example]
        equal = ours.shape == theirs.shape and bool((ours == theirs).all())
        differing = int((ours != theirs).sum()) if ours.shape == theirs.shape else ours.size
        print(f"check_examples: {scene} ({r.stderr.strip()}) against examples/{example}: "
              f"{'the same bytes' if equal else f'{differing} of {ours.size} pixels differ'} "
              f"(mean {theirs.mean():.3f})")
        ok = ok and equal
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
