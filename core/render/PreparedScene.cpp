#include "core/render/PreparedScene.h"

#include "core/integrate/profiles/ImageSpaceRenderer.h"

#include <algorithm>
#include <limits>

#include "core/Error.h"

namespace volref {

PreparedScene::PreparedScene(const Scene& scene_, const RenderOptions& options, std::span<const WholeDomain> whole)
    : scene(scene_) {
    if (scene.volumes.empty()) throw Error("volumes: expected at least one volume");
    const bool several = scene.volumes.size() > 1;
    if (several && !scene.render.reference_integrators())
        throw Error("render.profile: only \"reference\" (with no rules set over it) renders several volumes (the mirror and custom profiles and \"fast\" render one)");
    std::size_t held = 0;
    view_lo = glm::dvec3(std::numeric_limits<double>::infinity());
    view_hi = -view_lo;
    for (std::size_t k = 0; k < scene.volumes.size(); ++k) {
        volumes.push_back(std::make_unique<PreparedVolume>(scene, k, options, held, whole.empty() ? nullptr : &whole[k]));
        held += volumes.back()->bytes;
        view_lo = glm::min(view_lo, volumes.back()->view_lo);
        view_hi = glm::max(view_hi, volumes.back()->view_hi);
    }
    if (several) {
        std::vector<MultiVolumeIntegrator::Member> members;
        double step = std::numeric_limits<double>::infinity();
        for (const auto& v : volumes) {
            members.push_back({v->pipeline.get(), v->integrator.get(), v->context.get()});
            step = std::min(step, v->step);
        }
        multi = std::make_unique<MultiVolumeIntegrator>(std::move(members), scene.render, step);
    }
    const ImageSpaceRenderer* own = volumes.front()->image_space.get();
    const std::optional<CameraSpec> own_camera = own ? own->view_camera() : std::nullopt;
    camera = std::make_unique<Camera>(own_camera ? *own_camera : scene.camera, scene.image.width, scene.image.height, view_lo, view_hi);
}

PreparedScene::~PreparedScene() = default;

void PreparedScene::pixels(const int* x, const int* y, int count, PixelValue* out, bool simd, Scratch& scratch) const {
    if (const ImageSpaceRenderer* r = image_space()) {
        for (int i = 0; i < count; ++i) out[i] = r->pixel(x[i], y[i], nullptr);
        return;
    }
    Ray rays[kMaxPacketRays];
    camera->pixel_rays(x, y, count, rays);
    integrate(rays, count, out, simd, scratch);
}

void PreparedScene::integrate(const Ray* rays, int count, PixelValue* out, bool simd, Scratch& scratch) const {
    if (const ImageSpaceRenderer* r = image_space()) {  // the window pixel each ray passes through
        for (int i = 0; i < count; ++i) {
            const auto [x, y] = r->pixel_of(rays[i]);
            out[i] = r->pixel(x, y, nullptr);
        }
        return;
    }
    const std::size_t n = volumes.size();
    scratch.rays.resize(n);
    scratch.intervals.resize(n);
    scratch.values.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
        const PreparedVolume& v = *volumes[k];
        v.intervals(rays, count, scratch.rays[k].data(), scratch.intervals[k].data());
        if (multi && is_composite(scene.render.projection)) continue;  // mixed below
        PixelValue* values = n == 1 ? out : scratch.values[k].data();
        if (simd && v.packets)
            v.integrator->integrate_packet(scratch.rays[k].data(), scratch.intervals[k].data(), values, count);
        else
            for (int i = 0; i < count; ++i) values[i] = v.integrator->integrate(scratch.rays[k][std::size_t(i)], scratch.intervals[k][std::size_t(i)]);
    }
    if (!multi) return;
    std::vector<Ray>& ray_list = scratch.pixel_rays;
    std::vector<std::vector<Interval>>& interval_list = scratch.pixel_intervals;
    std::vector<PixelValue>& value_list = scratch.pixel_values;
    ray_list.resize(n);
    interval_list.resize(n);
    value_list.resize(n);
    for (int i = 0; i < count; ++i) {
        for (std::size_t k = 0; k < n; ++k) {
            ray_list[k] = scratch.rays[k][std::size_t(i)];
            interval_list[k].swap(scratch.intervals[k][std::size_t(i)]);
            value_list[k] = scratch.values[k][std::size_t(i)];
        }
        out[i] = is_composite(scene.render.projection) ? multi->composite(ray_list.data(), interval_list.data())
                                                                  : multi->combine(value_list.data(), interval_list.data());
        for (std::size_t k = 0; k < n; ++k) interval_list[k].swap(scratch.intervals[k][std::size_t(i)]);
    }
}

std::vector<Interval> PreparedScene::intervals(const Ray& ray) const {
    Ray local;
    std::vector<Interval> out;
    volume().intervals(&ray, 1, &local, &out);
    return out;
}

PixelValue PreparedScene::render_pixel(int x, int y) const {
    Scratch scratch;
    PixelValue out;
    pixels(&x, &y, 1, &out, false, scratch);
    return out;
}

const PreparedVolume& PreparedScene::traced_volume() const {
    if (volumes.size() > 1) throw Error("trace: a scene of several volumes is not traced yet (trace one volume at a time)");
    return volume();
}

PixelValue PreparedScene::trace_pixel(int x, int y, SampleRecorder& recorder) const {
    const PreparedVolume& v = traced_volume();
    if (v.image_space) {
        Recording rec{recorder};
        return v.image_space->pixel(x, y, &rec);
    }
    const Ray ray = pixel_ray(x, y);
    return v.integrator->integrate_traced(v.volume_ray(ray), intervals(ray), recorder);
}

}  // namespace volref
