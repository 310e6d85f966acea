#include "geometry/BoundingGeometry.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <embree3/rtcore.h>

#include "core/Conventions.h"
#include "core/Error.h"
#include "geometry/BoxIntersection.h"
#include "geometry/BoxIntervals.h"
#include "geometry/MeshIntervals.h"
#include "geometry/ShellIntersection.h"

namespace volref {

namespace {

struct BoxShape {
    BoxShapeBounds bounds;  // the box, its volume's domain, and whether they are the same (BoxIntervals.h)
    int volume_id;
};

struct MeshShape {
    TriangleMesh mesh;
    glm::dvec3 domain_lo, domain_hi;
    double scale;  // largest extent
    double pad;    // of each triangle's Embree bounds
    int volume_id;
};

template <class Intersector>
struct ShellShape {
    Intersector intersector;
    int volume_id;
};
using CylinderShape = ShellShape<CylindricalShellIntersector>;
using SphereShape = ShellShape<SphericalShellIntersector>;

// What the callbacks record for one ray, per volume.
struct RayRecord {
    std::vector<std::vector<Interval>> intervals;
    std::vector<std::vector<MeshCrossing>> crossings;
    void reset(std::size_t volumes) {
        intervals.resize(volumes);
        crossings.resize(volumes);
        for (auto& v : intervals) v.clear();
        for (auto& v : crossings) v.clear();
    }
};

// The query's context: Embree passes it to the callbacks. Ray `id` (the float ray's id field) is
// rays[id], prepared for triangles as frames[id], recording into records[id].
struct IntervalQuery {
    RTCIntersectContext context;  // must be first
    const Ray* rays;
    const RayTriangleFrame* frames;
    RayRecord* records;
    unsigned num_rays;
    int volume_id;  // the volume asked for; others are not recorded (-1: all)
};

inline IntervalQuery* query_of(RTCIntersectContext* context) { return reinterpret_cast<IntervalQuery*>(context); }

inline bool wanted(const IntervalQuery* q, int volume_id) { return q->volume_id < 0 || q->volume_id == volume_id; }

inline unsigned ray_id(const RTCIntersectFunctionNArguments* args, unsigned i) {
    return RTCRayN_id(RTCRayHitN_RayN(args->rayhit, args->N), args->N, i);
}

void set_bounds(RTCBounds* b, const glm::dvec3& lo, const glm::dvec3& hi, double pad) {
    b->lower_x = std::nextafter(float(lo.x - pad), -INFINITY);
    b->lower_y = std::nextafter(float(lo.y - pad), -INFINITY);
    b->lower_z = std::nextafter(float(lo.z - pad), -INFINITY);
    b->upper_x = std::nextafter(float(hi.x + pad), INFINITY);
    b->upper_y = std::nextafter(float(hi.y + pad), INFINITY);
    b->upper_z = std::nextafter(float(hi.z + pad), INFINITY);
}

double padding(const glm::dvec3& lo, const glm::dvec3& hi) {
    const glm::dvec3 extent = hi - lo;
    return conventions::kEmbreeBoundsPadding * (1.0 + std::max({extent.x, extent.y, extent.z}));
}

// ---- boxes ----

void box_bounds(const RTCBoundsFunctionArguments* args) {
    const auto* box = static_cast<const BoxShape*>(args->geometryUserPtr);
    const glm::dvec3 lo(box->bounds.lo[0], box->bounds.lo[1], box->bounds.lo[2]);
    const glm::dvec3 hi(box->bounds.hi[0], box->bounds.hi[1], box->bounds.hi[2]);
    set_bounds(args->bounds_o, lo, hi, padding(lo, hi));
}

// The ray's interval in the box AND its domain, in front of the origin (t >= 0), if not empty.
// A box that is its domain (the usual case) takes one slab test: the second would repeat the first.
// (box_shape_lanes, BoxIntersection-inl.h; box_shape_intervals for many rays at once.)
bool box_interval(const BoxShape& box, const Ray& ray, Interval& out) {
    const BoxShapeBounds& b = box.bounds;
    const double o[3] = {ray.origin.x, ray.origin.y, ray.origin.z}, d[3] = {ray.direction.x, ray.direction.y, ray.direction.z};
    return box_shape_lanes<Scalar>(o, d, b.lo, b.hi, b.is_domain ? nullptr : b.domain_lo, b.is_domain ? nullptr : b.domain_hi,
                                   out.t0, out.t1);
}

void box_intersect(const RTCIntersectFunctionNArguments* args) {
    const auto* box = static_cast<const BoxShape*>(args->geometryUserPtr);
    const IntervalQuery* query = query_of(args->context);
    if (!wanted(query, box->volume_id)) return;
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        const unsigned id = ray_id(args, i);
        if (id >= query->num_rays) continue;
        Interval clipped;
        if (box_interval(*box, query->rays[id], clipped))
            query->records[id].intervals[std::size_t(box->volume_id)].push_back(clipped);
    }
    // No hit is reported: traversal continues to every shape along the ray.
}

// ---- meshes: one user primitive per triangle ----

void mesh_bounds(const RTCBoundsFunctionArguments* args) {
    const auto* shape = static_cast<const MeshShape*>(args->geometryUserPtr);
    const auto& tri = shape->mesh.triangles[args->primID];
    const glm::dvec3& a = shape->mesh.vertices[tri[0]];
    const glm::dvec3& b = shape->mesh.vertices[tri[1]];
    const glm::dvec3& c = shape->mesh.vertices[tri[2]];
    const glm::dvec3 lo(std::min({a.x, b.x, c.x}), std::min({a.y, b.y, c.y}), std::min({a.z, b.z, c.z}));
    const glm::dvec3 hi(std::max({a.x, b.x, c.x}), std::max({a.y, b.y, c.y}), std::max({a.z, b.z, c.z}));
    set_bounds(args->bounds_o, lo, hi, shape->pad);
}

void mesh_intersect(const RTCIntersectFunctionNArguments* args) {
    const auto* shape = static_cast<const MeshShape*>(args->geometryUserPtr);
    const IntervalQuery* query = query_of(args->context);
    if (!wanted(query, shape->volume_id)) return;
    const auto& tri = shape->mesh.triangles[args->primID];
    const glm::dvec3& a = shape->mesh.vertices[tri[0]];
    const glm::dvec3& b = shape->mesh.vertices[tri[1]];
    const glm::dvec3& c = shape->mesh.vertices[tri[2]];
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        const unsigned id = ray_id(args, i);
        if (id >= query->num_rays) continue;
        double t;
        int winding;
        if (query->frames[id].cross(a, b, c, t, winding) && t >= 0.0)
            query->records[id].crossings[std::size_t(shape->volume_id)].push_back({t, winding, args->primID});
    }
}

// ---- shells ----

template <class Shape>
void shell_bounds_callback(const RTCBoundsFunctionArguments* args) {
    const auto* shape = static_cast<const Shape*>(args->geometryUserPtr);
    glm::dvec3 lo, hi;
    shell_bounds(shape->intersector.shell(), lo, hi);
    set_bounds(args->bounds_o, lo, hi, padding(lo, hi));
}

template <class Shape>
void shell_intersect(const RTCIntersectFunctionNArguments* args) {
    const auto* shape = static_cast<const Shape*>(args->geometryUserPtr);
    const IntervalQuery* query = query_of(args->context);
    if (!wanted(query, shape->volume_id)) return;
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        const unsigned id = ray_id(args, i);
        if (id >= query->num_rays) continue;
        shape->intersector.intervals(query->rays[id], query->records[id].intervals[std::size_t(shape->volume_id)]);
    }
}

void no_occlusion(const RTCOccludedFunctionNArguments*) {}

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
    std::vector<std::unique_ptr<MeshShape>> meshes;
    std::vector<std::unique_ptr<CylinderShape>> cylinders;
    std::vector<std::unique_ptr<SphereShape>> spheres;
    std::vector<const MeshShape*> volume_mesh;  // per volume: its mesh, if it is one
    std::vector<const BoxShape*> volume_box;    // per volume: its box, if it is one

    int next_id() const { return int(volume_mesh.size()); }

    void attach(unsigned primitives, void* user, RTCBoundsFunction bounds, RTCIntersectFunctionN intersect,
                const char* what) {
        RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
        rtcSetGeometryUserPrimitiveCount(geom, primitives);
        rtcSetGeometryUserData(geom, user);
        rtcSetGeometryBoundsFunction(geom, bounds, nullptr);
        rtcSetGeometryIntersectFunction(geom, intersect);
        rtcSetGeometryOccludedFunction(geom, no_occlusion);
        rtcCommitGeometry(geom);
        rtcAttachGeometry(scene, geom);
        rtcReleaseGeometry(geom);
        check_embree(what);
    }
};

BoundingGeometry::BoundingGeometry() : impl_(std::make_unique<Impl>()) {
    impl_->device = rtcNewDevice(nullptr);
    if (!impl_->device) throw Error("Embree: cannot create a device");
    rtcSetDeviceErrorFunction(impl_->device, embree_error, nullptr);
    impl_->scene = rtcNewScene(impl_->device);
    rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
    rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);
    check_embree("creating the scene");
}

BoundingGeometry::~BoundingGeometry() {
    if (impl_->scene) rtcReleaseScene(impl_->scene);
    if (impl_->device) rtcReleaseDevice(impl_->device);
}

int BoundingGeometry::add_box(const glm::dvec3& lo, const glm::dvec3& hi, const glm::dvec3& domain_lo,
                              const glm::dvec3& domain_hi) {
    const int id = impl_->next_id();
    BoxShapeBounds b;
    for (int a = 0; a < 3; ++a) {
        b.lo[a] = lo[a];
        b.hi[a] = hi[a];
        b.domain_lo[a] = domain_lo[a];
        b.domain_hi[a] = domain_hi[a];
    }
    b.is_domain = lo == domain_lo && hi == domain_hi;
    impl_->boxes.push_back(std::make_unique<BoxShape>(BoxShape{b, id}));
    impl_->attach(1, impl_->boxes.back().get(), box_bounds, box_intersect, "adding a box");
    impl_->volume_mesh.push_back(nullptr);
    impl_->volume_box.push_back(impl_->boxes.back().get());
    return id;
}

int BoundingGeometry::add_mesh(const TriangleMesh& mesh, const glm::dvec3& domain_lo, const glm::dvec3& domain_hi,
                                Closedness rule) {
    const int id = impl_->next_id();
    auto shape = std::make_unique<MeshShape>();
    shape->mesh = mesh;
    check_closed(shape->mesh, "bounding mesh", rule);
    shape->domain_lo = domain_lo;
    shape->domain_hi = domain_hi;
    shape->scale = mesh_scale(shape->mesh);
    shape->pad = conventions::kEmbreeBoundsPadding * (1.0 + shape->scale);
    shape->volume_id = id;
    if (shape->mesh.triangles.size() > std::numeric_limits<unsigned>::max())
        throw Error("bounding mesh: too many triangles for Embree");
    impl_->meshes.push_back(std::move(shape));
    const MeshShape* added = impl_->meshes.back().get();
    impl_->attach(unsigned(added->mesh.triangles.size()), impl_->meshes.back().get(), mesh_bounds, mesh_intersect,
                  "adding a mesh");
    impl_->volume_mesh.push_back(added);
    impl_->volume_box.push_back(nullptr);
    return id;
}

int BoundingGeometry::add_cylindrical_shell(const CylindricalShell& shell) {
    const int id = impl_->next_id();
    impl_->cylinders.push_back(std::make_unique<CylinderShape>(CylinderShape{CylindricalShellIntersector(shell), id}));
    impl_->attach(1, impl_->cylinders.back().get(), shell_bounds_callback<CylinderShape>, shell_intersect<CylinderShape>,
                  "adding a cylindrical shell");
    impl_->volume_mesh.push_back(nullptr);
    impl_->volume_box.push_back(nullptr);
    return id;
}

int BoundingGeometry::add_spherical_shell(const SphericalShell& shell) {
    const int id = impl_->next_id();
    impl_->spheres.push_back(std::make_unique<SphereShape>(SphereShape{SphericalShellIntersector(shell), id}));
    impl_->attach(1, impl_->spheres.back().get(), shell_bounds_callback<SphereShape>, shell_intersect<SphereShape>,
                  "adding a spherical shell");
    impl_->volume_mesh.push_back(nullptr);
    impl_->volume_box.push_back(nullptr);
    return id;
}

void BoundingGeometry::commit() {
    rtcCommitScene(impl_->scene);
    check_embree("building the scene");
}

int BoundingGeometry::volume_count() const { return impl_->next_id(); }

namespace {

// The intervals of volume v from one ray's record (the box and shell intervals, and a mesh's crossings).
void finish_intervals(const Ray& ray, RayRecord& record, std::size_t v, const MeshShape* mesh, std::vector<Interval>& out) {
    out = record.intervals[v];
    if (mesh) {
        Interval domain;
        if (intersect_box(ray, mesh->domain_lo, mesh->domain_hi, domain)) {
            thread_local std::vector<Interval> inside;
            inside.clear();
            crossings_to_intervals(record.crossings[v], mesh->mesh, mesh->scale, inside);
            for (const Interval& i : inside) {
                const Interval clipped{std::max({i.t0, domain.t0, 0.0}), std::min(i.t1, domain.t1)};
                if (clipped.t1 > clipped.t0) out.push_back(clipped);
            }
        }
    }
    normalize_intervals(out);
}

}  // namespace

void BoundingGeometry::intervals(const Ray& ray, int volume_id, std::vector<Interval>& out) const {
    out.clear();
    if (volume_id < 0 || volume_id >= volume_count()) return;
    if (impl_->volume_box[std::size_t(volume_id)]) return intervals(&ray, 1, volume_id, &out);  // no Embree query
    thread_local RayRecord record;
    record.reset(impl_->volume_mesh.size());
    const RayTriangleFrame frame(ray);

    IntervalQuery query;
    rtcInitIntersectContext(&query.context);
    query.rays = &ray;
    query.frames = &frame;
    query.records = &record;
    query.num_rays = 1;
    query.volume_id = volume_id;

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
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.ray.time = 0.0f;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(impl_->scene, &query.context, &rh);

    const std::size_t v = std::size_t(volume_id);
    finish_intervals(ray, record, v, impl_->volume_mesh[v], out);
}

void BoundingGeometry::intervals(const Ray* rays, int count, int volume_id, std::vector<Interval>* out) const {
    constexpr int kPacket = 16;
    for (int i = 0; i < count; ++i) out[i].clear();
    if (volume_id < 0 || volume_id >= volume_count()) return;
    const std::size_t v = std::size_t(volume_id);
    // A box needs no Embree query: its one interval is the slab test box_intersect would run (Embree's
    // float bounds are padded, so it calls box_intersect for every ray the double test can hit).
    if (const BoxShape* box = impl_->volume_box[v]) {
        box_shape_intervals(box->bounds, rays, count, out);
        return;
    }
    thread_local RayRecord records[kPacket];
    for (int first = 0; first < count; first += kPacket) {
        const int n = std::min(kPacket, count - first);
        const Ray* chunk = rays + first;
        thread_local std::vector<RayTriangleFrame> frames;
        frames.clear();
        for (int i = 0; i < n; ++i) {
            frames.emplace_back(chunk[i]);
            records[i].reset(impl_->volume_mesh.size());
        }
        IntervalQuery query;
        rtcInitIntersectContext(&query.context);
        query.rays = chunk;
        query.frames = frames.data();
        query.records = records;
        query.num_rays = unsigned(n);
        query.volume_id = volume_id;

        alignas(64) int valid[kPacket];  // Embree requires both 64-byte aligned
        alignas(64) RTCRayHit16 rh;
        for (int i = 0; i < kPacket; ++i) {
            const Ray& ray = chunk[std::min(i, n - 1)];
            valid[i] = i < n ? -1 : 0;
            rh.ray.org_x[i] = float(ray.origin.x);
            rh.ray.org_y[i] = float(ray.origin.y);
            rh.ray.org_z[i] = float(ray.origin.z);
            rh.ray.dir_x[i] = float(ray.direction.x);
            rh.ray.dir_y[i] = float(ray.direction.y);
            rh.ray.dir_z[i] = float(ray.direction.z);
            rh.ray.tnear[i] = 0.0f;
            rh.ray.tfar[i] = std::numeric_limits<float>::infinity();
            rh.ray.time[i] = 0.0f;
            rh.ray.mask[i] = 0xFFFFFFFFu;
            rh.ray.id[i] = unsigned(i);
            rh.ray.flags[i] = 0;
            rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
            rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
        }
        rtcIntersect16(valid, impl_->scene, &query.context, &rh);
        for (int i = 0; i < n; ++i) finish_intervals(chunk[i], records[i], v, impl_->volume_mesh[v], out[first + i]);
    }
}

}  // namespace volref
