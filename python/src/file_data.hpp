// What a .fft carries besides its points, for fiblet.load(data=True),
// read_streamlines and load_sft: the DATA chunk's arrays (formats/fft-data.md)
// as numpy arrays, the reference space its PROP keys hold, and, for subsets,
// each fiber's point count (to find a fiber's rows of the per-point arrays).
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "fiblet/block_index.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/streamline_field.hpp"

namespace fiblet::python {

// A field as a (rows, components) numpy array of its own dtype (a copy).
pybind11::array field_array(const StreamlineField& f);

// {"fields": {name: array}, "space": None or {"voxel_to_rasmm" (4, 4)
// float64, "dimensions" (3,) int64, "voxel_sizes" (3,) float64,
// "voxel_order" str}, "fibers", "points", "fiber_points": (F,) int64 from
// `index` (None without one)}.
pybind11::dict file_data(const FftFile& file, const BlockIndex* index);

}  // namespace fiblet::python
