// Thread scaling of render_scene: scale_probe of ../shared/gpu/h100/tools with a per-job tile side.
//   probe FRAMES THREADS(1,2,..) SCENE [--set k=v]... [--tile N] [-- SCENE ...]
// PROBE_NO_AVX512=1: Highway's dispatch leaves out AVX-512 (hwy::SetSupportedTargetsForTest), so the
// packets run on AVX2 (8 float / 4 double lanes) on a CPU that has AVX-512 (16 / 8).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <thread>
#include <vector>
#include <hwy/targets.h>
#include "core/render/Renderer.h"
#include "core/scene/SceneLoader.h"
int main(int argc, char** argv) {
    if (argc < 4) return 2;
    const int frames = std::atoi(argv[1]);
    std::vector<int> threads;
    { std::stringstream s(argv[2]); std::string t; while (std::getline(s, t, ',')) threads.push_back(std::atoi(t.c_str())); }
    struct Job { std::string scene; std::vector<std::string> sets; int tile = 0; };
    std::vector<Job> jobs;
    for (int i = 3; i < argc; ++i) {
        std::string a = argv[i];
        if (a == "--") continue;
        if (a == "--set" && i + 1 < argc) { jobs.back().sets.push_back(argv[++i]); continue; }
        if (a == "--tile" && i + 1 < argc) { jobs.back().tile = std::atoi(argv[++i]); continue; }
        jobs.push_back({a, {}, 0});
    }
    std::fprintf(stderr, "hardware_concurrency %u\n", std::thread::hardware_concurrency());
    if (std::getenv("PROBE_NO_AVX512")) hwy::SetSupportedTargetsForTest(hwy::SupportedTargets() & ~(HWY_AVX3 | HWY_AVX3_DL));
    const long long targets = hwy::SupportedTargets();
    for (const Job& j : jobs) {
        const volref::Scene scene = volref::load_scene(j.scene, j.sets);
        std::string label = j.scene; for (auto& s : j.sets) label += " " + s;
        for (int t : threads) {
            volref::RenderOptions o; o.threads = t; o.frames = frames; o.tile_size = j.tile;
            volref::RenderStats st;
            volref::render_scene(scene, o, &st);
            std::vector<double> f = st.frames_s; std::sort(f.begin(), f.end());
            std::printf("{\"targets\": %lld, \"scene\": \"%s\", \"tile\": %d, \"threads\": %d, \"setup_s\": %.4f, \"median_s\": %.5f, \"min_s\": %.5f}\n",
                        targets, label.c_str(), j.tile ? j.tile : volref::tile_side(scene.image.width, scene.image.height, t), t, st.setup_s, f[f.size() / 2], f[0]);
            std::fflush(stdout);
        }
    }
}
