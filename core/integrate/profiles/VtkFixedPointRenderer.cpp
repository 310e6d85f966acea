#include "core/integrate/profiles/VtkFixedPointRenderer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>

#include "core/Error.h"
#include "core/MemoryLimit.h"
#include "transfer/Classifier.h"
#include "transfer/Shader.h"

namespace volref::vtkcpu {

namespace {

constexpr double kPi = 3.14159265358979323846;
const char* const kWhere = "render.profile: \"vtk-cpu\" ";

double degrees(double radians) { return radians * (180.0 / kPi); }

}  // namespace

unsigned fixed_position(float v) { return static_cast<unsigned>(double(v) * kScale + 0.5); }

unsigned fixed_direction(float d) {
    return d < 0.0f ? static_cast<unsigned>(-double(d) * kScale + 0.5)
                    : 0x80000000u + static_cast<unsigned>(double(d) * kScale + 0.5);
}

void fixed_increment(unsigned pos[3], const unsigned dir[3]) {
    for (int a = 0; a < 3; ++a) {
        if (dir[a] & 0x80000000u)
            pos[a] += dir[a] & 0x7fffffffu;
        else
            pos[a] -= dir[a];
    }
}

std::array<unsigned, 8> trilinear_weights(const unsigned pos[3]) {
    const unsigned w2X = pos[0] & kMask, w2Y = pos[1] & kMask, w2Z = pos[2] & kMask;
    const unsigned w1X = (~w2X) & kMask, w1Y = (~w2Y) & kMask, w1Z = (~w2Z) & kMask;
    const unsigned w1Xw1Y = (0x4000u + w1X * w1Y) >> kShift;
    const unsigned w2Xw1Y = (0x4000u + w2X * w1Y) >> kShift;
    const unsigned w1Xw2Y = (0x4000u + w1X * w2Y) >> kShift;
    const unsigned w2Xw2Y = (0x4000u + w2X * w2Y) >> kShift;
    return {(0x4000u + w1Xw1Y * w1Z) >> kShift, (0x4000u + w2Xw1Y * w1Z) >> kShift,
            (0x4000u + w1Xw2Y * w1Z) >> kShift, (0x4000u + w2Xw2Y * w1Z) >> kShift,
            (0x4000u + w1Xw1Y * w2Z) >> kShift, (0x4000u + w2Xw1Y * w2Z) >> kShift,
            (0x4000u + w1Xw2Y * w2Z) >> kShift, (0x4000u + w2Xw2Y * w2Z) >> kShift};
}

unsigned interpolate(const std::array<unsigned, 8>& v, const std::array<unsigned, 8>& w) {
    unsigned sum = 0x7fffu;
    for (int i = 0; i < 8; ++i) sum += v[std::size_t(i)] * w[std::size_t(i)];
    return sum >> kShift;
}

Sample15 lookup(const unsigned short* color_table, const unsigned short* opacity_table, unsigned index) {
    Sample15 s;
    s.a = opacity_table[index];
    for (int c = 0; c < 3; ++c)
        s.rgb[c] = static_cast<unsigned short>((unsigned(color_table[3 * index + unsigned(c)]) * s.a + 0x7fffu) >> kShift);
    return s;
}

bool composite(unsigned color[3], unsigned short& remaining, const Sample15& s) {
    for (int c = 0; c < 3; ++c) color[c] += (unsigned(s.rgb[c]) * remaining + 0x7fffu) >> kShift;
    remaining = static_cast<unsigned short>((unsigned(remaining) * ((~unsigned(s.a)) & kMask) + 0x7fffu) >> kShift);
    return remaining < kTerminate;
}

unsigned encode_direction(const float n[3]) {
    if (n[0] == 0.0f && n[1] == 0.0f && n[2] == 0.0f) return 255u * 256u;
    float theta;
    if (n[0] == 0.0f) {
        theta = n[1] > 0.0f ? 90.0f : 270.0f;
    } else {
        theta = float(degrees(std::atan2(double(n[1]), double(n[0]))));
        theta = theta < 0.0f ? theta + 360.0f : theta;
        theta = theta >= 360.0f ? theta - 360.0f : theta;
    }
    float phi = float(degrees(std::asin(double(n[2]))));
    phi = phi > 90.5f ? phi - 360.0f : phi;
    int low = static_cast<int>(double(theta) * 255.0 / 359.0 + 0.5);
    int high = static_cast<int>((double(phi) + 90.0) * 254.0 / 180.0 + 0.5);
    low = std::clamp(low, 0, 255);
    high = std::clamp(high, 0, 254);
    return unsigned(low + high * 256);
}

glm::vec3 decode_direction(unsigned code) {
    const unsigned i = code & 0xffu, j = code >> 8;
    if (j == 255) return glm::vec3(0.0f);
    // phi = -89.5 + j 179 / 254, theta = i 359 / 255 (degrees, in float as the encoder's table);
    // (1, 0, 0) rotated by -phi about y, then by theta about z.
    const float phi = -89.5f + float(j) * (179.0f / 254.0f);
    const float theta = float(i) * (359.0f / 255.0f);
    const double p = double(phi) * kPi / 180.0, t = double(theta) * kPi / 180.0;
    return glm::vec3(float(std::cos(p) * std::cos(t)), float(std::cos(p) * std::sin(t)), float(std::sin(p)));
}

std::array<double, 2> clipping_range(const glm::dvec3& eye, const glm::dvec3& forward, double fov_y_degrees,
                                     const glm::dvec3& lo, const glm::dvec3& hi) {
    // Plane through the eye with normal `forward`: dist = forward . (p - eye), over the 8 corners.
    const double d = -glm::dot(forward, eye);
    double r0 = glm::dot(forward, lo) + d, r1 = 1e-18;
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 2; ++i) {
                const glm::dvec3 p(i ? hi.x : lo.x, j ? hi.y : lo.y, k ? hi.z : lo.z);
                const double dist = glm::dot(forward, p) + d;
                r0 = std::min(r0, dist);
                r1 = std::max(r1, dist);
            }
    double gap = 0.2 * std::tan(fov_y_degrees * kPi / 360.0) * r1;
    if (r1 - r0 < gap) {
        gap = gap - r1 + r0;
        r1 += gap / 2.0;
        r0 -= gap / 2.0;
    }
    if (r0 < 0.0) r0 = 0.0;
    r0 = 0.99 * r0 - (r1 - r0) * 0.5;
    r1 = 1.01 * r1 + (r1 - r0) * 0.5;
    r0 = r0 >= r1 ? 0.01 * r1 : r0;
    if (r0 < 0.001 * r1) r0 = 0.001 * r1;
    return {r0, r1};
}

// ---------------------------------------------------------------------------------------------

VtkFixedPointRenderer::VtkFixedPointRenderer(const Volume& volume, const Classifier& classifier, const Shader* shader, Projection projection,
               double step, const CameraSpec& camera, const ImageSpec& image, Interpolation interpolation)
    : dims_(volume.dims), origin_(volume.origin), spacing_(volume.spacing), projection_(projection),
      shaded_(shader != nullptr && is_composite(projection)), step_(step), width_(image.width),
      height_(image.height) {
    const std::string where = kWhere;
    if (!is_composite(projection) && !is_extremum(projection))
        throw Error(where + "renders composite, mip and minip only (VTK 9.1's fixed-point mapper renders neither "
                            "average, x-ray nor isosurfaces): render.projection");
    if (interpolation != Interpolation::Trilinear)
        throw Error(where + "mirrors the mapper's linear interpolation only: volume.interpolation must be \"trilinear\"");
    if (camera.type != CameraSpec::Type::Perspective)
        throw Error(where + "needs a perspective camera given by eye, target, up and fov_y: camera.type");
    for (int a = 0; a < 3; ++a)
        if (dims_[std::size_t(a)] < 2) throw Error(where + "needs at least 2 voxels along each axis: volume");
    eye_ = camera.eye;
    forward_ = glm::normalize(camera.target - camera.eye);
    right_ = glm::normalize(glm::cross(forward_, camera.up));
    up_ = glm::cross(right_, forward_);
    tan_half_ = std::tan(camera.fov_y * kPi / 360.0);
    aspect_ = double(width_) / double(height_);
    const glm::dvec3 lo = volume.domain_min(), hi = volume.domain_max();
    const auto range = clipping_range(eye_, forward_, camera.fov_y, lo, hi);
    near_ = range[0];
    far_ = range[1];
    build_view_to_voxels();

    // Scalars to table indices (UpdateColorTable): float data (and integer data whose range exceeds
    // 32767) use 32768 entries, shift = -min, scale = 32767 / (max - min); narrower integer data use
    // one entry per integer, shift = -min, scale = 1. Index = unsigned(scale (v + shift)) in float
    // (double for f64 data).
    const auto [vmin, vmax] = volume.value_range();
    const bool floating = volume.type == ScalarType::F32 || volume.type == ScalarType::F64;
    const bool scaled = floating || vmax - vmin > 32767.0;
    const int size = scaled ? kTableSize : int(vmax - vmin + 1.0);
    shift_ = float(-vmin);
    scale_ = scaled ? (vmax - vmin != 0.0 ? float(32767.0 / (vmax - vmin)) : 1.0f) : 1.0f;
    const std::size_t n = std::size_t(dims_[0] * dims_[1] * dims_[2]);
    // Per voxel: the table index (4 bytes), and when shaded the float data and the normal code (6 more),
    // plus the held volume (8 bytes per voxel at most).
    check_memory(n * (sizeof(unsigned) + (shaded_ ? sizeof(float) + sizeof(unsigned short) : 0) + sizeof(double)),
                 where + "voxel tables");
    scalars_.resize(n);
    if (shaded_) data_.resize(n);
    std::size_t idx = 0;
    for (std::int64_t k = 0; k < dims_[2]; ++k)
        for (std::int64_t j = 0; j < dims_[1]; ++j)
            for (std::int64_t i = 0; i < dims_[0]; ++i, ++idx) {
                const double v = volume.at(i, j, k);
                if (!std::isfinite(v)) throw Error(where + "cannot mirror non-finite voxels (VTK converts them to table indices unchecked): volume");
                scalars_[idx] = volume.type == ScalarType::F64
                                    ? static_cast<unsigned>(double(scale_) * (v + double(shift_)))
                                    : static_cast<unsigned>(scale_ * (float(v) + shift_));
                scalars_[idx] = std::min<unsigned>(scalars_[idx], unsigned(size - 1));
                if (shaded_) data_[idx] = float(v);
            }

    // Tables sampled at min + i (max - min) / (size - 1) (vtkPiecewiseFunction /
    // vtkColorTransferFunction::GetTable, stored as float), then unsigned(x 32767 + 0.5); composite
    // opacity entries > 0.0001 corrected first: 1 - (1 - a)^(step / unit distance).
    color_.resize(3 * std::size_t(size));
    opacity_.resize(std::size_t(size));
    const double factor = step_ / classifier.unit_distance();
    for (int e = 0; e < size; ++e) {
        const double x = vmin + double(e) * (vmax - vmin) / double(size - 1 > 0 ? size - 1 : 1);
        const Classified c = classifier.classify(x, 0.0);
        for (int ch = 0; ch < 3; ++ch)
            color_[3 * std::size_t(e) + std::size_t(ch)] =
                static_cast<unsigned short>(double(float(std::clamp(c.color[ch], 0.0, 1.0))) * kScale + 0.5);
        float a = float(std::clamp(c.opacity, 0.0, 1.0));
        if (is_composite(projection_) && a > 0.0001f) a = float(1.0 - std::pow(1.0 - double(a), factor));
        opacity_[std::size_t(e)] = static_cast<unsigned short>(double(a) * kScale + 0.5);
    }

    if (shaded_) {
        const ShadingSpec& s = shader->spec();
        if (s.model == ShadingSpec::Model::Phong)
            throw Error(where + "shades with Blinn-Phong (vtkEncodedGradientShader): volume.shading.model");
        if (s.kc != 1.0 || s.kl != 0.0)
            throw Error(where + "has no depth cueing: volume.shading.kc and kl must be 1 and 0");
        build_gradients();
        build_shading(*shader);
    }

    // ComputeRowBounds: the box's 8 corners in view coordinates (x, y in [-1, 1], depth in [0, 1]).
    Layout& L = layout_;
    float minX = 1.0f, minY = 1.0f, maxX = -1.0f, maxY = -1.0f, minZ = 1.0f, maxZ = 0.0f;
    float view[8][3];
    const glm::dvec3 cam_voxel = voxel(eye_);
    bool inside = true;
    for (int a = 0; a < 3; ++a)
        inside = inside && cam_voxel[a] >= 0.0 && cam_voxel[a] <= double(dims_[std::size_t(a)] - 1);
    for (int k = 0, c = 0; k < 2; ++k)
        for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 2; ++i, ++c) {
                const glm::dvec3 p(i ? hi.x : lo.x, j ? hi.y : lo.y, k ? hi.z : lo.z);
                const glm::dvec3 q = p - eye_;
                const double d = glm::dot(q, forward_);
                view[c][0] = float(glm::dot(q, right_) / (d * tan_half_ * aspect_));
                view[c][1] = float(glm::dot(q, up_) / (d * tan_half_));
                view[c][2] = float(far_ * (d - near_) / ((far_ - near_) * d));
                if (!inside) {
                    minX = std::min(minX, view[c][0]);
                    minY = std::min(minY, view[c][1]);
                    maxX = std::max(maxX, view[c][0]);
                    maxY = std::max(maxY, view[c][1]);
                    minZ = std::min(minZ, view[c][2]);
                    maxZ = std::max(maxZ, view[c][2]);
                }
            }
    if (inside) {
        minX = minY = -1.0f;
        maxX = maxY = 1.0f;
        minZ = maxZ = 0.001f;
    }
    if (minZ < 0.001f || maxZ > 0.9999f) {
        minX = minY = -1.0f;
        maxX = maxY = 1.0f;
        inside = true;
    }
    const float W = float(width_), H = float(height_);
    minX = (minX + 1.0f) * 0.5f * W - 2.0f;
    minY = (minY + 1.0f) * 0.5f * H - 2.0f;
    maxX = (maxX + 1.0f) * 0.5f * W + 2.0f;
    maxY = (maxY + 1.0f) * 0.5f * H + 2.0f;
    if ((minX < 0 && maxX < 0) || (minY < 0 && maxY < 0) || (minX > W - 1 && maxX > W - 1) ||
        (minY > H - 1 && maxY > H - 1)) {
        L.any = false;
        return;
    }
    minX = std::max(minX, 0.0f);
    minY = std::max(minY, 0.0f);
    maxX = std::min(maxX, W - 1);
    maxY = std::min(maxY, H - 1);
    L.any = true;
    L.in_use[0] = static_cast<int>(maxX - minX + 1.0f);
    L.in_use[1] = static_cast<int>(maxY - minY + 1.0f);
    L.origin[0] = static_cast<int>(minX);
    L.origin[1] = static_cast<int>(minY);
    L.row_lo.assign(std::size_t(L.in_use[1]), std::numeric_limits<int>::max());
    L.row_hi.assign(std::size_t(L.in_use[1]), -1);
    if (inside) {
        std::fill(L.row_lo.begin(), L.row_lo.end(), 0);
        std::fill(L.row_hi.begin(), L.row_hi.end(), L.in_use[0] - 1);
        return;
    }
    // The 12 box edges in internal-image pixels (x from the origin, y from the origin upwards);
    // per row j, each edge crossing row j at x gives xlow = int(x + 1.5), xhigh = int(x - 1).
    static const int edges[12][2] = {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                                     {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
    float lines[12][4];
    for (int e = 0; e < 12; ++e) {
        const float x1 = (view[edges[e][0]][0] + 1.0f) * 0.5f * W - float(L.origin[0]);
        const float y1 = (view[edges[e][0]][1] + 1.0f) * 0.5f * H - float(L.origin[1]);
        const float x2 = (view[edges[e][1]][0] + 1.0f) * 0.5f * W - float(L.origin[0]);
        const float y2 = (view[edges[e][1]][1] + 1.0f) * 0.5f * H - float(L.origin[1]);
        if (y1 < y2) {
            lines[e][0] = x1, lines[e][1] = y1, lines[e][2] = x2, lines[e][3] = y2;
        } else {
            lines[e][0] = x2, lines[e][1] = y2, lines[e][2] = x1, lines[e][3] = y1;
        }
    }
    for (int j = 0; j < L.in_use[1]; ++j) {
        int& rlo = L.row_lo[std::size_t(j)];
        int& rhi = L.row_hi[std::size_t(j)];
        for (int e = 0; e < 12; ++e) {
            if (float(j) >= lines[e][1] && float(j) <= lines[e][3] && lines[e][1] != lines[e][3]) {
                const float x = lines[e][0] +
                                (float(j) - lines[e][1]) / (lines[e][3] - lines[e][1]) * (lines[e][2] - lines[e][0]);
                int xlow = static_cast<int>(x + 1.5f), xhigh = static_cast<int>(x - 1.0f);
                xlow = std::clamp(xlow, 0, L.in_use[0] - 1);
                xhigh = std::clamp(xhigh, 0, L.in_use[0] - 1);
                rlo = std::min(rlo, xlow);
                rhi = std::max(rhi, xhigh);
            }
        }
        if (rlo == rhi) {  // a single pixel: VTK casts no ray in that row
            rlo = std::numeric_limits<int>::max();
            rhi = -1;
        }
    }
}

// vtkFixedPointVolumeRayCastMapperComputeGradients (float, double and 32-bit integer data; also
// used here for 8- and 16-bit integers, see conventions section 9): per voxel, central differences
// n = (f(x - d) - f(x + d)) / (d aspect) per axis (one-sided 2 (f(x) - f(x + d)) or
// 2 (f(x - d) - f(x)) within d of a face), aspect = 2 spacing / mean spacing, for d = 1, 2, 3 until
// |n| > 1e-5 (max - min); normalised and encoded (zero when no d gives one). Arithmetic in float.
void VtkFixedPointRenderer::build_gradients() {
    const std::int64_t nx = dims_[0], ny = dims_[1], nz = dims_[2];
    const double avg = (spacing_.x + spacing_.y + spacing_.z) / 3.0;
    const double aspect[3] = {spacing_.x * 2.0 / avg, spacing_.y * 2.0 / avg, spacing_.z * 2.0 / avg};
    const std::vector<float>& f = data_;  // the data as VTK reads them for the gradient: cast to float
    double lo = std::numeric_limits<double>::max(), hi = std::numeric_limits<double>::lowest();
    for (float v : f) {
        lo = std::min(lo, double(v));
        hi = std::max(hi, double(v));
    }
    const float tolerance = float(0.00001 * (hi - lo));
    auto at = [&](std::int64_t i, std::int64_t j, std::int64_t k) {
        i = std::clamp<std::int64_t>(i, 0, nx - 1);
        j = std::clamp<std::int64_t>(j, 0, ny - 1);
        k = std::clamp<std::int64_t>(k, 0, nz - 1);
        return f[std::size_t(i + nx * (j + ny * k))];
    };
    auto diff = [&](std::int64_t x, std::int64_t dim, int d, auto&& value) -> float {
        if (x < d) return 2.0f * (value(x) - value(x + d));
        if (x >= dim - d) return 2.0f * (value(x - d) - value(x));
        return value(x - d) - value(x + d);
    };
    normals_.resize(f.size());
    std::size_t idx = 0;
    for (std::int64_t z = 0; z < nz; ++z)
        for (std::int64_t y = 0; y < ny; ++y)
            for (std::int64_t x = 0; x < nx; ++x, ++idx) {
                float n[3] = {0.0f, 0.0f, 0.0f};
                bool found = false;
                for (int d = 1; d <= 3 && !found; ++d) {
                    n[0] = diff(x, nx, d, [&](std::int64_t v) { return at(v, y, z); });
                    n[1] = diff(y, ny, d, [&](std::int64_t v) { return at(x, v, z); });
                    n[2] = diff(z, nz, d, [&](std::int64_t v) { return at(x, y, v); });
                    for (int a = 0; a < 3; ++a) n[a] = float(double(n[a]) / (double(d) * aspect[a]));
                    const float t = float(std::sqrt(double(n[0] * n[0] + n[1] * n[1] + n[2] * n[2])));
                    if (t > tolerance) {
                        for (float& c : n) c /= t;
                        found = true;
                    } else {
                        n[0] = n[1] = n[2] = 0.0f;
                    }
                }
                normals_[idx] = static_cast<unsigned short>(encode_direction(n));
            }
}

// vtkEncodedGradientShader::BuildShadingTable per light (colour I, unit L towards it, all lights
// directional; a headlight's L = (eye - target) / |eye - target|), view direction
// V = (target - eye) / |target - eye|, H = normalize(L - V), for each code's decoded normal n:
// diffuse D += ka I + (n.L > 0 ? kd (n.L) I : 0), specular S += (n.L > 0 and n.H > 0.001 ? ks (n.H)^p I : 0),
// with n.L and n.H negated when two-sided lighting is on and n.V > 0; a zero normal gets D = ka I,
// S = 0. Accumulated in float, then unsigned(x 32767 + 0.5).
void VtkFixedPointRenderer::build_shading(const Shader& shader) {
    const ShadingSpec& s = shader.spec();
    const glm::dvec3 view = forward_;
    std::vector<float> D(3 * std::size_t(kDirections), 0.0f), S(3 * std::size_t(kDirections), 0.0f);
    bool first = true;
    for (const LightSpec& light : shader.lights()) {
        const glm::dvec3 L = light.type == LightSpec::Type::Headlight ? -forward_ : glm::normalize(light.direction);
        glm::dvec3 half = L - view;
        if (glm::length(half) != 0.0) half = glm::normalize(half);
        for (unsigned code = 0; code < unsigned(kDirections); ++code) {
            const glm::vec3 n = decode_direction(code);
            float* d = &D[3 * code];
            float* sp = &S[3 * code];
            if (n.x == 0.0f && n.y == 0.0f && n.z == 0.0f) {
                for (int c = 0; c < 3; ++c) d[c] += float(s.ka * light.color[c]);
                continue;
            }
            double ndl = double(n.x) * L.x + double(n.y) * L.y + double(n.z) * L.z;
            double ndh = double(n.x) * half.x + double(n.y) * half.y + double(n.z) * half.z;
            if (s.two_sided) {
                const double ndv = double(n.x) * view.x + double(n.y) * view.y + double(n.z) * view.z;
                if (ndv > 0.0) {
                    ndl = -ndl;
                    ndh = -ndh;
                }
            }
            for (int c = 0; c < 3; ++c) d[c] = first ? float(s.ka * light.color[c]) : d[c] + float(s.ka * light.color[c]);
            if (first)
                for (int c = 0; c < 3; ++c) sp[c] = 0.0f;
            if (ndl > 0.0) {
                for (int c = 0; c < 3; ++c) d[c] += float(s.kd * ndl * light.color[c]);
                if (ndh > 0.001) {
                    const double spec = s.ks * std::pow(ndh, s.n);
                    for (int c = 0; c < 3; ++c) sp[c] += float(spec * light.color[c]);
                }
            }
        }
        first = false;
    }
    diffuse_.resize(D.size());
    specular_.resize(S.size());
    for (std::size_t e = 0; e < D.size(); ++e) {
        diffuse_[e] = static_cast<unsigned short>(double(D[e]) * kScale + 0.5);
        specular_[e] = static_cast<unsigned short>(double(S[e]) * kScale + 0.5);
    }
}

// ComputeMatrices: ViewToVoxels = (P V VoxelsToWorld)^-1 in double, copied to float. V: the camera's
// view transform (rows r, u, (eye - target) / |eye - target|, translation -R eye); P:
// Perspective(fov_y, aspect, n, F) (Frustum with x_max = tan(fov_y / 2) n aspect, y_max =
// tan(fov_y / 2) n) after AdjustZBuffer(-1, 1, 0, 1) (view depth 0 at the near plane, 1 at the far).
void VtkFixedPointRenderer::build_view_to_voxels() {
    using M4 = std::array<double, 16>;  // row-major
    auto mul = [](const M4& a, const M4& b) {
        M4 c{};
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j)
                for (int k = 0; k < 4; ++k) c[std::size_t(4 * i + j)] += a[std::size_t(4 * i + k)] * b[std::size_t(4 * k + j)];
        return c;
    };
    const double n = near_, f = far_, ymax = tan_half_ * n, xmax = ymax * aspect_;
    const M4 frustum = {n / xmax, 0, 0, 0, 0, n / ymax, 0, 0, 0, 0, -(f + n) / (f - n), -2.0 * f * n / (f - n), 0, 0, -1, 0};
    const M4 adjust = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0.5, 0.5, 0, 0, 0, 1};
    const glm::dvec3 z = -forward_;
    const M4 view = {right_.x, right_.y, right_.z, -glm::dot(right_, eye_), up_.x, up_.y, up_.z, -glm::dot(up_, eye_),
                     z.x, z.y, z.z, -glm::dot(z, eye_), 0, 0, 0, 1};
    const M4 voxels_to_world = {spacing_.x, 0, 0, origin_.x, 0, spacing_.y, 0, origin_.y, 0, 0, spacing_.z, origin_.z,
                                0, 0, 0, 1};
    const M4 m = mul(mul(mul(adjust, frustum), view), voxels_to_world);
    glm::dmat4 g;  // column-major copy for the inverse
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) g[j][i] = m[std::size_t(4 * i + j)];
    const glm::dmat4 inv = glm::inverse(g);
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) view_to_voxels_[4 * i + j] = float(inv[j][i]);
}

std::array<int, 2> VtkFixedPointRenderer::pixel_of(const Ray& ray) const {
    const double a = glm::dot(ray.direction, forward_);
    const double nx = glm::dot(ray.direction, right_) / a / (tan_half_ * aspect_);
    const double ny = glm::dot(ray.direction, up_) / a / tan_half_;
    const int x = int(std::floor((nx + 1.0) * 0.5 * double(width_)));
    const int y = int(std::floor((1.0 - ny) * 0.5 * double(height_)));
    return {std::clamp(x, 0, width_ - 1), std::clamp(y, 0, height_ - 1)};
}

namespace {

// ClipRayAgainstVolume, in float as the mapper: the start moved onto the box inset by 0.01 voxel
// along each axis it is outside of, the end likewise, both then moved 1/1000 of the chord inwards.
bool clip_ray(float s[3], float e[3], const float dir[3], const double b[6]) {
    auto outside = [&](const float p[3]) {
        return p[0] >= b[1] || p[1] >= b[3] || p[2] >= b[5] || p[0] < b[0] || p[1] < b[2] || p[2] < b[4];
    };
    if (outside(s)) {
        for (int l = 0; l < 3; ++l) {
            float diff = 0.0f;
            if (s[l] < b[2 * l] + 0.01)
                diff = float((b[2 * l] + 0.01) - s[l]);
            else if (s[l] > b[2 * l + 1] - 0.01)
                diff = float((b[2 * l + 1] - 0.01) - s[l]);
            if (diff != 0.0f) {
                const float t = dir[l] != 0.0f ? diff / dir[l] : -1.0f;
                if (t > 0.0f)
                    for (int m = 0; m < 3; ++m) s[m] += dir[m] * t;
            }
        }
    }
    if (outside(s)) return false;
    if (outside(e)) {
        for (int l = 0; l < 3; ++l) {
            float diff = 0.0f;
            if (e[l] < b[2 * l] + 0.01)
                diff = float((b[2 * l] + 0.01) - e[l]);
            else if (e[l] > b[2 * l + 1] - 0.01)
                diff = float((b[2 * l + 1] - 0.01) - e[l]);
            if (diff != 0.0f) {
                const float t = dir[l] != 0.0f ? diff / dir[l] : 1.0f;
                if (t < 0.0f)
                    for (int m = 0; m < 3; ++m) e[m] += dir[m] * t;
            }
        }
    }
    for (int a = 0; a < 3; ++a) {
        const float offset = float(double(e[a] - s[a]) * 0.001);
        s[a] += offset;
        e[a] -= offset;
    }
    if (outside(e)) return false;
    for (int a = 0; a < 3; ++a)
        if ((e[a] - s[a]) * dir[a] < 0.0f) return false;
    return true;
}

}  // namespace

// ComputeRayInfo for internal pixel (i, j): the ray from the near plane (view depth 0) to the far
// plane (depth 1) through the window pixel centre (origin + (i, j) + 0.5), in voxel coordinates;
// clipped; its direction scaled to one step (step world units); the first sample the first point
// of the lattice near + k step (k = 1 + int(distance to the clipped start / step), counted along
// the axis the start moved most) and positions in fixed point; the sample count the smallest over
// the axes of 1 + (end - start) / step in fixed point.
VtkFixedPointRenderer::RayInfo VtkFixedPointRenderer::ray_info(int i, int j) const {
    RayInfo info;
    // viewRay in float as the mapper computes it; start at view depth 0, end at depth 1 (no z-buffer).
    const float offset_x = float(1.0 / double(float(width_))), offset_y = float(1.0 / double(float(height_)));
    const float view_x = float(double((float(i) + float(layout_.origin[0])) / float(width_)) * 2.0 - 1.0 + double(offset_x));
    const float view_y = float(double((float(j) + float(layout_.origin[1])) / float(height_)) * 2.0 - 1.0 + double(offset_y));
    auto transform = [&](float view_z, float out[3]) {  // vtkVRCMultiplyPointMacro, in float
        const float* M = view_to_voxels_;
        float b[4];
        for (int k = 0; k < 4; ++k) b[k] = view_x * M[4 * k] + view_y * M[4 * k + 1] + view_z * M[4 * k + 2] + M[4 * k + 3];
        if (b[3] != 1.0f)
            for (int k = 0; k < 3; ++k) b[k] /= b[3];
        for (int k = 0; k < 3; ++k) out[k] = b[k];
    };
    float start[3], end[3];
    transform(0.0f, start);
    transform(1.0f, end);
    float dir[3] = {end[0] - start[0], end[1] - start[1], end[2] - start[2]};
    const float original[3] = {start[0], start[1], start[2]};
    const double bounds[6] = {0.0, double(dims_[0] - 1), 0.0, double(dims_[1] - 1), 0.0, double(dims_[2] - 1)};
    if (!clip_ray(start, end, dir, bounds)) return info;
    glm::dvec3 world_dir(double(dir[0]) * spacing_.x, double(dir[1]) * spacing_.y, double(dir[2]) * spacing_.z);
    const double world_length = glm::length(world_dir) / step_;
    for (float& c : dir) c = float(double(c) / world_length);
    float diff[3];
    for (int a = 0; a < 3; ++a) diff[a] = (start[a] - original[a]) * (dir[a] < 0.0f ? -1.0f : 1.0f);
    int steps = -1;
    if (diff[0] >= diff[1] && diff[0] >= diff[2] && dir[0] != 0.0f) steps = 1 + int(diff[0] / std::fabs(dir[0]));
    if (diff[1] >= diff[0] && diff[1] >= diff[2] && dir[1] != 0.0f) steps = 1 + int(diff[1] / std::fabs(dir[1]));
    if (diff[2] >= diff[0] && diff[2] >= diff[1] && dir[2] != 0.0f) steps = 1 + int(diff[2] / std::fabs(dir[2]));
    if (steps > 0)
        for (int a = 0; a < 3; ++a) start[a] = original[a] + float(steps) * dir[a];
    if (!(start[0] > 0.0f && start[1] > 0.0f && start[2] > 0.0f)) return info;
    bool valid = false;
    for (int a = 0; a < 3; ++a) {
        info.pos[a] = fixed_position(start[a]);
        info.dir[a] = fixed_direction(dir[a]);
    }
    for (int a = 0; a < 3; ++a) {
        if (!(info.dir[a] & 0x7fffffffu)) continue;
        const unsigned end_val = fixed_position(end[a]);
        unsigned count;
        if (info.dir[a] & 0x80000000u)
            count = end_val > info.pos[a] ? 1u + (end_val - info.pos[a]) / (info.dir[a] & 0x7fffffffu) : 0u;
        else
            count = info.pos[a] > end_val ? 1u + (info.pos[a] - end_val) / info.dir[a] : 0u;
        if (!valid || count < info.steps) {
            info.steps = count;
            valid = true;
        }
    }
    return info;
}

namespace {

// The 15-bit display value of one channel: the texture holds v / 65535, the shader multiplies by 2.
constexpr double kDisplay = 2.0 / 65535.0;

}  // namespace

Pixel15 VtkFixedPointRenderer::cast(int i, int j, Recording* rec) const {
    Pixel15 out;
    if (!layout_.any || j < 0 || j >= layout_.in_use[1] || i < layout_.row_lo[std::size_t(j)] ||
        i > layout_.row_hi[std::size_t(j)])
        return out;  // outside the row bounds: the cleared image (0)
    RayInfo info = ray_info(i, j);
    const std::int64_t nx = dims_[0], nxy = dims_[0] * dims_[1];
    const std::size_t inc[8] = {0, 1, std::size_t(nx), std::size_t(nx + 1), std::size_t(nxy), std::size_t(nxy + 1),
                                std::size_t(nxy + nx), std::size_t(nxy + nx + 1)};
    unsigned color[3] = {0, 0, 0};
    unsigned short remaining = 0x7fff;
    bool defined = false;
    unsigned short extreme = 0;
    const bool minimum = !takes_maximum(projection_);
    // The sample's position on the ray (world) for the record: fixed point / 32768 voxels.
    auto record = [&](const unsigned pos[3], unsigned val, const Sample15* s, const glm::dvec4& acc, double before,
                      double after, bool composited) {
        SampleRecord r{};
        const glm::dvec3 vox(double(pos[0]) / 32768.0, double(pos[1]) / 32768.0, double(pos[2]) / 32768.0);
        const glm::dvec3 w = world(vox);
        const double t = glm::length(w - eye_);
        rec->begin(r, t - 0.5 * step_, t + 0.5 * step_);
        r.t = t;
        r.sample.position = w;
        r.sample.value = double(val) / double(scale_) - double(shift_);  // the value the index stands for
        r.sample.classified = true;
        r.sample.classified_color = glm::dvec3(color_[3 * val], color_[3 * val + 1], color_[3 * val + 2]) / kScale;
        r.sample.opacity = double(opacity_[val]) / kScale;
        if (s) r.sample.color = glm::dvec3(s->rgb[0], s->rgb[1], s->rgb[2]) / kScale;
        r.sample.shaded = composited && shaded_;
        r.composited = composited;
        r.alpha = s ? double(s->a) / kScale : 0.0;
        r.tau = r.alpha < 1.0 ? -std::log1p(-r.alpha) : std::numeric_limits<double>::infinity();
        r.transmittance_before = before;
        r.transmittance_after = after;
        r.running = double(val);
        r.accumulated = acc;
        rec->recorder.record(r);
    };
    for (unsigned k = 0; k < info.steps; ++k) {
        if (k) fixed_increment(info.pos, info.dir);
        const std::size_t base = std::size_t(info.pos[0] >> kShift) + std::size_t(nx) * std::size_t(info.pos[1] >> kShift) +
                                 std::size_t(nxy) * std::size_t(info.pos[2] >> kShift);
        std::array<unsigned, 8> corners;
        for (int c = 0; c < 8; ++c) corners[std::size_t(c)] = scalars_[base + inc[c]];
        const std::array<unsigned, 8> w = trilinear_weights(info.pos);
        const unsigned val = interpolate(corners, w);
        if (!is_composite(projection_)) {
            if (!defined || (minimum ? val < extreme : val > extreme)) extreme = static_cast<unsigned short>(val);
            defined = true;
            if (rec) {
                const Sample15 m = lookup(color_.data(), opacity_.data(), extreme);
                record(info.pos, val, nullptr, kDisplay * glm::dvec4(m.rgb[0], m.rgb[1], m.rgb[2], m.a), 1.0, 1.0, false);
            }
            continue;
        }
        Sample15 s = lookup(color_.data(), opacity_.data(), val);
        if (!s.a) {
            if (rec)
                record(info.pos, val, &s,
                       kDisplay * glm::dvec4(std::min(color[0], 32767u), std::min(color[1], 32767u),
                                             std::min(color[2], 32767u), (~unsigned(remaining)) & kMask),
                       double(remaining) / 32767.0, double(remaining) / 32767.0, false);
            continue;  // LookupColorUS: a transparent sample is skipped
        }
        if (shaded_) {
            // InterpolateShading: the diffuse and specular table entries of the 8 corners' encoded
            // normals, interpolated with the same weights; c = (D c + 0x7fff) >> 15 + (S a + 0x7fff) >> 15.
            std::array<unsigned, 8> dc[3], sc[3];
            for (int c = 0; c < 8; ++c) {
                const unsigned code = normals_[base + inc[c]];
                for (int ch = 0; ch < 3; ++ch) {
                    dc[ch][std::size_t(c)] = diffuse_[3 * code + unsigned(ch)];
                    sc[ch][std::size_t(c)] = specular_[3 * code + unsigned(ch)];
                }
            }
            for (int ch = 0; ch < 3; ++ch) {
                const unsigned D = interpolate(dc[ch], w), S = interpolate(sc[ch], w);
                s.rgb[ch] = static_cast<unsigned short>((D * s.rgb[ch] + 0x7fffu) >> kShift);
                s.rgb[ch] = static_cast<unsigned short>(s.rgb[ch] + ((S * s.a + 0x7fffu) >> kShift));
            }
        }
        const double before = double(remaining) / 32767.0;
        const bool stop = composite(color, remaining, s);
        if (rec) {
            record(info.pos, val, &s,
                   kDisplay * glm::dvec4(std::min(color[0], 32767u), std::min(color[1], 32767u),
                                         std::min(color[2], 32767u), (~unsigned(remaining)) & kMask),
                   before, double(remaining) / 32767.0, true);
        }
        if (stop) break;
    }
    if (!is_composite(projection_)) {
        if (!defined) return out;
        const Sample15 m = lookup(color_.data(), opacity_.data(), extreme);
        out.rgba = {m.rgb[0], m.rgb[1], m.rgb[2], m.a};
        return out;
    }
    // SetPixelColor: colours clamped to 32767, alpha = 0x7fff - remaining.
    for (int c = 0; c < 3; ++c) out.rgba[std::size_t(c)] = static_cast<unsigned short>(std::min(color[c], 32767u));
    out.rgba[3] = static_cast<unsigned short>((~unsigned(remaining)) & kMask);
    return out;
}

// The internal image drawn as a texture (vtkOpenGLRayCastImageDisplayHelper): a quad over window
// pixels [origin, origin + M) (M = in-use size per axis) with texel centres 0 and M - 1 on its
// edges, GL_LINEAR: window pixel p reads the texture at s = (p + 0.5 - origin) (M - 1) / M texels
// from texel 0's centre, i.e. texels floor(s) and floor(s) + 1 with weights 1 - frac(s), frac(s);
// the texel value v / 65535 times the shader's scale 2. Pixels outside the quad are background.
glm::dvec4 VtkFixedPointRenderer::display(int x, int y, Recording* rec) const {
    glm::dvec4 out(0.0);
    if (!layout_.any) return out;
    const int px = x, py = height_ - 1 - y;  // VTK's window rows count from the bottom
    const int M0 = layout_.in_use[0], M1 = layout_.in_use[1];
    if (px < layout_.origin[0] || px >= layout_.origin[0] + M0 || py < layout_.origin[1] ||
        py >= layout_.origin[1] + M1) {
        if (rec) {
            SampleRecord r{};
            rec->begin(r, 0.0, 0.0);
            rec->recorder.record(r);
        }
        return out;
    }
    const double sx = (double(px - layout_.origin[0]) + 0.5) * double(M0 - 1) / double(M0);
    const double sy = (double(py - layout_.origin[1]) + 0.5) * double(M1 - 1) / double(M1);
    const int i0 = int(std::floor(sx)), j0 = int(std::floor(sy));
    const double fx = sx - double(i0), fy = sy - double(j0);
    const double wx[2] = {1.0 - fx, fx}, wy[2] = {1.0 - fy, fy};
    for (int b = 0; b < 2; ++b)
        for (int a = 0; a < 2; ++a) {
            const double weight = wx[a] * wy[b];
            if (weight == 0.0) continue;
            const Pixel15 t = cast(i0 + a, j0 + b, rec);
            for (int c = 0; c < 4; ++c) out[c] += weight * kDisplay * double(t.rgba[std::size_t(c)]);
        }
    if (rec) {
        SampleRecord r{};
        rec->begin(r, 0.0, 0.0);
        r.accumulated = out;
        rec->recorder.record(r);
    }
    return out;
}

}  // namespace volref::vtkcpu
