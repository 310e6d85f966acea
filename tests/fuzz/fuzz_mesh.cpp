// libFuzzer target for a bounding-mesh reader (OBJ through tinyobjloader, PLY by geometry/PlyReader): the
// input is a whole mesh file named "input" + VOLREF_FUZZ_EXTENSION, read and checked for closedness
// as a scene's bounds.mesh is.
#include "core/Error.h"
#include "geometry/TriangleMesh.h"
#include "tests/fuzz/FuzzTarget.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto path = volref::fuzz::input_file(data, size, std::string("input") + VOLREF_FUZZ_EXTENSION);
    try {
        (void)volref::read_closed_mesh(path.string());
    } catch (const volref::Error&) {
    }
    return 0;
}
