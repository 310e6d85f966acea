// Numpy arrays as volume sources (docs/python.md, "Numpy volumes").
//
// Axis order: array[k, j, i] is voxel (i, j, k), i.e. shape (nz, ny, nx) in C order, so that x (i)
// varies fastest in memory, as volref's VoxelArray stores it (core/grid/Volume.h). dtypes: the eight
// volref holds, uint8, int8, uint16, int16, uint32, int32, float32, float64, in either byte order;
// anything else (complex, bool, int64, float16, object, ...) is refused with a volref::Error naming
// the scene key. NaN and infinite values are allowed (rendered transparent, docs/accuracy.md).
//
// The array is copied once into a Volume (core/grid/Volume.h) in its own type, and the scene's volume
// holds it in memory (VolumeSourceSpec::memory): no file is written or read.
#pragma once
#include <memory>

#include "core/grid/Volume.h"
#include <filesystem>
#include <string>

#include <pybind11/pybind11.h>

namespace volref::python {

// True for a numpy.ndarray.
bool is_ndarray(pybind11::handle h);

// Checks `array` (a numpy.ndarray) and copies it into a Volume (dims nx, ny, nz; origin 0, spacing 1:
// read_scene_input sets the scene's origin and spacing in it). `key` names the scene key in messages, e.g. "scene:
// volume.source". Holds the GIL. Throws volref::Error.
std::shared_ptr<Volume> numpy_volume(pybind11::handle array, const std::string& key);

}  // namespace volref::python
