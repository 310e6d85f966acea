// tile_balance SCENE [--set KEY=VALUE ...] [--tile T ...]: why many threads speed a render up less than
// their count (issue 31, part 4). Each tile of side T is rendered alone at one thread, as render_scene
// renders it (4 x 4 packets, the same pixels), and timed; the program prints the tiles' cost
// distribution and, for W workers (1, 2, 4, 8, 16, 32), the makespan of TBB-like dynamic scheduling
// (each free worker takes the next tile in order) over the measured costs: speed-up = total / makespan.
// It measures one machine's single-thread costs and simulates the many-core schedule, so a 2-core
// machine can say what 16 cores would see from load balance alone (not memory bandwidth).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <queue>
#include <string>
#include <vector>

#include "core/Error.h"
#include "core/render/PreparedScene.h"
#include "core/render/Renderer.h"
#include "core/scene/SceneLoader.h"

using namespace volref;

namespace {

// The makespan of `costs` taken in order by `workers` workers (each takes the next tile when free).
double makespan(const std::vector<double>& costs, int workers) {
    std::priority_queue<double, std::vector<double>, std::greater<>> free_at;
    for (int w = 0; w < workers; ++w) free_at.push(0.0);
    double end = 0.0;
    for (double c : costs) {
        const double start = free_at.top();
        free_at.pop();
        free_at.push(start + c);
        end = std::max(end, start + c);
    }
    return end;
}

std::vector<double> tile_costs(const PreparedScene& prepared, int W, int H, int T) {
    constexpr int kBlockW = 4, kBlockH = kMaxPacketRays / 4;
    std::vector<double> costs;
    PreparedScene::Scratch scratch;
    PixelValue values[kMaxPacketRays];
    int px[kMaxPacketRays], py[kMaxPacketRays];
    for (int y0 = 0; y0 < H; y0 += T)
        for (int x0 = 0; x0 < W; x0 += T) {
            const auto start = std::chrono::steady_clock::now();
            for (int by = y0; by < std::min(y0 + T, H); by += kBlockH)
                for (int bx = x0; bx < std::min(x0 + T, W); bx += kBlockW) {
                    int n = 0;
                    for (int y = by; y < std::min({by + kBlockH, y0 + T, H}); ++y)
                        for (int x = bx; x < std::min({bx + kBlockW, x0 + T, W}); ++x) {
                            px[n] = x;
                            py[n] = y;
                            ++n;
                        }
                    prepared.pixels(px, py, n, values, true, scratch);
                }
            costs.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        }
    return costs;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: tile_balance SCENE [--set KEY=VALUE ...] [--tile T ...]\n");
        return 2;
    }
    std::vector<std::string> sets;
    std::vector<int> tiles;
    for (int i = 2; i + 1 < argc; i += 2) {
        const std::string flag = argv[i];
        if (flag == "--set") sets.push_back(argv[i + 1]);
        else if (flag == "--tile") tiles.push_back(std::atoi(argv[i + 1]));
        else {
            std::fprintf(stderr, "tile_balance: unknown option %s\n", argv[i]);
            return 2;
        }
    }
    if (tiles.empty()) tiles = {16, 8, 4};
    try {
        const Scene scene = load_scene(argv[1], sets);
        RenderOptions options;
        options.threads = 1;
        const PreparedScene prepared(scene, options);
        const int W = scene.image.width, H = scene.image.height;
        for (int T : tiles) {
            if (T < 1) throw Error("--tile: expected a side >= 1");
            std::vector<double> c = tile_costs(prepared, W, H, T);
            std::vector<double> sorted = c;
            std::sort(sorted.begin(), sorted.end());
            double total = 0.0;
            for (double x : c) total += x;
            std::printf("tile %d: %zu tiles, total %.3f s, median %.2f ms, p90 %.2f ms, max %.2f ms (%.1f%% of the total)\n", T,
                        c.size(), total, 1e3 * sorted[sorted.size() / 2], 1e3 * sorted[sorted.size() * 9 / 10], 1e3 * sorted.back(),
                        100.0 * sorted.back() / total);
            for (int w : {1, 2, 4, 8, 16, 32})
                std::printf("  %2d workers: makespan %.3f s, speed-up %.2f (ideal %d)\n", w, makespan(c, w), total / makespan(c, w), w);
        }
    } catch (const Error& e) {
        std::fprintf(stderr, "tile_balance: %s\n", e.what());
        return 1;
    }
    return 0;
}
