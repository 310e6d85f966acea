#include "cli/mpi/ImageOutput.h"

#include <dlfcn.h>

#include <cstddef>
#include <cstdio>

#include "core/Error.h"

namespace volref::mpi {

namespace {

// OUT ending in ".img": the pixels as doubles in tests/identity/image_dump.cpp's format (a text line
// "W H R G B A", then W H 4 IEEE-754 doubles in the host's byte order), so that tests compare doubles
// (EXR stores floats).
bool dump_output(const std::string& path) { return path.size() > 4 && path.compare(path.size() - 4, 4, ".img") == 0; }

void write_dump(const Image& image, const std::string& path) {
    const std::string temp = path + ".part";
    std::FILE* f = std::fopen(temp.c_str(), "wb");
    if (!f) throw Error(path + ": cannot write");
    std::string header = std::to_string(image.width) + " " + std::to_string(image.height);
    for (const std::string& c : image.channels) header += " " + c;
    header += "\n";
    const bool ok = std::fwrite(header.data(), 1, header.size(), f) == header.size() &&
                    std::fwrite(image.pixels.data(), sizeof(double), image.pixels.size(), f) == image.pixels.size();
    if (std::fclose(f) != 0 || !ok || std::rename(temp.c_str(), path.c_str()) != 0) {
        std::remove(temp.c_str());
        throw Error(path + ": cannot write");
    }
}

// libvolref_tools' C entry points (ImageWriter.h), loaded once. The library is found as the loader
// finds any: volref-mpi's run path (the build folder), LD_LIBRARY_PATH, the system's folders.
struct Tools {
    int (*check)(const char*, char*, std::size_t) = nullptr;
    int (*write)(const Image*, const char*, const double*, char*, std::size_t) = nullptr;
};
const Tools& tools(const std::string& path) {
    static const Tools loaded = [&] {
        void* library = dlopen("libvolref_tools.so.0", RTLD_NOW | RTLD_LOCAL);
        const char* why = library ? nullptr : dlerror();
        Tools t;
        if (library) {
            t.check = reinterpret_cast<decltype(t.check)>(dlsym(library, "volref_check_output_path"));
            t.write = reinterpret_cast<decltype(t.write)>(dlsym(library, "volref_write_image"));
        }
        if (!t.check || !t.write)
            throw Error(path + ": writing this format needs libvolref_tools.so.0 (" + (why ? why : "its entry points are missing") +
                        "); an OUT ending in .img needs nothing more");
        return t;
    }();
    return loaded;
}

void checked(int failed, const char* message) {
    if (failed) throw Error(message);
}

}  // namespace

void check_output(const std::string& path) {
    if (dump_output(path)) return;
    char message[1024] = {};
    checked(tools(path).check(path.c_str(), message, sizeof message), message);
}

void write_output(const Image& image, const std::string& path, const glm::dvec4& background) {
    if (dump_output(path)) return write_dump(image, path);
    const double bg[4] = {background.r, background.g, background.b, background.a};
    char message[1024] = {};
    checked(tools(path).write(&image, path.c_str(), bg, message, sizeof message), message);
}

}  // namespace volref::mpi
