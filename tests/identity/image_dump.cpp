// volref_image_dump: renders a list of cases to memory and writes each image's doubles, bit for bit,
// so that scripts/image-identity.sh can prove that a change to the renderer changed no pixel.
//
// Usage: volref_image_dump CASES OUT_DIR
// CASES holds one case a line, fields separated by '|':
//   name | scene path | overrides (PATH=VALUE, separated by spaces) | options (nosimd noskip error threads=N)
// For each case OUT_DIR/name.img receives a text header (width, height, channel names) followed by the
// pixels as IEEE-754 doubles in the host's byte order; a case whose scene or render is refused gets
// OUT_DIR/name.err with volref's one-line message instead (refusals must not change either).
// Each case renders in a child process (fork) given VOLREF_IMAGE_DUMP_TIMEOUT seconds (default 20);
// a case that takes longer is killed and gets OUT_DIR/name.slow (the adaptive integrator can run away
// on some scenes: issue 18), which scripts/image-identity.sh counts but cannot compare.
// Only the public API (load_scene, render_scene) is used, so the same source builds before and after a
// refactor of the renderer.
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <thread>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "core/Error.h"
#include "core/render/Renderer.h"
#include "core/scene/SceneLoader.h"

namespace {

std::string trim(const std::string& s) {
    const auto a = s.find_first_not_of(" \t");
    if (a == std::string::npos) return "";
    const auto b = s.find_last_not_of(" \t");
    return s.substr(a, b - a + 1);
}

std::vector<std::string> split(const std::string& s, char sep) {
    std::vector<std::string> out;
    std::string item;
    std::istringstream in(s);
    while (std::getline(in, item, sep)) out.push_back(trim(item));
    return out;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 3) {
        std::cerr << "usage: volref_image_dump CASES OUT_DIR\n";
        return 2;
    }
    std::ifstream cases(argv[1]);
    if (!cases) {
        std::cerr << "volref_image_dump: cannot read " << argv[1] << "\n";
        return 2;
    }
    const std::string out_dir = argv[2];
    std::string line;
    int count = 0;
    while (std::getline(cases, line)) {
        if (trim(line).empty() || trim(line)[0] == '#') continue;
        std::vector<std::string> f = split(line, '|');
        f.resize(4);
        const std::string& name = f[0];
        std::vector<std::string> overrides;
        for (const std::string& o : split(f[2], ' '))
            if (!o.empty()) overrides.push_back(o);
        volref::RenderOptions options;
        options.threads = 2;
        for (const std::string& o : split(f[3], ' ')) {
            if (o == "nosimd") options.simd = false;
            else if (o == "noskip") options.empty_space_skipping = false;
            else if (o == "error") options.error_estimate = true;
            else if (o.rfind("threads=", 0) == 0) options.threads = std::stoi(o.substr(8));
            else if (!o.empty()) {
                std::cerr << "volref_image_dump: " << name << ": unknown option " << o << "\n";
                return 2;
            }
        }
        const char* limit = std::getenv("VOLREF_IMAGE_DUMP_TIMEOUT");
        const double timeout = limit ? std::atof(limit) : 20.0;
        std::cout.flush();
        const pid_t child = fork();
        if (child < 0) {
            std::cerr << "volref_image_dump: fork failed\n";
            return 2;
        }
        if (child > 0) {  // the parent never renders (no threads to fork with): it waits
            const auto start = std::chrono::steady_clock::now();
            int status = 0;
            while (waitpid(child, &status, WNOHANG) == 0) {
                if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > timeout) {
                    kill(child, SIGKILL);
                    waitpid(child, &status, 0);
                    std::ofstream(out_dir + "/" + name + ".slow") << "over " << timeout << " s\n";
                    break;
                }
                std::this_thread::sleep_for(std::chrono::milliseconds(5));
            }
            ++count;
            continue;
        }
        try {
            const volref::Scene scene = volref::load_scene(f[1], overrides);
            const volref::Image image = volref::render_scene(scene, options);
            std::ofstream out(out_dir + "/" + name + ".img", std::ios::binary);
            out << image.width << " " << image.height;
            for (const std::string& c : image.channels) out << " " << c;
            out << "\n";
            out.write(reinterpret_cast<const char*>(image.pixels.data()),
                      std::streamsize(image.pixels.size() * sizeof(double)));
        } catch (const std::exception& e) {
            std::ofstream(out_dir + "/" + name + ".err") << e.what() << "\n";
        }
        std::_Exit(0);
    }
    std::cerr << "volref_image_dump: " << count << " cases\n";
    return 0;
}
