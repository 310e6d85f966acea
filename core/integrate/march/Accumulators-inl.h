// The accumulator templates of Accumulators.h (read that file's header first). Included once inside
// namespace volref (Accumulators.h) and once inside each Highway target's namespace
// (PacketKernels-inl.h), so that every instantiation is compiled for the instruction set of the lanes
// it runs on; hence no include guard and no includes: the enclosing file provides the lane types.
// Neumaier's compensated addition of x to (s, c) on the lanes `on` (the value is s + c).
template <class L>
inline void compensated_add(typename L::V& s, typename L::V& c, typename L::V x, typename L::M on) {
    using V = typename L::V;
    const V t = s + x;
    const V comp = L::select(L::ge(L::abs(s), L::abs(x)), (s - t) + x, (x - t) + s);
    c = L::select(on, c + comp, c);
    s = L::select(on, t, s);
}

// A sample of transfer-function opacity a standing for length d (unit distance l), on the lanes `alive`:
// visible where a > 0, solid (opaque, alpha = 1) where a >= 1, partial otherwise with
// tau = optical_depth(a, d, l) and alpha = segment_alpha(tau).
template <class L>
struct SampleOpacity {
    typename L::M visible, solid, partial;
    typename L::V tau, alpha;
};
template <class L>
inline SampleOpacity<L> sample_opacity(typename L::M alive, typename L::V a, typename L::V d, typename L::V l) {
    SampleOpacity<L> o;
    o.visible = L::and_(alive, L::gt(a, L::splat(0.0)));
    o.solid = L::and_(o.visible, L::ge(a, L::splat(1.0)));
    o.partial = L::and_not(o.solid, o.visible);
    o.tau = optical_depth<L>(L::select_zero(o.partial, a), d, l);
    o.alpha = L::select(o.solid, L::splat(1.0), segment_alpha<L>(o.tau));
    return o;
}

// Front-to-back compositing of premultiplied colour C (kCompensatedColour: each channel a
// compensated sum, for the adaptive integrator's many small pieces).
template <class L, ::volref::TransmittanceRule R = ::volref::TransmittanceRule::OpticalDepthSum, bool kCompensatedColour = false>
class FrontToBack {
public:
    using V = typename L::V;
    using M = typename L::M;
    // (Constructors are written out: an implicit one would not be compiled for the lanes' target.)
    FrontToBack() {}

    // The transmittance in front of the next sample.
    V transmittance() const {
        if constexpr (R == ::volref::TransmittanceRule::OpticalDepthSum) return L::exp(L::neg(s_ + c_));
        else if constexpr (R == ::volref::TransmittanceRule::Product) return s_;
        else return L::splat(1.0) - s_;
    }
    // The accumulated opacity, not counting an opaque sample.
    V partial_alpha() const {
        // + 0: a ray that met nothing has A = +0, never -0 (Highway's expm1(-0) is +0, so its negation
        // was -0 on the SIMD path); x + 0 = x for every other x.
        if constexpr (R == ::volref::TransmittanceRule::OpticalDepthSum) return segment_alpha<L>(s_ + c_) + L::splat(0.0);
        else if constexpr (R == ::volref::TransmittanceRule::Product) return L::splat(1.0) - s_;
        else return s_;
    }
    // The pixel's alpha: 1 on lanes that met an opaque sample.
    V alpha() const {
        if constexpr (R == ::volref::TransmittanceRule::OpacitySum) return s_;
        else return L::select(opaque_, L::splat(1.0), partial_alpha());
    }
    V color(int channel) const {
        if constexpr (kCompensatedColour) return color_[channel] + color_c_[channel];
        else return color_[channel];
    }

    // One sample on the lanes `visible`: opacity alpha (optical depth tau, read by the optical-depth
    // rule) and colour c (not premultiplied): C += (T alpha) c. `solid` lanes (a = 1) have alpha = 1
    // and make the ray opaque.
    void add(M visible, M solid, V tau, V alpha, const V c[3]) {
        const V w = L::select_zero(visible, transmittance() * alpha);
        for (int i = 0; i < 3; ++i) add_color(i, L::select_zero(visible, w * c[i]));
        const M partial = L::and_not(solid, visible);
        if constexpr (R == ::volref::TransmittanceRule::OpticalDepthSum) compensated_add<L>(s_, c_, tau, partial);
        else if constexpr (R == ::volref::TransmittanceRule::Product) s_ = L::select(visible, s_ * (L::splat(1.0) - alpha), s_);
        else s_ = L::select(visible, s_ + w, s_);
        opaque_ = L::or_(opaque_, L::and_(visible, solid));
    }
    // Continues behind an already composited pixel (C, A) (opacity-sum rule): the film puts the
    // background behind a rendered pixel this way.
    void resume(const V C[3], V A) {
        static_assert(R == ::volref::TransmittanceRule::OpacitySum);
        for (int i = 0; i < 3; ++i) color_[i] = C[i];
        s_ = A;
    }
    // A piece integrated by quadrature (the adaptive integrator): its emission E relative to the
    // transmittance at its front, C += T E, and its optical depth in two halves (optical-depth rule).
    void add_emission(const V E[3], V tau0, V tau1) {
        static_assert(R == ::volref::TransmittanceRule::OpticalDepthSum);
        const V T = transmittance();
        for (int i = 0; i < 3; ++i) add_color(i, T * E[i]);
        compensated_add<L>(s_, c_, tau0, L::all_lanes());
        compensated_add<L>(s_, c_, tau1, L::all_lanes());
    }
    // An opaque piece whose front has colour c: C += T c, and the ray is opaque.
    void add_opaque(const V c[3]) {
        const V T = transmittance();
        for (int i = 0; i < 3; ++i) add_color(i, T * c[i]);
        opaque_ = L::all_lanes();
    }

    // The whole state: 8 values (optical depth or transmittance and its compensation, colour and its
    // compensation) and the opaque lanes: the composite's RayState (march/SpanStates.h, composite_state),
    // which a span resumes and volref-mpi hands from rank to rank; load(save()) changes no bit.
    static constexpr int kStateValues = 8;
    void save(V* out, M& opaque) const {
        out[0] = s_;
        out[1] = c_;
        for (int i = 0; i < 3; ++i) out[2 + i] = color_[i], out[5 + i] = color_c_[i];
        opaque = opaque_;
    }
    void load(const V* in, M opaque) {
        s_ = in[0];
        c_ = in[1];
        for (int i = 0; i < 3; ++i) color_[i] = in[2 + i], color_c_[i] = in[5 + i];
        opaque_ = opaque;
    }

    // The lanes among `partial` (lanes that took a partially transparent sample) that stop here.
    M stops(M partial, const ::volref::Termination& t) const {
        M stop = L::no_lanes();
        if (t.test_alpha_above || t.test_alpha_at_least) {
            const V A = partial_alpha();
            if (t.test_alpha_above) stop = L::or_(stop, L::gt(A, L::splat(t.alpha_above)));
            if (t.test_alpha_at_least) stop = L::or_(stop, L::ge(A, L::splat(t.alpha_at_least)));
        }
        if (t.test_transmittance) stop = L::or_(stop, L::le(transmittance(), L::splat(t.transmittance_at_most)));
        return L::and_(partial, stop);
    }

private:
    void add_color(int i, V x) {
        if constexpr (kCompensatedColour) compensated_add<L>(color_[i], color_c_[i], x, L::all_lanes());
        else color_[i] = color_[i] + x;
    }
    // OpticalDepthSum: (s_, c_) the compensated optical depth; Product: s_ = T; OpacitySum: s_ = A.
    V s_ = R == ::volref::TransmittanceRule::Product ? L::splat(1.0) : L::splat(0.0);
    V c_ = L::splat(0.0);
    V color_[3] = {L::splat(0.0), L::splat(0.0), L::splat(0.0)};
    V color_c_[3] = {L::splat(0.0), L::splat(0.0), L::splat(0.0)};
    M opaque_ = L::no_lanes();
};

// Back-to-front compositing (the rule: Accumulators.h).
template <class L, ::volref::BackToFrontRule R = ::volref::BackToFrontRule::Over>
class BackToFront {
public:
    using V = typename L::V;
    using M = typename L::M;
    BackToFront() {}

    V color(int channel) const { return color_[channel]; }
    V alpha() const {
        if constexpr (R == ::volref::BackToFrontRule::Lerp) return color_[3];
        else return L::select(opaque_, L::splat(1.0), segment_alpha<L>(s_ + c_) + L::splat(0.0));  // + 0: as FrontToBack
    }
    // The transmittance of what is composited so far (0 once a sample was opaque).
    V transmittance() const { return L::select(opaque_, L::splat(0.0), L::exp(L::neg(s_ + c_))); }
    // Over: the optical depth of the partial samples so far, and the lanes that met an opaque one (a
    // part handed to what lies in front: march/SpanStates.h).
    V optical_depth() const { return s_ + c_; }
    M opaque() const { return opaque_; }

    // Over: a sample in front of everything so far, on the lanes `visible` (see FrontToBack::add).
    void add(M visible, M solid, V tau, V alpha, const V c[3]) {
        static_assert(R == ::volref::BackToFrontRule::Over);
        const V keep = L::splat(1.0) - alpha;
        for (int i = 0; i < 3; ++i)
            color_[i] = L::select(solid, c[i], L::select(visible, alpha * c[i] + keep * color_[i], color_[i]));
        compensated_add<L>(s_, c_, tau, L::and_not(solid, visible));
        opaque_ = L::or_(opaque_, L::and_(visible, solid));
    }
    // Lerp: sum += (col - sum) w, col = (c, a).
    void lerp(M on, V w, const V c[3], V a) {
        static_assert(R == ::volref::BackToFrontRule::Lerp);
        for (int i = 0; i < 4; ++i)
            color_[i] = L::select(on, color_[i] + ((i < 3 ? c[i] : a) - color_[i]) * w, color_[i]);
    }

private:
    V s_ = L::splat(0.0), c_ = L::splat(0.0);
    V color_[4] = {L::splat(0.0), L::splat(0.0), L::splat(0.0), L::splat(0.0)};
    M opaque_ = L::no_lanes();
};

// MIP / MinIP: the first sample with the largest (smallest) finite value, and where it lies.
template <class L>
class Extremum {
public:
    using V = typename L::V;
    using M = typename L::M;
    explicit Extremum(bool maximum) : maximum_(maximum) {}

    // A sample of value v at t on the lanes `alive`; returns the lanes where it is the new extremum.
    // Non-finite values are ignored (docs/accuracy.md).
    M add(M alive, V v, V t) {
        const M finite = L::and_(alive, L::is_finite(v));
        const M better = maximum_ ? L::gt(v, best_) : L::lt(v, best_);
        const M take = L::or_(L::and_not(seen_, finite), L::and_(finite, better));
        best_ = L::select(take, v, best_);
        t_best_ = L::select(take, t, t_best_);
        seen_ = L::or_(seen_, finite);
        return take;
    }
    V value() const { return best_; }
    V where() const { return t_best_; }
    M any() const { return seen_; }

private:
    bool maximum_;
    V best_ = L::splat(0.0), t_best_ = L::splat(0.0);
    M seen_ = L::no_lanes();
};

// One sample of emission-absorption compositing on the lanes `alive`: the one sequence every
// reference composite path takes once its sample's value is fetched, on any lanes and either order.
//   classify    a = sample.opacity()            the transfer function's opacity per unit distance l
//   correct     sample_opacity(alive, a, d, l)  visible, solid, tau, alpha for the length d
//   shade       sample.colour(c)                the colour (shaded where the scene shades), taken only
//                                               when some live lane is visible
//   accumulate  acc.add(visible, solid, tau, alpha, c)
//   retire      the lanes that became opaque or reached `stop` (front to back; `stop` null: none)
// `on` observes the step: on.transparent(acc) when no live lane is visible (nothing changes),
// on.composited(o, acc) after accumulating. Returns the lanes to retire.
template <class L, class Acc, class Sample, class Hooks>
[[gnu::always_inline]] inline typename L::M composite_step(Acc& acc, Sample& sample, typename L::M alive, typename L::V d, typename L::V l,
                                    const ::volref::Termination* stop, Hooks& on) {
    using V = typename L::V;
    const V a = sample.opacity();
    if (L::none(L::and_(alive, L::gt(a, L::splat(0.0))))) {
        on.transparent(acc);
        return L::no_lanes();
    }
    const SampleOpacity<L> o = sample_opacity<L>(alive, a, d, l);
    V c[3];
    sample.colour(c);
    acc.add(o.visible, o.solid, o.tau, o.alpha, c);
    on.composited(o, acc);
    if constexpr (requires { acc.stops(o.partial, *stop); }) {
        if (stop) return L::or_(o.solid, acc.stops(o.partial, *stop));
    }
    return L::no_lanes();
}
