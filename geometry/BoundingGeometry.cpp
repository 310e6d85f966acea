#include "geometry/BoundingGeometry.h"

#include <cmath>
#include <limits>
#include <string>

#include <embree3/rtcore.h>

#include "core/Conventions.h"
#include "core/Error.h"
#include "geometry/BoxIntersection.h"

namespace volref {

namespace {

struct BoxShape {
    glm::dvec3 lo, hi;
    glm::dvec3 domain_lo, domain_hi;
    int volume_id;
};

// The query's context: Embree passes it to the callbacks, which append intervals per volume.
struct IntervalQuery {
    RTCIntersectContext context;  // must be first
    const Ray* ray;               // the double-precision ray (rtcIntersect1 only: N = 1)
    std::vector<std::vector<Interval>>* per_volume;
};

void box_bounds(const RTCBoundsFunctionArguments* args) {
    const auto* box = static_cast<const BoxShape*>(args->geometryUserPtr);
    const glm::dvec3 extent = box->hi - box->lo;
    const double pad = conventions::kEmbreeBoundsPadding * (1.0 + std::max({extent.x, extent.y, extent.z}));
    RTCBounds* b = args->bounds_o;
    b->lower_x = std::nextafter(float(box->lo.x - pad), -INFINITY);
    b->lower_y = std::nextafter(float(box->lo.y - pad), -INFINITY);
    b->lower_z = std::nextafter(float(box->lo.z - pad), -INFINITY);
    b->upper_x = std::nextafter(float(box->hi.x + pad), INFINITY);
    b->upper_y = std::nextafter(float(box->hi.y + pad), INFINITY);
    b->upper_z = std::nextafter(float(box->hi.z + pad), INFINITY);
}

void box_intersect(const RTCIntersectFunctionNArguments* args) {
    const auto* box = static_cast<const BoxShape*>(args->geometryUserPtr);
    auto* query = reinterpret_cast<IntervalQuery*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        Interval shape, domain;
        if (!intersect_box(*query->ray, box->lo, box->hi, shape)) continue;
        if (!intersect_box(*query->ray, box->domain_lo, box->domain_hi, domain)) continue;
        const Interval clipped{std::max({shape.t0, domain.t0, 0.0}), std::min(shape.t1, domain.t1)};
        if (clipped.t1 > clipped.t0) (*query->per_volume)[std::size_t(box->volume_id)].push_back(clipped);
    }
    // No hit is reported: traversal continues to every shape along the ray.
}

void box_occluded(const RTCOccludedFunctionNArguments*) {}

// Embree reports errors through this callback (C code: it must not throw); they are checked after
// each call that can fail.
thread_local std::string embree_last_error;
void embree_error(void*, RTCError code, const char* message) {
    if (code != RTC_ERROR_NONE) embree_last_error = message ? message : "unknown error";
}
void check_embree(const char* what) {
    if (!embree_last_error.empty()) {
        const std::string message = "Embree: " + std::string(what) + ": " + embree_last_error;
        embree_last_error.clear();
        throw Error(message);
    }
}

}  // namespace

struct BoundingGeometry::Impl {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    std::vector<std::unique_ptr<BoxShape>> boxes;
};

BoundingGeometry::BoundingGeometry() : impl_(std::make_unique<Impl>()) {
    impl_->device = rtcNewDevice(nullptr);
    if (!impl_->device) throw Error("Embree: cannot create a device");
    rtcSetDeviceErrorFunction(impl_->device, embree_error, nullptr);
    impl_->scene = rtcNewScene(impl_->device);
    rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
    check_embree("creating the scene");
}

BoundingGeometry::~BoundingGeometry() {
    if (impl_->scene) rtcReleaseScene(impl_->scene);
    if (impl_->device) rtcReleaseDevice(impl_->device);
}

int BoundingGeometry::add_box(const glm::dvec3& lo, const glm::dvec3& hi, const glm::dvec3& domain_lo,
                              const glm::dvec3& domain_hi) {
    const int id = int(impl_->boxes.size());
    impl_->boxes.push_back(std::make_unique<BoxShape>(BoxShape{lo, hi, domain_lo, domain_hi, id}));
    RTCGeometry geom = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(geom, 1);
    rtcSetGeometryUserData(geom, impl_->boxes.back().get());
    rtcSetGeometryBoundsFunction(geom, box_bounds, nullptr);
    rtcSetGeometryIntersectFunction(geom, box_intersect);
    rtcSetGeometryOccludedFunction(geom, box_occluded);
    rtcCommitGeometry(geom);
    rtcAttachGeometry(impl_->scene, geom);
    rtcReleaseGeometry(geom);
    check_embree("adding a box");
    return id;
}

void BoundingGeometry::commit() {
    rtcCommitScene(impl_->scene);
    check_embree("building the scene");
}

void BoundingGeometry::intervals(const Ray& ray, int volume_id, std::vector<Interval>& out) const {
    thread_local std::vector<std::vector<Interval>> per_volume;
    per_volume.resize(impl_->boxes.size());
    for (auto& v : per_volume) v.clear();

    IntervalQuery query;
    rtcInitIntersectContext(&query.context);
    query.ray = &ray;
    query.per_volume = &per_volume;

    RTCRayHit rh{};
    rh.ray.org_x = float(ray.origin.x);
    rh.ray.org_y = float(ray.origin.y);
    rh.ray.org_z = float(ray.origin.z);
    rh.ray.dir_x = float(ray.direction.x);
    rh.ray.dir_y = float(ray.direction.y);
    rh.ray.dir_z = float(ray.direction.z);
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = std::numeric_limits<float>::infinity();
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.flags = 0;
    rh.ray.time = 0.0f;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(impl_->scene, &query.context, &rh);

    out = per_volume[std::size_t(volume_id)];
    normalize_intervals(out);
}

}  // namespace volref
