// Reading NIfTI-1 and NIfTI-2 images (.nii, .nii.gz, .hdr + .img) into a Volume. nifti_clib
// (libnifti2-dev) reads the header: both versions, either byte order, gzip, the qform and sform
// matrices. volref then reads the image bytes itself and decodes them through ByteDecoding.h, so a
// short file is reported in bytes like every other format.
//
// Orientation: the sform is used when sform_code > 0, else the qform when qform_code > 0, else
// pixdim alone (origin 0). The matrix must be axis-aligned (each voxel axis along one world axis,
// within 1e-6 of its largest entry): flips and permutations are applied by reordering the samples so
// that the volume's axes are world x, y, z (RAS+, mm) with positive spacing, and every voxel keeps its
// world position. An oblique matrix is an error (volref's grids are axis-aligned; resample it first).
// scl_slope / scl_inter, when not 0 or the identity, are applied (the volume's type becomes f64).
// Only 3-D scalar images: dims 4..7 must be 1. docs/formats.md lists every error.
#pragma once
#include <filesystem>

#include "core/grid/Volume.h"

namespace volref {

Volume read_nifti(const std::filesystem::path& path);

// NIfTI's scaling of stored samples: every value becomes slope * stored + inter, as f64 (the volume's
// type becomes F64). read_nifti and volref-mpi's brick reader (VolumeLayout::scaled) apply it; the
// caller checks the memory for the f64 copy first.
void scale_samples(Volume& volume, double slope, double inter);

}  // namespace volref
