#include "cli/mpi/Bricks.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/Error.h"

namespace volref::mpi {

namespace {

void split(const Brick& box, int count, std::vector<Brick>& out) {
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
    cut = std::clamp<std::int64_t>(cut, box.lo[axis] + first, box.hi[axis] - (count - first));
    Brick a = box, b = box;
    a.hi[axis] = cut;
    b.lo[axis] = cut;
    split(a, first, out);
    split(b, count - first, out);
}

}  // namespace

std::vector<Brick> split_lattice(const Lattice& cells_box, int count) {
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
    split(whole, count, out);
    return out;
}

Lattice union_lattice(const std::vector<GridBox>& grids) {
    Lattice out;
    const GridBox& g0 = grids.front();
    for (int a = 0; a < 3; ++a) out.hi[a] = std::max<std::int64_t>(g0.dims[a] - 1, 0);
    for (std::size_t k = 1; k < grids.size(); ++k) {
        const GridBox& g = grids[k];
        for (int a = 0; a < 3; ++a) {
            const double x0 = g.origin[a], x1 = g.origin[a] + double(g.dims[a] - 1) * g.spacing[a];
            const double u0 = (std::min(x0, x1) - g0.origin[a]) / g0.spacing[a];
            const double u1 = (std::max(x0, x1) - g0.origin[a]) / g0.spacing[a];
            if (!(std::fabs(u0) < 1e15 && std::fabs(u1) < 1e15))
                throw Error("volumes: volref-mpi needs every volume within 1e15 voxels of the first volume's grid");
            out.lo[a] = std::min(out.lo[a], std::int64_t(std::floor(u0)));
            out.hi[a] = std::max(out.hi[a], std::int64_t(std::ceil(u1)));
        }
    }
    return out;
}

void voxels_for(const Brick& b, const Lattice& lattice, const GridBox& first, const GridBox& grid, int ghost,
                std::array<std::int64_t, 3>& vlo, std::array<std::int64_t, 3>& vhi) {
    for (int a = 0; a < 3; ++a) {
        const std::int64_t last = grid.dims[a] - 1;
        std::int64_t lo = 0, hi = last;
        if (grid.origin[a] == first.origin[a] && grid.spacing[a] == first.spacing[a]) {  // the lattice's own grid
            if (b.lo[a] > lattice.lo[a]) lo = b.lo[a] - ghost;
            if (b.hi[a] < lattice.hi[a]) hi = b.hi[a] + ghost;
        } else if (b.lo[a] > lattice.lo[a]) {
            const double u = (first.origin[a] + double(b.lo[a]) * first.spacing[a] - grid.origin[a]) / grid.spacing[a];
            lo = std::int64_t(std::floor(std::clamp(u, -1e15, 1e15))) - ghost;
        }
        if (!(grid.origin[a] == first.origin[a] && grid.spacing[a] == first.spacing[a]) && b.hi[a] < lattice.hi[a]) {
            const double u = (first.origin[a] + double(b.hi[a]) * first.spacing[a] - grid.origin[a]) / grid.spacing[a];
            hi = std::int64_t(std::ceil(std::clamp(u, -1e15, 1e15))) + ghost;
        }
        lo = std::clamp<std::int64_t>(lo, 0, last);
        hi = std::clamp<std::int64_t>(hi, 0, last);
        if (lo > hi) std::swap(lo, hi);  // the brick misses the grid on this axis: a sliver at the face
        vlo[a] = lo;
        vhi[a] = hi;
    }
}

int ghost_voxels(const VolumeSpec& vs, const RenderSpec& render) {
    const bool tricubic =
        vs.interpolation == Interpolation::TricubicBSpline || vs.interpolation == Interpolation::TricubicCatmullRom;
    const bool shades = vs.shading.has_value() &&
                        (render.projection == Projection::Composite || render.projection == Projection::FirstHit);
    const bool gradient = shades || vs.classification.has_value() || !vs.transfer.gradient_opacity.empty();
    GradientSpec::Scheme scheme = vs.gradient.scheme;
    if (scheme == GradientSpec::Scheme::Default) scheme = tricubic ? GradientSpec::Scheme::Analytic : GradientSpec::Scheme::Central;
    const bool differences = gradient && scheme != GradientSpec::Scheme::Analytic;
    return 1 + (tricubic ? 1 : 0) + (differences ? 1 : 0);
}

bool owns(const Brick& b, const Lattice& lattice, const glm::dvec3& u) {
    for (int a = 0; a < 3; ++a) {
        if (b.lo[a] > lattice.lo[a] && !(u[a] >= double(b.lo[a]))) return false;
        if (b.hi[a] < lattice.hi[a] && !(u[a] < double(b.hi[a]))) return false;
    }
    return true;
}

}  // namespace volref::mpi
