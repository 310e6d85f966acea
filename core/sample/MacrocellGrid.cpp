#include "core/sample/MacrocellGrid.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "core/Conventions.h"

namespace volref {

namespace {
constexpr std::int64_t M = conventions::kMacrocellSize;
constexpr double kInf = std::numeric_limits<double>::infinity();
}  // namespace

std::array<double, 2> MacrocellGrid::reconstruction_bounds(Interpolation interpolation, double lo, double hi) {
    if (interpolation == Interpolation::Nearest) return {lo, hi};
    if (interpolation == Interpolation::TricubicCatmullRom) {
        const double mid = 0.5 * lo + 0.5 * hi, r = 0.5 * hi - 0.5 * lo;
        const double e = 1.953125 * r;  // (5/4)^3 r
        lo = std::min(lo, mid - e);
        hi = std::max(hi, mid + e);
    }
    const double m = std::max(std::fabs(lo), std::fabs(hi));
    if (m == 0.0) return {lo, hi};
    const double margin = 1e-12 * m + 1e-300;
    return {lo - margin, hi + margin};
}

MacrocellGrid::MacrocellGrid(const VolumeSampler& sampler, const Classifier& classifier, Classification classification)
    : sampler_(sampler) {
    const Volume& v = sampler.volume();
    for (int a = 0; a < 3; ++a) cells_[a] = std::max<std::int64_t>(v.dims[a] - 1, 1);
    counts_ = counts_for(v.dims.data());
    apron_ = sampler.is_tricubic() ? 1 : 0;
    const std::size_t total = std::size_t(counts_[0] * counts_[1] * counts_[2]);
    ranges_.resize(total);
    empty_.assign(total, 0);

    const Interpolation interpolation = sampler.interpolation();
    const bool pre = classification == Classification::Pre;
    const bool value_only = !classifier.needs_gradient();
    // Pre-classification: can voxel value x have a pre-classified opacity a_i != 0?
    auto voxel_visible = [&](double x) {
        return value_only ? classifier.classify(x, 0.0).opacity != 0.0 : classifier.may_have_opacity(x, x);
    };

    empty_count_ = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, total), std::int64_t(0),
        [&](const tbb::blocked_range<std::size_t>& r, std::int64_t count) {
            for (std::size_t id = r.begin(); id != r.end(); ++id) {
                const std::int64_t s = std::int64_t(id);
                const Index m{s % counts_[0], (s / counts_[0]) % counts_[1], s / (counts_[0] * counts_[1])};
                Index first, last;
                voxel_box(m, first, last);
                double lo = kInf, hi = -kInf;
                bool finite = true, visible = false;
                v.values.visit([&](const auto* values) {  // one switch on the storage type per macrocell
                    const std::int64_t row_length = last[0] - first[0] + 1;
                    for (std::int64_t k = first[2]; k <= last[2]; ++k)
                        for (std::int64_t j = first[1]; j <= last[1]; ++j) {
                            const auto* row = values + v.index(first[0], j, k);
                            for (std::int64_t i = 0; i < row_length; ++i) {
                                const double x = double(row[i]);
                                if (!std::isfinite(x)) {
                                    finite = false;
                                    continue;
                                }
                                lo = std::min(lo, x);
                                hi = std::max(hi, x);
                                if (pre && !visible) visible = voxel_visible(x);
                            }
                        }
                });
                if (!finite) {
                    ranges_[id] = {-kInf, kInf};
                    continue;
                }
                ranges_[id] = {lo, hi};
                if (!pre) {
                    const auto b = reconstruction_bounds(interpolation, lo, hi);
                    visible = classifier.may_have_opacity(b[0], b[1]);
                }
                if (!visible) {
                    empty_[id] = 1;
                    ++count;
                }
            }
            return count;
        },
        [](std::int64_t a, std::int64_t b) { return a + b; });
    empty_radius_ = chebyshev_radii();
}

std::vector<std::uint8_t> MacrocellGrid::chebyshev_radii() const {
    // Chebyshev distance to the nearest macrocell that is not empty, by the two-pass
    // chamfer transform with unit weights on all 26 neighbours (exact for this metric): a raster pass
    // taking min(d, d(neighbour) + 1) over the 13 neighbours already visited, then the reverse pass over
    // the other 13. Linear in the number of macrocells.
    const std::size_t total = empty_.size();
    constexpr std::int64_t far = kMaxEmptyRadius;
    std::vector<std::int64_t> d(total);
    for (std::size_t i = 0; i < total; ++i) d[i] = empty_[i] != 0 ? far : 0;
    auto pass = [&](int sign) {
        for (std::size_t n = 0; n < total; ++n) {
            const std::int64_t s = std::int64_t(sign > 0 ? n : total - 1 - n);
            const Index m{s % counts_[0], (s / counts_[0]) % counts_[1], s / (counts_[0] * counts_[1])};
            std::int64_t& here = d[std::size_t(s)];
            for (int dz = -1; dz <= 1; ++dz)
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        // the neighbours before m in this pass's order (linear index smaller, or larger)
                        const std::int64_t offset = dx + counts_[0] * (dy + counts_[1] * dz);
                        if (sign * offset >= 0 || (dx == 0 && dy == 0 && dz == 0)) continue;
                        const Index q{m[0] + dx, m[1] + dy, m[2] + dz};
                        if (inside(q)) here = std::min(here, d[linear(q)] + 1);
                    }
        }
    };
    pass(+1);
    pass(-1);
    std::vector<std::uint8_t> out(total);
    for (std::size_t i = 0; i < total; ++i) out[i] = std::uint8_t(std::min(d[i], far));
    return out;
}

MacrocellGrid::Index MacrocellGrid::counts_for(const std::int64_t dims[3]) {
    Index counts;
    for (int a = 0; a < 3; ++a) counts[a] = (std::max<std::int64_t>(dims[a] - 1, 1) + M - 1) / M;
    return counts;
}

std::size_t MacrocellGrid::bytes_for(const std::int64_t dims[3], bool octant_radii) {
    const Index c = counts_for(dims);
    // ranges_, empty_, empty_radius_; chebyshev_radii's distance field and result while it runs.
    std::size_t per = sizeof(std::array<double, 2>) + sizeof(unsigned char) + sizeof(std::uint8_t) + sizeof(std::int64_t) + sizeof(std::uint8_t);
    if (octant_radii) per += 8 * sizeof(std::int32_t);
    return std::size_t(c[0] * c[1] * c[2]) * per;
}

std::vector<std::int32_t> MacrocellGrid::octant_radii() const {
    const std::size_t total = empty_.size();
    constexpr std::int64_t far = kMaxEmptyRadius;
    std::vector<std::int32_t> out(8 * total);
    for (int o = 0; o < 8; ++o) {
        const Index s{(o & 1) ? -1 : 1, (o & 2) ? -1 : 1, (o & 4) ? -1 : 1};
        std::int32_t* r = out.data() + std::size_t(o) * total;  // signed: + empty, - not
        // Visit the neighbours ahead first: each axis from its far end backwards.
        Index m;
        for (std::int64_t c2 = 0; c2 < counts_[2]; ++c2)
            for (std::int64_t c1 = 0; c1 < counts_[1]; ++c1)
                for (std::int64_t c0 = 0; c0 < counts_[0]; ++c0) {
                    m[0] = s[0] > 0 ? counts_[0] - 1 - c0 : c0;
                    m[1] = s[1] > 0 ? counts_[1] - 1 - c1 : c1;
                    m[2] = s[2] > 0 ? counts_[2] - 1 - c2 : c2;
                    const std::size_t here = linear(m);
                    std::int64_t ahead = far;
                    for (int n = 1; n < 8; ++n) {
                        const Index q{m[0] + ((n & 1) ? s[0] : 0), m[1] + ((n & 2) ? s[1] : 0), m[2] + ((n & 4) ? s[2] : 0)};
                        if (!inside(q)) continue;
                        const std::size_t there = linear(q);
                        ahead = std::min<std::int64_t>(ahead, empty_[there] == empty_[here] ? std::abs(r[there]) : 0);
                    }
                    const auto size = std::int32_t(std::min(ahead + 1, far));
                    r[here] = empty_[here] != 0 ? size : -size;
                }
    }
    return out;
}

void MacrocellGrid::voxel_box(const Index& m, Index& first, Index& last) const {
    const Volume& v = sampler_.volume();
    for (int a = 0; a < 3; ++a) {
        const std::int64_t c0 = m[a] * M, c1 = std::min(c0 + M, cells_[a]);  // cells [c0, c1)
        first[a] = std::clamp<std::int64_t>(c0 - apron_, 0, v.dims[a] - 1);
        last[a] = std::clamp<std::int64_t>(c1 + apron_, 0, v.dims[a] - 1);
    }
}

double MacrocellGrid::exit_distance(const Ray& ray, const Index& m, std::int64_t r) const {
    const Volume& v = sampler_.volume();
    double t = kInf;
    for (int a = 0; a < 3; ++a) {
        const double d = ray.direction[a];
        std::int64_t plane;
        if (d > 0.0 && m[a] + r < counts_[a]) plane = (m[a] + r) * M;
        else if (d < 0.0 && m[a] - (r - 1) > 0) plane = (m[a] - (r - 1)) * M;
        else continue;
        t = std::min(t, (v.origin[a] + double(plane) * v.spacing[a] - ray.origin[a]) / d);
    }
    return t;
}

double MacrocellGrid::entry_distance(const Ray& ray, const Index& m) const {
    const Volume& v = sampler_.volume();
    double t = -kInf;
    for (int a = 0; a < 3; ++a) {
        const double d = ray.direction[a];
        std::int64_t plane;
        if (d > 0.0 && m[a] > 0) plane = m[a] * M;
        else if (d < 0.0 && m[a] + 1 < counts_[a]) plane = (m[a] + 1) * M;
        else continue;
        t = std::max(t, (v.origin[a] + double(plane) * v.spacing[a] - ray.origin[a]) / d);
    }
    return t;
}

std::array<double, 2> MacrocellGrid::value_bounds(const Index& m) const {
    const auto [lo, hi] = ranges_[linear(m)];
    if (!(std::isfinite(lo) && std::isfinite(hi)))
        return {-std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
    return reconstruction_bounds(sampler_.interpolation(), lo, hi);
}

}  // namespace volref
