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
#include "core/integrate/profiles/CudaCurvilinearKernel.h"
#include "core/render/PreparedVolume.h"
#include "transfer/Classifier.h"
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

    // The frame is volref's own (core/integrate/profiles/CudaCurvilinearKernel.h, seed001_frame), so that this
    // program and the cuda-curvilinear profile read the same bounding triangles (volref's tessellation,
    // bounds.tessellate segments per turn, 64 when absent, minus the centre, in float), the same unsigned
    // shorts and the same 9-entry table. Its data are the volume as volref renders it (build_volume_model):
    // a procedural field on a shell is evaluated at the shell's samples. Until issue 28 this host used
    // load_volume, which evaluates a field at origin + index x spacing: the fixtures recorded on the H100
    // (tests/gpu/h100/seed001) with a Gaussian or linear field hold that index-space field (their scenes
    // name it as data files).
    VolumeModel model;
    build_volume_model(vs, model);
    const std::unique_ptr<Classifier> classifier = make_classifier(vs, model.volume());
    const volref::Seed001Frame k = seed001_frame(model.volume(), vs.bounds, *classifier, r, r.step);
    ::Seed001Frame f;
    f.geomType = k.geom_type;
    for (int a = 0; a < 3; ++a) f.geomSize[a] = k.geom_size[std::size_t(a)], f.dims[a] = int(k.dims[std::size_t(a)]);
    f.data = k.data;
    for (const auto& e : k.table) f.table.insert(f.table.end(), e.begin(), e.end());
    for (const auto& v : k.vertices) f.triangles.insert(f.triangles.end(), {v[0], v[1], v[2], 0.0f});
    const glm::dvec3 center = k.center;
    const std::array<glm::dvec3, 2> box = vs.bounds.type == BoundsSpec::Type::Cylindrical ? bounding_box(vs.bounds.cylinder)
                                                                                          : bounding_box(vs.bounds.sphere);
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
    f.step = k.step;
    f.triCubic = (tricubic || k.tricubic) ? 1 : 0;  // --tricubic or render.profile_options.tricubic
    f.density = k.density;
    f.regBrightness = k.reg_brightness;
    f.xrayBrightness = k.xray_brightness;
    f.isoValue = k.iso;
    f.transferScale = k.transfer_scale;
    f.compoType = k.xray ? 1 : 0;

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
