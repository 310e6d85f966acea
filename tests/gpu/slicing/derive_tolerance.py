#!/usr/bin/python3
"""The tolerance of one slicing test: how far gl_slicer on llvmpipe (float32 fragments, GL's frame buffer)
can be from volref's placement "slices" (double fragments, the contract's frame-buffer model) on the same
scene, from the arithmetic. gl_probe measures the llvmpipe arithmetic taken here (tests slicing_probe*).

1. The fragment (what one crossing computes), per channel on [0, 1]:
    u    = 2^-24                     float32 unit roundoff
    X    = max(|E|, |box corners|)   the size of the coordinates (world units)
    dx   = 2 u X                     the fragment's world position, interpolated from the polygon's float
                                     vertices (gl_probe "interp", a slice of a 48^3 box from 125 away: at
                                     most 1.09 u X, on average 0.53 u X; shells: E + lambda dir, a few u);
                                     dx_mean = 0.6 u X for the rates below
    G_s  = max |grad s|              of the trilinear interpolant of the stored texels s_i (per world
                                     unit: the largest texel difference per axis over the spacing)
    ds   = G_s dx + 8 u              the filtered texel (llvmpipe filters with float weights under
                                     GALLIVM_PERF=no_aos_sampling: within 1.4e-7, gl_probe "filter")
    S_a, S_c                         the transfer function's largest opacity and colour slopes per unit s
    da = S_a ds + 8 u, dc = S_c ds + 8 u   (table 0, linear and texture reads, pre-unweighted)
    a nearest read returns an entry exactly (da = dc = 0) but takes the next entry where s (N - 1) lies
    within (N - 1) ds of a half-integer: an index event, at rate p_idx = 2 (N - 1) ds_mean per fragment
    (the fractional part of s (N - 1) taken as uniform), each moving the fragment by one entry step
    (e_c in colour, e_a in opacity)
    correction exact: alpha = 1 - (1 - a)^r, r = d / l, d = s_k / |n . dir| <= s_k / c_min (c_min: the cosine
    of the frustum's corner half-angle; axis planes a further 1 / sqrt 3): dalpha <= D da + 64 u,
    D = max(1, r_max) / (1 - a_max)
    d = dalpha + dc (premultiplied: a c), else max(dalpha, dc)
   texture_filter "fixed8" (the scenes under scenes-default/, llvmpipe's default 8-bit filter; gl_probe
   "filter", "texel8"): both renderers lerp codes with weights i & 255, i = rint(fl(x fl(256 n))) - 128, so s
   is the same code (ds = 0) but for a weight event: i differs between llvmpipe's coordinate (the rasteriser's
   float position through the shader's float32 ((x - o) / s + 1/2) / n) and volref's float((c + 1/2) / n) of
   its double crossing (per axis on average 256 u (1.6 X / s_a + 3 n_a), the fraction of i uniform); a weight
   one off moves that lerp by one code with chance |v1 - v0| / 256, and s by one code (later lerps are
   monotone, steps <= 1): p_w per fragment, times the chance that the neighbouring code reads another entry
   (over the shown voxels' codes); each moves the fragment by (e_c, e_a), the largest entry step between
   neighbouring codes. The table is read per code k exactly as each renderer does (fixed8_fragments):
   llvmpipe addresses it with its texel's float fl(k fl(1/255)) (126 of the 256 codes an ulp from k / 255),
   volref with float((pos + 1/2) / N) of the exact k / 255, which decides another i for a few (k, N) (e.g.
   N 256 "texture" k 127: fl(127 fl(1/255)) 65536 = 32639.5, a tie to even 32640, against 32639.498; N 1000
   k 236, linear N 255 k 128): where the two reads differ (table_event codes) every fragment is taken off by
   that much; the scenes have none. Nearest reads never flip (s (N - 1) = k (N - 1) / 255 is >= 1/510 from a
   half-integer, 2 k (N - 1) even against 255 (2 m + 1) odd). With a unorm8 table and correction none the
   fragment is a code in both (frag_exact): no conversion events (fl(k fl(1/255)) is within 255 2^-24 codes
   of k, a premultiplied a c within 1e-5 codes of q_a q_c / 255, itself >= 1/510 from a tie).

2. The frame buffer. A ray meets at most N fragments that are not transparent (a transparent fragment
   leaves every buffer as it is in both: c 0 + C 1 = C exactly): N = floor(L / s) + 1, L the diagonal of
   the box of the voxels whose opacity (mip: colour or opacity) is not 0, one voxel wider, s the level
   spacing (crossings of planes lie at least s apart along a ray, |n . dir| <= 1).
   - Float buffers: both blend in float32 with each product and the sum rounded (gl_probe: llvmpipe does
     not fuse); one blend moves the difference by at most |d(c a)| + |C da| + rounding <= 3 d + 4 u:
     first-order part N (3 d + 4 u); rgba16f adds N 2^-11: each store within one unit in the last place of
     a value below 1 of the other's, whichever way llvmpipe (toward zero, gl_probe "blendf", in both
     environments) and the scene (framebuffer_rounding) round. With framebuffer_rounding "truncate" and a
     fragment that is a code in both (fixed8): the float32 blends differ by the fragments' ulp only (2 u
     relative before a store, on average), and truncating two values closer than binary16's spacing (>= 2^-11
     of the value) gives the same value or neighbours: first-order part 0, a flip event of <= 2^-11 per store
     and channel with chance 2 u 2^11. GL_MAX is exact: d.
   - rgba8: both blend codes with llvmpipe's products (the scenes set framebuffer_rounding "nearest" and
     blend_products "llvmpipe", or "rounded" with operands below 152), so the codes agree but for events,
     each not growing after it (mul8(Q + e, f) - mul8(Q, f) <= e): a code tie moves a channel by at most 2
     codes (an alpha code moves both products by at most 1); an index or weight event moves the fragment by
     Dc, Da codes and the blend by at most max(Dc + 2 Da, 3 Da) + 2 (q_c q_a by Dc + Da + 1, C (255 - q_a)
     by Da + 1; alpha 2 Da + 1 and Da + 1). blend_products "exact" or framebuffer_rounding "truncate" are not
     llvmpipe's: up to 2 codes a blend, first-order part 2 N / 255. The events:
       a fragment channel within d of a code's rounding tie: p_q = 2 (255 d_mean) per channel, plus 1.6e-5
         where d > 0 (llvmpipe converts by RNE(fl(x 255/256) 256), which differs from floor(255 x + 1/2)
         within 7.6e-6 codes of a tie, gl_probe "convert");
       a product t = a f llvmpipe rounds to (t + (t >> 8) + 128) >> 8, one less than the contract's
         round(t / 255) for 24 pairs (a, f) (gl_probe "blend8"), both a and f >= 152 (blend_products
         "llvmpipe" models them: no events; "rounded"): none in a channel
         whose operands stay below 152 (colour: C <= the largest colour code c_max under src-alpha,
         premultiplied and under, as q a / 255 + C (255 - a) / 255 <= c_max and the two roundings cannot
         both go up; alpha under src-alpha: A <= the largest alpha code); elsewhere per product the
         fraction of the blend's factors that are listed, over 256;
       index and weight events (above).
     The first-order part is 0: without events the codes are the same.
   - Index events in float buffers move a blend by at most e_c a_max + e_a (1 + 1) (c a and C (1 - a)).

3. The bounds (events are rare and each is bounded, a convention moves most pixels): events per pixel
   mu = N (the rates of one fragment's events);
     SMALL = the first-order part + 1e-6: a pixel without an event is within it;
     M     = the least m with P(Poisson(W H (1 - e^-mu)) > m) <= 1e-3: the most pixels over SMALL (the
             pixels an event touches);
     BIG   = SMALL + K e, e the largest event, K the least k with P(Poisson(mu) >= k) W H <= 1e-2 over
             the image's W H pixels: no pixel past it.
   run_case.sh passes when no pixel is over BIG and at most M are over SMALL.

Outside the bound, by the scenes' design: a crossing within 1/512 pixel of a polygon's edge (llvmpipe
rasterises coverage from vertices snapped to 1/256 pixel; the attributes are interpolated unsnapped) may
be in or out of the box for the two renderers, so every scene is transparent at the box's faces (mip:
black there); levels on camera.near / camera.far are kept by gl_slicer's clip planes moved out by 1e-6.

Usage: derive_tolerance.py SCENE.json [--explain]   (prints SMALL M BIG; --explain: the terms on stderr)
"""
import json
import math
import sys

import numpy as np  # Debian's python3-numpy

U = 2.0 ** -24


def field_values(src, dims, spacing, origin):
    nx, ny, nz = dims
    k, j, i = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
    x, y, z = (origin[0] + i * spacing[0], origin[1] + j * spacing[1], origin[2] + k * spacing[2])
    kind = src["field"]
    if kind == "gaussian":
        c = src.get("center", [0, 0, 0])
        r2 = (x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2
        return src.get("amplitude", 1.0) * np.exp(-r2 / (2 * src.get("sigma", 1.0) ** 2))
    if kind == "radial":
        c = src.get("center", [0, 0, 0])
        return np.sqrt((x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2)
    if kind == "constant":
        return np.full(i.shape, float(src.get("value", 0.0)))
    if kind == "linear":
        a = src.get("coefficients", [0, 0, 0, 0])
        return a[0] * x + a[1] * y + a[2] * z + a[3]
    sys.exit(f"derive_tolerance.py: no values for field {kind}")


def piecewise(rows, v):
    """The rows' piecewise-linear function at v (constant beyond the ends), per channel."""
    xs = np.array([r[0] for r in rows], float)
    ys = np.array([r[1:] for r in rows], float)
    return np.stack([np.interp(v, xs, ys[:, c]) for c in range(ys.shape[1])], axis=-1)


def slope(rows, width):
    """The largest |dy/dx| over the rows' segments, times the window's width (per unit s)."""
    s = [abs(b[c] - a[c]) / (b[0] - a[0]) for a, b in zip(rows, rows[1:]) if b[0] > a[0] for c in range(1, len(a))]
    return max(s + [0.0]) * width


def poisson_k(mu, pixels, budget=1e-2):
    """The least k with P(Poisson(mu) >= k) pixels <= budget."""
    if mu <= 0:
        return 0
    k, term, tail = 0, math.exp(-mu), 1.0
    while tail * pixels > budget:
        tail -= term
        k += 1
        term *= mu / k
    return k


def poisson_quantile(mean, tail):
    """The least m with P(Poisson(mean) > m) <= tail."""
    if mean <= 0:
        return 0
    m, log_term = 0, -mean  # in logs: exp(-mean) underflows past mean 745
    cdf = math.exp(log_term)
    while 1 - cdf > tail:
        m += 1
        log_term += math.log(mean / m)
        cdf += math.exp(log_term)
    return m


F32 = np.float32


def fixed8_index(x, n):
    """llvmpipe's 8.8 texel coordinate of the float32 coordinate x on n texels: i = rint(fl(x fl(256 n))) - 128."""
    return int(np.rint(np.float64(F32(x) * F32(256 * n)))) - 128


def lerp8(v0, v1, w):
    return v0 + ((w * (v1 - v0) + 128) >> 8)


def table_read8(ent, i):
    """The 1D RGBA8 table's fixed8 read at index i (clamped taps, weight i & 255), per channel, in codes."""
    n = len(ent)
    t0, t1, w = min(max(i >> 8, 0), n - 1), min(max((i >> 8) + 1, 0), n - 1), i & 255
    return [lerp8(int(ent[t0][c]), int(ent[t1][c]), w) for c in range(4)]


def fixed8_fragments(ent, lookup):
    """(volref, llvmpipe): the fragment codes (r, g, b, a) for each texel code k = 0..255 of the fixed8 value texture.
    volref (ProfileSlices.cpp): s = k / 255 in double, the table's position pos (texture: clamp(s N - 1/2, 0, N - 1),
    linear: s (N - 1)), x = float((pos + 1/2) / N). llvmpipe (measured: its unorm8 texel converts to float as
    fl(k fl(1/255)), not the correctly rounded k / 255, on 126 of the 256 codes): s = fl(k fl(1/255)); texture:
    x = s; linear: gl_slicer's float32 (s (N - 1) + 1/2) / N. Both: i = rint(fl(x fl(256 N))) - 128. Nearest
    (j = floor(s (N - 1) + 1/2)): the same entry in both (s (N - 1) = k (N - 1) / 255 is at least 1/510 from a
    half-integer, 2 k (N - 1) even against 255 (2 m + 1) odd; the float error is about N 2^-24)."""
    n = len(ent)
    vr, gl = [], []
    for k in range(256):
        if lookup == "nearest":
            e = [int(c) for c in ent[min(max(int(math.floor(k / 255 * (n - 1) + 0.5)), 0), n - 1)]]
            vr.append(e), gl.append(e)
            continue
        s = k / 255.0
        pos = min(max(s * n - 0.5, 0.0), n - 1.0) if lookup == "texture" else s * (n - 1)
        vr.append(table_read8(ent, fixed8_index((pos + 0.5) / n, n)))
        sg = F32(k) * F32(F32(1.0) / F32(255.0))
        xg = sg if lookup == "texture" else (sg * F32(n - 1) + F32(0.5)) / F32(n)
        gl.append(table_read8(ent, fixed8_index(xg, n)))
    return np.array(vr), np.array(gl)


def profile_rules(profile):
    """render.profile -> the rules this bound reads, with the preset's defaults (gl_slicer's read_profile)."""
    if isinstance(profile, str):
        profile = {"base": profile}
    base = profile.get("base", "reference")
    rules = {"orientation": "viewport", "range": "object", "first": "bound", "texture": "3d",
             "texture_format": "unorm8", "texture_window": "transfer-rows", "table": 256, "table_lookup": "nearest",
             "table_format": "unorm8", "classify": "post", "correction": "none", "framebuffer": "rgba8",
             "blend": "src-alpha"}
    if base == "reference":
        rules.update({"texture_format": "float", "table": 0, "table_lookup": "texture", "table_format": "float"})
    sl = profile.get("slices", {})
    for k in ("orientation", "range", "first"):
        if k in sl:
            rules[k] = sl[k]
    rules["slices_order"] = sl.get("order", "back-to-front")
    for k in ("spacing", "count", "period", "max_count"):
        if k in sl:
            rules[k] = sl[k]
    rules.update({"texture_filter": "exact", "blend_products": "exact", "framebuffer_rounding": "nearest"})
    for k in ("texture", "texture_format", "texture_window", "table", "table_lookup", "table_format", "classify",
              "correction", "framebuffer", "blend", "blend_alpha", "texture_filter", "blend_products", "framebuffer_rounding"):
        if k in profile:
            rules[k] = profile[k]
    return rules


def main(path):
    s = json.load(open(path))
    v = s["volume"]
    src = v["source"]
    dims = src["dims"]
    spacing = v.get("spacing", [1, 1, 1])
    origin = v.get("origin", [0, 0, 0])
    rules = profile_rules(s["render"]["profile"])
    tf = v["transfer"]
    color, opacity, l = tf["color"], tf["opacity"], tf.get("opacity_unit_distance", 1.0)
    values = field_values(src, dims, spacing, origin)
    w = rules["texture_window"]
    if w == "transfer-rows":
        lo, hi = min(color[0][0], opacity[0][0]), max(color[-1][0], opacity[-1][0])
    elif w == "data-range":
        lo, hi = float(values.min()), float(values.max())
    else:
        lo, hi = w
    st = np.clip((values - lo) / (hi - lo), 0, 1)
    fmt = rules["texture_format"]
    if fmt == "unorm8":
        st = np.round(st * 255) / 255
    elif fmt == "unorm16":
        st = np.round(st * 65535) / 65535
    # G_s: the trilinear interpolant's gradient bound from the stored texels' differences
    g = 0.0
    for axis, s_a in ((2, spacing[0]), (1, spacing[1]), (0, spacing[2])):
        d = np.abs(np.diff(st, axis=axis))
        g += (d.max() / s_a) ** 2 if d.size else 0.0
    G_s = math.sqrt(g)
    width = hi - lo
    S_a, S_c = slope(opacity, width), slope(color, width)
    a_max = max(r[1] for r in opacity)
    # the visible voxels' box: opacity > 0 (mip: colour or opacity > 0), one voxel wider
    vv = lo + st * width
    shown = piecewise(opacity, vv)[..., 0] > 0
    mip = s["render"].get("projection", "composite") == "mip"
    if mip:
        shown |= piecewise(color, vv).max(axis=-1) > 0
    idx = np.argwhere(shown)  # (k, j, i)
    if idx.size == 0:
        print("0")
        return
    ext = [(idx[:, 2 - a].max() - idx[:, 2 - a].min() + 2) * spacing[a] for a in range(3)]
    L = math.sqrt(sum(e * e for e in ext))
    # the level spacing along the surfaces' normal
    cam = s["camera"]
    E = np.array(cam["eye"], float)
    box_lo = np.array(origin, float)
    box_hi = box_lo + (np.array(dims) - 1) * np.array(spacing, float)
    corners = [np.array([box_hi[0] if c & 1 else box_lo[0], box_hi[1] if c & 2 else box_lo[1],
                         box_hi[2] if c & 4 else box_lo[2]]) for c in range(8)]
    f = np.array(cam["target"], float) - E
    f /= np.linalg.norm(f)
    W, H = s["image"]["width"], s["image"]["height"]
    ortho = cam["type"] == "orthographic"
    tan_half = math.tan(math.radians(cam.get("fov_y", 30)) / 2)
    cos_c = 1.0 if ortho else 1.0 / math.sqrt(1 + tan_half ** 2 * (1 + (W / H) ** 2))
    orient = rules["orientation"]
    unit = 1.0 if s["render"].get("step_units", "voxel") == "world" else min(spacing)
    h = s["render"]["step"] * unit
    layer_axis = None
    if rules["texture"] == "2d":  # the slicing axis: f (orthographic), E -> the box's centre (perspective)
        w_ax = f if ortho else (box_lo + box_hi) / 2 - E
        layer_axis = a = int(np.argmax([abs(x) for x in w_ax]))
        step = spacing[a]
    elif "count" in rules or "period" in rules:
        if rules["range"] == "view_volume":
            b_near, b_far = cam["near"], cam["far"]
        elif orient == "viewport":
            lam = [float((c - E) @ f) for c in corners]
            b_near, b_far = min(lam), max(lam)
        elif orient == "spherical":
            b_near = float(np.linalg.norm(E - np.clip(E, box_lo, box_hi)))
            b_far = max(float(np.linalg.norm(c - E)) for c in corners)
        else:
            a = int(np.argmax([abs(x) for x in f]))
            b_near, b_far = box_lo[a], box_hi[a]
        n = rules.get("count")
        if n is None:  # period: a lower bound on the spacing from the largest count
            n = rules.get("max_count", 10 ** 6)
        n = min(n, rules.get("max_count", n))
        half = rules["first"] == "half"
        step = (b_far - b_near) / (n if half or n == 1 else n - 1)
    else:
        step = rules.get("spacing", None)
        step = step * unit if step is not None else h
    N = math.floor(L / step) + 1
    X = max([float(np.linalg.norm(E))] + [float(np.linalg.norm(c)) for c in corners])
    fixed8 = rules["texture_filter"] == "fixed8"
    table = rules["table"]
    pre = rules["classify"] == "pre-unweighted"
    nearest = table > 0 and rules["table_lookup"] == "nearest" and not pre
    # fixed8: the filtered s is a code in both renderers (lerps of codes) but for weight events, so ds = 0
    ds = 0.0 if fixed8 else G_s * 2 * U * X + 8 * U
    ds_mean = 0.0 if fixed8 else G_s * 0.6 * U * X + 2 * U
    frag_exact = False  # fixed8: the fragment's channels are codes in both renderers
    table_event = 0.0   # fixed8: the largest difference (codes) of the two table reads at one texel code
    p_w = 0.0           # fixed8: weight events per fragment
    if fixed8:
        if table == 0 or (not nearest and rules["table_format"] != "unorm8"):
            sys.exit("derive_tolerance.py: texture_filter fixed8 is derived for unorm8 tables (read nearest: any format)")
        pos = lo + np.arange(table) * width / (table - 1)
        ent = np.concatenate([piecewise(color, pos), piecewise(opacity, pos)], axis=-1)
        ent = np.floor(np.clip(ent, 0, 1) * 255 + 0.5)
        F_vr, F_gl = fixed8_fragments(ent.astype(int), rules["table_lookup"])
        q = np.floor(st * 255 + 0.5).astype(int)
        k_lo, k_hi = int(q.min()), int(q.max())
        table_event = float(np.abs(F_vr - F_gl)[k_lo:k_hi + 1].max())
        steps = np.abs(np.diff(F_vr[k_lo:k_hi + 1], axis=0)) if k_hi > k_lo else np.zeros((1, 4))
        e_c, e_a = float(steps[:, :3].max()) / 255, float(steps[:, 3].max()) / 255
        # A weight event: i = rint(256 n tc) - 128 differs between llvmpipe's coordinate tc (the rasteriser's
        # float position, dx = 0.6 u X on average, through the shader's float32 ((x - o) / s + 1/2) / n) and
        # volref's float((c + 1/2) / n) of its double crossing: per axis |delta i| <= 256 (dx + u X) / s_a +
        # 6 u 256 n_a (the roundings of tc and of fl(x 256 n) in both); on average 256 u (1.6 X / s_a + 3 n_a),
        # the chance that i differs (its fraction uniform). A weight one off moves that axis's lerp
        # v0 + ((w (v1 - v0) + 128) >> 8) by one code with chance |v1 - v0| / 256 (w uniform), |v1 - v0| on
        # average the mean stored code difference along a over the shown voxels, plus 1 for the y and z lerps
        # (they take lerped codes); the next lerps are monotone with steps of at most one code, so s moves by
        # one code. The layer axis of a 2D texture has no weight. Then the fragment moves (by at most e_c, e_a)
        # only where the code's neighbours read other entries: the chance of that over the shown voxels' codes
        # (the fragments' s distributed as the voxels' codes). Rates from means, sizes from maxima.
        for a_ in range(3):
            if a_ == layer_axis or dims[a_] < 2:
                continue
            diff = np.abs(np.diff(q, axis=2 - a_)).astype(float)
            both = np.logical_or(np.delete(shown, -1, axis=2 - a_), np.delete(shown, 0, axis=2 - a_))
            D_mean = float(diff[both].mean()) if both.any() else 0.0
            e_i = 256 * U * (1.6 * X / spacing[a_] + 3 * dims[a_])
            p_w += e_i * min(1.0, (D_mean + (0 if a_ == 0 else 1)) / 256)
        moves = np.zeros(256)
        for k in range(256):
            moves[k] = 0.5 * ((k > 0 and (F_vr[k] != F_vr[k - 1]).any()) + (k < 255 and (F_vr[k] != F_vr[k + 1]).any()))
        p_w *= float(moves[q[shown]].mean()) if shown.any() else 1.0
        frag_exact = table_event == 0 and rules["correction"] == "none"
    if nearest and not fixed8:
        da = dc = da_mean = dc_mean = 0.0
        pos = lo + np.arange(table) / (table - 1) * width
        ent = np.concatenate([piecewise(color, pos), piecewise(opacity, pos)], axis=-1)
        if rules["table_format"] == "unorm8":
            ent = np.round(np.clip(ent, 0, 1) * 255) / 255
        step_ent = np.abs(np.diff(ent, axis=0))
        e_c, e_a = float(step_ent[:, :3].max()), float(step_ent[:, 3].max())
        p_idx = 2 * (table - 1) * ds_mean
    elif fixed8:
        # the fragment floats: llvmpipe's fl(k fl(1/255)) against volref's float(k / 255), one ulp; a table
        # read that differs at a code (table_event) is a fragment off by that much wherever the code occurs
        da = dc = da_mean = dc_mean = 8 * U + table_event / 255
        p_idx = 0.0
    else:
        da, dc = S_a * ds + 8 * U, S_c * ds + 8 * U
        da_mean, dc_mean = S_a * ds_mean + 8 * U, S_c * ds_mean + 8 * U
        e_c = e_a = p_idx = 0.0
    D = 1.0
    if rules["correction"] == "exact":
        c_min = cos_c if orient == "viewport" else (cos_c / math.sqrt(3) if orient == "axis" else 1.0)
        D = max(1.0, step / (l * c_min)) / (1 - a_max)
    premult = rules["blend"] == "premultiplied"
    def frag(da_, dc_):
        dalpha = D * da_ + (64 * U if rules["correction"] == "exact" else 0.0)
        return dalpha + dc_ if premult else max(dalpha, dc_)
    d, d_mean = frag(da, dc), frag(da_mean, dc_mean)
    fb = rules["framebuffer"]
    pixels = W * H
    p_ev = p_idx + p_w  # index and weight events per fragment, each moving the fragment by (e_c, e_a)
    if rules["blend"] == "max":
        first, event, rate = d, max(e_c, e_a), p_ev
    elif fb == "rgba8":
        # an index or weight event moves the fragment by Dc = 255 e_c, Da = 255 e_a codes; the blend's
        # products move by at most Dc + Da + 1 (q_c q_a) and Da + 1 (C (255 - q_a)), alpha 2 Da + 1 and Da + 1:
        # max(Dc + 2 Da, 3 Da) + 2 codes; a code tie moves a channel by at most 2
        Dc, Da = round(255 * e_c), round(255 * e_a)
        event = max(2, max(Dc + 2 * Da, 3 * Da) + 2 if p_ev > 0 else 0) / 255
        # the fragment's codes: a channel within d of a code's tie; none where the fragment is a code in both
        # (fixed8 reads of a unorm8 table, no correction: llvmpipe's fl(k fl(1/255)) is within 255 2^-24 codes of
        # k, its premultiplied a c within 1e-5 codes of q_a q_c / 255, which is at least 1/510 from a tie)
        p_q = 0.0 if frag_exact else 2 * 255 * d_mean + (1.6e-5 if d_mean > 0 else 0.0)
        products = rules["blend_products"]
        first = 0.0
        if rules["framebuffer_rounding"] != "nearest" or products == "exact":
            # not llvmpipe's blend (its products round each term to nearest): up to two codes a blend
            first = 2.0 * N / 255
        # blend_products "llvmpipe": the products are llvmpipe's, no events. "rounded": they differ from
        # round(t / 255) only where both operands are >= 152. Per channel, the products a blend forms:
        # src-alpha: (q_c, q_a) and (C, 255 - q_a), alpha (q_a, q_a) and (A, 255 - q_a) (blend_alpha one:
        # (q_a, ONE), no product); premultiplied: (C, 255 - q_a) and (A, 255 - q_a); under: (q_src, 255 - A), no
        # dst product. C <= c_max (the largest fragment colour code); A <= a_code under src-alpha / src-alpha,
        # otherwise up to 255.
        under = rules.get("slices_order") == "front-to-back"
        c_max = round(255 * max(max(r[1:]) for r in color))
        a_code = round(255 * a_max)
        if premult:
            c_max = round(255 * max(max(r[1:]) for r in color) * a_max)
        alpha_one = rules.get("blend_alpha", "src-alpha") == "one"
        qa = list(range(1, a_code + 1))
        dst_factors = [255 - q for q in qa]
        listed = {152, 169, 173, 188, 191, 194, 196, 197, 208, 212, 214, 223, 226, 227, 229, 232, 233, 236, 239,
                  241, 244, 247, 251, 253}
        def frac(fs):  # per product: the fraction of the factors that are listed, times 1/256 for the operand
            return sum(f in listed for f in fs) / max(len(fs), 1) / 256
        colour_p = alpha_p = 0.0
        if products != "rounded":
            pass
        elif under:
            colour_p = frac(range(256)) if c_max >= 152 else 0.0
            alpha_p = frac(range(256)) if a_code >= 152 else 0.0
        elif premult:
            colour_p = frac(dst_factors) if c_max >= 152 else 0.0
            alpha_p = frac(dst_factors)  # A accumulates past 152
        else:
            colour_p = (frac(qa) if c_max >= 152 and a_code >= 152 else 0.0) + (frac(dst_factors) if c_max >= 152 else 0.0)
            alpha_p = (frac(qa) if a_code >= 152 and not alpha_one else 0.0) + \
                      (frac(dst_factors) if alpha_one or a_code >= 152 else 0.0)
        rate = 4 * p_q + 3 * colour_p + alpha_p + p_ev
    elif fb == "rgba16f" and frag_exact and rules["framebuffer_rounding"] == "truncate":
        # llvmpipe's binary16 stores toward zero, as volref's under "truncate": both blend the same float32
        # arithmetic on fragments within an ulp of each other (fl(k fl(1/255)) against float(k / 255), on 126
        # of the 256 codes), a relative difference before a store of 2 u on average (c a: both operands; d (1 -
        # a): 1 - a's, a u relative to 1 - a). Truncating two values closer than binary16's spacing (at least
        # 2^-11 of the value) gives the same value or two neighbours: each store of each channel either agrees
        # exactly or is a flip event of one binary16 unit (<= 2^-11 below 1; later blends scale it by 1 - a, and
        # stores keep it within it) with chance 2 u 2^11 = 2^-12. First-order part 0.
        first = 0.0
        p_h = 2 * U * 2.0 ** 11
        event = max(2.0 ** -11, e_c * a_max + 2 * e_a if p_ev > 0 else 0.0)
        rate = 4 * p_h + p_ev
    else:
        # rgba16f otherwise: each store within one binary16 unit (<= 2^-11 below 1) of the other's, whichever
        # way llvmpipe and the scene round
        first = N * (3 * d + 4 * U) + (N * 2.0 ** -11 if fb == "rgba16f" else 0.0)
        event = e_c * a_max + 2 * e_a
        rate = p_ev
    mu = N * rate
    K = poisson_k(mu, pixels)
    small = first + 1e-6
    big = small + K * event
    # the pixels an event can touch: expected W H (1 - e^-mu); M the count exceeded with chance <= 1e-3
    M = poisson_quantile(pixels * (1 - math.exp(-mu)), 1e-3)
    if "--explain" in sys.argv:
        print(f"N {N} (L {L:.3g}, s {step:.4g}) X {X:.3g} G_s {G_s:.3g} ds {ds:.3g} d {d:.3g} first {first:.3g}; "
              f"events per pixel {mu:.3g} (index {p_idx:.3g}, weight {p_w:.3g} per fragment), K {K} of {event:.3g}"
              + (f"; fixed8 table reads unlike llvmpipe's by {table_event:g} codes" if fixed8 else ""), file=sys.stderr)
    print(f"{small:.3e} {M} {big:.3e}")


if __name__ == "__main__":
    main([a for a in sys.argv[1:] if a != "--explain"][0])
