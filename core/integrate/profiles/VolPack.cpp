#include "core/integrate/profiles/VolPack.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/Error.h"

namespace volref::volpack {

Matrix4 identity() {
    Matrix4 m{};
    for (int i = 0; i < 4; ++i) m[i][i] = 1.0;
    return m;
}

Matrix4 multiply(const Matrix4& a, const Matrix4& b) {
    Matrix4 p{};
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            double s = 0.0;
            for (int k = 0; k < 4; ++k) s += a[i][k] * b[k][j];
            p[i][j] = s;
        }
    return p;
}

Vector4 multiply(const Matrix4& m, const Vector4& v) {
    Vector4 out{};
    for (int i = 0; i < 4; ++i) {
        double s = 0.0;
        for (int j = 0; j < 4; ++j) s += m[i][j] * v[j];
        out[i] = s;
    }
    return out;
}

bool normalize3(double* v) {
    double magsqr = 0.0;
    for (int i = 0; i < 3; ++i) magsqr += v[i] * v[i];
    if (std::fabs(magsqr) < kEps) return false;
    const double invmag = 1.0 / std::sqrt(magsqr);
    for (int i = 0; i < 3; ++i) v[i] *= invmag;
    return true;
}

Matrix4 rotation(VolPackSpec::Axis axis, double degrees) {
    const double radians = degrees * M_PI / 180.0;
    const double s = std::sin(radians), c = std::cos(radians);
    Matrix4 m = identity();
    switch (axis) {
        case VolPackSpec::Axis::X: m[1][1] = c; m[1][2] = s; m[2][1] = -s; m[2][2] = c; break;
        case VolPackSpec::Axis::Y: m[0][0] = c; m[0][2] = -s; m[2][0] = s; m[2][2] = c; break;
        case VolPackSpec::Axis::Z: m[0][0] = c; m[0][1] = s; m[1][0] = -s; m[1][1] = c; break;
    }
    return m;
}

bool solve_system(Matrix4 a, std::vector<Vector4*> b) {
    const std::size_t m = b.size();
    int pivot[4] = {-1, -1, -1, -1};
    double row_scale[4];
    for (int i = 0; i < 4; ++i) {
        double max_entry = 0.0;
        for (int j = 0; j < 4; ++j) max_entry = std::max(max_entry, std::fabs(a[i][j]));
        if (std::fabs(max_entry) < kEps) return false;
        row_scale[i] = 1.0 / max_entry;
    }
    for (int j = 0; j < 4; ++j) {
        double max_entry = 0.0;
        int ipivot = -1;
        for (int i = 0; i < 4; ++i) {
            if (pivot[i] >= 0) continue;
            const double entry = std::fabs(a[i][j] * row_scale[i]);
            if (entry > max_entry) {
                max_entry = entry;
                ipivot = i;
            }
        }
        if (ipivot < 0 || std::fabs(max_entry) < kEps) return false;
        pivot[ipivot] = j;
        const double inv = 1.0 / a[ipivot][j];
        for (int l = j + 1; l < 4; ++l) a[ipivot][l] *= inv;
        for (std::size_t l = 0; l < m; ++l) (*b[l])[std::size_t(ipivot)] *= inv;
        for (int k = 0; k < 4; ++k) {
            if (k == ipivot) continue;
            const double entry = a[k][j];
            for (int l = j + 1; l < 4; ++l) a[k][l] -= a[ipivot][l] * entry;
            for (std::size_t l = 0; l < m; ++l) (*b[l])[std::size_t(k)] -= (*b[l])[std::size_t(ipivot)] * entry;
        }
    }
    for (std::size_t l = 0; l < m; ++l) {
        Vector4 t{};
        for (int i = 0; i < 4; ++i) t[std::size_t(pivot[i])] = (*b[l])[std::size_t(i)];
        *b[l] = t;
    }
    return true;
}

View factor_view(const VolPackSpec& spec, const std::array<std::int64_t, 3>& dims, int image_width, int image_height) {
    View v;
    v.model = identity();
    for (const auto& [axis, degrees] : spec.rotate) {
        const Matrix4 r = rotation(axis, degrees);
        v.model = spec.concat_left ? multiply(r, v.model) : multiply(v.model, r);
    }
    // vpWindow(VP_PARALLEL, ...) on an identity VP_PROJECT (vp_context.c): C = +2 / (far - near).
    const auto& w = spec.window;
    Matrix4 window = identity();
    window[0][0] = 2.0 / (w[1] - w[0]);
    window[1][1] = 2.0 / (w[3] - w[2]);
    window[2][2] = 2.0 / (w[5] - w[4]);
    window[0][3] = (w[0] + w[1]) / (w[0] - w[1]);
    window[1][3] = (w[2] + w[3]) / (w[2] - w[3]);
    window[2][3] = (w[4] + w[5]) / (w[4] - w[5]);
    v.projection = spec.concat_left ? multiply(window, identity()) : multiply(identity(), window);
    // VPComputeViewTransform: the prematrix takes voxel indices to the unit cube centred at n / 2.
    const std::int64_t maxdim = std::max({dims[0], dims[1], dims[2]});
    const double scale = 1.0 / double(maxdim);
    Matrix4 pre = identity();
    for (int a = 0; a < 3; ++a) {
        pre[a][a] = scale;
        pre[a][3] = double(-dims[std::size_t(a)]) * scale * 0.5;
    }
    Matrix4 viewport = identity();
    viewport[0][0] = 0.5 * image_width;
    viewport[0][3] = 0.5 * image_width;
    viewport[1][1] = 0.5 * image_height;
    viewport[1][3] = 0.5 * image_height;
    viewport[2][2] = -0.5;  // VolPack's left-handed switch
    viewport[2][3] = 0.5;
    const Matrix4 tmp1 = multiply(v.model, pre), tmp2 = multiply(identity(), tmp1), tmp3 = multiply(v.projection, tmp2);
    const Matrix4 vm = v.view_transform = multiply(viewport, tmp3);

    // FactorAffineView: the object axis most parallel to the view (largest |z| of the transformed,
    // normalised unit vector), ties x over y over z.
    double az[3];
    for (int a = 0; a < 3; ++a) {
        Vector4 e{0.0, 0.0, 0.0, 0.0};
        e[std::size_t(a)] = 1.0;
        Vector4 im = multiply(vm, e);
        az[a] = normalize3(im.data()) ? std::fabs(im[2]) : 0.0;
    }
    const double x = az[0], y = az[1], z = az[2];
    v.axis = x >= y ? (x >= z ? 0 : 2) : (y >= z ? 1 : 2);
    if (spec.axis) {
        const int forced = int(*spec.axis);
        if (az[forced] < kEps)
            throw Error("render.profile_options.axis: the view looks along the slices of this axis edge-on "
                        "(VolPack's VP_AXIS_OVERRIDE returns VPERROR_SINGULAR)");
        v.axis = forced;
    }
    Matrix4 p{};
    if (v.axis == 0) {
        p[0][2] = p[1][0] = p[2][1] = p[3][3] = 1.0;
        v.icount = int(dims[1]), v.jcount = int(dims[2]), v.kcount = int(dims[0]);
    } else if (v.axis == 1) {
        p[0][1] = p[1][2] = p[2][0] = p[3][3] = 1.0;
        v.icount = int(dims[2]), v.jcount = int(dims[0]), v.kcount = int(dims[1]);
    } else {
        p[0][0] = p[1][1] = p[2][2] = p[3][3] = 1.0;
        v.icount = int(dims[0]), v.jcount = int(dims[1]), v.kcount = int(dims[2]);
    }
    const Matrix4 pvm = multiply(vm, p);
    const double denom = pvm[0][0] * pvm[1][1] - pvm[0][1] * pvm[1][0];
    if (std::fabs(denom) < kEps)
        throw Error("render.profile_options.rotate: VolPack cannot factor this view (FactorAffineView: VPERROR_SINGULAR)");
    v.shear_i = (pvm[0][2] * pvm[1][1] - pvm[0][1] * pvm[1][2]) / denom;
    v.shear_j = (pvm[0][0] * pvm[1][2] - pvm[1][0] * pvm[0][2]) / denom;
    v.reverse_slice_order = !(pvm[2][0] * v.shear_i + pvm[2][1] * v.shear_j - pvm[2][2] > 0);
    // The intermediate image's size (held in int as VolPack holds it): a view nearly edge-on to the
    // slices (an axis override) shears them past any memory; refused before the int overflows.
    const double iw = v.icount + 1 + std::ceil((v.kcount - 1) * std::fabs(v.shear_i));
    const double ih = v.jcount + 1 + std::ceil((v.kcount - 1) * std::fabs(v.shear_j));
    if (!(iw * ih <= double(1 << 30))) {
        char size[96];
        std::snprintf(size, sizeof size, "%.4g x %.4g", iw, ih);
        throw Error(std::string(spec.axis ? "render.profile_options.axis" : "render.profile_options.rotate") +
                    ": the slices are seen nearly edge-on: VolPack's intermediate image would be " + size + " pixels");
    }
    v.intermediate_width = int(iw);
    v.intermediate_height = int(ih);
    v.trans_i = v.shear_i >= 0.0 ? 1.0 : 1.0 - v.shear_i * (v.kcount - 1);
    v.trans_j = v.shear_j >= 0.0 ? 1.0 : 1.0 - v.shear_j * (v.kcount - 1);
    v.depth_di = pvm[2][0];
    v.depth_dj = pvm[2][1];
    v.depth_dk = pvm[2][2];
    v.depth_000 = pvm[2][3];
    v.warp[0][0] = pvm[0][0];
    v.warp[0][1] = pvm[0][1];
    v.warp[0][2] = pvm[0][3] - pvm[0][0] * v.trans_i - pvm[0][1] * v.trans_j;
    v.warp[1][0] = pvm[1][0];
    v.warp[1][1] = pvm[1][1];
    v.warp[1][2] = pvm[1][3] - pvm[1][0] * v.trans_i - pvm[1][1] * v.trans_j;
    v.warp[2][0] = v.warp[2][1] = 0.0;
    v.warp[2][2] = 1.0;
    // ComputeAffineOpacityCorrection: L in float, the table in double stored as float.
    v.voxel_size = float(std::sqrt(1 + v.shear_i * v.shear_i + v.shear_j * v.shear_j));
    for (int i = 0; i <= kOpacityMax; ++i)
        v.opacity_correction[std::size_t(i)] = float(1.0 - std::pow(1.0 - double(i) / double(kOpacityMax), double(v.voxel_size)));
    // VPSliceDepthCueRatio.
    if (spec.depth_cue) {
        float delta = float(v.depth_dk - v.depth_di * v.shear_i - v.depth_dj * v.shear_j);
        if (v.reverse_slice_order) delta = -delta;
        v.slice_dc_ratio = float(std::exp((*spec.depth_cue)[1] * double(delta)));
    }
    return v;
}

namespace {

// InitNormalTables (vp_shade.c): NormalPy[y] is the code of (0, y, +), NormalXLimit[y] = 44 - |y|.
struct NormalTables {
    int py[2 * kNormN + 1];
    int xlimit[2 * kNormN + 1];
    NormalTables() {
        int xcount = 1, codepoint = 2;
        for (int y = -kNormN; y <= kNormN; ++y) {
            py[y + kNormN] = codepoint + (((xcount - 1) / 2) << 1);
            codepoint += xcount << 1;
            xlimit[y + kNormN] = (xcount - 1) / 2;
            xcount += y < 0 ? 2 : -2;
        }
    }
};
const NormalTables& normal_tables() {
    static const NormalTables t;
    return t;
}

}  // namespace

int normal_index(double nx, double ny, double nz) {
    const NormalTables& t = normal_tables();
    const double denom = std::fabs(nx) + std::fabs(ny) + std::fabs(nz);
    const double denominv = double(kNormN) / denom;
    // Debian's libvolpack1-dev rounds to the nearest integer, ties to even (its vpNormalIndex inlines
    // rint; measured: tests/volpack); the 1.0b3 sources read as truncation.
    int x = int(std::nearbyint(nx * denominv));
    const int y = int(std::nearbyint(ny * denominv));
    const int xlimit = t.xlimit[y + kNormN];
    if (x < 0) {
        if (-x > xlimit) x = -xlimit;
    } else if (x > xlimit) {
        x = xlimit;
    }
    int n = t.py[y + kNormN] + (x << 1);
    if (nz < 0) n |= 1;
    return n;
}

std::array<double, 3> code_normal(int code) {
    if (code < 2 || code > kMaxNormal) return {0.0, 0.0, 0.0};
    const NormalTables& t = normal_tables();
    int py = -kNormN;
    for (; py <= kNormN; ++py) {
        const int lim2 = 2 * (py < 0 ? kNormN + py : kNormN - py);
        if (t.py[py + kNormN] - lim2 <= code && t.py[py + kNormN] + lim2 + 1 >= code) break;
    }
    const int px = (code - t.py[py + kNormN]) >> 1;
    const int pz = kNormN - std::abs(px) - std::abs(py);
    const double pxd = px, pyd = py, pzd = pz;
    const double plength = 1.0 / std::sqrt(pxd * pxd + pyd * pyd + pzd * pzd);
    const double nz = pzd * plength;
    return {pxd * plength, pyd * plength, (code & 1) ? -nz : nz};
}

std::array<int, 3> central_differences(const std::uint8_t* s, const std::array<std::int64_t, 3>& dims, std::int64_t x,
                                       std::int64_t y, std::int64_t z) {
    const std::int64_t nx = dims[0], ny = dims[1], nz = dims[2];
    if (x <= 0 || x >= nx - 1 || y <= 0 || y >= ny - 1 || z <= 0 || z >= nz - 1) return {0, 0, 0};
    const std::size_t i = std::size_t((z * ny + y) * nx + x), sy = std::size_t(nx), sz = std::size_t(nx * ny);
    return {int(s[i + 1]) - int(s[i - 1]), int(s[i + sy]) - int(s[i - sy]), int(s[i + sz]) - int(s[i - sz])};
}

VoxelNormals volume_normals(const std::uint8_t* s, const std::array<std::int64_t, 3>& dims, bool keep_delta) {
    const std::int64_t nx = dims[0], ny = dims[1], nz = dims[2];
    VoxelNormals out;
    const std::size_t n = std::size_t(nx * ny * nz);
    out.code.assign(n, 0);
    out.gradient.assign(n, 0);
    if (keep_delta) out.delta.assign(n, {0, 0, 0});
    for (std::int64_t z = 1; z < nz - 1; ++z)
        for (std::int64_t y = 1; y < ny - 1; ++y)
            for (std::int64_t x = 1; x < nx - 1; ++x) {
                const std::size_t i = std::size_t((z * ny + y) * nx + x);
                const std::array<int, 3> d = central_differences(s, dims, x, y, z);
                const double gx = d[0], gy = d[1], gz = d[2];
                const double twice = std::sqrt(gx * gx + gy * gy + gz * gz);
                // Debian's libvolpack1-dev rounds |Delta| / 2 to the nearest integer, ties to even
                // (measured: tests/volpack; the 1.0b3 sources read as truncation).
                out.gradient[i] = std::uint8_t(std::nearbyint(0.5 * twice));
                out.code[i] = std::uint16_t(twice < kEps ? 0 : normal_index(gx / twice, gy / twice, gz / twice));
                if (keep_delta) out.delta[i] = {std::int16_t(d[0]), std::int16_t(d[1]), std::int16_t(d[2])};
            }
    return out;
}

namespace {

// vpShadeTable's set-up: the viewpoint and the lights in object space (MODEL^-1 of the eye-space
// vectors; a light's vector is (normalised direction, 1) as vpSetLight stores it under an identity
// model), and the half vectors.
struct Lighting {
    Vector4 viewpoint{0.0, 0.0, 1.0, 1.0};
    std::vector<Vector4> light, half;
    std::vector<glm::dvec3> color;
};

Lighting lighting(const VolPackSpec& spec, const Matrix4& model) {
    Lighting g;
    if (!spec.lights) {
        g.light.push_back({0.57735, 0.57735, 0.57735, 1.0});  // InitContext's VP_LIGHT0
        g.color.push_back(glm::dvec3(1.0));
    } else {
        for (const VolPackLight& l : *spec.lights) {
            Vector4 v1{l.direction.x, l.direction.y, l.direction.z, 1.0};
            normalize3(v1.data());
            g.light.push_back(multiply(identity(), v1));
            g.color.push_back(l.color);
        }
    }
    std::vector<Vector4*> rhs{&g.viewpoint};
    for (Vector4& l : g.light) rhs.push_back(&l);
    if (!solve_system(model, rhs)) throw Error("render.profile_options.rotate: the model matrix is singular (vpShadeTable)");
    for (const Vector4& l : g.light) {
        Vector4 h{l[0] + g.viewpoint[0], l[1] + g.viewpoint[1], l[2] + g.viewpoint[2], l[3]};
        normalize3(h.data());
        g.half.push_back(h);
    }
    return g;
}

// The material of VP_MATERIAL0 as vpSetMaterial stores it: x 255 (in double), per channel.
struct Material {
    double ambient[3], diffuse[3], specular[3], shininess;
};
Material material(const VolPackSpec& spec) {
    Material m{};
    for (int c = 0; c < 3; ++c) {
        m.ambient[c] = spec.ambient[c] * 255.0;
        m.diffuse[c] = spec.diffuse[c] * 255.0;
        m.specular[c] = spec.specular[c] * 255.0;
    }
    m.shininess = spec.shininess;
    return m;
}

// One light's term added to an entry, for n . v = ndv, n . l = ndl, n . h = ndh (vpShadeTable's loop).
void add_light(const VolPackSpec& spec, const Material& m, const glm::dvec3& color, double ndv, double ndl, double ndh,
               float* entry) {
    const bool exterior = ndv >= 0;
    if (spec.two_sided) {
        ndl = std::fabs(ndl);
        ndh = std::fabs(ndh);
    } else if (exterior) {
        ndl = ndl > 0.0 ? ndl : 0.0;
        ndh = ndh > 0.0 ? ndh : 0.0;
    } else {
        ndl = -ndl > 0.0 ? -ndl : 0.0;
        ndh = -ndh > 0.0 ? -ndh : 0.0;
    }
    for (int c = 0; c < spec.channels; ++c)
        entry[c] = float(double(entry[c]) + color[c] * (m.diffuse[c] * ndl + m.specular[c] * std::pow(ndh, m.shininess)));
}

void clamp_entry(int channels, float* entry) {
    for (int c = 0; c < channels; ++c)
        if (entry[c] > 255.) entry[c] = 255.0f;
}

}  // namespace

std::vector<float> shade_table(const VolPackSpec& spec, const Matrix4& model) {
    const int C = spec.channels;
    std::vector<float> table(std::size_t(kMaxNormal + 1) * std::size_t(C), 255.0f);
    if (!spec.shaded) return table;
    const Lighting g = lighting(spec, model);
    const Material m = material(spec);
    // Codes 0 and 1 (the zero vector, exterior and interior): ambient only.
    for (int code = 0; code < 2; ++code)
        for (int c = 0; c < C; ++c) table[std::size_t(code * C + c)] = float(m.ambient[c]);
    float* row = table.data() + 2 * C;
    for (int py = -kNormN; py <= kNormN; ++py) {
        const int pxlimit = py < 0 ? kNormN + py : kNormN - py;
        double pxd = double(-pxlimit - 1), pzd = -1.0;
        const double pyd = py;
        for (int px = -pxlimit; px <= pxlimit; ++px) {
            pxd += 1.0;
            pzd += px <= 0 ? 1.0 : -1.0;
            const double plength = 1.0 / std::sqrt(pxd * pxd + pyd * pyd + pzd * pzd);
            const double nx = pxd * plength, ny = pyd * plength, nz = pzd * plength;
            const double ndv_xy = nx * g.viewpoint[0] + ny * g.viewpoint[1], ndv_z = nz * g.viewpoint[2];
            for (int neg = 0; neg < 2; ++neg)
                for (int c = 0; c < C; ++c) row[neg * C + c] = float(m.ambient[c]);
            for (std::size_t l = 0; l < g.light.size(); ++l) {
                const double ndl_xy = nx * g.light[l][0] + ny * g.light[l][1], ndl_z = nz * g.light[l][2];
                const double ndh_xy = nx * g.half[l][0] + ny * g.half[l][1], ndh_z = nz * g.half[l][2];
                for (int neg = 0; neg < 2; ++neg) {
                    const double ndv = neg ? ndv_xy - ndv_z : ndv_xy + ndv_z;
                    const double ndl = neg ? ndl_xy - ndl_z : ndl_xy + ndl_z;
                    const double ndh = neg ? ndh_xy - ndh_z : ndh_xy + ndh_z;
                    add_light(spec, m, g.color[l], ndv, ndl, ndh, row + neg * C);
                }
            }
            clamp_entry(C, row);
            clamp_entry(C, row + C);
            row += 2 * C;
        }
    }
    return table;
}

void shade_normal(const VolPackSpec& spec, const Matrix4& model, const std::array<double, 3>& n, float* out) {
    const int C = spec.channels;
    if (!spec.shaded) {
        for (int c = 0; c < C; ++c) out[c] = 255.0f;
        return;
    }
    const Lighting g = lighting(spec, model);
    const Material m = material(spec);
    for (int c = 0; c < C; ++c) out[c] = float(m.ambient[c]);
    if (n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0) return;
    const double ndv = n[0] * g.viewpoint[0] + n[1] * g.viewpoint[1] + n[2] * g.viewpoint[2];
    for (std::size_t l = 0; l < g.light.size(); ++l) {
        const double ndl = n[0] * g.light[l][0] + n[1] * g.light[l][1] + n[2] * g.light[l][2];
        const double ndh = n[0] * g.half[l][0] + n[1] * g.half[l][1] + n[2] * g.half[l][2];
        add_light(spec, m, g.color[l], ndv, ndl, ndh, out);
    }
    clamp_entry(C, out);
}

const std::array<std::array<std::array<float, 4>, kWarpWeightEntries>, kWarpWeightEntries>& warp_weights() {
    static const auto table = [] {
        std::array<std::array<std::array<float, 4>, kWarpWeightEntries>, kWarpWeightEntries> t{};
        for (int y = 0; y < kWarpWeightEntries; ++y) {
            const double in_y = double(y) / (kWarpWeightEntries - 1);
            for (int x = 0; x < kWarpWeightEntries; ++x) {
                const double in_x = double(x) / (kWarpWeightEntries - 1);
                auto& w = t[std::size_t(y)][std::size_t(x)];
                w[0] = float((1.0 - in_x) * (1.0 - in_y));
                w[1] = float(in_x * (1.0 - in_y));
                w[2] = float((1.0 - in_x) * in_y);
                w[3] = float(1.0 - double(w[2]) - double(w[1]) - double(w[0]));
            }
        }
        return t;
    }();
    return table;
}

VoxelClass classify_voxel(const VolPackSpec& spec, const View& view, int scalar, int gradient) {
    VoxelClass v;
    float opacity = 1.0f;
    opacity *= spec.scalar_table.entries[std::size_t(scalar)];
    if (spec.gradient_table) opacity *= spec.gradient_table->entries[std::size_t(gradient)];
    v.opacity = opacity;
    v.kept = opacity > float(spec.min_voxel_opacity);
    v.opacity_byte = std::clamp(int(double(opacity) * 255.0), 0, 255);
    v.corrected = v.kept ? view.opacity_correction[std::size_t(v.opacity_byte)] : 0.0f;
    return v;
}

}  // namespace volref::volpack
