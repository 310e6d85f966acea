// The convention search behind `volref compare GPU.exr --fit --scene SCENE` and volref.fit:
// which of another renderer's conventions explain the difference between its image G and volref's
// render of the same scene.
//
// The scene is re-rendered with the rules of its profile (render.profile, core/integrate/profiles/
// Profile.h) changed: every candidate value of one rule (`candidate_rules`); then pairs of those singles
// (every pair when pairs x pixels <= kSearchAllPairsPixels, else the pairs of the kSearchPairsOf singles
// of smallest RMS residual); then the best set grown by one more rule while that helps (at most
// kSearchMaxRules rules, an image model counting as one); then each rule of the best set swapped for the
// other values of its rule while that helps. Every render R is read under each image model M (identity,
// vertical flip, unpremultiplied or double-premultiplied colour, BGRA order, sRGB-encoded colour): a
// pixel p is explained by (rules, M) when
//     |M(R)(p, c) - G(p, c)| <= tol(p, c)   for c = R, G, B, A,
//     tol(p, c) = T + e_R(p) + Q_G(p, c),
// T the stated tolerance (kSearchTolerance, or SearchOptions::tolerance), e_R the render's own `error`
// channel where the scene makes one (the adaptive integrator), Q_G the quantisation of an integer G
// (Tolerance.h). A set explains the image when at most kSearchUnexplainedFraction of the pixels stay
// unexplained; among those the one with fewer rules wins, then the smaller RMS residual. Among sets that
// do not explain it: fewer unexplained pixels, then the smaller RMS (equal within rounding: fewer rules).
// When none explains it no convention is named: what stays unexplained is a bug (or a convention volref
// does not model), shown by the best set's residual (the heat map). "alpha agrees, colour differs" names
// the best-ranked set that explains every pixel's alpha when no set explains the colour.
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/compare/ComparedImage.h"
#include "core/scene/Scene.h"

namespace volref::compare {

struct SearchOptions {
    double tolerance = -1.0;  // T; < 0: kSearchTolerance
    int threads = 0;          // 0: all cores
    // B's background, as read_compared_image composited an associated G over it (compare --background).
    std::optional<glm::dvec4> background;
    // The scene's own render when the caller has made it already (compare renders B from --scene): not
    // rendered again. Null: the search renders it.
    const Image* base_render = nullptr;
};

// One tried set: its rules (render.profile's keys and values) and the image model.
struct SearchCandidate {
    nlohmann::json rules = nlohmann::json::object();
    std::string image_model = "identity";
    long unexplained_pixels = 0;
    long alpha_unexplained = 0;  // pixels whose alpha alone is over the tolerance
    double residual_max = 0.0, residual_rms = 0.0;
    std::vector<double> residual;  // |M(R) - G| max over R, G, B, A per pixel (SearchResult::best's moved out)
    std::string describe() const;  // "placement from-entry, first 0, ray_box texel (vertical flip)"
};

struct SearchResult {
    bool explained = false;
    SearchCandidate best;              // the closest set (named as the explanation only when explained)
    long pixels = 0;                   // pixels compared (fault pixels left out)
    long unexplained_before = 0;       // pixels the scene's own profile leaves unexplained
    double tolerance = 0.0;            // T
    // Not explained, but some tried set explains every pixel's alpha (`alpha_set`, the best such):
    // "alpha agrees, colour differs".
    bool alpha_agrees = false;
    SearchCandidate alpha_set;
    std::vector<SearchCandidate> tried;  // every set rendered, in the order tried
    std::vector<double> residual;      // |M(R) - G| max over R, G, B, A per pixel for the best set (heat map)
    int width = 0, height = 0;
    std::string verdict;               // one line
    nlohmann::json to_json() const;    // {"explained", "rules", "image_model", "unexplained_pixels", ...}
};

// The rules the search may change on `scene` (each a JSON object of render.profile keys), by rule.
std::vector<std::vector<nlohmann::json>> candidate_rules(const Scene& scene);

// The image models: identity, "vertical flip", "unpremultiplied", "double-premultiplied", "BGRA",
// "sRGB-encoded" applied to premultiplied RGBA (4 channels, interleaved).
const std::vector<std::string>& image_models();
std::vector<double> apply_image_model(const std::string& model, const Image& rgba);

// Searches; G is the other renderer's image (read by read_compared_image, faults already excluded).
SearchResult search_conventions(const ComparedImage& g, const Scene& scene, const SearchOptions& options = {});

// `scene` with render.profile's rules `rules` (a JSON object of keys) set over its own (throws
// volref::Error for a rule or value render.profile does not have).
Scene with_rules(const Scene& scene, const nlohmann::json& rules);

}  // namespace volref::compare
