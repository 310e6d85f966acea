// libFuzzer target for the tetrahedral bounds reader (geometry/TetrahedralMesh.h: VTK legacy
// UNSTRUCTURED_GRID, ASCII or BINARY, both cell layouts): the input is a whole file named "input.vtk",
// read, oriented and turned into its union's closed boundary as a scene's volume.bounds type
// "tetrahedra" is.
#include "core/Error.h"
#include "geometry/TetrahedralMesh.h"
#include "tests/fuzz/FuzzTarget.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto path = volref::fuzz::input_file(data, size, "input.vtk");
    try {
        (void)volref::read_tetrahedral_bounds(path.string());
    } catch (const volref::Error&) {
    }
    return 0;
}
