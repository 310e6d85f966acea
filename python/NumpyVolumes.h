// Numpy arrays as volume sources (docs/python.md, "Numpy volumes").
//
// Axis order: array[k, j, i] is voxel (i, j, k), i.e. shape (nz, ny, nx) in C order, so that x (i)
// varies fastest in memory, as volref's VoxelArray stores it (core/grid/Volume.h). dtypes: the eight
// volref holds, uint8, int8, uint16, int16, uint32, int32, float32, float64, in either byte order;
// anything else (complex, bool, int64, float16, object, ...) is refused with a volref::Error naming
// the scene key. NaN and infinite values are allowed (rendered transparent, docs/accuracy.md).
//
// The core reads volumes from files or procedural fields only, so an array is written once to a raw
// file with its JSON sidecar (docs/formats.md) in a private temporary folder, the scene points at it,
// and volref's raw reader reads it as it reads any raw file; the folder is removed when the call
// returns (TempDir).
#pragma once
#include <filesystem>
#include <string>

#include <pybind11/pybind11.h>

namespace volref::python {

// A private folder under std::filesystem::temp_directory_path() ($TMPDIR, else /tmp), created on first
// use and removed with everything in it by the destructor.
class TempDir {
public:
    TempDir() = default;
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    ~TempDir();
    const std::filesystem::path& path();  // creates it; throws volref::Error if it cannot
    bool created() const { return !path_.empty(); }

private:
    std::filesystem::path path_;
};

// True for a numpy.ndarray.
bool is_ndarray(pybind11::handle h);

// Checks `array` (a numpy.ndarray) and writes it as `file` (raw samples) + `file`.json (sidecar).
// `key` names the scene key in messages, e.g. "scene: volume.source". Holds the GIL on entry; releases
// it while writing the bytes. Throws volref::Error.
void write_numpy_volume(pybind11::handle array, const std::string& key, const std::filesystem::path& file);

}  // namespace volref::python
