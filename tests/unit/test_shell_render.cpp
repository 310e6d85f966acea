// Shell and mesh bounds through the whole renderer, against closed-form chords.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "TestScenes.h"
#include "core/grid/ProceduralField.h"
#include "core/sample/Resample.h"
#include "core/io/NrrdWriter.h"
#include "geometry/ShellTessellation.h"

using namespace volref;
using namespace volref::test;

namespace {

constexpr double kA = 0.3, kL = 0.5;  // opacity per unit distance l

// alpha of a chord of length L through a constant medium: 1 - (1 - a)^(L / l).
double chord_alpha(double L) { return 1.0 - std::pow(1.0 - kA, L / kL); }

// A constant field on a shell grid, seen orthographically along -z over [-1.2, 1.2]^2 (N x N pixels).
Scene shell_scene(BoundsSpec bounds, int n) {
    Scene s = field_scene(constant_field(1.0, {9, 7, 5}));
    s.volume().origin.reset();
    s.volume().spacing.reset();
    s.volume().bounds = bounds;
    s.volume().transfer.opacity = {{0.0, kA}};
    s.volume().transfer.color = {{0.0, 0.5, 0.25, 1.0}};
    s.volume().transfer.opacity_unit_distance = kL;
    s.camera = ortho_down_z(0.0, 0.0, 5.0, 2.4);
    s.image.width = s.image.height = n;
    s.render.step = 0.07;
    s.render.step_units = StepUnits::World;
    return s;
}

double pixel_coordinate(int i, int n) { return -1.2 + 2.4 * (i + 0.5) / n; }

}  // namespace

// A full spherical shell r0 = 0.5, r1 = 1: a ray at distance rho from the centre crosses
// 2 (sqrt(r1^2 - rho^2) - sqrt(max(r0^2 - rho^2, 0))) of it (two intervals through the hole).
TEST(ShellRender, SphericalShellChords) {
    BoundsSpec b;
    b.type = BoundsSpec::Type::Spherical;
    b.sphere.r0 = 0.5;
    b.sphere.r1 = 1.0;
    const int n = 24;
    const Image im = render_scene(shell_scene(b, n), {.threads = 2});
    int through_hole = 0;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const double px = pixel_coordinate(x, n), py = -pixel_coordinate(y, n);
            const double rho2 = px * px + py * py;
            const double L = 2.0 * (std::sqrt(std::max(1.0 - rho2, 0.0)) - std::sqrt(std::max(0.25 - rho2, 0.0)));
            EXPECT_NEAR(im.at(x, y, 3), chord_alpha(L), 1e-12) << x << "," << y;
            EXPECT_NEAR(im.at(x, y, 0), 0.5 * chord_alpha(L), 1e-12);
            if (rho2 < 0.25) ++through_hole;
        }
    EXPECT_GT(through_hole, 50);
}

// A cylindrical annulus (axis y, r0 = 0.4, r1 = 1, height [-0.5, 0.8]) seen along -z: the ray at
// (x, y) crosses 2 (sqrt(r1^2 - x^2) - sqrt(max(r0^2 - x^2, 0))) when -0.5 <= y <= 0.8, else nothing.
// A quarter wedge angle [0, 90] (x >= 0, z <= 0): only the far half of those chords, for x >= 0.
TEST(ShellRender, CylindricalAnnulusAndWedge) {
    BoundsSpec b;
    b.type = BoundsSpec::Type::Cylindrical;
    b.cylinder.r0 = 0.4;
    b.cylinder.r1 = 1.0;
    b.cylinder.h0 = -0.5;
    b.cylinder.h1 = 0.8;
    const int n = 24;
    const Image full = render_scene(shell_scene(b, n), {.threads = 2});
    b.cylinder.a0 = 0.0;
    b.cylinder.a1 = 90.0;
    const Image wedge = render_scene(shell_scene(b, n), {.threads = 2});
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const double px = pixel_coordinate(x, n), py = -pixel_coordinate(y, n);
            const bool in_height = py >= -0.5 && py <= 0.8;
            const double half = std::sqrt(std::max(1.0 - px * px, 0.0)) - std::sqrt(std::max(0.16 - px * px, 0.0));
            EXPECT_NEAR(full.at(x, y, 3), in_height ? chord_alpha(2.0 * half) : 0.0, 1e-12) << x << "," << y;
            EXPECT_NEAR(wedge.at(x, y, 3), in_height && px >= 0.0 ? chord_alpha(half) : 0.0, 1e-12) << x << "," << y;
        }
}

// The tessellated shell (a triangle mesh through Embree) against the analytic one. Each curved
// surface of radius r is within eps = r (1 - cos(pi / N)) of its polygon (ShellTessellation.h); a
// ray meeting it at angle theta to the normal moves its crossing by at most eps / cos(theta), so the
// chord changes by at most the sum over the crossings, and alpha by (-ln(1 - a) / l) times that.
// Rays with cos(theta) < 0.5 at some surface (near the silhouettes) are skipped.
TEST(ShellRender, TessellatedAgreesWithAnalytic) {
    BoundsSpec b;
    b.type = BoundsSpec::Type::Spherical;
    b.sphere.r0 = 0.5;
    b.sphere.r1 = 1.0;
    const int n = 24, N = 96;
    const Image analytic = render_scene(shell_scene(b, n), {.threads = 2});
    b.tessellate = N;
    const Image mesh = render_scene(shell_scene(b, n), {.threads = 2});
    const double sigma = -std::log1p(-kA) / kL;
    int checked = 0;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const double px = pixel_coordinate(x, n), py = -pixel_coordinate(y, n);
            const double rho = std::hypot(px, py);
            double dL = 0.0;
            bool skip = false;
            for (double r : {0.5, 1.0}) {
                if (rho >= r) continue;
                const double cos_theta = std::sqrt(1.0 - (rho / r) * (rho / r));
                if (cos_theta < 0.5) skip = true;
                dL += 2.0 * r * (1.0 - std::cos(M_PI / N)) / cos_theta;
            }
            if (skip || rho >= 1.0) continue;
            EXPECT_NEAR(mesh.at(x, y, 3), analytic.at(x, y, 3), sigma * dL + 1e-12) << x << "," << y;
            ++checked;
        }
    EXPECT_GT(checked, 200);
}

// A concave mesh: a U (two pillars joined at the bottom) extruded along y, written as an OBJ, seen
// along -z. Rays through both pillars have two intervals whose lengths add: chord = 2 pillar depths.
TEST(ShellRender, ConcaveMeshChords) {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("volref-mesh-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    // The U in the x-z plane (outline, counter-clockwise seen from +y): pillars x in [0, 1] and
    // [3, 4], z in [0, 4]; the base z in [0, 1] joins them. Extruded over y in [0, 4].
    const double outline[8][2] = {{0, 0}, {4, 0}, {4, 4}, {3, 4}, {3, 1}, {1, 1}, {1, 4}, {0, 4}};
    std::ofstream obj(dir / "u.obj");
    for (double yv : {0.0, 4.0})
        for (auto& p : outline) obj << "v " << p[0] << " " << yv << " " << -p[1] << "\n";
    // Caps: the U split into three convex pieces (base, left pillar, right pillar).
    const int cap[6][3] = {{1, 2, 5}, {2, 3, 4}, {2, 4, 5}, {1, 5, 6}, {1, 6, 7}, {1, 7, 8}};
    for (auto& t : cap) obj << "f " << t[0] << " " << t[2] << " " << t[1] << "\n";        // y = 0, facing -y
    for (auto& t : cap) obj << "f " << t[0] + 8 << " " << t[1] + 8 << " " << t[2] + 8 << "\n";  // y = 4, facing +y
    for (int i = 0; i < 8; ++i) {  // sides
        const int a = i + 1, c = (i + 1) % 8 + 1;
        obj << "f " << a << " " << c << " " << c + 8 << "\nf " << a << " " << c + 8 << " " << a + 8 << "\n";
    }
    obj.close();
    Scene s = field_scene(constant_field(1.0, {6, 6, 6}), glm::dvec3(-0.5, -0.5, -4.5), glm::dvec3(1.0));
    s.volume().bounds.type = BoundsSpec::Type::Mesh;
    s.volume().bounds.mesh = dir / "u.obj";
    s.volume().transfer.opacity = {{0.0, kA}};
    s.volume().transfer.opacity_unit_distance = kL;
    // Looking along -x (from +x) at y in (0, 4): a ray at height z crosses both pillars (2 units)
    // for -4 < z < -1 and the solid base (4 units) for -1 < z < 0.
    s.camera.type = CameraSpec::Type::Orthographic;
    s.camera.eye = {10.0, 2.0, -2.0};
    s.camera.target = {0.0, 2.0, -2.0};
    s.camera.up = {0.0, 0.0, 1.0};
    s.camera.height = 4.0;
    s.image.width = s.image.height = 8;
    s.render.step = 0.3;
    s.render.step_units = StepUnits::World;
    const Image im = render_scene(s, {.threads = 1});
    for (int y = 0; y < 8; ++y) {
        const double z = -2.0 + 2.0 - 4.0 * (y + 0.5) / 8.0;  // row 0 at the top: z = -0.25
        const double L = z > -1.0 ? 4.0 : 2.0;
        for (int x = 0; x < 8; ++x) EXPECT_NEAR(im.at(x, y, 3), chord_alpha(L), 1e-12) << x << "," << y << " z " << z;
    }
    std::filesystem::remove_all(dir);
}

// A Cartesian Gaussian resampled to a spherical grid and rendered in its shell matches the Cartesian
// render within the resampling error. The shell holds every voxel with opacity > 0 (value >= 0.2,
// within radius sigma sqrt(2 ln 5) = 0.90 of the centre), so both renders integrate the same medium.
// Measured: max |alpha difference| 9.3e-4 with a 48 x 24 x 24 grid; asserted below 5e-3.
TEST(ShellRender, ResampledCartesianVolumeMatches) {
    FieldSpec g;
    g.kind = FieldSpec::Kind::Gaussian;
    g.dims = {49, 49, 49};
    g.sigma = 0.5;
    const Volume cart = make_procedural_volume(g, glm::dvec3(-1.2), glm::dvec3(2.4 / 48.0));
    SphericalShell sh;
    sh.r0 = 0.0;
    sh.r1 = 1.15;
    const Volume beam = resample_to_spherical(cart, Interpolation::Trilinear, sh, {48, 24, 24});
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("volref-resample-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    write_nrrd(beam, dir / "beam.nrrd");

    Scene c = field_scene(g, glm::dvec3(-1.2), glm::dvec3(2.4 / 48.0));
    c.volume().transfer.opacity = {{0.0, 0.0}, {0.2, 0.0}, {1.0, 0.8}};
    c.volume().transfer.opacity_unit_distance = 0.5;
    c.camera = ortho_down_z(0.0, 0.0, 5.0, 2.4);
    c.image.width = c.image.height = 20;
    c.render.step = 0.01;
    c.render.step_units = StepUnits::World;
    Scene s = c;
    s.volume().source.field.reset();
    s.volume().source.file = dir / "beam.nrrd";
    s.volume().origin.reset();
    s.volume().spacing.reset();
    s.volume().bounds.type = BoundsSpec::Type::Spherical;
    s.volume().bounds.sphere = sh;
    const Image a = render_scene(c, {.threads = 2}), b = render_scene(s, {.threads = 2});
    double max_diff = 0.0, max_alpha = 0.0;
    for (std::size_t i = 3; i < a.pixels.size(); i += 4) {
        max_diff = std::max(max_diff, std::fabs(a.pixels[i] - b.pixels[i]));
        max_alpha = std::max(max_alpha, a.pixels[i]);
    }
    std::printf("resampled render: max |alpha difference| %.3g (max alpha %.3g)\n", max_diff, max_alpha);
    EXPECT_GT(max_alpha, 0.3);
    EXPECT_LT(max_diff, 5e-3);
    std::filesystem::remove_all(dir);
}
