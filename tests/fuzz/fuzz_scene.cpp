// libFuzzer target for the scene parser: the input is a scene file's text (parse_scene, as
// `volref render` reads it). Only the parser runs; nothing is rendered.
#include "core/Error.h"
#include "core/scene/SceneLoader.h"
#include "tests/fuzz/FuzzTarget.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        (void)volref::parse_scene(text, volref::fuzz::scratch_folder(), "fuzz.json");
    } catch (const volref::Error&) {
    }
    return 0;
}
