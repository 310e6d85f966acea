"""An independent "external renderer": a small numpy ray caster in float32, as a GPU shader computes.

Written from volref's documented contract only (docs/conventions.md sections 1-10, docs/scene-format.md,
docs/python.md), not from its C++ code, so that the test suite has a second renderer to hold volref's
presets against. Every convention a GPU renderer may choose differently is a keyword switch of `render`,
and `bug=` plants one mistake a shader writer makes (tests/python/test_external_caster.py).

What it renders: one Cartesian volume given as a numpy array indexed [k, j, i] (shape (nz, ny, nx),
x fastest; voxel (i, j, k) at origin + (i, j, k) spacing), trilinear reconstruction (Levoy's term order,
positions clamped to the domain = CLAMP_TO_EDGE), a piecewise-linear transfer function in the `data`
domain (colour and opacity rows, `opacity_unit_distance` l), a perspective or orthographic camera, the
composite and mip projections, and optionally Blinn-Phong / Phong shading (section 8) with headlights
and directional lights. All arithmetic on the rays is float32; the transfer-function tables are built
in double on the "CPU" and stored as float32 texels, as a GPU program uploads them.
"""
import math

import numpy as np

F32 = np.float32

PLACEMENTS = ("midpoints", "from-entry", "from-exit")
STEP_COUNTS = ("through-exit", "before-exit")
RAY_BOXES = ("domain", "texel")
CORRECTIONS = ("none", "pow", "exact", "extinction")
COMPOSITINGS = ("opacity-sum", "product")
TERMINATIONS = ("alpha_at_least", "alpha_above", "transmittance_at_most")
OUTPUT_MODELS = ("flip", "unpremultiplied", "double-premultiplied", "bgra", "srgb")
BUGS = ("half-texel-shift", "colour-missing-correction", "wrong-order", "double-premultiply", "flip-data-z")

SEGMENT_SLACK = 1e-9  # docs/conventions.md section 4 (kSegmentSlack); below float32's resolution of L / h

# The switches that reproduce volref's presets (docs/conventions.md section 9), unshaded.
PRESETS = {
    "reference": dict(placement="midpoints", correction="pow", table=0, compositing="product", termination=None),
    "vtk-gpu": dict(placement="from-entry", first=1, step_count="through-exit", table=1024, correction="pow",
                    correction_floor=1e-4, compositing="opacity-sum", termination=("alpha_above", 1 - 1 / 255)),
    "ospray": dict(placement="midpoints", correction="extinction", table=0, compositing="opacity-sum",
                   termination=("alpha_at_least", 0.999)),
}


def _vec(x):
    return np.asarray(x, dtype=F32).reshape(3)


def _normalize(v):
    return (v / np.sqrt(np.sum(v * v, axis=-1, keepdims=True))).astype(F32)


def _cross(a, b):
    return np.cross(a, b).astype(F32)


class _TransferFunction:
    """Piecewise-linear rows, clamped to the end rows, right-continuous at a repeated value (section 3)."""

    def __init__(self, rows, width):
        rows = np.asarray(rows, dtype=np.float64).reshape(-1, width + 1)
        if np.any(np.diff(rows[:, 0]) < 0):
            raise ValueError("transfer-function rows must be sorted by value")
        self.rows = rows

    def __call__(self, v, dtype=F32):
        rows = self.rows.astype(dtype)
        xs, ys = rows[:, 0], rows[:, 1:]
        v = np.asarray(v, dtype=dtype)
        i = np.searchsorted(xs, v, side="right") - 1  # the last row with x <= v (a jump's later row)
        lo = np.clip(i, 0, len(xs) - 1)
        hi = np.clip(i + 1, 0, len(xs) - 1)
        span = xs[hi] - xs[lo]
        w = np.where((i >= 0) & (i < len(xs) - 1) & (span > 0), (v - xs[lo]) / np.where(span > 0, span, 1), 0)
        w = w.astype(dtype)[..., None]
        out = ys[lo] * (dtype(1) - w) + ys[hi] * w
        return out.astype(dtype)


class _Volume:
    def __init__(self, spec, bug):
        data = np.asarray(spec["source"])
        if data.ndim != 3:
            raise ValueError("volume.source: expected a 3-D numpy array indexed [k, j, i]")
        data = data.astype(F32)
        if bug == "flip-data-z":
            data = data[::-1]
        self.data = np.ascontiguousarray(data)
        self.flat = self.data.reshape(-1)
        self.dims = np.array(data.shape[::-1])  # (nx, ny, nz)
        self.origin = _vec(spec.get("origin", [0, 0, 0]))
        self.spacing = _vec(spec.get("spacing", [1, 1, 1]))
        self.lo = self.origin
        self.hi = (self.origin + (self.dims - 1).astype(F32) * self.spacing).astype(F32)
        self.vmin = float(np.min(data))
        self.vmax = float(np.max(data))

    def sample(self, p):
        """Trilinear value at world points p (M, 3), float32; points clamped to the domain."""
        n = self.dims
        u = (p - self.origin) / self.spacing
        u = np.minimum(np.maximum(u, F32(0)), (n - 1).astype(F32)).astype(F32)
        i = np.minimum(np.floor(u).astype(np.int64), np.maximum(n - 2, 0))
        f = (u - i.astype(F32)).astype(F32)
        i1 = np.minimum(i + 1, n - 1)
        nx, ny = int(n[0]), int(n[1])
        x0, y0, z0 = i[:, 0], i[:, 1], i[:, 2]
        x1, y1, z1 = i1[:, 0], i1[:, 1], i1[:, 2]
        p_, q_, r_ = f[:, 0], f[:, 1], f[:, 2]
        one = F32(1)
        fv = self.flat

        def at(x, y, z):
            return fv[(z * ny + y) * nx + x]

        # Levoy's sum, term by term in his order (section 2)
        v = at(x0, y0, z0) * (one - p_) * (one - q_) * (one - r_)
        v = v + at(x1, y0, z0) * p_ * (one - q_) * (one - r_)
        v = v + at(x1, y1, z0) * p_ * q_ * (one - r_)
        v = v + at(x0, y1, z0) * (one - p_) * q_ * (one - r_)
        v = v + at(x0, y0, z1) * (one - p_) * (one - q_) * r_
        v = v + at(x1, y0, z1) * p_ * (one - q_) * r_
        v = v + at(x1, y1, z1) * p_ * q_ * r_
        v = v + at(x0, y1, z1) * (one - p_) * q_ * r_
        return v.astype(F32)

    def gradient(self, p, scheme="central-in-domain", offset=1.0):
        """Differences of the reconstructed field at offset o = offset spacings per axis: central with the
        stencil inside the domain, one-sided at it (section 2), central of the clamped field, or forward."""
        g = np.empty_like(p)
        for a in range(3):
            o = F32(offset * self.spacing[a])
            c = p.copy()
            b = p.copy()
            if scheme == "central-in-domain":
                c[:, a] = np.maximum(p[:, a] - o, self.lo[a])
                b[:, a] = np.minimum(p[:, a] + o, self.hi[a])
                w = b[:, a] - c[:, a]
                g[:, a] = np.where(w > 0, (self.sample(b) - self.sample(c)) / np.where(w > 0, w, 1), 0)
            elif scheme == "central":
                c[:, a] = p[:, a] - o
                b[:, a] = p[:, a] + o
                g[:, a] = (self.sample(b) - self.sample(c)) / (F32(2) * o)
            elif scheme == "forward":
                b[:, a] = p[:, a] + o
                g[:, a] = (self.sample(b) - self.sample(p)) / o
            else:
                raise ValueError(f"gradient {scheme!r}")
        return g.astype(F32)


def _camera_rays(camera, width, height):
    """Origins and unit directions (H W, 3) through the pixel centres, row 0 on top (section 10)."""
    W, H = F32(width), F32(height)
    x = np.arange(width, dtype=F32)
    y = np.arange(height, dtype=F32)
    nx = F32(2) * (x + F32(0.5)) / W - F32(1)
    ny = F32(1) - F32(2) * (y + F32(0.5)) / H
    NX, NY = np.meshgrid(nx, ny)
    NX, NY = NX.reshape(-1, 1), NY.reshape(-1, 1)
    eye, target, up = _vec(camera["eye"]), _vec(camera["target"]), _vec(camera["up"])
    f = _normalize(target - eye)
    r = _normalize(_cross(f, up))
    u = _cross(r, f)
    aspect = W / H
    kind = camera.get("type", "perspective")
    if kind == "perspective":
        tan_half = F32(math.tan(math.radians(float(camera["fov_y"])) / 2))
        d = f + NX * tan_half * aspect * r + NY * tan_half * u
        d = _normalize(d.astype(F32))
        o = np.broadcast_to(eye, d.shape).astype(F32)
    elif kind == "orthographic":
        half = F32(float(camera["height"]) / 2)
        o = (eye + NX * half * aspect * r + NY * half * u).astype(F32)
        d = np.broadcast_to(f, o.shape).astype(F32)
    else:
        raise ValueError(f"camera.type: {kind!r} not supported by the external caster")
    return np.ascontiguousarray(o), np.ascontiguousarray(d)


def _slab(o, d, lo, hi):
    """float32 ray/box slab test for t >= 0: (t0, t1, hit)."""
    t0 = np.zeros(len(o), F32)
    t1 = np.full(len(o), np.inf, F32)
    inside_all = np.ones(len(o), bool)
    for a in range(3):
        da = d[:, a]
        zero = da == 0
        safe = np.where(zero, F32(1), da)
        ta = (lo[a] - o[:, a]) / safe
        tb = (hi[a] - o[:, a]) / safe
        near = np.where(zero, -np.inf, np.minimum(ta, tb)).astype(F32)
        far = np.where(zero, np.inf, np.maximum(ta, tb)).astype(F32)
        # a direction exactly 0 on an axis: the slab holds for all t or none (no 0 x inf)
        inside_all &= ~zero | ((o[:, a] >= lo[a]) & (o[:, a] <= hi[a]))
        t0 = np.maximum(t0, near)
        t1 = np.minimum(t1, far)
    hit = inside_all & (t1 > t0)
    return t0.astype(F32), t1.astype(F32), hit


def _srgb(x):
    x = np.clip(x, 0, 1)
    return np.where(x <= F32(0.0031308), F32(12.92) * x, F32(1.055) * x ** F32(1 / 2.4) - F32(0.055)).astype(F32)


def apply_output_model(img, model):
    """One output model applied to a premultiplied RGBA image (H, W, 4), row 0 on top."""
    img = np.asarray(img, dtype=F32)
    rgb, a = img[..., :3], img[..., 3:]
    if model == "flip":
        return np.ascontiguousarray(img[::-1])
    if model == "unpremultiplied":
        return np.concatenate([np.where(a > 0, rgb / np.where(a > 0, a, 1), 0), a], axis=-1).astype(F32)
    if model == "double-premultiplied":
        return np.concatenate([rgb * a, a], axis=-1).astype(F32)
    if model == "bgra":
        return np.ascontiguousarray(img[..., [2, 1, 0, 3]])
    if model == "srgb":
        return np.concatenate([_srgb(rgb), a], axis=-1).astype(F32)
    raise ValueError(f"output model {model!r} is not one of {OUTPUT_MODELS}")


def render(scene, *, placement="midpoints", first=0.0, step_count="through-exit", ray_box="domain",
           correction="pow", correction_floor=0.0, table=0, compositing="product", termination=None,
           projection=None, shading=True, gradient="central-in-domain", normal="-gradient", gradient_offset=1.0,
           clamp_shaded=False, output=(), bug=None):
    """Render `scene` (a volref scene dict, one numpy volume) to float32 premultiplied RGBA (H, W, 4), row 0 on top.

    placement: "midpoints" (volref's: [t0, t1] cut into n = max(1, ceil(L/h - 1e-9)) segments of length h,
        the last shorter, each sampled at its midpoint standing for its own length d); "from-entry"
        (t0 + (first + k) h, each standing for h); "from-exit" (t1 - (first + k) h, composited back to front).
    first: the first sample's offset in steps for "from-entry" / "from-exit".
    step_count ("from-entry"/"from-exit"): "through-exit" n = max(1, floor(L/h + 1 - first));
        "before-exit" n = max(0, ceil(L/h - first)) (samples strictly before the exit).
    ray_box: "domain" ([origin, origin + (n-1) spacing]) or "texel" (grown by half a spacing per side;
        reads are still clamped to the domain).
    correction: "none" (alpha = a), "pow" (alpha = 1 - (1 - a)^(d/l); with a table each entry corrected
        with the step h, then filtered), "exact" (the same formula on the sample's filtered opacity with
        its own d), "extinction" (alpha = 1 - exp(-a d)). Opacities a <= correction_floor are not
        corrected (vtk-gpu corrects table entries > 1e-4 only).
    table: 0 reads the transfer function exactly; N > 1 builds N-entry tables at
        min + j (max - min)/(N - 1) over the volume's data range, read linearly at texel position
        u N - 0.5 clamped to [0, N - 1], u = (v - min)/(max - min).
    compositing: "opacity-sum" (C += (1-A) alpha c; A += (1-A) alpha) or "product" (C += T alpha c; T *= 1 - alpha).
    termination: None or (rule, x), rule in "alpha_at_least" (A >= x), "alpha_above" (A > x),
        "transmittance_at_most" (T <= x); tested after each sample (front to back only).
    projection: None (the scene's render.projection), "composite" or "mip".
    shading: honour the scene's volume.shading (composite only; blinn-phong / phong, section 8).
    gradient: "central-in-domain" (central differences with the stencil inside the domain, one-sided at
        its boundary: volref's reference), "central" ((f(x + o) - f(x - o)) / 2o of the field clamped to
        the domain, a shader's), "forward" ((f(x + o) - f(x)) / o); o = gradient_offset spacings.
    normal: "-gradient" (N = -g / |g|, volref's) or "+gradient" (a shader's that forgets the sign).
    clamp_shaded: the shaded colour clamped to [0, 1] before compositing.
    output: an output model name or a sequence of them, applied in order to the final image:
        "flip", "unpremultiplied", "double-premultiplied", "bgra", "srgb".
    bug: None or one planted mistake: "half-texel-shift", "colour-missing-correction", "wrong-order",
        "double-premultiply", "flip-data-z".
    """
    if placement not in PLACEMENTS:
        raise ValueError(f"placement {placement!r} is not one of {PLACEMENTS}")
    if step_count not in STEP_COUNTS:
        raise ValueError(f"step_count {step_count!r} is not one of {STEP_COUNTS}")
    if ray_box not in RAY_BOXES:
        raise ValueError(f"ray_box {ray_box!r} is not one of {RAY_BOXES}")
    if correction not in CORRECTIONS:
        raise ValueError(f"correction {correction!r} is not one of {CORRECTIONS}")
    if compositing not in COMPOSITINGS:
        raise ValueError(f"compositing {compositing!r} is not one of {COMPOSITINGS}")
    if bug is not None and bug not in BUGS:
        raise ValueError(f"bug {bug!r} is not one of {BUGS}")
    if termination is not None:
        rule, limit = termination
        if rule not in TERMINATIONS:
            raise ValueError(f"termination {rule!r} is not one of {TERMINATIONS}")
        limit = F32(limit)
    if placement == "from-exit" and termination is not None:
        raise ValueError("termination needs front-to-back compositing (not placement 'from-exit')")

    vspec = scene["volume"]
    vol = _Volume(vspec, bug)
    tf_spec = vspec.get("transfer", {})
    if tf_spec.get("domain", "data") != "data":
        raise ValueError("volume.transfer.domain: only 'data' is supported by the external caster")
    colour_tf = _TransferFunction(tf_spec.get("color", [[0, 1, 1, 1]]), 3)
    opacity_tf = _TransferFunction(tf_spec.get("opacity", [[vol.vmin, 0], [vol.vmax, 1]]), 1)
    l = float(tf_spec.get("opacity_unit_distance", 1.0))

    image = scene.get("image", {})
    width, height = int(image.get("width", 256)), int(image.get("height", 256))
    rspec = scene.get("render", {})
    if projection is None:
        projection = rspec.get("projection", "composite")
    if projection not in ("composite", "mip"):
        raise ValueError(f"projection {projection!r}: the external caster does composite and mip")
    step = float(rspec.get("step", 0.5))
    if rspec.get("step_units", "voxel") == "voxel":
        step *= float(np.min(vol.spacing))
    h = F32(step)

    shade = shading and projection == "composite" and vspec.get("shading") is not None
    if shade:
        sh = dict(model="blinn-phong", ka=0.1, kd=0.7, ks=0.2, n=10, kc=1, kl=0, two_sided=False)
        sh.update(vspec["shading"])
        lights = scene.get("lights", [{"type": "headlight", "color": [1, 1, 1]}])
        zero_gradient = F32(1e-9 * max(abs(vol.vmin), abs(vol.vmax)) / float(np.min(vol.spacing)))

    # ---- transfer function: exact, or float32 tables built in double over the data range
    def correct(a, d):
        if correction == "none":
            return a
        if correction == "extinction":
            alpha = 1 - np.exp(-a * d)
        else:
            alpha = 1 - (1 - np.minimum(a, 1)) ** (d / l)
        return np.where(a > correction_floor, alpha, a).astype(a.dtype)

    if table:
        N = int(table)
        xs = vol.vmin + np.arange(N, dtype=np.float64) * (vol.vmax - vol.vmin) / (N - 1)
        colour_table = colour_tf(xs, np.float64).astype(F32)
        a_table = opacity_tf(xs, np.float64)[:, 0]
        alpha_table = (correct(a_table, float(step)) if correction == "pow" else a_table).astype(F32)
        a_table = a_table.astype(F32)
        span = F32(vol.vmax - vol.vmin) if vol.vmax > vol.vmin else F32(1)
        vmin32 = F32(vol.vmin)

        def fetch(tab, v):
            pos = (v - vmin32) / span * F32(N) - F32(0.5)
            pos = np.minimum(np.maximum(pos, F32(0)), F32(N - 1)).astype(F32)
            i0 = np.floor(pos).astype(np.int64)
            i1 = np.minimum(i0 + 1, N - 1)
            w = (pos - i0.astype(F32)).astype(F32)
            if tab.ndim == 2:
                w = w[:, None]
            return (tab[i0] * (F32(1) - w) + tab[i1] * w).astype(F32)

        def classify(v):  # (colour, uncorrected a, alpha-so-far: corrected table entries or None)
            return fetch(colour_table, v), fetch(a_table, v), (fetch(alpha_table, v) if correction == "pow" else None)
    else:
        def classify(v):
            return colour_tf(v), opacity_tf(v)[:, 0], None

    def sample_alpha(a, pre, d):
        if pre is not None:  # pow with a table: entries corrected with h, then filtered
            return pre
        return correct(a, d).astype(F32)

    # ---- rays and intervals
    o, dirs = _camera_rays(scene["camera"], width, height)
    lo, hi = vol.lo, vol.hi
    if ray_box == "texel":
        lo = (lo - F32(0.5) * vol.spacing).astype(F32)
        hi = (hi + F32(0.5) * vol.spacing).astype(F32)
    t0, t1, hit = _slab(o, dirs, lo, hi)
    L = np.where(hit, t1 - t0, F32(0)).astype(F32)
    Lh = (L / h).astype(F32)
    firstf = F32(first)
    if placement == "midpoints":
        n = np.maximum(1, np.ceil(Lh - F32(SEGMENT_SLACK))).astype(np.int64)
    elif step_count == "through-exit":
        n = np.maximum(1, np.floor(Lh + F32(1) - firstf)).astype(np.int64)
    else:
        n = np.maximum(0, np.ceil(Lh - firstf)).astype(np.int64)
    n = np.where(hit, n, 0)

    rays = len(o)
    C = np.zeros((rays, 3), F32)
    A = np.zeros(rays, F32)
    T = np.ones(rays, F32)
    vbest = np.full(rays, -np.inf, F32)
    alive = np.ones(rays, bool)
    shift = np.array([F32(0.5) * vol.spacing[0], 0, 0], F32) if bug == "half-texel-shift" else None

    for k in range(int(n.max(initial=0))):
        idx = np.nonzero((k < n) & alive)[0]
        if len(idx) == 0:
            break
        kf = F32(k)
        if placement == "midpoints":
            start = t0[idx] + kf * h
            end = np.where(k == n[idx] - 1, t1[idx], t0[idx] + (kf + F32(1)) * h)
            d = (end - start).astype(F32)
            t = (start + F32(0.5) * d).astype(F32)
        elif placement == "from-entry":
            t = (t0[idx] + (firstf + kf) * h).astype(F32)
            d = np.full(len(idx), h, F32)
        else:
            t = (t1[idx] - (firstf + kf) * h).astype(F32)
            d = np.full(len(idx), h, F32)
        p = (o[idx] + t[:, None] * dirs[idx]).astype(F32)
        if shift is not None:
            p = (p + shift).astype(F32)
        v = vol.sample(p)

        if projection == "mip":
            better = v > vbest[idx]
            vbest[idx] = np.where(better, v, vbest[idx])
            continue

        c, a, pre = classify(v)
        alpha = sample_alpha(a, pre, d)
        if shade:
            c = _shade(c, alpha, p, dirs[idx], t, vol, sh, lights, zero_gradient, gradient, normal, gradient_offset)
            if clamp_shaded:
                c = np.clip(c, F32(0), F32(1)).astype(F32)
        weight = a if bug == "colour-missing-correction" else alpha
        if bug == "double-premultiply":
            c = c * alpha[:, None]

        if placement == "from-exit":  # back to front: C = alpha c + (1 - alpha) C
            C[idx] = (weight[:, None] * c + (F32(1) - alpha)[:, None] * C[idx]).astype(F32)
            A[idx] = (alpha + (F32(1) - alpha) * A[idx]).astype(F32)
            continue

        if compositing == "opacity-sum":
            Ai = A[idx]
            if bug == "wrong-order":
                Ai = (Ai + (F32(1) - Ai) * alpha).astype(F32)
                C[idx] = (C[idx] + ((F32(1) - Ai) * weight)[:, None] * c).astype(F32)
            else:
                C[idx] = (C[idx] + ((F32(1) - Ai) * weight)[:, None] * c).astype(F32)
                Ai = (Ai + (F32(1) - Ai) * alpha).astype(F32)
            A[idx] = Ai
            T[idx] = F32(1) - Ai
        else:
            Ti = T[idx]
            if bug == "wrong-order":
                Ti = (Ti * (F32(1) - alpha)).astype(F32)
                C[idx] = (C[idx] + (Ti * weight)[:, None] * c).astype(F32)
            else:
                C[idx] = (C[idx] + (Ti * weight)[:, None] * c).astype(F32)
                Ti = (Ti * (F32(1) - alpha)).astype(F32)
            T[idx] = Ti
            A[idx] = F32(1) - Ti

        if termination is not None:
            Ai, Ti = A[idx], T[idx]
            if rule == "alpha_at_least":
                stop = Ai >= limit
            elif rule == "alpha_above":
                stop = Ai > limit
            else:
                stop = Ti <= limit
            alive[idx[stop]] = False

    if projection == "mip":
        seen = vbest > -np.inf
        vb = np.where(seen, vbest, F32(0)).astype(F32)
        c, a, _ = classify(vb)  # uncorrected opacity at the extremum
        a = np.where(seen, a, F32(0)).astype(F32)
        C = (a[:, None] * c).astype(F32)
        A = a

    img = np.concatenate([C, A[:, None]], axis=1).reshape(height, width, 4).astype(F32)
    if isinstance(output, str):
        output = (output,)
    for model in output:
        img = apply_output_model(img, model)
    return img


def _shade(m, alpha, p, dirs, t, vol, sh, lights, zero_gradient, scheme="central-in-domain", normal="-gradient", offset=1.0):
    """Section 8 at the samples with alpha > 0: c = sum_l I (ka m + kd m max(N.L, 0) cue) + I ks s^n cue."""
    out = m.copy()
    vis = alpha > 0
    if not vis.any():
        return out
    g = vol.gradient(p[vis], scheme, offset)
    gl = np.sqrt(np.sum(g * g, axis=1))
    flat = gl <= zero_gradient
    sign = F32(-1) if normal == "-gradient" else F32(1)
    N = (sign * g / np.where(flat, F32(1), gl)[:, None]).astype(F32)
    V = (-dirs[vis]).astype(F32)
    mv = m[vis]
    cue = (F32(1) / (F32(sh["kc"]) + F32(sh["kl"]) * t[vis]))[:, None]
    c = np.zeros_like(mv)
    for light in lights:
        I = _vec(light.get("color", [1, 1, 1]))
        if light.get("type", "headlight") == "headlight":
            Ld = V
        else:
            Ld = np.broadcast_to(_normalize(_vec(light["direction"])), V.shape)
        NL = np.sum(N * Ld, axis=1)
        if sh["model"] == "phong":
            R = (F32(2) * NL[:, None] * N - Ld).astype(F32)
            S = np.sum(R * V, axis=1)
        else:
            H = _normalize((Ld + V).astype(F32))
            S = np.sum(N * H, axis=1)
        if sh["two_sided"]:  # |N.L| and |N.H|; phong's R = 2 (N.L) N - L is the same for -N: R.V stays
            NL = np.abs(NL)
            if sh["model"] != "phong":
                S = np.abs(S)
        diffuse = np.maximum(NL, F32(0))[:, None]
        spec = (np.maximum(S, F32(0)) ** F32(sh["n"]))[:, None]
        ks = 0 if sh["model"] == "nodal" else sh["ks"]
        c = c + I * F32(sh["ka"]) * mv + I * F32(sh["kd"]) * mv * diffuse * cue + I * F32(ks) * spec * cue
    out[vis] = np.where(flat[:, None], mv, c).astype(F32)
    return out
