// The source dtypes a .fft records in PROP, and the dtypes an output gets back.
#include "fiblet/source_dtypes.hpp"

#include <cstring>
#include <limits>
#include <map>
#include <optional>

namespace fiblet {
namespace {

constexpr const char* kPositions = "trx_positions_dtype";
constexpr const char* kOffsets = "trx_offsets_dtype";
constexpr const char* kSource = "source_dtype";

// A float32 array as `to` (float16 or float64), values as they are.
void convert_floats(StreamlineField& f, FieldType to) {
    std::vector<std::uint8_t> out(std::size_t(f.values()) * field_type_size(to));
    for (std::uint64_t k = 0; k < f.values(); ++k) {
        float v;
        std::memcpy(&v, &f.bytes[k * 4], 4);
        if (to == FieldType::float64) {
            const double d = v;
            std::memcpy(&out[k * 8], &d, 8);
        } else {
            const std::uint16_t h = float_to_half(v);
            std::memcpy(&out[k * 2], &h, 2);
        }
    }
    f.bytes = std::move(out);
    f.type = to;
}

}  // namespace

void add_trx_dtype_properties(Properties& properties, FieldType positions, FieldType offsets) {
    properties.emplace_back(kPositions, field_type_name(positions));
    properties.emplace_back(kOffsets, field_type_name(offsets));
}

void add_source_dtype_property(Properties& properties, const std::string& array, FieldType source) {
    properties.emplace_back(kSource, std::string(field_type_name(source)) + " " + array);
}

bool is_source_dtype_property(const std::string& key) noexcept {
    return key == kPositions || key == kOffsets || key == kSource;
}

std::vector<DtypeChange> restore_source_dtypes(SinkHeader& header, TractogramFormat format) {
    std::optional<FieldType> positions, offsets;
    std::map<std::string, FieldType> sources;
    for (const auto& [key, value] : header.properties) {
        if (key == kPositions) {
            const auto t = field_type_from_name(value);
            if (t && is_float_type(*t)) positions = t;
        } else if (key == kOffsets) {
            const auto t = field_type_from_name(value);
            if (t == FieldType::uint32 || t == FieldType::uint64) offsets = t;
        } else if (key == kSource) {
            const auto space = value.find(' ');
            if (space == std::string::npos) continue;
            if (const auto t = field_type_from_name(std::string_view(value).substr(0, space)))
                sources[value.substr(space + 1)] = *t;
        }
    }
    std::vector<DtypeChange> changes;
    const bool trx = format == TractogramFormat::trx;
    header.positions_type = FieldType::float32;
    header.offsets_type = FieldType::uint64;
    if (positions && *positions != FieldType::float32) {
        if (trx) header.positions_type = *positions;
        else
            changes.push_back({"positions", *positions, FieldType::float32,
                               format == TractogramFormat::trk ? "a .trk holds float32 points"
                                                               : "a .tck is written as Float32LE"});
    }
    if (trx && offsets == FieldType::uint32) {
        if (header.points <= std::numeric_limits<std::uint32_t>::max()) header.offsets_type = FieldType::uint32;
        else changes.push_back({"offsets", FieldType::uint32, FieldType::uint64, "more points than uint32 offsets hold"});
    }
    for (StreamlineField& f : header.fields) {
        const auto it = sources.find(f.name);
        const FieldType source = it != sources.end() && f.type == FieldType::float32 ? it->second : f.type;
        if (!trx) {  // a .trk writes per-streamline and per-point values (and refuses the rest)
            const auto scope = f.scope();
            if (source != FieldType::float32 && (scope == FieldScope::streamline || scope == FieldScope::point))
                changes.push_back({f.name, source, FieldType::float32, "a .trk holds float32 values"});
        } else if (source != f.type) {
            if (is_float_type(source)) convert_floats(f, source);
            else
                changes.push_back({f.name, source, f.type, "interpolated on the resampled points, kept as float32"});
        }
    }
    return changes;
}

}  // namespace fiblet
