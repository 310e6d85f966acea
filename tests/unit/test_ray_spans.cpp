// Resumable integration (core/integrate/march/RaySpan.h, issue 30): a ray cut into spans and
// integrated span after span (Integrator::integrate_span, the state handed on) gives integrate()'s
// pixel bit for bit; spans integrated from fresh states and merged in ray order give it to rounding;
// the SIMD packet form resumes as the scalar one; volref-mpi's owned_span is exactly the set of t a
// brick owns.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "TestScenes.h"
#include "cli/mpi/Bricks.h"
#include "core/integrate/march/SpanStates.h"
#include "core/render/PreparedScene.h"

using namespace volref;
using namespace volref::test;

namespace {

Scene ml_scene(Projection projection) {
    FieldSpec ml;
    ml.kind = FieldSpec::Kind::MarschnerLobb;
    ml.dims = {21, 19, 23};
    Scene s = field_scene(ml, glm::dvec3(-3.0, 1.0, 2.0), glm::dvec3(0.5, 0.7, 0.6));
    s.volume().transfer.color = {{0.0, 0.1, 0.2, 0.9}, {0.4, 0.3, 0.5, 0.2}, {0.55, 1.0, 0.8, 0.3}, {1.0, 1.0, 0.9, 0.6}};
    // (Some opacity at the lowest values, so that minip's pixels are not all 0.)
    s.volume().transfer.opacity = {{0.0, 0.05}, {0.3, 0.0}, {0.5, 0.35}, {0.52, 0.35}, {0.8, 0.9}, {1.0, 1.0}};
    s.volume().transfer.opacity_unit_distance = 2.0;
    s.image.width = 19;
    s.image.height = 17;
    s.render.projection = projection;
    s.render.step = 0.37;
    if (projection == Projection::FirstHit) s.render.isovalue = 0.5;
    return s;  // the default camera: perspective, framing the volume
}

struct RayCase {
    Ray ray;
    std::vector<Interval> intervals;
};

// Every pixel's local ray and intervals (the first volume's).
std::vector<RayCase> rays_of(const PreparedScene& ps) {
    std::vector<RayCase> out;
    const PreparedVolume& v = ps.volume();
    for (int y = 0; y < ps.scene.image.height; ++y)
        for (int x = 0; x < ps.scene.image.width; ++x) {
            RayCase c;
            const Ray world = ps.pixel_ray(x, y);
            c.ray = v.volume_ray(world);
            c.intervals = ps.intervals(world);
            if (!c.intervals.empty()) out.push_back(c);
        }
    return out;
}

// Three spans covering the ray, cut at random points inside its intervals.
std::vector<RaySpan> cut(const RayCase& c, std::mt19937& rng) {
    const double a = c.intervals.front().t0, b = c.intervals.back().t1;
    std::uniform_real_distribution<double> u(a, b);
    double s = u(rng), t = u(rng);
    if (s > t) std::swap(s, t);
    const double inf = std::numeric_limits<double>::infinity();
    return {{-inf, s}, {s, t}, {t, inf}};
}

bool same(const PixelValue& a, const PixelValue& b) {
    for (int c = 0; c < 4; ++c)
        if (std::memcmp(&a.rgba[c], &b.rgba[c], sizeof(double)) != 0) return false;
    return std::memcmp(&a.depth, &b.depth, sizeof(double)) == 0 || (std::isinf(a.depth) && std::isinf(b.depth));
}

double difference(const PixelValue& a, const PixelValue& b) {
    double d = 0.0;
    for (int c = 0; c < 4; ++c) d = std::max(d, std::fabs(a.rgba[c] - b.rgba[c]));
    return d;
}

struct Variant {
    const char* name;
    Projection projection;
    bool back_to_front = false, adaptive = false, early_termination = false;
    bool resumes_exactly = true;  // resuming span after span gives integrate() bit for bit
    bool fast = false;            // render.profile "fast" (float lanes; product_state, SpanStates.h)
    double merge_tolerance = 1e-13;
};

const Variant kVariants[] = {
    {"composite", Projection::Composite},
    {"composite-terminated", Projection::Composite, false, false, true},
    {"composite-back-to-front", Projection::Composite, true, false, false, false},
    {"mip", Projection::Mip},
    {"minip", Projection::Minip},
    {"average", Projection::Average},
    {"xray", Projection::Xray},
    {"first-hit", Projection::FirstHit},
    {"adaptive-mip", Projection::Mip, false, true},
    {"adaptive-average", Projection::Average, false, true, false, false},
    {"adaptive-first-hit", Projection::FirstHit, false, true},
    // The fast profile: its float transmittance product resumes bit for bit (its composite stops at
    // kFastTransmittanceCutoff, so its spans go in order: spans_in_order); its mip's parts merge
    // within float rounding.
    {"fast", Projection::Composite, false, false, false, true, true, 1e-6},
    {"fast-terminated", Projection::Composite, false, false, true, true, true, 1e-6},
    {"fast-mip", Projection::Mip, false, false, false, true, true, 1e-6},
};

Scene variant_scene(const Variant& v) {
    Scene s = ml_scene(v.projection);
    if (v.back_to_front) s.render.order = CompositeOrder::BackToFront;
    if (v.adaptive) s.render.integrator = IntegrationMethod::Adaptive;
    if (v.early_termination) s.render.early_termination = 0.5;
    if (v.fast) s.render.profile = ProfileId::Fast;
    return s;
}

}  // namespace

// Spans resumed in order (the state handed on): integrate()'s pixel bit for bit where the variant's
// accumulator resumes (front to back, extrema, sums, the hit), within 1e-14 where a span's part is
// put behind the state (back to front) or the adaptive sums are regrouped; and spans from fresh states
// merged in ray order (volref-mpi's independent parts) within 1e-13.
TEST(RaySpans, SpansResumedOrMergedGiveTheWholeRay) {
    std::mt19937 rng(7);
    for (const Variant& v : kVariants) {
        const Scene s = variant_scene(v);
        const PreparedScene ps(s, RenderOptions{.threads = 1});
        const Integrator& integrator = ps.integrator();
        ASSERT_TRUE(integrator.resumable()) << v.name;
        EXPECT_EQ(integrator.spans_in_order(), v.early_termination || (v.fast && v.projection == Projection::Composite)) << v.name;
        int compared = 0, nonzero = 0;
        for (const RayCase& c : rays_of(ps)) {
            const PixelValue whole = integrator.integrate(c.ray, c.intervals);
            const std::vector<RaySpan> spans = cut(c, rng);
            RayState resumed;
            for (const RaySpan& span : spans) integrator.integrate_span(c.ray, c.intervals, span, resumed);
            const PixelValue r = integrator.finish(c.ray, c.intervals, resumed);
            if (v.resumes_exactly) EXPECT_TRUE(same(r, whole)) << v.name << " difference " << difference(r, whole);
            else EXPECT_LT(difference(r, whole), 1e-14) << v.name;
            // Merging independent parts applies where no span's result depends on what is in front: not
            // with early termination (the reference's, or the fast profile's transmittance cutoff).
            if (!integrator.spans_in_order()) {
                RayState merged;
                for (const RaySpan& span : spans) {
                    RayState part;
                    integrator.integrate_span(c.ray, c.intervals, span, part);
                    integrator.merge_spans(merged, part);
                }
                EXPECT_LT(difference(integrator.finish(c.ray, c.intervals, merged), whole), v.merge_tolerance) << v.name;
            }
            ++compared;
            nonzero += whole.rgba.a > 0.0 ? 1 : 0;
        }
        EXPECT_GT(compared, 50) << v.name;
        EXPECT_GT(nonzero, 10) << v.name;  // the scene shows something
    }
}

// A span that owns nothing leaves the state as it was; the whole span is integrate() itself.
TEST(RaySpans, EmptyAndWholeSpans) {
    const Scene s = variant_scene(kVariants[0]);
    const PreparedScene ps(s, RenderOptions{.threads = 1});
    const double inf = std::numeric_limits<double>::infinity();
    for (const RayCase& c : rays_of(ps)) {
        RayState st;
        ps.integrator().integrate_span(c.ray, c.intervals, RaySpan{inf, inf}, st);
        ps.integrator().integrate_span(c.ray, c.intervals, RaySpan{-inf, c.intervals.front().t0 - 1.0}, st);
        for (double x : st.v) EXPECT_EQ(x, 0.0);
        ps.integrator().integrate_span(c.ray, c.intervals, RaySpan{}, st);
        EXPECT_TRUE(same(ps.integrator().finish(c.ray, c.intervals, st), ps.integrator().integrate(c.ray, c.intervals)));
    }
}

// The packet form (SIMD lanes, each with its own span and state) resumes as the scalar form, with
// empty-space skipping on; the scalar form is checked against integrate() above. With empty space (no
// opacity below 0.3: empty macrocells, so the lanes skip) every lane of one interval takes its span's
// segments as one run (RayPacketT's one-run lanes, owned_segments), the others walk.
TEST(RaySpans, PacketsResumeAsTheScalarPath) {
    std::mt19937 rng(11);
    for (int variant = 0; variant < 3; ++variant) {
        const bool terminated = variant == 1, empty_space = variant == 2;
        Scene s = ml_scene(Projection::Composite);
        if (terminated) s.render.early_termination = 0.5;
        if (empty_space) {  // a Gaussian blob's shell at 0.6: empty macrocells around and inside it
            FieldSpec g;
            g.kind = FieldSpec::Kind::Gaussian;
            g.dims = {37, 29, 33};
            g.center = {12.0, 14.0, 15.0};
            g.sigma = 6.0;
            const Scene blob = field_scene(g, glm::dvec3(0.0), glm::dvec3(0.7, 1.0, 0.9));
            s.volume().source = blob.volume().source;
            s.volume().origin = blob.volume().origin;
            s.volume().spacing = blob.volume().spacing;
            s.volume().transfer.opacity = {{0.0, 0.0}, {0.55, 0.0}, {0.6, 0.8}, {0.65, 0.0}};
        }
        SCOPED_TRACE(variant);
        const PreparedScene ps(s, RenderOptions{.threads = 1});
        const Integrator& integrator = ps.integrator();
        const std::vector<RayCase> cases = rays_of(ps);
        for (std::size_t first = 0; first + kMaxPacketRays <= cases.size(); first += kMaxPacketRays) {
            Ray rays[kMaxPacketRays];
            std::vector<Interval> intervals[kMaxPacketRays];
            std::vector<RaySpan> spans[kMaxPacketRays];
            RayState packet[kMaxPacketRays], scalar[kMaxPacketRays];
            for (int i = 0; i < kMaxPacketRays; ++i) {
                rays[i] = cases[first + std::size_t(i)].ray;
                intervals[i] = cases[first + std::size_t(i)].intervals;
                spans[i] = cut(cases[first + std::size_t(i)], rng);
            }
            for (int k = 0; k < 3; ++k) {
                RaySpan span_k[kMaxPacketRays];
                for (int i = 0; i < kMaxPacketRays; ++i) span_k[i] = spans[i][std::size_t(k)];
                integrator.integrate_span_packet(rays, intervals, span_k, packet, kMaxPacketRays);
                for (int i = 0; i < kMaxPacketRays; ++i) integrator.integrate_span(rays[i], intervals[i], span_k[i], scalar[i]);
            }
            for (int i = 0; i < kMaxPacketRays; ++i) {
                EXPECT_EQ(packet[i].stopped, scalar[i].stopped);
                EXPECT_LT(difference(integrator.finish(rays[i], intervals[i], packet[i]),
                                     integrator.finish(rays[i], intervals[i], scalar[i])), 1e-13);
            }
        }
    }
}

// owned_segments finds its run's ends from the closed form and a local correction; here against the
// definition counted segment by segment (the owned k are those with t0 <= midpoint < t1) and against
// a bisection on k, over random intervals, steps and spans, spans ending exactly on midpoints, on the
// interval's ends, at +-inf and NaN, and a long interval (2^20 segments).
TEST(RaySpans, OwnedSegmentsAsBisection) {
    auto bisection = [](const Interval& iv, double step, std::int64_t n, double t) {
        std::int64_t lo = 0, hi = n;
        while (lo < hi) {
            const std::int64_t mid = lo + (hi - lo) / 2;
            if (segment(iv, step, mid, n).midpoint() >= t) hi = mid;
            else lo = mid + 1;
        }
        return lo;
    };
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-300.0, 300.0), h(0.01, 7.0);
    const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
    int checked = 0;
    for (int c = 0; c < 4000; ++c) {
        double a = u(rng), b = u(rng);
        if (a > b) std::swap(a, b);
        Interval iv{a, b};
        double step = h(rng);
        if (c == 0) iv = Interval{-17.25, -17.25 + 1048576.0 * 0.5}, step = 0.5;  // 2^20 segments
        const std::int64_t n = segment_count(iv, step);
        auto pick = [&](int kind) {
            std::uniform_int_distribution<std::int64_t> k(0, n - 1);
            switch (kind) {
                case 0: return u(rng);
                case 1: return segment(iv, step, k(rng), n).midpoint();  // exactly on a midpoint
                case 2: return std::nextafter(segment(iv, step, k(rng), n).midpoint(), -inf);
                case 3: return iv.t0;
                case 4: return iv.t1;
                case 5: return -inf;
                case 6: return inf;
                default: return nan;
            }
        };
        for (int k0 = 0; k0 < 8; ++k0) {
            const RaySpan span{pick(k0), pick((k0 + c) % 8)};
            const auto [first, end] = owned_segments(iv, step, n, span);
            if (span.whole()) {
                EXPECT_EQ(first, 0);
                EXPECT_EQ(end, n);
                continue;
            }
            const std::int64_t b0 = bisection(iv, step, n, span.t0);
            EXPECT_EQ(first, b0) << iv.t0 << " " << iv.t1 << " " << step << " " << span.t0;
            EXPECT_EQ(end, std::max(b0, bisection(iv, step, n, span.t1))) << span.t1;
            // The definition, segment by segment (not for a NaN end, which no midpoint reaches: the run
            // then ends at n, as the bisection's).
            if (n <= 4096 && !std::isnan(span.t0) && !std::isnan(span.t1)) {
                std::int64_t lo = n, count = 0;
                for (std::int64_t k = 0; k < n; ++k)
                    if (span.owns(segment(iv, step, k, n).midpoint())) lo = std::min(lo, k), ++count;
                EXPECT_EQ(end - first, count);
                if (count > 0) EXPECT_EQ(first, lo);
            }
            ++checked;
        }
    }
    EXPECT_GT(checked, 25000);
}

// The fast profile's parts (product_state, SpanStates.h) by hand: C = C_f + T_f C_b, T = T_f T_b, and a
// fresh state stands for T = 1, C = 0.
TEST(RaySpans, ProductMergeByHand) {
    RayState front, back;
    front.v[0] = 0.5, front.v[9] = 1.0;  // T
    front.v[2] = 0.2, front.v[3] = 0.25, front.v[4] = 0.125;
    back.v[0] = 0.75, back.v[9] = 1.0;
    back.v[2] = 0.5, back.v[3] = 0.0, back.v[4] = 1.0;
    product_state::merge(front, back);
    const glm::dvec4 p = product_state::rgba(front);
    EXPECT_EQ(p.r, 0.2 + 0.5 * 0.5);
    EXPECT_EQ(p.g, 0.25);
    EXPECT_EQ(p.b, 0.125 + 0.5);
    EXPECT_EQ(p.a, 1.0 - 0.375);  // 1 - 0.5 x 0.75, exact in float
    RayState fresh;
    product_state::merge(fresh, back);  // a fresh front: T = 1
    EXPECT_EQ(product_state::rgba(fresh), product_state::rgba(back));
    EXPECT_EQ(product_state::rgba(RayState{}), glm::dvec4(0.0));  // nothing seen: (0, 0, 0, 1 - 1)
}

// Composite parts merge by C = C_f + exp(-tau_f) C_b, tau = tau_f + tau_b (SpanStates.h), by hand.
TEST(RaySpans, CompositeMergeByHand) {
    RayState front, back;
    front.v[0] = 0.5;  // tau
    front.v[2] = 0.2, front.v[3] = 0.3, front.v[4] = 0.4;
    back.v[0] = 0.25;
    back.v[2] = 0.1, back.v[3] = 0.0, back.v[4] = 1.0;
    composite_state::merge(front, back);
    const glm::dvec4 p = composite_state::rgba(front);
    EXPECT_DOUBLE_EQ(p.r, 0.2 + std::exp(-0.5) * 0.1);
    EXPECT_DOUBLE_EQ(p.g, 0.3);
    EXPECT_DOUBLE_EQ(p.b, 0.4 + std::exp(-0.5) * 1.0);
    EXPECT_DOUBLE_EQ(p.a, -std::expm1(-0.75));
    back = RayState{};
    back.v[8] = 1.0;  // an opaque part behind
    back.stopped = 1.0;
    composite_state::merge(front, back);
    EXPECT_EQ(composite_state::rgba(front).a, 1.0);
    RayState after = front;
    composite_state::merge(after, RayState{});  // nothing is added behind a stopped ray
    EXPECT_EQ(std::memcmp(&after, &front, sizeof front), 0);
}

// owned_span is exactly {t : owns(brick, lattice, u(t))}: checked at its ends (and one double beyond
// them) and at random t, for random rays through a 4-brick split, every brick, axis-parallel rays too.
TEST(RaySpans, OwnedSpanIsExactlyTheBricksPoints) {
    mpi::Lattice lattice;
    lattice.hi = {40, 30, 20};
    const std::vector<mpi::Brick> bricks = mpi::split_lattice(lattice, 4);
    mpi::GridBox grid;
    grid.dims = {41, 31, 21};
    grid.origin = glm::dvec3(-2.0, 3.0, 0.5);
    grid.spacing = glm::dvec3(0.5, 1.25, 0.75);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> pos(-40.0, 60.0), dir(-1.0, 1.0), t(-200.0, 200.0);
    auto u = [&](const Ray& r, double x) { return (r.at(x) - grid.origin) / grid.spacing; };
    int nonempty = 0;
    for (int n = 0; n < 400; ++n) {
        Ray ray;
        ray.origin = glm::dvec3(pos(rng), pos(rng), pos(rng));
        ray.direction = glm::dvec3(dir(rng), dir(rng), dir(rng));
        if (n % 5 == 0) ray.direction[n % 3] = 0.0;  // parallel to a face
        for (const mpi::Brick& b : bricks) {
            const RaySpan span = mpi::owned_span(b, lattice, grid, ray);
            for (int k = 0; k < 50; ++k) {
                const double x = t(rng);
                EXPECT_EQ(span.owns(x), mpi::owns(b, lattice, u(ray, x)));
            }
            if (!(span.t0 < span.t1)) continue;
            ++nonempty;
            const double inf = std::numeric_limits<double>::infinity();
            const double last = std::nextafter(span.t1, -inf);
            for (double x : {span.t0, last}) EXPECT_TRUE(std::isinf(x) || mpi::owns(b, lattice, u(ray, x)));
            if (std::isfinite(span.t0)) {
                EXPECT_FALSE(mpi::owns(b, lattice, u(ray, std::nextafter(span.t0, -inf))));
            }
            if (std::isfinite(span.t1)) {
                EXPECT_FALSE(mpi::owns(b, lattice, u(ray, span.t1)));
            }
        }
    }
    EXPECT_GT(nonempty, 200);
}
