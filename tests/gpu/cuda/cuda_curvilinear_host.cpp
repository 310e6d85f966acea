// The host of seed 001's CUDA program (cuda_curvilinear.cu has the seed's kernel; issue 17, part 2):
// reads a volref scene with volref's loader and builds what the seed's host loads onto the GPU (see
// cuda_curvilinear.cu's header for each choice), calls seed001_render and writes the image as an EXR.
// Usage: cuda_curvilinear SCENE.json OUT.exr [--set key=value]... [--tricubic]
// Exit 0 written, 2 the scene is not one the seed renders (one line on stderr), 3 a CUDA error (no GPU).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <string>
#include <vector>

#include "core/film/ImageWriter.h"
#include "geometry/ShellCoordinates.h"
#include "geometry/ShellTessellation.h"
#include "seed001.h"
#include "volref_core.h"

namespace {

[[noreturn]] void fail(int code, const std::string& message) {
    std::fprintf(stderr, "cuda_curvilinear: error: %s\n", message.c_str());
    std::exit(code);
}

int run(int argc, char** argv) {
    using namespace volref;
    std::vector<std::string> overrides, positional;
    bool tricubic = false;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--set" && i + 1 < argc) overrides.emplace_back(argv[++i]);
        else if (a == "--tricubic") tricubic = true;
        else positional.push_back(a);
    }
    if (positional.size() != 2) fail(2, "usage: cuda_curvilinear SCENE.json OUT.exr [--set key=value]... [--tricubic]");
    const Scene scene = load_scene(positional[0], overrides);
    if (scene.volumes.size() != 1) fail(2, "one volume only");
    const VolumeSpec& vs = scene.volume();
    const RenderSpec& r = scene.render;
    if (r.projection != Projection::Composite && r.projection != Projection::Xray) fail(2, "render.projection: composite or xray");
    if (r.step_units != StepUnits::World) fail(2, "render.step_units: world");
    if (vs.transform || !vs.clip_planes.empty() || vs.crop) fail(2, "no transform, clip planes or crop");
    const CameraSpec& cam = scene.camera;
    if (cam.type != CameraSpec::Type::Perspective && cam.type != CameraSpec::Type::Orthographic)
        fail(2, "camera: perspective or orthographic");

    Seed001Frame f;
    glm::dvec3 center(0.0);
    TriangleMesh mesh;
    std::array<glm::dvec3, 2> box;
    const int segments = vs.bounds.tessellate > 0 ? vs.bounds.tessellate : 64;
    const double rad = std::numbers::pi / 180.0;
    if (vs.bounds.type == BoundsSpec::Type::Cylindrical) {
        const CylindricalShell& c = vs.bounds.cylinder;
        if (c.r0 != 0.0 || c.a0 != 0.0 || c.h0 != 0.0) fail(2, "volume.bounds: the seed's cylinder starts at radius, angle and height 0");
        f.geomType = 0;
        f.geomSize[0] = float(c.r1), f.geomSize[1] = float(c.a1 * rad), f.geomSize[2] = float(c.h1);
        center = c.center;
        mesh = tessellate(c, segments);
        box = bounding_box(c);
    } else if (vs.bounds.type == BoundsSpec::Type::Spherical) {
        const SphericalShell& s = vs.bounds.sphere;
        if (s.r0 != 0.0 || s.lon0 != 0.0 || s.lat0 != -s.lat1 || s.axes != std::array<int, 3>{0, 1, 2})
            fail(2, "volume.bounds: the seed's sphere has radius and longitude from 0, latitude [-F, F], the default axes");
        f.geomType = 1;
        f.geomSize[0] = float(s.r1), f.geomSize[1] = float(s.lon1 * rad), f.geomSize[2] = float(s.lat1 * rad);
        center = s.center;
        mesh = tessellate(s, segments);
        box = bounding_box(s);
    } else {
        fail(2, "volume.bounds: a cylindrical or spherical shell");
    }

    // The data: unsigned short over the data range (the seed's readVtk normalises to [0, 65535]).
    const Volume vol = load_volume(vs);
    const auto [vmin, vmax] = vol.value_range();
    const std::size_t n = std::size_t(vol.dims[0] * vol.dims[1] * vol.dims[2]);
    f.data.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        const double s = vmax > vmin ? (double(vol.values[i]) - vmin) / (vmax - vmin) : 0.0;
        f.data[i] = static_cast<unsigned short>(std::lrint(std::clamp(s, 0.0, 1.0) * 65535.0));
    }
    for (int a = 0; a < 3; ++a) f.dims[a] = int(vol.dims[std::size_t(a)]);
    // The 9-entry table: cuda-curvilinear's entries, colour and opacity at min + j (max - min) / 8.
    const TransferFunction tf(vs.transfer, vol);
    for (int j = 0; j < 9; ++j) {
        const Classified k = tf.classify(vmin + double(j) * (vmax - vmin) / 8.0, 0.0);
        f.table.insert(f.table.end(), {float(k.color.r), float(k.color.g), float(k.color.b), float(k.opacity)});
    }
    // The bounding triangles (volref's tessellation, outward), in the seed's frame (world - centre).
    for (const auto& t : mesh.triangles)
        for (std::uint32_t k : t) {
            const glm::dvec3 v = mesh.vertices[k] - center;
            f.triangles.insert(f.triangles.end(), {float(v.x), float(v.y), float(v.z), 0.0f});
        }
    // The rays: volref's camera, in double, then float.
    f.width = scene.image.width;
    f.height = scene.image.height;
    const Camera camera(cam, f.width, f.height, box[0], box[1]);
    for (int y = 0; y < f.height; ++y)
        for (int x = 0; x < f.width; ++x) {
            const Ray ray = camera.pixel_ray(x, y);
            const glm::dvec3 o = ray.origin - center, d = glm::normalize(ray.direction);
            f.origins.insert(f.origins.end(), {float(o.x), float(o.y), float(o.z)});
            f.directions.insert(f.directions.end(), {float(d.x), float(d.y), float(d.z)});
        }
    f.step = float(r.step);
    f.triCubic = tricubic ? 1 : 0;
    f.density = float(r.profile_options.density);
    f.regBrightness = 1.0f;
    f.xrayBrightness = float(r.profile_options.brightness);
    f.isoValue = float(r.profile_options.iso_threshold);
    f.transferScale = float(r.profile_options.transfer_scale);
    f.compoType = r.projection == Projection::Xray ? 1 : 0;

    std::vector<float> px;
    if (const std::string e = seed001_render(f, px); !e.empty()) fail(3, e);
    Image img(f.width, f.height, {"R", "G", "B", "A"});
    for (int y = 0; y < f.height; ++y)
        for (int x = 0; x < f.width; ++x)
            for (int c = 0; c < 4; ++c)
                img.at(x, y, std::size_t(c)) = px[(std::size_t(y) * std::size_t(f.width) + std::size_t(x)) * 4 + std::size_t(c)];
    write_image(img, positional[1], scene.image.background);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        return run(argc, argv);
    } catch (const std::exception& e) {
        fail(2, e.what());
    }
}
