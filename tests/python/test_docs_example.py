# The example of docs/python.md ("Checking a GPU-style renderer"): a float32 ray marcher written in numpy,
# checked against volref with a tolerance derived from float32 rounding. Keep the two copies identical.
import numpy as np
import volref

N, STEP, SIZE = 16, 0.5, 64  # a 16^3 volume on [0, 15]^3, the world step, the image size
z, y, x = np.mgrid[0:N, 0:N, 0:N].astype(np.float32)  # indexed [k, j, i]: x fastest
VOL = np.exp(-((x - 7) ** 2 + (y - 8) ** 2 + (z - 7.5) ** 2) / 18).astype(np.float32)
SCENE = {"volume": {"source": VOL, "transfer": {"color": [[0, .1, .2, .9], [1, 1, .6, .1]], "opacity": [[0, 0], [1, .8]]}},
         "camera": {"type": "orthographic", "eye": [7.5, 7.5, 30], "target": [7.5, 7.5, 0], "up": [0, 1, 0], "height": 15},
         "image": {"width": SIZE, "height": SIZE}, "render": {"step": STEP, "step_units": "world"}}


def toy_render(vol):  # "GPU-style": float32, front to back along -z, one sample at each segment's midpoint
    p = (np.arange(SIZE, dtype=np.float32) + 0.5) * np.float32(15 / SIZE)  # pixel centres (volref's camera)
    X, Y = np.meshgrid(p, p[::-1])  # row 0 on top
    i0, j0 = np.minimum(X.astype(int), N - 2), np.minimum(Y.astype(int), N - 2)
    fx, fy = X - i0, Y - j0
    C, T = np.zeros((SIZE, SIZE, 3), np.float32), np.ones((SIZE, SIZE), np.float32)
    for k in range(int(15 / STEP)):
        Z = np.float32(15 - (k + 0.5) * STEP)
        k0 = min(int(Z), N - 2)
        fz = Z - k0
        v = sum(vol[k0 + c, j0 + b, i0 + a] * (fx if a else 1 - fx) * (fy if b else 1 - fy) * (fz if c else 1 - fz)
                for a in (0, 1) for b in (0, 1) for c in (0, 1))
        alpha = 1 - (1 - np.float32(.8) * v) ** np.float32(STEP)  # opacity .8 v per unit length, corrected
        C += (T * alpha)[..., None] * (np.float32([.1, .2, .9]) + v[..., None] * np.float32([.9, .4, -.8]))
        T *= 1 - alpha
    return np.dstack([C, 1 - T])


def test_toy_renderer_matches_volref():
    reference = volref.render(SCENE)
    tolerance = int(15 / STEP) * 32 * 2.0 ** -24  # N samples x at most ~32 float32 roundings (2^-24) each
    r = volref.compare(toy_render(VOL), reference, tolerance=tolerance)
    print(f"\nmax abs {r['overall']['max_abs']:.3g} (tolerance {tolerance:.3g}), "
          f"PSNR {r['overall']['psnr_db']:.1f} dB, pixels over: {r['pixels_over']} of {r['pixels']}")
    assert r["within_tolerance"] and reference.rgba[..., 3].max() > 0.5
