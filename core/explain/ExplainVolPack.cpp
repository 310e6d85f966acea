// explain volpack-warp, volpack-voxel, volpack-scene: one output pixel's 2D warp, one
// voxel's classification and shading, and the continuous scene of a VolPack scene, with the volpack
// profile's own renderer (VolPackRenderer.h, VolPack.h).
#include <cmath>
#include <string>

#include "core/Error.h"
#include "core/explain/Explain.h"
#include "core/integrate/profiles/VolPackRenderer.h"
#include "core/render/PreparedScene.h"
#include "core/scene/SceneWriter.h"

namespace volref::explain {

namespace {

const VolPackRenderer& volpack_of(const PreparedScene& scene) {
    const auto* r = dynamic_cast<const VolPackRenderer*>(scene.image_space());
    if (!r) throw Error("--scene: not a render.profile \"volpack\" scene");
    return *r;
}

void add_view(Explanation& e, const VolPackRenderer& r) {
    const volpack::View& v = r.view();
    Section& s = e.section("view");
    add(s, "axis", double(v.axis), "the principal axis (0 x, 1 y, 2 z): the largest |z| of the transformed unit vectors, ties x, y, z");
    add(s, "shear", {v.shear_i, v.shear_j}, "s_i, s_j: [p00 p01; p10 p11] (s_i, s_j) = (p02, p12) of the permuted view matrix");
    add(s, "translation", {v.trans_i, v.trans_j}, "t = 1 if s >= 0, else 1 - s (kcount - 1)");
    add(s, "intermediate", {double(v.intermediate_width), double(v.intermediate_height)},
        "icount + 1 + ceil((kcount - 1) |s_i|), jcount + 1 + ceil((kcount - 1) |s_j|)");
    add(s, "warp", {v.warp[0][0], v.warp[0][1], v.warp[0][2], v.warp[1][0], v.warp[1][1], v.warp[1][2]},
        "intermediate (u, v) -> image (X, Y): [p00 p01 p03 - p00 t_i - p01 t_j; p10 p11 p13 - p10 t_i - p11 t_j]");
    add(s, "L", double(v.voxel_size), "sqrt(1 + s_i^2 + s_j^2) (float): the slices' distance along a ray, voxels");
}

}  // namespace

Explanation volpack_warp(const PreparedScene& scene, int x, int y) {
    const VolPackRenderer& r = volpack_of(scene);
    Explanation e;
    e.topic = "volpack-warp";
    add_view(e, r);
    const VolPackRenderer::Warp w = r.warp(x, y);
    Section& s = e.section("warp");
    add(s, "pixel", {double(x), double(y)}, "output pixel (x, y): VolPack's image point X = x, Y = y (buffer row y)");
    add(s, "covered", w.covered ? 1.0 : 0.0, "1: inside the scanline's span of VPAffineImageOverlap's trapezoids; 0: VolPack writes 0");
    if (w.covered) {
        add(s, "in", {w.in_x, w.in_y}, "warp^-1 (x, y): the point of the intermediate image (exact)");
        add(s, "tap", {double(w.u), double(w.v)}, "the top-left tap, stepped along the scanline from its first covered pixel");
        add(s, "fraction", {w.xfrac / 2147483648.0, w.yfrac / 2147483648.0},
            "the 31-bit fixed-point fractions / 2^31, stepped by (int)(frac(dx_in/dx_out) 2^31) per pixel");
        add(s, "index", {double(w.x_index), double(w.y_index)}, "the fractions' top 6 bits: the weight table's row and column");
        Section& t = e.section("taps");
        t.columns = {"u", "v", "inside", "weight"};
        const int C = r.spec().channels;
        for (int c = 0; c < C; ++c) t.columns.push_back(C == 1 ? "color" : std::string("color_") + "rgb"[c]);
        t.columns.push_back("opacity");
        const int tu[4] = {w.u, w.u + 1, w.u, w.u + 1}, tv[4] = {w.v, w.v, w.v + 1, w.v + 1};
        for (int q : {0, 2, 1, 3}) {
            const VolPackRenderer::IntermediatePixel p = r.intermediate(tu[q], tv[q]);
            std::vector<double> row{double(tu[q]), double(tv[q]), w.inside[q] ? 1.0 : 0.0, double(w.weight[q])};
            for (int c = 0; c < C; ++c) row.push_back(p.color[c]);
            row.push_back(p.opacity);
            t.rows.push_back(row);
        }
        t.notes.push_back("weights: VPBilirpWeight[y index][x index]: (1 - x/63)(1 - y/63), (x/63)(1 - y/63), (1 - x/63)(y/63) "
                          "and 1 - the others; summed in float in this order, taps outside the intermediate image skipped");
        Section& o = e.section("result");
        std::vector<double> sums, bytes;
        for (int c = 0; c < C; ++c) {
            sums.push_back(w.sum[c]);
            bytes.push_back(w.bytes[c]);
        }
        add(o, "color", sums, "sum of weight x colour (float, 0 .. 255)");
        add(o, "opacity", double(w.sum[3]), "sum of weight x opacity (float)");
        bytes.push_back(w.bytes[3]);
        add(o, "bytes", bytes, "(int) colour and (int)(opacity x 255.0f), each at most 255: truncated, not rounded");
        add(o, "tie", w.tie ? 1.0 : 0.0, "1: some value lies within 1/1024 of an integer (the error channel's 1/255)");
    }
    return e;
}

Explanation volpack_voxel(const PreparedScene& scene, std::int64_t x, std::int64_t y, std::int64_t z) {
    const VolPackRenderer& r = volpack_of(scene);
    const Volume& vol = scene.volume().model.volume();
    if (x < 0 || y < 0 || z < 0 || x >= vol.dims[0] || y >= vol.dims[1] || z >= vol.dims[2])
        throw Error("--voxel: outside the volume (" + std::to_string(vol.dims[0]) + " x " + std::to_string(vol.dims[1]) + " x " +
                    std::to_string(vol.dims[2]) + ")");
    const VolPackRenderer::Voxel v = r.voxel(x, y, z);
    const VolPackSpec& spec = r.spec();
    Explanation e;
    e.topic = "volpack-voxel";
    Section& f = e.section("fields");
    add(f, "voxel", {double(x), double(y), double(z)});
    add(f, "scalar", double(v.scalar), "the 8-bit value");
    add(f, "delta", {double(v.delta[0]), double(v.delta[1]), double(v.delta[2])},
        "f(x+1) - f(x-1), f(y+1) - f(y-1), f(z+1) - f(z-1) (0 on the volume's boundary)");
    const double len = std::sqrt(double(v.delta[0]) * v.delta[0] + double(v.delta[1]) * v.delta[1] + double(v.delta[2]) * v.delta[2]);
    add(f, "|delta|", len);
    add(f, "gradient", double(v.gradient), "rint(|delta| / 2) (ties to even): the gradient-magnitude field, 0 .. 221");
    add(f, "code", double(v.code), "vpNormalIndex(delta / |delta|): rint(44 n / L1) per axis, 0 for a zero or boundary voxel");
    add(f, "normal", {v.normal[0], v.normal[1], v.normal[2]}, "the code's normal (px, py, +-(44 - |px| - |py|)) / length");
    Section& c = e.section("classification");
    add(c, "scalar_table", double(spec.scalar_table.entries[std::size_t(v.scalar)]), "scalar_table[scalar] (float)");
    if (spec.gradient_table)
        add(c, "gradient_table", double(spec.gradient_table->entries[std::size_t(v.gradient)]), "gradient_table[gradient] (float)");
    add(c, "opacity", double(v.cls.opacity), "the tables' product (float)");
    add(c, "kept", v.cls.kept ? 1.0 : 0.0, "opacity > min_voxel_opacity");
    add(c, "byte", double(v.cls.opacity_byte), "(int)(opacity x 255.): truncated");
    add(c, "L", double(r.view().voxel_size));
    add(c, "corrected", double(v.cls.corrected), "1 - (1 - byte / 255)^L (float), 0 when not kept: the opacity interpolated");
    Section& s = e.section("shading");
    std::vector<double> entry;
    for (int k = 0; k < spec.channels; ++k) entry.push_back(v.shade[k]);
    add(s, "entry", entry, spec.shaded ? "the shade table's entry of the code (vpShadeTable, clamped to 255)" : "unshaded: 255");
    std::vector<double> premultiplied;
    for (int k = 0; k < spec.channels; ++k) premultiplied.push_back(double(v.shade[k] * 1.0f * v.cls.corrected));
    add(s, "color", premultiplied, "entry x corrected opacity (x the slice's depth-cue factor): the colour interpolated");
    return e;
}

Explanation volpack_scene(const PreparedScene& scene, double step) {
    const Scene c = volpack_continuous_scene(scene.scene, volpack_of(scene), step);
    Explanation e;
    e.topic = "volpack-scene";
    Section& s = e.section("scene");
    s.notes.push_back(scene_json(c).dump(2));
    return e;
}

}  // namespace volref::explain
