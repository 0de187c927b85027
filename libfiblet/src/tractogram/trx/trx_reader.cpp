// TRX reader: header.json and offsets at open, positions streamed, data
// arrays (dps/, dpv/, groups/, dpg/) read whole and checked.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/bytes.hpp"
#include "core/finite_points.hpp"
#include "core/streamline_label.hpp"
#include "fiblet/error.hpp"
#include "fiblet/source_dtypes.hpp"
#include "fiblet/tractogram_format.hpp"
#include "fiblet/trx.hpp"
#include "tractogram/trx/trx_archive.hpp"

namespace fiblet {
namespace {

using detail::TrxEntryName;

[[noreturn]] void bad(const std::string& path, const std::string& what) {
    throw Error(Errc::trx_format, path + ": not a valid TRX file: " + what);
}

// Counts no file can hold more of: sizes computed from them (count x 3 x 8
// bytes) stay far from overflowing 64 bits.
constexpr std::uint64_t kMaxCount = std::uint64_t(1) << 56;

// A JSON count: an integer in [0, max] (a float only where it is one
// exactly), checked before any cast.
std::uint64_t json_count(const nlohmann::json& v, const char* key, std::uint64_t max, const std::string& path) {
    if (v.is_number_unsigned() && v.get<std::uint64_t>() <= max) return v.get<std::uint64_t>();
    if (v.is_number_integer() && v.get<std::int64_t>() >= 0 && std::uint64_t(v.get<std::int64_t>()) <= max)
        return std::uint64_t(v.get<std::int64_t>());
    if (v.is_number_float()) {
        const double x = v.get<double>();
        if (x >= 0 && x <= double(max) && x == std::floor(x)) return std::uint64_t(x);
    }
    bad(path, std::string("header.json: ") + key + " is " + v.dump() + ", not an integer in [0, " + std::to_string(max) + "]");
}

struct TrxHeaderJson {
    Affine affine{};
    std::array<int, 3> dimensions{};
    std::uint64_t streamlines = 0, vertices = 0;
};

TrxHeaderJson parse_header(const std::vector<std::uint8_t>& text, const std::string& path) {
    TrxHeaderJson h;
    try {
        // header.json is two levels deep; a file of nested '[' made the
        // parser build ~80 bytes per level (16 MiB of them: 1.3 GB).
        constexpr int kMaxDepth = 32;
        const auto shallow = [&](int depth, nlohmann::json::parse_event_t, nlohmann::json&) {
            if (depth > kMaxDepth) bad(path, "header.json nests deeper than " + std::to_string(kMaxDepth) + " levels");
            return true;
        };
        const auto j = nlohmann::json::parse(text.begin(), text.end(), shallow);
        const auto& m = j.at("VOXEL_TO_RASMM");
        if (!m.is_array() || m.size() != 4) bad(path, "header.json: VOXEL_TO_RASMM is not 4 rows");
        for (std::size_t r = 0; r < 4; ++r) {
            if (!m[r].is_array() || m[r].size() != 4) bad(path, "header.json: VOXEL_TO_RASMM is not 4 x 4");
            for (std::size_t c = 0; c < 4; ++c) h.affine[4 * r + c] = m[r][c].get<double>();
        }
        const auto& d = j.at("DIMENSIONS");
        if (!d.is_array() || d.size() != 3) bad(path, "header.json: DIMENSIONS is not 3 numbers");
        for (std::size_t k = 0; k < 3; ++k) h.dimensions[k] = int(json_count(d[k], "DIMENSIONS", 65535, path));
        h.streamlines = json_count(j.at("NB_STREAMLINES"), "NB_STREAMLINES", kMaxCount, path);
        h.vertices = json_count(j.at("NB_VERTICES"), "NB_VERTICES", kMaxCount, path);
    } catch (const nlohmann::json::exception& e) {
        bad(path, std::string("header.json: ") + e.what());
    }
    // Finite, and within float32 (the affine and its voxel sizes are stored as floats).
    for (double x : h.affine)
        if (!(std::fabs(x) <= double(std::numeric_limits<float>::max())))
            bad(path, "header.json: VOXEL_TO_RASMM holds " + std::to_string(x) + ", not a float32 number");
    return h;
}

FieldType dtype(const TrxEntryName& n, const std::string& entry, const std::string& path) {
    const auto t = field_type_from_name(n.dtype);
    if (!t)
        throw Error(Errc::unsupported, path + ": TRX entry " + entry + ": dtype \"" + n.dtype +
                                           "\" is not supported (fiblet reads (u)int8-64 and float16-64)");
    return *t;
}

}  // namespace

struct TrxReader::Impl {
    std::string path;
    SourceOptions options;
    std::uint64_t budget_used = 0;  // the arrays read so far and the offsets table
    std::unique_ptr<detail::TrxArchive> archive;
    TrxHeaderJson header;
    TractogramSpace space;
    std::string positions_entry;
    FieldType positions_type = FieldType::float32, offsets_type = FieldType::uint64;
    std::vector<std::uint64_t> offsets;  // NB_STREAMLINES + 1
    std::vector<StreamlineField> fields;
    std::unique_ptr<detail::TrxEntryStream> positions;
    std::uint64_t next_fiber = 0;
    std::vector<std::uint8_t> raw;

    void read_offsets(const std::string& entry, const TrxEntryName& n) {
        const FieldType t = dtype(n, entry, path);
        if ((t != FieldType::uint32 && t != FieldType::uint64) || n.components != 1)
            bad(path, entry + ": offsets must be uint32 or uint64");
        offsets_type = t;
        const std::size_t size = field_type_size(t);
        const std::uint64_t stored = archive->size(entry);
        if (stored != header.streamlines * size && stored != (header.streamlines + 1) * size)
            bad(path, entry + " holds " + std::to_string(stored) + " bytes for NB_STREAMLINES = " +
                          std::to_string(header.streamlines));
        draw_from_budget(stored + 8 * (header.streamlines + 1), entry);  // the entry, then its 64-bit table
        const auto bytes = archive->read_all(entry);
        const std::uint64_t count = bytes.size() / size;
        if (bytes.size() % size || (count != header.streamlines && count != header.streamlines + 1))
            bad(path, entry + " holds " + std::to_string(bytes.size()) + " bytes for NB_STREAMLINES = " +
                          std::to_string(header.streamlines));
        offsets.reserve(count + 1);  // the sentinel below must not double the table
        offsets.resize(count);
        for (std::uint64_t i = 0; i < count; ++i) {  // integers as stored (a double is not exact above 2^53)
            if (t == FieldType::uint64) std::memcpy(&offsets[i], &bytes[i * 8], 8);
            else offsets[i] = detail::get_le<std::uint32_t>(&bytes[i * 4]);
        }
        if (count == header.streamlines) offsets.push_back(header.vertices);  // no sentinel (older writers)
        if (offsets.back() != header.vertices)
            bad(path, entry + ": the last offset is " + std::to_string(offsets.back()) + ", NB_VERTICES " +
                          std::to_string(header.vertices));
        if (!offsets.empty() && offsets[0] != 0) bad(path, entry + ": the first offset is not 0");
        for (std::size_t i = 1; i < offsets.size(); ++i)
            if (offsets[i] < offsets[i - 1])
                bad(path, entry + ": offsets decrease at " + detail::streamline_label(i - 1));
    }

    // Every array is counted (decompressed size) before it is read: a small
    // zip can hold gigabytes of zeros.
    void draw_from_budget(std::uint64_t bytes, const std::string& entry) {
        budget_used += bytes;
        if (options.max_memory && budget_used > options.max_memory)
            throw Error(Errc::unsupported,
                        path + ": its arrays take " + std::to_string(budget_used >> 20) + " MiB and more (" + entry +
                            " included), more than the memory budget of " + std::to_string(options.max_memory >> 20) +
                            " MiB",
                        Remedy::max_memory);
    }

    // Before reading an array: the size its rows must have (dps, dpv), or a
    // bound (a group lists each streamline at most once; per-group values
    // are few), so that a damaged entry is refused rather than allocated.
    void check_plausible_size(const StreamlineField& f, const std::string& entry) const {
        const std::uint64_t stored = archive->size(entry), row = f.value_size() * f.components;
        const auto scope = *f.scope();
        const std::uint64_t rows = scope == FieldScope::streamline ? header.streamlines : header.vertices;
        const bool ok = scope == FieldScope::group        ? stored <= 4 * header.streamlines
                        : scope == FieldScope::group_data ? stored <= (64u << 20)
                                                          : stored / row == rows && stored % row == 0;
        if (!ok) bad(path, entry + ": " + std::to_string(stored) + " bytes do not fit NB_STREAMLINES = " +
                               std::to_string(header.streamlines) + ", NB_VERTICES = " + std::to_string(header.vertices));
    }

    void read_entries() {
        std::string offsets_entry;
        TrxEntryName offsets_name;
        for (const std::string& entry : archive->entries()) {
            if (entry == "header.json") continue;
            const auto n = detail::parse_trx_entry_name(entry);
            if (!n) bad(path, "entry " + entry + " has no dtype extension");
            if (n->name == "positions") {
                if (!positions_entry.empty()) bad(path, "more than one positions array");
                positions_entry = entry;
                positions_type = dtype(*n, entry, path);
                if (n->components != 3 || !is_float_type(positions_type))
                    bad(path, entry + ": positions must be 3 float16/32/64 components");
            } else if (n->name == "offsets") {
                if (!offsets_entry.empty()) bad(path, "more than one offsets array");
                offsets_entry = entry, offsets_name = *n;
            } else {
                StreamlineField f{n->name, dtype(*n, entry, path), n->components, {}};
                if (!f.scope()) throw Error(Errc::unsupported, path + ": TRX entry " + entry + " is not one fiblet reads");
                // One array per name: dps/w.float32 beside dps/w.float64 would be one field twice.
                for (const StreamlineField& earlier : fields)
                    if (earlier.name == f.name) bad(path, "more than one array named " + f.name + " (" + entry + ")");
                check_plausible_size(f, entry);
                draw_from_budget(archive->size(entry), entry);
                f.bytes = archive->read_all(entry);
                const std::string problem = check_streamline_field(f, header.streamlines, header.vertices);
                if (!problem.empty()) bad(path, problem);
                fields.push_back(std::move(f));
            }
        }
        if (positions_entry.empty()) bad(path, "no positions array");
        if (offsets_entry.empty()) bad(path, "no offsets array");
        const std::uint64_t expect = header.vertices * 3 * field_type_size(positions_type);
        if (archive->size(positions_entry) != expect)
            bad(path, positions_entry + " holds " + std::to_string(archive->size(positions_entry)) + " bytes, " +
                          std::to_string(expect) + " for NB_VERTICES = " + std::to_string(header.vertices));
        read_offsets(offsets_entry, offsets_name);
    }

    bool next(std::vector<Vec3f>& points) {
        points.clear();
        if (next_fiber + 1 >= offsets.size()) return false;
        if (!positions) positions = archive->stream(positions_entry);
        const std::uint64_t n = offsets[next_fiber + 1] - offsets[next_fiber];
        if (options.max_points && n > options.max_points)
            throw Error(Errc::unsupported, path + ": " + detail::streamline_label(next_fiber) + " has " +
                                               std::to_string(n) + " points (at most " +
                                               std::to_string(options.max_points) + " supported)");
        const std::size_t size = field_type_size(positions_type);
        raw.resize(std::size_t(n) * 3 * size);
        if (!raw.empty()) positions->read(raw.data(), raw.size());
        points.resize(std::size_t(n));
        if (n == 0) return ++next_fiber, true;
        float* out = &points.data()->x;
        if (positions_type == FieldType::float32) std::memcpy(out, raw.data(), raw.size());
        else
            for (std::size_t i = 0; i < 3 * n; ++i) out[i] = narrow_to_float(field_value(positions_type, &raw[i * size]));
        if (const auto k = detail::first_non_finite(points))
            bad(path, detail::streamline_label(next_fiber) + " " + detail::non_finite_point_message(points, *k));
        ++next_fiber;
        return true;
    }
};

TrxReader::TrxReader(const std::string& path, const SourceOptions& options) : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    m.path = path;
    m.options = options;
    m.archive = detail::TrxArchive::open(path);
    const auto entries = m.archive->entries();
    if (std::find(entries.begin(), entries.end(), "header.json") == entries.end()) {
        // A zip of another kind, unless it says it is TRX (by its name, or as a directory given to the reader).
        if (detect_tractogram_format(path) == TractogramFormat::zip_other)
            throw Error(Errc::unsupported, path + ": " + tractogram_format_description(TractogramFormat::zip_other) +
                                               ": not a TRX tractogram");
        bad(path, "no header.json");
    }
    if (m.archive->size("header.json") > (16u << 20)) bad(path, "header.json is larger than 16 MiB");
    m.header = parse_header(m.archive->read_all("header.json"), path);
    m.space = TractogramSpace::from_affine(m.header.affine, m.header.dimensions);
    m.read_entries();
}

TrxReader::~TrxReader() = default;
const std::string& TrxReader::path() const { return impl_->path; }
const TractogramSpace& TrxReader::space() const { return impl_->space; }
std::uint64_t TrxReader::streamline_count() const { return impl_->header.streamlines; }
std::uint64_t TrxReader::point_count() const { return impl_->header.vertices; }

Properties TrxReader::properties() const {
    Properties p;
    add_space_properties(p, impl_->space);
    add_trx_dtype_properties(p, impl_->positions_type, impl_->offsets_type);  // what a .fft cannot keep otherwise
    return p;
}

bool TrxReader::next(std::vector<Vec3f>& points) { return impl_->next(points); }
void TrxReader::rewind() {
    impl_->positions.reset();
    impl_->next_fiber = 0;
}
std::vector<StreamlineField> TrxReader::take_fields() { return std::move(impl_->fields); }
std::uint64_t TrxReader::bytes_consumed() const {
    return impl_->offsets.empty() ? 0 : impl_->offsets[impl_->next_fiber] * 3 * field_type_size(impl_->positions_type);
}
std::uint64_t TrxReader::data_bytes() const { return impl_->header.vertices * 3 * field_type_size(impl_->positions_type); }

}  // namespace fiblet
