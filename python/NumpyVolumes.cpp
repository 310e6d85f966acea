#include "python/NumpyVolumes.h"

#include <bit>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <system_error>

#include <nlohmann/json.hpp>
#include <pybind11/numpy.h>

#include "core/Error.h"

namespace py = pybind11;

namespace volref::python {

namespace fs = std::filesystem;

TempDir::~TempDir() {
    if (path_.empty()) return;
    std::error_code ec;
    fs::remove_all(path_, ec);
}

const fs::path& TempDir::path() {
    if (!path_.empty()) return path_;
    std::error_code ec;
    const fs::path base = fs::temp_directory_path(ec);
    if (ec) throw Error("cannot find a temporary folder for the numpy volumes: " + ec.message() + " (set TMPDIR)");
    std::string pattern = (base / "volref-py-XXXXXX").string();
    if (!::mkdtemp(pattern.data()))
        throw Error(base.string() + ": cannot create a temporary folder for the numpy volumes: " + std::strerror(errno) +
                    " (set TMPDIR)");
    path_ = pattern;
    return path_;
}

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

void write_numpy_volume(py::handle handle, const std::string& key, const fs::path& file) {
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
    // Byte order: '>' big-endian, '<' little, '=' native, '|' not applicable (1 byte).
    const char order = dt.attr("byteorder").cast<std::string>().at(0);
    const bool big = order == '>' || (order == '=' && std::endian::native == std::endian::big);
    // C order (x fastest) is written as it is; any other layout (a transposed view, a slice with
    // steps, Fortran order) is first copied into C order by numpy.
    if (!(array.flags() & py::array::c_style))
        array = py::module_::import("numpy").attr("ascontiguousarray")(array).cast<py::array>();

    nlohmann::json sidecar;
    sidecar["dims"] = {nx, ny, nz};
    sidecar["type"] = type;
    sidecar["endian"] = big ? "big" : "little";
    const std::string sidecar_text = sidecar.dump();
    const char* data = static_cast<const char*>(array.data());
    const std::size_t bytes = std::size_t(array.nbytes());

    std::string failure;
    {
        py::gil_scoped_release release;  // `array` stays referenced (and so unchanged) by this frame
        auto write = [&](const fs::path& path, const char* p, std::size_t n) {
            std::FILE* f = std::fopen(path.c_str(), "wb");
            if (!f) return std::string(std::strerror(errno));
            const std::size_t written = n ? std::fwrite(p, 1, n, f) : 0;
            const int err = written == n ? 0 : errno;
            if (std::fclose(f) != 0 && err == 0) return std::string(std::strerror(errno));
            if (written != n) return std::string(err ? std::strerror(err) : "short write");
            return std::string();
        };
        failure = write(file, data, bytes);
        if (failure.empty()) {
            fs::path side = file;
            side += ".json";
            failure = write(side, sidecar_text.data(), sidecar_text.size());
        }
    }
    if (!failure.empty())
        throw Error(key + ": cannot write the numpy array to the temporary file " + file.string() + ": " + failure +
                    " (set TMPDIR to a folder with room)");
}

}  // namespace volref::python
