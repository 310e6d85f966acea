#include "core/GaussKronrod.h"

#include <vector>

namespace volref::gauss_kronrod {

namespace {

// QUADPACK qk15: the non-negative K15 nodes (descending) and weights; G7 weights of nodes 1, 3, 5, 7.
constexpr long double kXgk[8] = {0.991455371120812639206854697526329L, 0.949107912342758524526189684047851L,
                                 0.864864423359769072789712788640926L, 0.741531185599394439863864773280788L,
                                 0.586087235467691130294144845693013L, 0.405845151377397166906606412076961L,
                                 0.207784955007898467600689403773245L, 0.000000000000000000000000000000000L};
constexpr long double kWgk[8] = {0.022935322010529224963732008058970L, 0.063092092629978553290700663189204L,
                                 0.104790010322250183839876322541518L, 0.140653259715525918745189590510238L,
                                 0.169004726639267902826583426598550L, 0.190350578064785409913256402421014L,
                                 0.204432940075298892414161999234649L, 0.209482141084727828012999174891714L};
constexpr long double kWg[4] = {0.129484966168869693270611432679082L, 0.279705391489276667901467771423780L,
                                0.381830050505118944950369775488975L, 0.417959183673469387755102040816327L};

// Lagrange basis polynomial j over `nodes`, at s.
long double lagrange(const std::vector<long double>& nodes, std::size_t j, long double s) {
    long double v = 1.0L;
    for (std::size_t k = 0; k < nodes.size(); ++k)
        if (k != j) v *= (s - nodes[k]) / (nodes[j] - nodes[k]);
    return v;
}

Tables build() {
    std::array<long double, kNodes> x, wk;
    // Ascending: x_i = -xgk[i] for i < 7, 0, then xgk[14 - i].
    for (int i = 0; i < kNodes; ++i) {
        const int m = i < 7 ? i : 14 - i;
        x[std::size_t(i)] = i < 7 ? -kXgk[m] : kXgk[m];
        wk[std::size_t(i)] = kWgk[m];
    }
    x[7] = 0.0L;
    std::array<long double, kGaussNodes> wg;
    for (int g = 0; g < kGaussNodes; ++g) wg[std::size_t(g)] = kWg[g < 4 ? g : 6 - g];

    // Integral over [-1, b] of a polynomial of degree <= 22, by K15 mapped to [-1, b].
    auto integral = [&](long double b, auto&& f) {
        const long double half = 0.5L * (b + 1.0L), mid = 0.5L * (b - 1.0L);
        long double sum = 0.0L;
        for (int m = 0; m < kNodes; ++m) sum += wk[std::size_t(m)] * f(mid + half * x[std::size_t(m)]);
        return half * sum;
    };
    Tables t;
    std::vector<long double> kn(x.begin(), x.end()), gn;
    for (int g = 0; g < kGaussNodes; ++g) gn.push_back(x[std::size_t(2 * g + 1)]);
    for (int i = 0; i < kNodes; ++i) {
        t.x[std::size_t(i)] = double(x[std::size_t(i)]);
        t.wk[std::size_t(i)] = double(wk[std::size_t(i)]);
        for (int j = 0; j < kNodes; ++j)
            t.sk[std::size_t(i)][std::size_t(j)] =
                double(integral(x[std::size_t(i)], [&](long double s) { return lagrange(kn, std::size_t(j), s); }));
    }
    for (int g = 0; g < kGaussNodes; ++g) {
        t.wg[std::size_t(g)] = double(wg[std::size_t(g)]);
        for (int j = 0; j < kGaussNodes; ++j)
            t.sg[std::size_t(g)][std::size_t(j)] =
                double(integral(gn[std::size_t(g)], [&](long double s) { return lagrange(gn, std::size_t(j), s); }));
    }
    return t;
}

}  // namespace

const Tables& tables() {
    static const Tables t = build();
    return t;
}

}  // namespace volref::gauss_kronrod
