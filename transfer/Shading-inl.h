// Gradient shading's arithmetic (conventions section 8; Shader.h states the model) as templates over
// a lane type L (core/Lanes.h: ScalarLanes for Shader, SimdLanes for the packet kernels,
// core/integrate/packet/PacketComposite.cpp), so that the scalar and SIMD paths share one formula, as
// the accumulators do. Included once inside namespace volref (Shader.cpp) and once inside
// each Highway target's namespace; hence no include guard and no includes. Every product and sum is
// written in the order the scalar shader evaluates it (glm's dot: (x + y) + z).

// The shading coefficients the lanes read (ks = 0 for nodal; phong: R.V instead of N.H).
struct ShadingConstants {
    double ka = 0.1, kd = 0.7, ks = 0.2, n = 10.0, kc = 1.0, kl = 0.0;
    bool two_sided = false, phong = false;
};

template <class L>
inline typename L::V dot3(const typename L::V a[3], const typename L::V b[3]) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

// A dot product as the lighting takes it: |x| two-sided, else max(x, 0).
template <class L>
inline typename L::V clamp_dot(bool two_sided, typename L::V x) {
    return two_sided ? L::abs(x) : L::max(x, L::splat(0.0));
}

// One light's terms (Shader.h's LightTerms, per lane).
template <class L>
struct LightLanes {
    typename L::V Ld[3], H[3], n_dot_l, specular_dot, depth_cue, ambient[3], diffuse[3], specular[3];
};

// One light of colour I, towards Ld (unit), at a sample of unit normal N, material colour m, view
// direction `view` (unit, towards the eye) and distance `depth` from the eye.
template <class L>
inline void light_lanes(const ShadingConstants& k, const typename L::V N[3], const typename L::V Ld[3],
                        const typename L::V view[3], typename L::V depth, const typename L::V m[3], const double I[3],
                        LightLanes<L>& t) {
    using V = typename L::V;
    const V zero = L::splat(0.0), one = L::splat(1.0);
    for (int c = 0; c < 3; ++c) t.Ld[c] = Ld[c];
    const V n_dot_l = dot3<L>(N, Ld);
    t.n_dot_l = clamp_dot<L>(k.two_sided, n_dot_l);
    if (k.phong) {
        const V twice = L::splat(2.0) * n_dot_l;
        for (int c = 0; c < 3; ++c) t.H[c] = twice * N[c] - Ld[c];  // R = 2 (N.L) N - L
        t.specular_dot = L::max(dot3<L>(t.H, view), zero);
    } else {
        for (int c = 0; c < 3; ++c) t.H[c] = Ld[c] + view[c];
        const V inv = one / L::sqrt(dot3<L>(t.H, t.H));  // glm::normalize: x * (1 / sqrt(x.x))
        for (int c = 0; c < 3; ++c) t.H[c] = t.H[c] * inv;
        t.specular_dot = clamp_dot<L>(k.two_sided, dot3<L>(N, t.H));
    }
    t.depth_cue = one / (L::splat(k.kc) + L::splat(k.kl) * depth);
    const V s = k.ks == 0.0 ? zero : L::splat(k.ks) * L::pow(t.specular_dot, k.n) * t.depth_cue;
    for (int c = 0; c < 3; ++c) {
        const V Ic = L::splat(I[c]);
        t.ambient[c] = Ic * (L::splat(k.ka) * m[c]);
        t.diffuse[c] = Ic * (L::splat(k.kd) * m[c] * t.n_dot_l * t.depth_cue);
        t.specular[c] = k.ks == 0.0 ? zero : Ic * s;
    }
}

// The shaded colour, in place of m, on the lanes where |g| > tolerance (the others keep m): N = -g / |g|,
// the lights' terms summed, c += (ambient + diffuse) + specular light by light. light_at(i, Ld, I)
// gives light i's direction lanes and colour; on_light(i, terms) sees each light's terms (explain).
// Returns |g| and sets N (only meaningful on lit lanes) and `lit`.
template <class L, class LightAt, class OnLight>
inline typename L::V shade_lanes(const ShadingConstants& k, double tolerance, int light_count, LightAt&& light_at,
                                 typename L::V m[3], const typename L::V g[3], const typename L::V view[3],
                                 typename L::V depth, typename L::V N[3], typename L::M& lit, OnLight&& on_light) {
    using V = typename L::V;
    const V length = L::sqrt(dot3<L>(g, g));
    lit = L::gt(length, L::splat(tolerance));
    if (L::none(lit)) return length;
    for (int c = 0; c < 3; ++c) N[c] = L::neg(g[c]) / length;
    V out[3] = {L::splat(0.0), L::splat(0.0), L::splat(0.0)};
    for (int i = 0; i < light_count; ++i) {
        V Ld[3];
        double I[3];
        light_at(i, Ld, I);
        LightLanes<L> t;
        light_lanes<L>(k, N, Ld, view, depth, m, I, t);
        for (int c = 0; c < 3; ++c) out[c] = out[c] + (t.ambient[c] + t.diffuse[c] + t.specular[c]);
        on_light(i, t);
    }
    for (int c = 0; c < 3; ++c) m[c] = L::select(lit, out[c], m[c]);
    return length;
}
