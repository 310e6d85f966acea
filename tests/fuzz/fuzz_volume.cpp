// libFuzzer target for one volume reader: the input is a whole file of format VOLREF_FUZZ_FORMAT
// (named "input" + VOLREF_FUZZ_EXTENSION), read through read_volume as `volref render` reads it.
// tests/fuzz/CMakeLists.txt builds one executable per format.
#include "core/Error.h"
#include "core/io/VolumeReader.h"
#include "tests/fuzz/FuzzTarget.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto path = volref::fuzz::input_file(data, size, std::string("input") + VOLREF_FUZZ_EXTENSION);
    try {
        const volref::Volume v = volref::read_volume(path, VOLREF_FUZZ_FORMAT);
        (void)v.value_range();
    } catch (const volref::Error&) {
    }
    return 0;
}
