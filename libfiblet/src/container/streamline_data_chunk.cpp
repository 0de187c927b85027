// The DATA trailer chunk: streamline fields as (name, dtype, components, bytes).
#include "fiblet/streamline_data_chunk.hpp"

#include <set>

#include "core/bytes.hpp"
#include "fiblet/error.hpp"

namespace fiblet {

using detail::get_le;
using detail::put_le;

TrailerChunk make_streamline_data_chunk(const std::vector<StreamlineField>& fields) {
    TrailerChunk c{kStreamlineDataTag, {}};
    std::size_t size = 4;  // reserved whole: growing by doubling would hold two payloads at once
    for (const StreamlineField& f : fields) size += 4 + f.name.size() + 4 + 4 + 8 + f.bytes.size();
    c.payload.reserve(size);
    put_le<std::uint32_t>(c.payload, std::uint32_t(fields.size()));
    for (const StreamlineField& f : fields) {
        put_le<std::uint32_t>(c.payload, std::uint32_t(f.name.size()));
        c.payload.insert(c.payload.end(), f.name.begin(), f.name.end());
        const std::uint8_t type_and_reserved[4] = {std::uint8_t(f.type), 0, 0, 0};
        c.payload.insert(c.payload.end(), type_and_reserved, type_and_reserved + 4);
        put_le<std::uint32_t>(c.payload, f.components);
        put_le<std::uint64_t>(c.payload, f.bytes.size());
        c.payload.insert(c.payload.end(), f.bytes.begin(), f.bytes.end());
    }
    return c;
}

std::vector<StreamlineField> parse_streamline_data_chunk(const TrailerChunk& c, std::uint64_t fibers,
                                                         std::uint64_t points, const std::string& path) {
    const auto& p = c.payload;
    auto bad = [&](const std::string& what) -> void {
        throw Error(Errc::fft_format, path + ": not a valid .fft file: DATA chunk: " + what);
    };
    std::size_t pos = 0;
    auto need = [&](std::uint64_t n, const char* what) {
        if (p.size() - pos < n) bad(std::string("truncated ") + what);
    };
    need(4, "field count");
    const std::uint32_t count = get_le<std::uint32_t>(&p[pos]);
    pos += 4;
    std::vector<StreamlineField> fields;
    std::set<std::string> names;
    for (std::uint32_t i = 0; i < count; ++i) {
        StreamlineField f;
        need(4, "name length");
        const std::uint32_t n = get_le<std::uint32_t>(&p[pos]);
        pos += 4;
        need(n, "name");
        f.name.assign(reinterpret_cast<const char*>(&p[pos]), n);
        pos += n;
        need(16, "field header");
        const auto type = field_type_name(FieldType(p[pos]));
        if (std::string(type) == "?" || p[pos + 1] || p[pos + 2] || p[pos + 3])
            bad("\"" + f.name + "\" has an unknown value type " + std::to_string(p[pos]));
        f.type = FieldType(p[pos]);
        f.components = get_le<std::uint32_t>(&p[pos + 4]);
        const std::uint64_t bytes = get_le<std::uint64_t>(&p[pos + 8]);
        pos += 16;
        need(bytes, "values");
        f.bytes.assign(p.begin() + std::ptrdiff_t(pos), p.begin() + std::ptrdiff_t(pos + bytes));
        pos += bytes;
        const std::string problem = check_streamline_field(f, fibers, points);
        if (!problem.empty()) bad(problem);
        if (!names.insert(f.name).second) bad("\"" + f.name + "\" appears twice");
        fields.push_back(std::move(f));
    }
    if (pos != p.size()) bad(std::to_string(p.size() - pos) + " bytes after the last field");
    return fields;
}

}  // namespace fiblet
