#include "core/film/ImageFileModule.h"

#include <dlfcn.h>

#include <filesystem>

#include "core/Error.h"

namespace volref::image_files {

namespace {

constexpr const char* kModuleName = "libvolref_image_files.so";

struct Module {
    int (*write)(const WriteRequest*, char*, std::size_t) = nullptr;
    int (*read)(const char*, ReadResult*, char*, std::size_t) = nullptr;
    std::string failure;  // why it could not be loaded (empty when loaded)
};

// The folder this library was loaded from (dladdr on one of its own functions).
std::filesystem::path own_folder() {
    Dl_info info{};
    if (dladdr(reinterpret_cast<const void*>(&own_folder), &info) == 0 || !info.dli_fname) return {};
    return std::filesystem::path(info.dli_fname).parent_path();
}

Module load() {
    Module m;
    const std::filesystem::path beside = own_folder() / kModuleName;
    void* library = dlopen(beside.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!library) {
        const char* why = dlerror();
        m.failure = why ? std::string(why) : beside.string() + ": cannot be loaded";
        return m;
    }
    auto version = reinterpret_cast<int (*)()>(dlsym(library, "volref_image_files_version"));
    m.write = reinterpret_cast<decltype(m.write)>(dlsym(library, "volref_image_files_write"));
    m.read = reinterpret_cast<decltype(m.read)>(dlsym(library, "volref_image_files_read"));
    if (!version || !m.write || !m.read) {
        m.failure = beside.string() + " lacks the image-file entry points";
    } else if (version() != kInterfaceVersion) {
        m.failure = beside.string() + " is interface version " + std::to_string(version()) + ", this libvolref_tools needs " +
                    std::to_string(kInterfaceVersion) + " (a mixed installation)";
    }
    if (!m.failure.empty()) m.write = nullptr, m.read = nullptr;
    return m;  // the library stays loaded for the process' life
}

const Module& module() {
    static const Module m = load();  // once, thread-safe
    return m;
}

const Module& loaded(const std::string& shown_path) {
    const Module& m = module();
    if (!m.failure.empty()) throw Error(shown_path + ": image files need the plugin " + std::string(kModuleName) + " beside libvolref_tools: " + m.failure);
    return m;
}

}  // namespace

void require(const std::string& shown_path) { loaded(shown_path); }

void write(const WriteRequest& request, const std::string& shown_path) {
    const Module& m = loaded(shown_path);
    char error[512] = {};
    if (m.write(&request, error, sizeof error) != 0) throw Error(shown_path + ": " + error);
}

ReadImage read(const std::string& path) {
    const Module& m = loaded(path);
    ReadImage image;
    ReadResult result;
    result.owner = &image;
    result.add_channel_name = [](void* owner, const char* name) { static_cast<ReadImage*>(owner)->channels.emplace_back(name); };
    result.pixels = [](void* owner, std::size_t count) {
        auto& px = static_cast<ReadImage*>(owner)->pixels;
        px.assign(count, 0.0);
        return px.data();
    };
    char error[512] = {};
    if (m.read(path.c_str(), &result, error, sizeof error) != 0) throw Error(path + ": " + error);
    image.width = result.width;
    image.height = result.height;
    image.bits = result.bits;
    image.unassociated_alpha = result.unassociated_alpha != 0;
    return image;
}

}  // namespace volref::image_files
