#!/usr/bin/python3
"""Checks run_case.py's comparison rules without volref's profile (issue 55).

    selftest_compare.py VOLPACK_RENDER WORKDIR

run_case.py is run on two scenes with this script standing in for volref: called as
`selftest_compare.py render SCENE -o OUT.exr` it writes VolPack's own image (volpack_render's PAM, the
path in $SELFTEST_PAM) as an EXR of k/255 values, changed as $SELFTEST_MODE says. Each mode has the
verdict the rules in run_case.py's docstring give; run_case.py must return it, with and without
--expect-mismatch. Exit 0 when every verdict is right.
"""
import os
import subprocess
import sys

import numpy as np

sys.dont_write_bytecode = True
import run_case  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))

# mode: (what it does, passes?)
MODES = {
    "exact": ("VolPack's bytes (no error channel)", True),
    "one_off": ("one byte of one pixel + 1, no error channel", False),
    "one_off_flagged": ("one byte + 1 where the error channel is 1/255", True),
    "two_off_flagged": ("one byte + 2 where the error channel is 1/255", False),
    "many_off_flagged": ("0.2 % of the pixels + 1, all flagged (below 99.9 % exact)", False),
    "few_off_flagged": ("0.05 % of the pixels + 1, all flagged", True),
    "green_off": ("G differs from R where VolPack's luminance is (R = G = B = luminance)", False),
    "alpha_off": ("alpha - 1 at one pixel, no error", False),
    "rows_flipped": ("image rows in reverse order", False),
}


def fake_volref(argv):
    """`render SCENE -o OUT.exr`: VolPack's PAM as the EXR, changed by $SELFTEST_MODE."""
    import OpenImageIO as oiio
    out = argv[argv.index("-o") + 1]
    mode = os.environ["SELFTEST_MODE"]
    channels = int(os.environ["SELFTEST_CHANNELS"])
    img = run_case.as_rgba(run_case.read_pam(os.environ["SELFTEST_PAM"]), channels).astype(np.int32)
    h, w = img.shape[:2]
    error = np.zeros((h, w))
    covered = np.argwhere((img[..., 3] > 10) & (img[..., 3] < 245) & (img[..., 0] < 250))
    y, x = covered[len(covered) // 2]
    if mode.startswith(("one_off", "two_off")):
        img[y, x, 0] += 1 if mode.startswith("one") else 2
        if mode.endswith("flagged"):
            error[y, x] = 1 / 255
    elif mode in ("many_off_flagged", "few_off_flagged"):
        count = int(h * w * (0.002 if mode.startswith("many") else 0.0005))
        picks = covered[np.linspace(0, len(covered) - 1, count).astype(int)]
        img[picks[:, 0], picks[:, 1], 3] -= 1
        error[picks[:, 0], picks[:, 1]] = 1 / 255
    elif mode == "green_off":
        img[y, x, 1] += 1
    elif mode == "alpha_off":
        img[y, x, 3] -= 1
    elif mode == "rows_flipped":
        img = img[::-1]
    # An `error` channel only where the mode flags pixels: the other modes check run_case's "no error
    # channel = 0".
    flagged = mode.endswith("flagged")
    pixels = np.concatenate([img / 255.0] + ([error[..., None]] if flagged else []), axis=-1).astype(np.float32)
    spec = oiio.ImageSpec(w, h, pixels.shape[-1], "float")
    spec.channelnames = ("R", "G", "B", "A", "error")[:pixels.shape[-1]]
    o = oiio.ImageOutput.create(out)
    o.open(out, spec)
    o.write_image(np.ascontiguousarray(pixels))
    o.close()
    return 0


def main(argv):
    if argv and argv[0] == "render":
        return fake_volref(argv[1:])
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    volpack_render, workdir = argv
    os.makedirs(workdir, exist_ok=True)
    ok = True
    for scene, channels in (("ml_unshaded_gray_x", 1), ("ml_shaded_rgb_lights_z", 3)):
        path = os.path.join(HERE, "scenes", f"{scene}.json")
        for mode, (what, passes) in MODES.items():
            if mode == "green_off" and channels == 3:
                continue
            env = dict(os.environ, SELFTEST_MODE=mode, SELFTEST_CHANNELS=str(channels),
                       SELFTEST_PAM=os.path.join(workdir, f"{scene}-volpack.pam"), PYTHONDONTWRITEBYTECODE="1")
            for expect_mismatch in (False, True):
                cmd = ["/usr/bin/python3", os.path.join(HERE, "run_case.py"), volpack_render, os.path.abspath(__file__),
                       path, workdir] + (["--expect-mismatch"] if expect_mismatch else [])
                r = subprocess.run(cmd, env=env, capture_output=True, text=True)
                want = 0 if passes != expect_mismatch else 1
                right = r.returncode == want
                ok = ok and right
                if not right or not expect_mismatch:
                    print(f"selftest_compare: {scene}, {what}{' (--expect-mismatch)' if expect_mismatch else ''}: "
                          f"exit {r.returncode}, expected {want}: {'right' if right else 'WRONG'}")
                if not right:
                    sys.stdout.write(r.stdout + r.stderr)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
