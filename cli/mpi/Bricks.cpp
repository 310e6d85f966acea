#include "cli/mpi/Bricks.h"

#include <bit>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/Error.h"

namespace volref::mpi {

namespace {

// The work of each cell of `box` along `axis` (WorkBins' rule, Bricks.h); empty when there is none.
std::vector<double> work_along(const Brick& box, int axis, const Lattice& lattice, const WorkBins& w) {
    const std::int64_t n = box.hi[axis] - box.lo[axis];
    std::vector<double> per_bin(std::size_t(w.bins[std::size_t(axis)]), 0.0);
    // The part of bin b on axis a that the box covers (cells of the bin inside the box / its cells).
    auto covered = [&](int a, std::int64_t b) {
        const std::int64_t lo = lattice.lo[std::size_t(a)] + b * w.width[std::size_t(a)];
        const std::int64_t hi = std::min(lo + w.width[std::size_t(a)], lattice.hi[std::size_t(a)]);
        const std::int64_t in = std::min(hi, box.hi[std::size_t(a)]) - std::max(lo, box.lo[std::size_t(a)]);
        return hi > lo ? double(std::max<std::int64_t>(in, 0)) / double(hi - lo) : 1.0;
    };
    double total = 0.0;
    for (std::int64_t k = 0; k < w.bins[2]; ++k)
        for (std::int64_t j = 0; j < w.bins[1]; ++j)
            for (std::int64_t i = 0; i < w.bins[0]; ++i) {
                const std::int64_t b[3] = {i, j, k};
                double f = w.work[std::size_t(i + w.bins[0] * (j + w.bins[1] * k))];
                for (int a = 0; a < 3; ++a)
                    if (a != axis) f *= covered(a, b[a]);
                per_bin[std::size_t(b[axis])] += f;
                total += f;
            }
    if (!(total > 0.0)) return {};
    std::vector<double> cell(std::size_t(std::max<std::int64_t>(n, 0)), 0.0);
    for (std::int64_t c = 0; c < n; ++c) {
        const std::int64_t b = std::min((box.lo[axis] + c - lattice.lo[axis]) / w.width[std::size_t(axis)], w.bins[std::size_t(axis)] - 1);
        const std::int64_t blo = lattice.lo[axis] + b * w.width[std::size_t(axis)];
        const std::int64_t bhi = std::min(blo + w.width[std::size_t(axis)], lattice.hi[axis]);
        cell[std::size_t(c)] = per_bin[std::size_t(b)] / double(std::max<std::int64_t>(bhi - blo, 1));
    }
    return cell;
}

void split(const Brick& box, int count, const Lattice& lattice, const WorkBins* work, std::vector<Brick>& out) {
    if (count == 1) {
        out.push_back(box);
        return;
    }
    int axis = 0;
    for (int a = 1; a < 3; ++a)
        if (box.hi[a] - box.lo[a] > box.hi[axis] - box.lo[axis]) axis = a;
    const std::int64_t cells = box.hi[axis] - box.lo[axis];
    const int first = count / 2;
    // Cells in proportion to the ranks (the other axes are shared): balanced by voxel count.
    std::int64_t cut = box.lo[axis] + (cells * first + count / 2) / count;
    if (work) {
        // Balanced by work: the first cell boundary where the work before it reaches first / count.
        const std::vector<double> w = work_along(box, axis, lattice, *work);
        if (!w.empty()) {
            double total = 0.0;
            for (double x : w) total += x;
            const double target = total * double(first) / double(count);
            double before = 0.0;
            std::int64_t c = 0;
            while (c < cells && before + w[std::size_t(c)] <= target) before += w[std::size_t(c++)];
            // the nearer of the boundaries around the target
            if (c < cells && target - before > before + w[std::size_t(c)] - target) ++c;
            cut = box.lo[axis] + c;
        }
    }
    cut = std::clamp<std::int64_t>(cut, box.lo[axis] + first, box.hi[axis] - (count - first));
    Brick a = box, b = box;
    a.hi[axis] = cut;
    b.lo[axis] = cut;
    split(a, first, lattice, work, out);
    split(b, count - first, lattice, work, out);
}

}  // namespace

WorkBins::WorkBins(const Lattice& cells, std::int64_t bins_per_axis) {
    for (int a = 0; a < 3; ++a) {
        const std::int64_t n = std::max<std::int64_t>(cells.hi[a] - cells.lo[a], 1);
        bins[a] = std::clamp<std::int64_t>(bins_per_axis, 1, n);
        width[a] = (n + bins[a] - 1) / bins[a];
        bins[a] = (n + width[a] - 1) / width[a];
    }
    work.assign(std::size_t(bins[0] * bins[1] * bins[2]), 0.0);
}

std::size_t WorkBins::bin_of(const Lattice& cells, const glm::dvec3& u) const {
    std::int64_t b[3];
    for (int a = 0; a < 3; ++a) {
        const double c = std::floor(u[a]) - double(cells.lo[a]);
        b[a] = c > 0.0 ? std::min(std::int64_t(std::min(c, 9e18)) / width[a], bins[a] - 1) : 0;  // NaN: 0
    }
    return std::size_t(b[0] + bins[0] * (b[1] + bins[1] * b[2]));
}

void add_packet_work(const std::vector<LaneSample>* lanes, int count, std::vector<double>& work) {
    constexpr double kShares = 840.0;  // lcm(1, ..., 8): a step's cost in whole units for 1 to 8 lanes
    static_assert(kWorkPacketLanes <= 8);
    std::size_t steps = 0;
    for (int l = 0; l < count; ++l) steps = std::max(steps, lanes[l].size());
    for (std::size_t j = 0; j < steps; ++j) {
        std::int64_t seen[kWorkPacketLanes];
        int live = 0, distinct = 0;
        for (int l = 0; l < count; ++l) {
            if (j >= lanes[l].size()) continue;
            ++live;
            const std::int64_t line = lanes[l][j].line;
            if (std::find(seen, seen + distinct, line) == seen + distinct) seen[distinct++] = line;
        }
        const double share = (kWorkStepCost + double(distinct)) * (kShares / double(live));
        for (int l = 0; l < count; ++l)
            if (j < lanes[l].size()) work[lanes[l][j].bin] += share;
    }
}

std::vector<Brick> split_lattice(const Lattice& cells_box, int count, const WorkBins* work) {
    Brick whole;
    std::int64_t cells = 1;
    for (int a = 0; a < 3; ++a) {
        whole.lo[a] = cells_box.lo[a];
        whole.hi[a] = std::max(cells_box.hi[a], cells_box.lo[a]);
        cells = std::max(cells, whole.hi[a] - whole.lo[a]);
    }
    if (cells < count)
        throw Error("volume: " + std::to_string(count) + " ranks but the longest axis has only " + std::to_string(cells) +
                    " cells; use at most that many ranks");
    std::vector<Brick> out;
    split(whole, count, cells_box, work, out);
    return out;
}

namespace {

// A point of `from`'s index space (u = (x_local - origin) / spacing) in `to`'s, through world space.
glm::dvec3 map_index(const GridBox& from, const GridBox& to, const glm::dvec3& u) {
    glm::dvec3 x = from.origin + u * from.spacing;  // from's own space
    if (from.to_world) x = from.to_world->to_world(x);
    if (to.to_world) x = to.to_world->to_local(x);
    return (x - to.origin) / to.spacing;
}

// The box [lo, hi] of `from`'s index space mapped into `to`'s: the bounds of its 8 mapped corners.
void map_box(const GridBox& from, const GridBox& to, const glm::dvec3& lo, const glm::dvec3& hi, glm::dvec3& out_lo,
             glm::dvec3& out_hi) {
    out_lo = glm::dvec3(std::numeric_limits<double>::infinity());
    out_hi = -out_lo;
    for (int c = 0; c < 8; ++c) {
        const glm::dvec3 u = map_index(from, to, glm::dvec3(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z));
        out_lo = glm::min(out_lo, u);
        out_hi = glm::max(out_hi, u);
    }
}

// The same lattice: no mapping (exact integer voxel ranges).
bool same_grid(const GridBox& a, const GridBox& b) {
    return a.origin == b.origin && a.spacing == b.spacing && a.to_world == b.to_world;
}

}  // namespace

Lattice union_lattice(const std::vector<GridBox>& grids) {
    Lattice out;
    const GridBox& g0 = grids.front();
    for (int a = 0; a < 3; ++a) out.hi[a] = std::max<std::int64_t>(g0.dims[a] - 1, 0);
    for (std::size_t k = 1; k < grids.size(); ++k) {
        const GridBox& g = grids[k];
        glm::dvec3 lo, hi;
        map_box(g, g0, glm::dvec3(0.0), glm::dvec3(double(g.dims[0] - 1), double(g.dims[1] - 1), double(g.dims[2] - 1)), lo, hi);
        for (int a = 0; a < 3; ++a) {
            if (!(std::fabs(lo[a]) < 1e15 && std::fabs(hi[a]) < 1e15))
                throw Error("volumes: volref-mpi needs every volume within 1e15 voxels of the first volume's grid");
            out.lo[a] = std::min(out.lo[a], std::int64_t(std::floor(lo[a])));
            out.hi[a] = std::max(out.hi[a], std::int64_t(std::ceil(hi[a])));
        }
    }
    return out;
}

void voxels_for(const Brick& b, const Lattice& lattice, const GridBox& first, const GridBox& grid, int ghost,
                std::array<std::int64_t, 3>& vlo, std::array<std::int64_t, 3>& vhi) {
    glm::dvec3 lo(0.0), hi(0.0);
    const bool same = same_grid(first, grid);
    if (!same)
        map_box(first, grid, glm::dvec3(double(b.lo[0]), double(b.lo[1]), double(b.lo[2])),
                glm::dvec3(double(b.hi[0]), double(b.hi[1]), double(b.hi[2])), lo, hi);
    const bool axis_aligned = !first.to_world && !grid.to_world;  // else an outer face bounds no single axis
    for (int a = 0; a < 3; ++a) {
        const std::int64_t last = grid.dims[a] - 1;
        std::int64_t l = 0, h = last;
        if (same) {  // the lattice's own grid
            if (b.lo[a] > lattice.lo[a]) l = b.lo[a] - ghost;
            if (b.hi[a] < lattice.hi[a]) h = b.hi[a] + ghost;
        } else {
            // On the lattice's outer faces the brick owns everything beyond: up to the grid's face
            // (axis-aligned grids); a rotated grid takes the mapped box, which the union covers.
            if (!(axis_aligned && b.lo[a] == lattice.lo[a])) l = std::int64_t(std::floor(std::clamp(lo[a], -1e15, 1e15))) - ghost;
            if (!(axis_aligned && b.hi[a] == lattice.hi[a])) h = std::int64_t(std::ceil(std::clamp(hi[a], -1e15, 1e15))) + ghost;
        }
        l = std::clamp<std::int64_t>(l, 0, last);
        h = std::clamp<std::int64_t>(h, 0, last);
        if (l > h) std::swap(l, h);  // the brick misses the grid on this axis: a sliver at the face
        vlo[a] = l;
        vhi[a] = h;
    }
}

int ghost_voxels(const VolumeSpec& vs, const RenderSpec& render) {
    const bool tricubic =
        vs.interpolation == Interpolation::TricubicBSpline || vs.interpolation == Interpolation::TricubicCatmullRom;
    const bool shades = vs.shading.has_value() && shades_samples(render.projection);
    const bool gradient = shades || vs.classification.has_value() || !vs.transfer.gradient_opacity.empty();
    GradientSpec::Scheme scheme = vs.gradient.scheme;
    if (scheme == GradientSpec::Scheme::Default) scheme = tricubic ? GradientSpec::Scheme::Analytic : GradientSpec::Scheme::Central;
    const bool differences = gradient && scheme != GradientSpec::Scheme::Analytic;
    const int ghost = 1 + (tricubic ? 1 : 0) + (differences ? 1 : 0);
    // A gradient cache is the scheme at every voxel, trilinearly interpolated: the cell's corners (one
    // voxel beyond the owned cells, for rounding) read the scheme's taps around them: one voxel further
    // for differences, two for the analytic tricubic derivative (conservatively: its kernel reads taps
    // i - 1 .. i + 2, though at a voxel the weight of i + 2 is 0; a ghost of 2 gave the same image).
    if (gradient && vs.gradient.cache) return std::max(ghost, 1 + (scheme == GradientSpec::Scheme::Analytic ? 2 : 1));
    return ghost;
}

bool owns(const Brick& b, const Lattice& lattice, const glm::dvec3& u) {
    for (int a = 0; a < 3; ++a) {
        if (b.lo[a] > lattice.lo[a] && !(u[a] >= double(b.lo[a]))) return false;
        if (b.hi[a] < lattice.hi[a] && !(u[a] < double(b.hi[a]))) return false;
    }
    return true;
}

namespace {

// Doubles in order as integers (-0 and +0 both 0), and back.
std::int64_t ordered(double x) {
    const std::int64_t k = std::bit_cast<std::int64_t>(x);
    return k < 0 ? std::numeric_limits<std::int64_t>::min() - k : k;
}
double from_ordered(std::int64_t k) {
    return std::bit_cast<double>(k < 0 ? std::numeric_limits<std::int64_t>::min() - k : k);
}

// The smallest t in [lo, hi] with pred(t) for a predicate false then true on the doubles (hi's
// successor when none), searched from `guess`: galloping away from it in doubles (1, 2, 4, ... apart)
// until the predicate changes, then bisection between the last two points.
template <class Pred>
double first_true(Pred&& pred, double lo, double hi, double guess) {
    if (!pred(hi)) return std::nextafter(hi, std::numeric_limits<double>::infinity());
    if (pred(lo)) return lo;
    // Invariant: pred(from_ordered(a)) is false, pred(from_ordered(b)) is true.
    std::int64_t a = ordered(lo), b = ordered(hi);
    // b - a as unsigned (it can exceed the int64 range).
    auto gap = [&] { return std::uint64_t(b) - std::uint64_t(a); };
    const std::int64_t g = std::isfinite(guess) ? std::clamp(ordered(guess), a, b) : a;
    if (pred(from_ordered(g))) {
        b = g;
        for (std::uint64_t d = 1; gap() > 1 && d != 0; d *= 2) {  // down from g
            const std::int64_t c = gap() > d ? b - std::int64_t(d) : a;
            if (c == a || !pred(from_ordered(c))) {
                a = c;
                break;
            }
            b = c;
        }
    } else {
        a = g;
        for (std::uint64_t d = 1; gap() > 1 && d != 0; d *= 2) {  // up from g
            const std::int64_t c = gap() > d ? a + std::int64_t(d) : b;
            if (c == b || pred(from_ordered(c))) {
                b = c;
                break;
            }
            a = c;
        }
    }
    while (gap() > 1) {
        const std::int64_t mid = a + std::int64_t(gap() / 2);
        (pred(from_ordered(mid)) ? b : a) = mid;
    }
    return from_ordered(b);
}

}  // namespace

RaySpan owned_span(const Brick& b, const Lattice& lattice, const GridBox& first, const Ray& ray) {
    constexpr double kFar = 1e300;  // every t a sample can have
    constexpr double kInf = std::numeric_limits<double>::infinity();
    double t0 = -kFar, t_last = kFar;  // the owned t: [t0, t_last]
    auto u = [&](int a, double t) { return (ray.at(t)[a] - first.origin[a]) / first.spacing[a]; };
    // Where the ray meets the plane u_a = plane (the search's first guess).
    auto guess = [&](int a, double plane) {
        return (first.origin[a] + plane * first.spacing[a] - ray.origin[a]) / ray.direction[a];
    };
    for (int a = 0; a < 3; ++a) {
        const bool lower = b.lo[a] > lattice.lo[a], upper = b.hi[a] < lattice.hi[a];
        const double lo = double(b.lo[a]), hi = double(b.hi[a]);
        auto inside_lower = [&](double t) { return u(a, t) >= lo; };
        auto inside_upper = [&](double t) { return u(a, t) < hi; };
        auto outside_lower = [&](double t) { return !inside_lower(t); };
        auto outside_upper = [&](double t) { return !inside_upper(t); };
        if (ray.direction[a] == 0.0) {  // the index does not change along the ray
            if ((lower && !inside_lower(0.0)) || (upper && !inside_upper(0.0))) return RaySpan{kInf, kInf};
            continue;
        }
        // u >= lo holds from a first t on (u increasing along the ray) or up to a last one; u < hi the
        // other way round. The last t where a predicate holds is the one before it first fails.
        const bool increasing = ray.direction[a] > 0.0;
        if (lower && increasing) t0 = std::max(t0, first_true(inside_lower, -kFar, kFar, guess(a, lo)));
        if (lower && !increasing)
            t_last = std::min(t_last, std::nextafter(first_true(outside_lower, -kFar, kFar, guess(a, lo)), -kInf));
        if (upper && increasing)
            t_last = std::min(t_last, std::nextafter(first_true(outside_upper, -kFar, kFar, guess(a, hi)), -kInf));
        if (upper && !increasing) t0 = std::max(t0, first_true(inside_upper, -kFar, kFar, guess(a, hi)));
    }
    if (!(t0 <= t_last)) return RaySpan{kInf, kInf};
    return RaySpan{t0 == -kFar ? -kInf : t0, t_last == kFar ? kInf : std::nextafter(t_last, kInf)};
}

}  // namespace volref::mpi
