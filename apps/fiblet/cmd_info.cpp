// fiblet info FILE — the header of a .fft, .tck, .trk or TRX file.
#include <fmt/core.h>

#include <cstdio>
#include <fstream>

#include "cli_common.hpp"
#include "fiblet/block_index.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/tck.hpp"
#include "fiblet/tractogram_format.hpp"
#include "fiblet/trk.hpp"
#include "fiblet/trx.hpp"

namespace fiblet::cli {
namespace {

struct InfoArgs {
    bool ignore_trailer = false;
    std::string input;
    bool json = false;
};

std::string properties_json(const std::vector<std::pair<std::string, std::string>>& props) {
    std::string out = "[";
    for (std::size_t i = 0; i < props.size(); ++i)
        out += (i ? ", " : "") + fmt::format("[{}, {}]", json_quote(props[i].first), json_quote(props[i].second));
    return out + "]";
}

// ["CSUM", "PROP", ...]: the trailer's chunk tags, in file order.
std::string chunk_tags_json(const FftFile& f) {
    std::string out;
    for (const auto& c : f.trailer()) out += (out.empty() ? "" : ", ") + json_quote(std::string(c.tag.data(), 4));
    return "[" + out + "]";
}

void print_properties(const std::vector<std::pair<std::string, std::string>>& props) {
    for (const auto& [k, v] : props) fmt::print("  {:<22} {}\n", k + ":", v);
}

void info_tck(const InfoArgs& a) {
    const TckHeader h = read_tck_header(a.input);
    if (a.json) {
        fmt::print("{}\n", Json{}
                               .str("file", a.input)
                               .str("format", "tck")
                               .str("datatype", tck_datatype_name(h.datatype))
                               .integer("data_offset", h.data_offset)
                               .raw("properties", properties_json(h.properties))
                               .render());
        return;
    }
    fmt::print("{}: MRtrix3 tracks file, {}, data at byte {}\n", a.input, tck_datatype_name(h.datatype), h.data_offset);
    print_properties(h.properties);
}

std::string fields_text(const std::vector<StreamlineField>& fields) {
    std::string s;
    for (const StreamlineField& f : fields)
        s += (s.empty() ? "" : ", ") + f.name + (f.components > 1 ? fmt::format(" ({} x {})", f.components, field_type_name(f.type))
                                                                  : fmt::format(" ({})", field_type_name(f.type)));
    return s;
}

// A .trk or TRX: streamline count, space, data arrays (its header and sizes).
void info_streamlines(const InfoArgs& a, TractogramFormat format) {
    std::unique_ptr<StreamlineSource> source = open_streamline_source(a.input);
    const std::string what = format == TractogramFormat::trk
                                 ? fmt::format("TrackVis .trk version {}, {}-endian",
                                               static_cast<TrkReader&>(*source).header().version,
                                               static_cast<TrkReader&>(*source).header().big_endian ? "big" : "little")
                                 : "TRX tractogram";
    // Counted from the data (which this also checks); .trk fields are gathered on the way.
    std::uint64_t streamlines = 0, points = 0;
    std::vector<Vec3f> fiber;
    while (source->next(fiber)) ++streamlines, points += fiber.size();
    const auto fields = source->take_fields();
    const auto props = source->properties();
    if (a.json) {
        std::string names = "[";
        for (std::size_t i = 0; i < fields.size(); ++i) names += (i ? ", " : "") + json_quote(fields[i].name);
        fmt::print("{}\n", Json{}
                               .str("file", a.input)
                               .str("format", format == TractogramFormat::trk ? "trk" : "trx")
                               .integer("streamlines", streamlines)
                               .integer("points", points)
                               .raw("data", names + "]")
                               .raw("properties", properties_json(props))
                               .render());
        return;
    }
    fmt::print("{}: {}\n  streamlines            {} ({} points)\n", a.input, what, streamlines, points);
    if (!fields.empty()) fmt::print("  data                   {}\n", fields_text(fields));
    print_properties(props);
}

// Fibers whose last step the ENDS chunk shortens (formats/fft-ends.md).
std::uint64_t partial_last_steps(const FftFile& f) {
    std::uint64_t n = 0;
    if (f.end_fractions())
        for (std::uint16_t q : *f.end_fractions()) n += q != kWholeLastStep;
    return n;
}

// The stored block index (BIDX, formats/fft-index.md): which version, and
// what a version holds.
std::string block_index_text(std::uint32_t version, std::uint64_t bytes) {
    const char* holds = version == 4   ? "an rANS-coded box per block"
                        : version == 3 ? "a range-coded box per block"
                        : version == 2 ? "a box per group of 8 blocks"
                        : version == 1 ? "a box per block"
                                       : "unknown to this fiblet";
    return fmt::format("version {}: {}, {}", version, holds, human_bytes(bytes));
}

void info_fft(const InfoArgs& a) {
    const FftFile f = open_fft_input(a.input, a.ignore_trailer);
    const FftHeader& h = f.header();
    const std::uint64_t partial = partial_last_steps(f);
    std::string chunks;
    for (const auto& c : f.trailer()) chunks += (chunks.empty() ? "" : " ") + std::string(c.tag.data(), 4);
    const std::optional<std::uint32_t> index_version = BlockIndex::stored_version(f);
    const std::uint64_t index_bytes = index_version ? f.find_chunk(kBlockIndexTag)->payload.size() : 0;
    if (a.json) {
        Json j;
        j.str("file", a.input).str("format", f.is_zstd_container() ? "fftz" : "fft").integer("version", h.version);
        j.integer("fibers", h.fibers).integer("points", h.points).integer("blocks", h.blocks);
        j.integer("points_per_block", h.points_per_block).integer("block_bytes", h.block_bytes());
        if (h.packed()) j.integer("packed_block_bytes", h.packed_block_bytes);
        j.num("scaling_mm", h.scaling);
        j.raw("offset_mm", fmt::format("[{:.9g}, {:.9g}, {:.9g}]", h.offset[0], h.offset[1], h.offset[2]));
        j.num("cap_ratio", h.ratio).num("step", h.step).num("step_mm", double(h.step) * h.scaling);
        j.num("max_error_um", h.max_error_mm * 1e3).num("mean_error_um", h.mean_error_mm * 1e3);
        j.integer("gpu_buffers", h.buffer_ends.size()).integer("file_bytes", f.file_size());
        j.raw("trailer_chunks", chunk_tags_json(f));
        if (index_version) j.integer("block_index_version", *index_version).integer("block_index_bytes", index_bytes);
        else j.raw("block_index_version", "null");
        j.boolean("ends_kept", f.end_fractions() != nullptr).integer("fibers_with_partial_last_step", partial);
        j.raw("properties", properties_json(f.properties()));
        fmt::print("{}\n", j.render());
        return;
    }
    fmt::print("{}: fiblet .fft version {}{}, {}\n", a.input, h.version,
               f.is_zstd_container() ? fmt::format(" in a seekable zstd container ({} as .fft)", human_bytes(f.logical_size()))
                                     : std::string(),
               human_bytes(f.file_size()));
    fmt::print("  fibers                 {}\n  points                 {}\n", h.fibers, h.points);
    if (h.packed())
        fmt::print("  blocks                 {} packed, {} ({} points each, 15-bit codes)\n", h.blocks,
                   human_bytes(h.packed_block_bytes), h.points_per_block);
    else
        fmt::print("  blocks                 {} x {} B ({} points each)\n", h.blocks, h.block_bytes(), h.points_per_block);
    fmt::print("  step                   {:.6g} mm ({:.6g} normalized)\n", double(h.step) * h.scaling, h.step);
    fmt::print("  cap ratio              {:.6g}\n", h.ratio);
    fmt::print("  scaling, offset (mm)   {:.6g}, ({:.6g}, {:.6g}, {:.6g})\n", h.scaling, h.offset[0], h.offset[1],
               h.offset[2]);
    fmt::print("  recorded error         max {}, mean {}\n", micrometres(h.max_error_mm, 3), micrometres(h.mean_error_mm, 3));
    fmt::print("  GPU buffers            {}\n", h.buffer_ends.size());
    if (!chunks.empty()) fmt::print("  trailer chunks         {}\n", chunks);
    fmt::print("  block index            {}\n", index_version ? block_index_text(*index_version, index_bytes)
                                                          : std::string("none stored (computed when a selection needs it)"));
    if (!f.streamline_fields().empty()) fmt::print("  data (DATA)            {}\n", fields_text(f.streamline_fields()));
    if (f.end_fractions())
        fmt::print("  fiber ends             kept (ENDS): {} of {} fibers end on a partial last step\n", partial, h.fibers);
    const auto props = f.properties();
    if (!props.empty()) {
        fmt::print("  source properties:\n");
        print_properties(props);
    }
}

}  // namespace

void add_info(CLI::App& app) {
    auto args = std::make_shared<InfoArgs>();
    CLI::App* cmd = app.add_subcommand("info", "Print the header of a .fft, .tck, .trk or TRX file");
    cmd->add_option("file", args->input, "A .fft, .tck, .trk or TRX file")->required()->check(CLI::ExistingPath);
    cmd->add_flag("--json", args->json, "Print as JSON");
    add_ignore_trailer_flag(cmd, args->ignore_trailer);
    cmd->callback([args] {
        const TractogramFormat f = detect_tractogram_format(args->input);
        if (f == TractogramFormat::tck) info_tck(*args);
        else if (f == TractogramFormat::trk || f == TractogramFormat::trx) info_streamlines(*args, f);
        else info_fft(*args);  // a .fft, or a message naming what the file is
    });
}

}  // namespace fiblet::cli
