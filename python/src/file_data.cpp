#include "file_data.hpp"

#include <cstring>
#include <string>
#include <vector>

#include "fiblet/tractogram_space.hpp"

namespace py = pybind11;

namespace fiblet::python {

// numpy's dtype names are the field type names ("float16", "uint32", ...).
py::array field_array(const StreamlineField& f) {
    py::array a(py::dtype(field_type_name(f.type)), std::vector<py::ssize_t>{py::ssize_t(f.rows()), py::ssize_t(f.components)});
    std::memcpy(a.mutable_data(), f.bytes.data(), f.bytes.size());
    return a;
}

namespace {

py::object space_dict(const FftFile& file) {
    const std::optional<TractogramSpace> space = space_from_properties(file.properties(), file.path());
    if (!space) return py::none();
    py::array_t<double> affine({4, 4});
    std::memcpy(affine.mutable_data(), space->voxel_to_rasmm.data(), sizeof(double) * 16);
    py::array_t<std::int64_t> dimensions(3);
    py::array_t<double> voxel_sizes(3);
    for (int k = 0; k < 3; ++k)
        dimensions.mutable_at(k) = space->dimensions[k], voxel_sizes.mutable_at(k) = space->voxel_sizes[k];
    py::dict d;
    d["voxel_to_rasmm"] = affine, d["dimensions"] = dimensions, d["voxel_sizes"] = voxel_sizes;
    d["voxel_order"] = space->voxel_order;
    return d;
}

}  // namespace

py::dict file_data(const FftFile& file, const BlockIndex* index) {
    py::dict fields;
    for (const StreamlineField& f : file.streamline_fields()) fields[py::str(f.name)] = field_array(f);
    py::dict d;
    d["fields"] = fields;
    d["space"] = space_dict(file);
    d["fibers"] = file.header().fibers, d["points"] = file.header().points;
    if (index) {
        py::array_t<std::int64_t> points(py::ssize_t(index->fibers()));
        for (std::uint64_t f = 0; f < index->fibers(); ++f) points.mutable_at(py::ssize_t(f)) = std::int64_t(index->fiber_points(f));
        d["fiber_points"] = points;
    } else {
        d["fiber_points"] = py::none();
    }
    return d;
}

}  // namespace fiblet::python
