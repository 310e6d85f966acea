#include "python/NumpyVolumes.h"

#include <bit>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <system_error>

#include <nlohmann/json.hpp>
#include <pybind11/numpy.h>

#include "core/MemoryLimit.h"

#include "core/Error.h"

namespace py = pybind11;

namespace volref::python {

namespace fs = std::filesystem;

bool is_ndarray(py::handle h) { return py::isinstance<py::array>(h); }

namespace {

// volref's name of a numpy dtype ("u8" ... "f64"), or "" when volref does not hold that type.
std::string volref_type(const py::dtype& dt) {
    const char kind = dt.kind();
    const auto size = dt.itemsize();
    if (kind == 'u' || kind == 'i') {
        if (size == 1 || size == 2 || size == 4) return std::string(1, kind) + std::to_string(size * 8);
        return "";
    }
    if (kind == 'f' && (size == 4 || size == 8)) return "f" + std::to_string(size * 8);
    return "";
}

}  // namespace

std::shared_ptr<Volume> numpy_volume(py::handle handle, const std::string& key) {
    if (!is_ndarray(handle)) throw Error(key + ": expected a 3-D numpy array");
    py::array array = py::reinterpret_borrow<py::array>(handle);
    if (array.ndim() != 3)
        throw Error(key + ": expected a 3-D numpy array (shape (nz, ny, nx), x fastest), got " +
                    std::to_string(array.ndim()) + (array.ndim() == 1 ? " dimension" : " dimensions"));
    const py::dtype dt = array.dtype();
    const std::string type = volref_type(dt);
    if (type.empty())
        throw Error(key + ": numpy dtype " + std::string(py::str(static_cast<const py::handle&>(dt))) +
                    " is not a volume type volref holds (uint8, int8, uint16, int16, uint32, int32, float32, "
                    "float64); convert the array, e.g. array.astype(numpy.float32)");
    const auto nz = array.shape(0), ny = array.shape(1), nx = array.shape(2);
    if (nx < 1 || ny < 1 || nz < 1)
        throw Error(key + ": the array is empty (shape (" + std::to_string(nz) + ", " + std::to_string(ny) + ", " +
                    std::to_string(nx) + "))");
    // Native byte order and C order (x fastest), as VoxelArray stores its values: numpy converts any
    // other byte order or layout (a transposed view, a slice with steps, Fortran order) first.
    const char order = dt.attr("byteorder").cast<std::string>().at(0);
    const bool swapped = order == '>' ? std::endian::native == std::endian::little : order == '<' && std::endian::native == std::endian::big;
    if (swapped) array = array.attr("astype")(dt.attr("newbyteorder")("=")).cast<py::array>();
    if (!(array.flags() & py::array::c_style))
        array = py::module_::import("numpy").attr("ascontiguousarray")(array).cast<py::array>();
    static const std::pair<const char*, ScalarType> kTypes[] = {{"u8", ScalarType::U8},   {"i8", ScalarType::I8},
                                                                {"u16", ScalarType::U16}, {"i16", ScalarType::I16},
                                                                {"u32", ScalarType::U32}, {"i32", ScalarType::I32},
                                                                {"f32", ScalarType::F32}, {"f64", ScalarType::F64}};
    ScalarType st = ScalarType::F64;
    for (const auto& [name, t] : kTypes)
        if (type == name) st = t;
    const std::size_t count = std::size_t(nx) * std::size_t(ny) * std::size_t(nz);
    check_memory(std::size_t(array.nbytes()), key + " (numpy array): a volume of " + std::to_string(nx) + " x " + std::to_string(ny) +
                                                  " x " + std::to_string(nz));
    auto v = std::make_shared<Volume>();
    v->dims = {nx, ny, nz};
    v->type = st;
    v->values = VoxelArray(st, count);
    std::memcpy(v->values.raw(), array.data(), std::size_t(array.nbytes()));
    return v;
}

}  // namespace volref::python
