#include "core/integrate/profiles/VolPackRenderer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/Error.h"
#include "core/MemoryLimit.h"

namespace volref {

using namespace volpack;

namespace {

// FLTFRAC_TO_FIX31 (vp_warpA*.c): (int)(f * 2^31), as x86-64 converts (out of range: INT_MIN).
int fix31(double f) {
    const double t = f * 2147483648.0;
    if (!(t < 2147483648.0) || !(t > -2147483649.0)) return std::numeric_limits<int>::min();
    return int(t);
}

// floor(a / 2^31) for a 64-bit a.
std::int64_t carries(std::int64_t a) {
    constexpr std::int64_t kOne = std::int64_t(1) << 31;
    return a >= 0 ? a / kOne : -((-a + kOne - 1) / kOne);
}

// VPAffineImageOverlap (vp_warp.c): the output image's scanlines split into at most 9 trapezoids, each
// with the span of pixels whose filter overlaps the input image fully and partly.
struct Trapezoid {
    int miny = 0, maxy = 0;
    double x_top_lft = 0.0, x_top_rgt = -1.0, x_incr_lft = 0.0, x_incr_rgt = 0.0;
};

// OrderCoords: the four corners sorted into the left chain and the right chain (3 points each), from
// the top (smallest y, ties smallest x).
void order_coords(double c[4][2], double lft[3][2], double rgt[3][2]) {
    int index = 0;
    for (int q = 1; q < 4; ++q)
        if (c[q][1] < c[index][1] || (c[q][1] == c[index][1] && c[q][0] < c[index][0])) index = q;
    double s[4][2];
    s[0][0] = c[index][0];
    s[0][1] = c[index][1];
    s[2][0] = c[(index + 2) % 4][0];
    s[2][1] = c[(index + 2) % 4][1];
    index = (index + 1) % 4;
    auto set = [](double* d, const double* v) {
        d[0] = v[0];
        d[1] = v[1];
    };
    if (std::fabs(s[0][1] - s[2][1]) < kEps) {  // the input maps to a horizontal line
        for (int q = 0; q < 3; ++q) {
            set(lft[q], s[0]);
            set(rgt[q], s[2]);
        }
        return;
    }
    const double xmid = s[0][0] + (c[index][1] - s[0][1]) * (s[2][0] - s[0][0]) / (s[2][1] - s[0][1]);
    if (c[index][0] < xmid) {
        set(s[1], c[index]);
        set(s[3], c[(index + 2) % 4]);
    } else {
        set(s[1], c[(index + 2) % 4]);
        set(s[3], c[index]);
    }
    set(lft[0], s[0]);
    set(lft[1], s[1]);
    set(lft[2], s[1][1] == s[2][1] ? s[1] : s[2]);
    if (s[0][1] == s[3][1]) {
        set(rgt[0], s[3]);
        set(rgt[1], s[2]);
        set(rgt[2], s[2]);
    } else {
        set(rgt[0], s[0]);
        set(rgt[1], s[3]);
        set(rgt[2], s[2]);
    }
}

void corners(const double w[3][3], int in_width, int in_height, double inset, double c[4][2]) {
    const double a[4] = {inset, in_width - 1 - inset, in_width - 1 - inset, inset};
    const double b[4] = {inset, inset, in_height - 1 - inset, in_height - 1 - inset};
    for (int q = 0; q < 4; ++q) {
        c[q][0] = w[0][0] * a[q] + w[0][1] * b[q] + w[0][2];
        c[q][1] = w[1][0] * a[q] + w[1][1] * b[q] + w[1][2];
    }
}

void image_overlap(int in_width, int in_height, int out_height, const double w[3][3], double filter_width,
                   Trapezoid full[9], Trapezoid part[9]) {
    double int_lft[3][2], int_rgt[3][2], ext_lft[3][2], ext_rgt[3][2], c[4][2];
    corners(w, in_width, in_height, -1.0 + filter_width / 2.0 + 1.0e-5, c);
    order_coords(c, int_lft, int_rgt);
    corners(w, in_width, in_height, -filter_width / 2.0, c);
    order_coords(c, ext_lft, ext_rgt);
    int ilft = 0, irgt = 0, elft = 0, ergt = 0;
    while (ilft < 3 && int_lft[ilft][1] <= 0.) ++ilft;
    while (irgt < 3 && int_rgt[irgt][1] <= 0.) ++irgt;
    while (elft < 3 && ext_lft[elft][1] <= 0.) ++elft;
    while (ergt < 3 && ext_rgt[ergt][1] <= 0.) ++ergt;
    auto edge = [](const double chain[3][2], int at, int lasty, Trapezoid& t, bool left) {
        const double incr = (chain[at][0] - chain[at - 1][0]) / (chain[at][1] - chain[at - 1][1]);
        const double top = chain[at - 1][0] + (lasty + 1 - chain[at - 1][1]) * incr;
        (left ? t.x_incr_lft : t.x_incr_rgt) = incr;
        (left ? t.x_top_lft : t.x_top_rgt) = top;
    };
    int region = 0, lasty = -1;
    while (lasty < out_height - 1 && region < 9) {
        int nexty = out_height - 1;
        if (ilft < 3) nexty = std::min(nexty, int(std::floor(int_lft[ilft][1])));
        if (irgt < 3) nexty = std::min(nexty, int(std::floor(int_rgt[irgt][1])));
        if (elft < 3) nexty = std::min(nexty, int(std::floor(ext_lft[elft][1])));
        if (ergt < 3) nexty = std::min(nexty, int(std::floor(ext_rgt[ergt][1])));
        Trapezoid& f = full[region];
        Trapezoid& p = part[region];
        f = p = Trapezoid{};
        f.miny = p.miny = lasty + 1;
        f.maxy = p.maxy = nexty;
        if (ilft != 0 && ilft != 3) {
            edge(int_lft, ilft, lasty, f, true);
            edge(int_rgt, irgt, lasty, f, false);
        }
        if (elft != 0 && elft != 3) {
            edge(ext_lft, elft, lasty, p, true);
            edge(ext_rgt, ergt, lasty, p, false);
        }
        while (ilft < 3 && int(std::floor(int_lft[ilft][1])) <= nexty) ++ilft;
        while (irgt < 3 && int(std::floor(int_rgt[irgt][1])) <= nexty) ++irgt;
        while (elft < 3 && int(std::floor(ext_lft[elft][1])) <= nexty) ++elft;
        while (ergt < 3 && int(std::floor(ext_rgt[ergt][1])) <= nexty) ++ergt;
        ++region;
        lasty = nexty;
    }
    for (; region < 9; ++region) {
        full[region] = part[region] = Trapezoid{};
        full[region].miny = full[region].maxy = part[region].miny = part[region].maxy = out_height;
    }
}

}  // namespace

VolPackRenderer::VolPackRenderer(const Volume& volume, const VolPackSpec& spec, int width, int height)
    : spec_(spec), width_(width), height_(height), dims_(volume.dims), origin_(volume.origin), spacing_(volume.spacing) {
    if (volume.type != ScalarType::U8)
        throw Error("volume.source: VolPack's scalar field is 8-bit (vpVolumeNormals and vpClassifyScalars read unsigned "
                    "char); this volume's voxels are not u8 (convert it, e.g. volref resample, or quantise it)");
    view_ = factor_view(spec_, dims_, width_, height_);
    check_memory(std::size_t(view_.intermediate_width) * std::size_t(view_.intermediate_height) * sizeof(IntermediatePixel),
                 std::string(spec_.axis ? "render.profile_options.axis" : "render.profile_options.rotate") +
                     ": VolPack's intermediate image of " + std::to_string(view_.intermediate_width) + " x " +
                     std::to_string(view_.intermediate_height) + " pixels");
    const std::size_t n = volume.values.size();
    scalars_.resize(n);
    for (std::size_t i = 0; i < n; ++i) scalars_[i] = std::uint8_t(volume.values[i]);
    const std::int64_t nx = dims_[0], nxy = dims_[0] * dims_[1];
    stride_ = view_.axis == 0 ? std::array<std::int64_t, 3>{nx, nxy, 1}
              : view_.axis == 1 ? std::array<std::int64_t, 3>{nxy, 1, nx}
                                : std::array<std::int64_t, 3>{1, nx, nxy};
    classify();
    composite();
    depth_cue();
    prepare_warp();
}

void VolPackRenderer::classify() {
    const bool exact_normals = spec_.normal_code == VolPackSpec::NormalCode::Exact;
    normals_ = volume_normals(scalars_.data(), dims_, exact_normals);
    shade_table_ = shade_table(spec_, view_.model);
    const std::size_t n = scalars_.size();
    opacity_.assign(n, 0.0f);
    for (std::size_t i = 0; i < n; ++i) {
        const VoxelClass c = classify_voxel(spec_, view_, scalars_[i], normals_.gradient[i]);
        if (!c.kept) continue;
        opacity_[i] = spec_.correction_order == VolPackSpec::CorrectionOrder::Sample ? float(c.opacity_byte) / 255.0f : c.corrected;
    }
    if (exact_normals) {  // the variant: each voxel shaded with its own normal Delta / |Delta|
        const int C = spec_.channels;
        voxel_shade_.assign(n * std::size_t(C), 0.0f);
        for (std::size_t i = 0; i < n; ++i) {
            const auto& d = normals_.delta[i];
            const double len = std::sqrt(double(d[0]) * d[0] + double(d[1]) * d[1] + double(d[2]) * d[2]);
            const std::array<double, 3> nrm = normals_.code[i] == 0 ? std::array<double, 3>{0.0, 0.0, 0.0}
                                                                    : std::array<double, 3>{d[0] / len, d[1] / len, d[2] / len};
            shade_normal(spec_, view_.model, nrm, &voxel_shade_[i * std::size_t(C)]);
        }
    }
    // VPRenderAffine: each slice's place and weights (float), and the depth-cue factor: 1 on the first
    // slice composited, times the ratio per slice.
    const View& w = view_;
    slices_.resize(std::size_t(w.kcount));
    float dc = 1.0f;
    for (int n = 0; n < w.kcount; ++n) {
        Slice& s = slices_[std::size_t(n)];
        s.k = w.reverse_slice_order ? w.kcount - 1 - n : n;
        const float slice_u = float(w.shear_i * s.k + w.trans_i), slice_v = float(w.shear_j * s.k + w.trans_j);
        s.u = int(std::ceil(slice_u)) - 1;
        s.v = int(std::ceil(slice_v)) - 1;
        const float fu = slice_u - float(s.u), fv = slice_v - float(s.v);
        s.weight[0] = fu * fv;
        s.weight[1] = fu * (1.0f - fv);
        s.weight[2] = (1.0f - fu) * fv;
        s.weight[3] = (1.0f - fu) * (1.0f - fv);
        s.dc = dc;
        dc *= w.slice_dc_ratio;
    }
}

void VolPackRenderer::composite_pixel(int u, int v, float* color, float& opacity) const {
    const View& w = view_;
    const int C = spec_.channels;
    const float min_opacity = float(spec_.min_voxel_opacity), max_opacity = float(spec_.max_ray_opacity);
    const bool sample_order = spec_.correction_order == VolPackSpec::CorrectionOrder::Sample;
    float clr[3] = {0.0f, 0.0f, 0.0f}, opc = 0.0f;
    for (const Slice& slice : slices_) {
        const int k = slice.k;
        const int i = u - slice.u, j = v - slice.v;
        if (i < 0 || i > w.icount || j < 0 || j > w.jcount) continue;
        const float* weight = slice.weight;
        const int ti[4] = {i - 1, i - 1, i, i}, tj[4] = {j - 1, j, j - 1, j};  // TL, BL, TR, BR
        float acc_opc = 0.0f, acc_clr[3] = {0.0f, 0.0f, 0.0f};
        const float dc = slice.dc;
        for (int t = 0; t < 4; ++t) {
            if (ti[t] < 0 || ti[t] >= w.icount || tj[t] < 0 || tj[t] >= w.jcount) continue;  // zero outside
            const std::size_t idx = std::size_t(ti[t] * stride_[0] + tj[t] * stride_[1] + std::int64_t(k) * stride_[2]);
            const float o = opacity_[idx];
            if (o == 0.0f) continue;
            const float* shade = voxel_shade_.empty() ? &shade_table_[std::size_t(normals_.code[idx]) * std::size_t(C)]
                                                      : &voxel_shade_[idx * std::size_t(C)];
            const float factor = o * dc;
            acc_opc += o * weight[t];
            for (int c = 0; c < C; ++c) {
                float vc = shade[c] * 1.0f;
                vc *= factor;
                acc_clr[c] += vc * weight[t];
            }
        }
        if (sample_order && acc_opc > 0.0f) {  // the variant: the resampled opacity corrected instead
            const float a = float(1.0 - std::pow(1.0 - double(acc_opc), double(w.voxel_size)));
            for (int c = 0; c < C; ++c) acc_clr[c] *= a / acc_opc;
            acc_opc = a;
        }
        if (acc_opc > min_opacity) {
            const float inv = 1.0f - opc;
            for (int c = 0; c < C; ++c) clr[c] += acc_clr[c] * inv;
            opc += acc_opc * inv;
            if (opc >= max_opacity) break;  // early ray termination
        }
    }
    for (int c = 0; c < 3; ++c) color[c] = clr[c];
    opacity = opc;
}

void VolPackRenderer::composite() {
    const int W = view_.intermediate_width, H = view_.intermediate_height;
    image_.assign(std::size_t(W) * std::size_t(H), IntermediatePixel{});
    tbb::parallel_for(tbb::blocked_range<int>(0, H), [&](const tbb::blocked_range<int>& rows) {
        for (int v = rows.begin(); v != rows.end(); ++v)
            for (int u = 0; u < W; ++u) {
                IntermediatePixel& p = image_[std::size_t(v) * std::size_t(W) + std::size_t(u)];
                composite_pixel(u, v, p.color, p.opacity);
            }
    });
}

// VPDepthCueIntImage (vp_view.c): each intermediate pixel's colour times the depth-cue table entry of
// its depth on the front slice, the depth stepped in float along rows and columns.
void VolPackRenderer::depth_cue() {
    if (!spec_.depth_cue) return;
    const View& w = view_;
    const double front = (*spec_.depth_cue)[0], density = (*spec_.depth_cue)[1];
    const int slicenum = w.reverse_slice_order ? w.kcount - 1 : 0;
    const float depth_quant = float(1.0 / kDepthCueQuantization);
    const float depth_di = float(w.depth_di), depth_dj = float(w.depth_dj);
    const float slice_u = float(w.shear_i * slicenum + w.trans_i), slice_v = float(w.shear_j * slicenum + w.trans_j);
    const float left_depth = float(w.depth_000 + w.depth_dk * slicenum - double(slice_u * depth_di) - double(slice_v * depth_dj));
    // The table's length as VolPack sizes it from the largest depth of the image (a fresh context's
    // table is empty): a pixel past it is VolPack's VPBug abort ("depth too large").
    const float W = float(w.intermediate_width), H = float(w.intermediate_height);
    const float max_depth = depth_di > 0 ? (depth_dj > 0 ? left_depth + depth_di * W + depth_dj * H : left_depth + depth_di * W)
                                         : (depth_dj > 0 ? left_depth + depth_dj * H : left_depth);
    const int max_depth_int = int(max_depth * depth_quant);
    const int table_len = max_depth_int >= 0 ? max_depth_int + 1 : 0;
    std::vector<float> table(static_cast<std::size_t>(table_len));  // VPComputeDepthCueTable
    for (int c = 0; c < table_len; ++c) table[std::size_t(c)] = float(front * std::exp(-density * (1.0 - c * kDepthCueQuantization)));
    const float di_quant = depth_di * depth_quant, dj_quant = depth_dj * depth_quant;
    float left_quant = left_depth * depth_quant;
    const int C = spec_.channels;
    for (int j = 0; j < w.intermediate_height; ++j) {
        float pixel_quant = left_quant;
        left_quant += dj_quant;
        for (int i = 0; i < w.intermediate_width; ++i) {
            int d = int(pixel_quant);
            pixel_quant += di_quant;
            if (d < 0) d = 0;
            if (d >= table_len)
                throw Error("render.profile_options.depth_cue: VolPack stops on this view (VPDepthCueIntImage: \"depth too "
                            "large\", a VPBug abort): the volume lies behind depth 0 of the window; move window's near and far");
            const float factor = table[std::size_t(d)];
            IntermediatePixel& p = image_[std::size_t(j) * std::size_t(w.intermediate_width) + std::size_t(i)];
            for (int c = 0; c < C; ++c) p.color[c] *= factor;
        }
    }
}

void VolPackRenderer::prepare_warp() {
    const View& w = view_;
    const int in_w = w.intermediate_width, in_h = w.intermediate_height;
    Trapezoid full[9], part[9];
    image_overlap(in_w, in_h, height_, w.warp, 2.0, full, part);
    denom_ = 1.0 / (w.warp[0][0] * w.warp[1][1] - w.warp[0][1] * w.warp[1][0]);
    in_x_incr_ = w.warp[1][1] * denom_;
    in_y_incr_ = -w.warp[1][0] * denom_;
    in_x_incr_int_ = in_x_incr_ < 0 ? int(std::ceil(in_x_incr_)) : int(std::floor(in_x_incr_));
    in_y_incr_int_ = in_y_incr_ < 0 ? int(std::ceil(in_y_incr_)) : int(std::floor(in_y_incr_));
    xfrac_incr_ = fix31(in_x_incr_ - in_x_incr_int_);
    yfrac_incr_ = fix31(in_y_incr_ - in_y_incr_int_);
    scanlines_.assign(std::size_t(height_), Scanline{});
    int y = 0;
    for (int region = 0; region < 9; ++region) {
        const Trapezoid& p = part[region];
        const Trapezoid& f = full[region];
        if (p.miny >= height_) break;
        const int rows = p.maxy - p.miny + 1;
        if (p.x_top_lft > p.x_top_rgt) {  // no pixel of these rows sees the intermediate image
            y += rows;
            continue;
        }
        double x_lft_full = f.x_top_lft, x_rgt_full = f.x_top_rgt, x_lft_part = p.x_top_lft, x_rgt_part = p.x_top_rgt;
        const bool no_full = x_lft_full > x_rgt_full;
        for (int r = 0; r < rows && y < height_; ++r, ++y) {
            auto clampw = [&](int c) { return std::clamp(c, 0, width_); };
            const int lft_zero = clampw(int(std::floor(x_lft_part)));
            int lft_edge = 0, full_cnt = 0, rgt_edge = 0;
            if (no_full) {
                lft_edge = std::max(clampw(int(std::ceil(x_rgt_part))) - lft_zero, 0);
            } else {
                lft_edge = std::max(clampw(int(std::ceil(x_lft_full))) - lft_zero, 0);
                full_cnt = std::max(clampw(int(std::floor(x_rgt_full))) - (lft_edge + lft_zero), 0);
                rgt_edge = std::max(clampw(int(std::ceil(x_rgt_part))) - (full_cnt + lft_edge + lft_zero), 0);
            }
            Scanline& s = scanlines_[std::size_t(y)];
            s.begin = lft_zero;
            s.end = lft_zero + lft_edge + full_cnt + rgt_edge;
            s.in_x = ((lft_zero - w.warp[0][2]) * w.warp[1][1] - (y - w.warp[1][2]) * w.warp[0][1]) * denom_;
            s.in_y = (-(lft_zero - w.warp[0][2]) * w.warp[1][0] + (y - w.warp[1][2]) * w.warp[0][0]) * denom_;
            s.in_x_int = int(std::floor(s.in_x));
            s.in_y_int = int(std::floor(s.in_y));
            s.xfrac = fix31(s.in_x - s.in_x_int);
            s.yfrac = fix31(s.in_y - s.in_y_int);
            x_lft_full += f.x_incr_lft;
            x_rgt_full += f.x_incr_rgt;
            x_lft_part += p.x_incr_lft;
            x_rgt_part += p.x_incr_rgt;
        }
    }
}

VolPackRenderer::IntermediatePixel VolPackRenderer::intermediate(int u, int v) const {
    if (u < 0 || v < 0 || u >= view_.intermediate_width || v >= view_.intermediate_height) return {};
    return image_[std::size_t(v) * std::size_t(view_.intermediate_width) + std::size_t(u)];
}

VolPackRenderer::Warp VolPackRenderer::warp(int x, int y) const {
    Warp out;
    if (y < 0 || y >= height_ || x < 0 || x >= width_) return out;
    const Scanline& s = scanlines_[std::size_t(y)];
    if (x < s.begin || x >= s.end) return out;
    out.covered = true;
    const std::int64_t n = x - s.begin;
    const std::int64_t tx = std::int64_t(s.xfrac) + n * xfrac_incr_, ty = std::int64_t(s.yfrac) + n * yfrac_incr_;
    const std::int64_t cx = carries(tx), cy = carries(ty);
    out.xfrac = int(tx - cx * (std::int64_t(1) << 31));
    out.yfrac = int(ty - cy * (std::int64_t(1) << 31));
    out.u = int(s.in_x_int + n * in_x_incr_int_ + cx);
    out.v = int(s.in_y_int + n * in_y_incr_int_ + cy);
    out.in_x = ((x - view_.warp[0][2]) * view_.warp[1][1] - (y - view_.warp[1][2]) * view_.warp[0][1]) * denom_;
    out.in_y = (-(x - view_.warp[0][2]) * view_.warp[1][0] + (y - view_.warp[1][2]) * view_.warp[0][0]) * denom_;
    out.x_index = std::clamp(out.xfrac >> kWarpWeightShift, 0, kWarpWeightEntries - 1);
    out.y_index = std::clamp(out.yfrac >> kWarpWeightShift, 0, kWarpWeightEntries - 1);
    if (spec_.warp_weights == VolPackSpec::WarpWeights::Exact) {  // the variant: the fractions themselves
        const float fx = float(double(out.xfrac) / 2147483648.0), fy = float(double(out.yfrac) / 2147483648.0);
        out.weight[0] = (1.0f - fx) * (1.0f - fy);
        out.weight[1] = fx * (1.0f - fy);
        out.weight[2] = (1.0f - fx) * fy;
        out.weight[3] = fx * fy;
    } else {
        const auto& t = warp_weights()[std::size_t(out.y_index)][std::size_t(out.x_index)];
        for (int q = 0; q < 4; ++q) out.weight[q] = t[std::size_t(q)];
    }
    const int W = view_.intermediate_width, H = view_.intermediate_height;
    const int tu[4] = {out.u, out.u + 1, out.u, out.u + 1}, tv[4] = {out.v, out.v, out.v + 1, out.v + 1};
    for (int q = 0; q < 4; ++q) out.inside[q] = tu[q] >= 0 && tu[q] < W && tv[q] >= 0 && tv[q] < H;
    const int C = spec_.channels;
    float acc[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    for (int q : {0, 2, 1, 3}) {  // VolPack's order: (u, v), (u, v + 1), (u + 1, v), (u + 1, v + 1)
        if (!out.inside[q]) continue;
        const IntermediatePixel& p = image_[std::size_t(tv[q]) * std::size_t(W) + std::size_t(tu[q])];
        for (int c = 0; c < C; ++c) acc[c] += out.weight[q] * p.color[c];
        acc[3] += out.weight[q] * p.opacity;
    }
    auto tie = [](float v) {
        const double r = std::nearbyint(double(v)), d = std::fabs(double(v) - r);
        return r >= 1.0 && d > 0.0 && d < kTieWindow;
    };
    for (int c = 0; c < C; ++c) {
        out.sum[c] = acc[c];
        out.bytes[c] = std::min(int(acc[c]), 255);
        out.tie = out.tie || tie(acc[c]);
    }
    out.sum[3] = acc[3];
    const float alpha = acc[3] * 255.0f;
    out.bytes[3] = std::min(int(alpha), 255);
    out.tie = out.tie || tie(alpha);
    return out;
}

PixelValue VolPackRenderer::pixel(int x, int y, Recording* rec) const {
    const Warp w = warp(x, y);
    PixelValue out;
    if (w.covered) {
        for (int c = 0; c < 3; ++c) out.rgba[c] = w.bytes[spec_.channels == 1 ? 0 : c] / 255.0;
        out.rgba[3] = w.bytes[3] / 255.0;
        out.error = w.tie ? 1.0 / 255.0 : 0.0;
    }
    if (rec) {
        // One row per tap (`accumulated`: the intermediate pixel on [0, 1]), then the pixel.
        const int tu[4] = {w.u, w.u + 1, w.u, w.u + 1}, tv[4] = {w.v, w.v, w.v + 1, w.v + 1};
        for (int q : {0, 2, 1, 3}) {
            if (!w.covered || !w.inside[q]) continue;
            SampleRecord r{};
            rec->begin(r, 0.0, 0.0);
            const IntermediatePixel p = intermediate(tu[q], tv[q]);
            for (int c = 0; c < 3; ++c) r.accumulated[c] = p.color[spec_.channels == 1 ? 0 : c] / 255.0;
            r.accumulated[3] = p.opacity;
            r.alpha = w.weight[q];
            rec->recorder.record(r);
        }
        SampleRecord r{};
        rec->begin(r, 0.0, 0.0);
        r.accumulated = out.rgba;
        rec->recorder.record(r);
    }
    return out;
}

std::array<int, 2> VolPackRenderer::pixel_of(const Ray& ray) const {
    const glm::dvec3 index = (ray.origin - origin_) / spacing_;
    const Vector4 p = multiply(view_.view_transform, Vector4{index.x, index.y, index.z, 1.0});
    return {int(std::lround(p[0])), int(std::lround(p[1]))};
}

VolPackRenderer::Voxel VolPackRenderer::voxel(std::int64_t x, std::int64_t y, std::int64_t z) const {
    Voxel v;
    const std::size_t i = std::size_t(x + dims_[0] * (y + dims_[1] * z));
    v.scalar = scalars_[i];
    v.gradient = normals_.gradient[i];
    v.code = normals_.code[i];
    v.delta = central_differences(scalars_.data(), dims_, x, y, z);
    v.cls = classify_voxel(spec_, view_, v.scalar, v.gradient);
    v.normal = code_normal(v.code);
    for (int c = 0; c < spec_.channels; ++c) v.shade[c] = shade_table_[std::size_t(v.code) * std::size_t(spec_.channels) + std::size_t(c)];
    return v;
}

CameraSpec VolPackRenderer::camera() const {
    // G: world -> (X, Y, depth) = VolPack's view transform after world -> voxel index.
    double G[3][4];
    for (int r = 0; r < 3; ++r) {
        const auto& m = view_.view_transform[std::size_t(r)];
        double t = m[3];
        for (int a = 0; a < 3; ++a) {
            G[r][a] = m[std::size_t(a)] / spacing_[a];
            t -= m[std::size_t(a)] * origin_[a] / spacing_[a];
        }
        G[r][3] = t;
    }
    // The depths of the grid's corners one voxel out (VolPack's opacity fades over one voxel past the last).
    double dmin = std::numeric_limits<double>::infinity(), dmax = -dmin;
    for (int c = 0; c < 8; ++c) {
        const Vector4 idx{c & 1 ? double(dims_[0]) : -1.0, c & 2 ? double(dims_[1]) : -1.0, c & 4 ? double(dims_[2]) : -1.0, 1.0};
        const Vector4 p = multiply(view_.view_transform, idx);
        dmin = std::min(dmin, p[2]);
        dmax = std::max(dmax, p[2]);
    }
    const double margin = 0.01 * (dmax - dmin) + 1e-9;
    const double front = dmax + margin, range = front - dmin + margin;
    CameraSpec cam;
    cam.type = CameraSpec::Type::Matrices;
    glm::dmat4 V(1.0), P(1.0);  // glm: m[column][row]
    for (int a = 0; a < 4; ++a) {
        V[a][0] = G[0][a];
        V[a][1] = G[1][a];
        V[a][2] = G[2][a];
        V[a][3] = a == 3 ? 1.0 : 0.0;
    }
    V[3][2] -= front;  // view z = depth - front <= 0: the viewer looks along -z towards smaller depths
    P[0][0] = 2.0 / width_;
    P[3][0] = 1.0 / width_ - 1.0;
    P[1][1] = -2.0 / height_;
    P[3][1] = 1.0 - 1.0 / height_;
    P[2][2] = -2.0 / range;
    P[3][2] = -1.0;
    cam.view = V;
    cam.projection = P;
    return cam;
}

}  // namespace volref

namespace volref {

Scene volpack_continuous_scene(const Scene& scene, const VolPackRenderer& renderer, double step) {
    const VolPackSpec& v = renderer.spec();
    const std::string key = "render.profile_options.";
    if (v.depth_cue) throw Error(key + "depth_cue: VolPack's exponential depth cueing has no continuous form in volref");
    Scene c;
    c.lights.clear();  // the lights are VolPack's (below), not the default headlight
    c.file = scene.file;
    c.image = scene.image;
    VolumeSpec vol;
    vol.source = scene.volumes.front().source;
    vol.interpolation = Interpolation::Trilinear;
    TransferSpec& t = vol.transfer;
    t.domain = TransferSpec::Domain::Data;
    for (int i = 0; i < 256; ++i) t.opacity.push_back({double(i), double(v.scalar_table.entries[std::size_t(i)])});
    t.color = {{0.0, 1.0, 1.0, 1.0}};
    t.opacity_unit_distance = 1.0;  // one voxel (VolPack's voxels are unit cubes)
    if (v.gradient_table)
        for (int g = 0; g <= kGradMax; ++g) t.gradient_opacity.push_back({double(g), double(v.gradient_table->entries[std::size_t(g)])});
    if (v.shaded) {
        const int C = v.channels;
        for (const auto* m : {&v.ambient, &v.diffuse, &v.specular})
            if (C == 3 && ((*m)[1] != (*m)[0] || (*m)[2] != (*m)[0]))
                throw Error(key + "shading.material: channels that differ have no continuous form in volref (its ka, kd, ks are scalars)");
        ShadingSpec sh;
        sh.model = ShadingSpec::Model::BlinnPhong;
        sh.ka = v.ambient[0];
        sh.kd = v.diffuse[0];
        sh.ks = v.specular[0];
        sh.n = v.shininess;
        sh.two_sided = v.two_sided;
        vol.shading = sh;
        // The lights in object space as vpShadeTable takes them (MODEL^-1 of the eye-space vector);
        // volref's L points towards the light: the reverse.
        const std::vector<VolPackLight> lights =
            v.lights ? *v.lights : std::vector<VolPackLight>{VolPackLight{glm::dvec3(0.57735), glm::dvec3(1.0)}};
        glm::dvec3 sum(0.0);
        for (const VolPackLight& l : lights) sum += l.color;
        if (lights.empty() || std::fabs(sum.x - 1.0) > 1e-12 || (C == 3 && (std::fabs(sum.y - 1.0) > 1e-12 || std::fabs(sum.z - 1.0) > 1e-12)))
            throw Error(key + "shading.lights: VolPack adds the ambient term once and volref once per light: "
                              "the continuous form needs light colours that sum to white");
        for (const VolPackLight& l : lights) {
            Vector4 e{l.direction.x, l.direction.y, l.direction.z, 1.0};
            if (v.lights) normalize3(e.data());
            if (!solve_system(renderer.view().model, {&e})) throw Error(key + "rotate: the model matrix is singular");
            LightSpec ls;
            ls.type = LightSpec::Type::Directional;
            ls.direction = -glm::normalize(glm::dvec3(e[0], e[1], e[2]));
            ls.color = l.color;
            c.lights.push_back(ls);
        }
    }
    c.volumes = {vol};
    c.camera = renderer.camera();
    c.render.projection = Projection::Composite;
    c.render.profile = ProfileId::Reference;
    c.render.step = step;
    c.render.step_units = StepUnits::Voxel;
    return c;
}

}  // namespace volref
