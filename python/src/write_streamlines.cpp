#include "write_streamlines.hpp"

#include <vector>

#include "fiblet/error.hpp"
#include "fiblet/tractogram_format.hpp"
#include "fiblet/tractogram_space.hpp"

namespace fiblet::python {

void require_streamline_output(const std::string& path) {
    if (!is_streamline_format(format_from_extension(path)))
        throw Error(Errc::invalid_argument, path + ": streamlines are written to .tck, .trk or .trx files");
}

void write_streamlines(const std::string& path, const float* xyz, std::span<const std::int64_t> offsets,
                       const Properties& properties, bool overwrite) {
    require_streamline_output(path);
    SinkHeader header;
    header.properties = properties;
    header.fibers = offsets.size() - 1;
    header.points = std::uint64_t(offsets.back());
    const auto sink = open_streamline_sink(path, header, overwrite);
    for (std::size_t i = 0; i + 1 < offsets.size(); ++i)
        sink->write(xyz + 3 * offsets[i], std::size_t(offsets[i + 1] - offsets[i]));
    sink->finish();
}

Conversion convert_streamlines(const std::string& input, const std::string& output, bool overwrite) {
    require_streamline_output(output);
    const auto source = open_streamline_source(input);
    std::vector<float> xyz;
    std::vector<std::uint64_t> offsets{0};
    std::vector<Vec3f> fiber;
    while (source->next(fiber)) {
        for (const Vec3f& p : fiber) xyz.insert(xyz.end(), {p.x, p.y, p.z});
        offsets.push_back(offsets.back() + fiber.size());
    }
    const Properties properties = source->properties();
    SinkHeader header{properties, space_from_properties(properties, input), source->take_fields(),
                      offsets.size() - 1, offsets.back()};
    Conversion c{header.fibers, header.points, 0};
    if (format_from_extension(output) == TractogramFormat::tck) {  // points only
        c.fields_dropped = header.fields.size();
        header.fields.clear();
    }
    const auto sink = open_streamline_sink(output, header, overwrite);
    sink->write_chunk(xyz.data(), offsets);
    sink->finish();
    return c;
}

}  // namespace fiblet::python
