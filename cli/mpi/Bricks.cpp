#include "cli/mpi/Bricks.h"

#include <algorithm>
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

std::vector<Brick> split_bricks(const std::array<std::int64_t, 3>& dims, int count, int ghost) {
    Brick whole;
    std::int64_t cells = 1;
    for (int a = 0; a < 3; ++a) {
        whole.hi[a] = std::max<std::int64_t>(dims[a] - 1, 0);
        cells = std::max(cells, whole.hi[a]);
    }
    if (cells < count)
        throw Error("volume: " + std::to_string(count) + " ranks but the longest axis has only " + std::to_string(cells) +
                    " cells; use at most that many ranks");
    std::vector<Brick> out;
    split(whole, count, out);
    for (Brick& b : out)
        for (int a = 0; a < 3; ++a) {
            b.vlo[a] = std::max<std::int64_t>(0, b.lo[a] - ghost);
            b.vhi[a] = std::min<std::int64_t>(dims[a] - 1, b.hi[a] + ghost);
        }
    return out;
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

bool owns(const Brick& b, const std::array<std::int64_t, 3>& dims, const glm::dvec3& u) {
    for (int a = 0; a < 3; ++a) {
        if (b.lo[a] > 0 && !(u[a] >= double(b.lo[a]))) return false;
        if (b.hi[a] < dims[a] - 1 && !(u[a] < double(b.hi[a]))) return false;
    }
    return true;
}

}  // namespace volref::mpi
