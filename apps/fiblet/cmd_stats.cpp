// fiblet stats IN.fft [--reference IN.tck|IN.trk|IN.trx]: the error against
// the source, or without it tckstats-style length statistics of the decoded fibers.
#include <fmt/core.h>

#include <optional>

#include "cli_common.hpp"
#include "fiblet/compare.hpp"
#include "geometry_report.hpp"
#include "length_stats.hpp"

namespace fiblet::cli {
namespace {

struct StatsArgs {
    bool ignore_trailer = false;
    std::string input, reference;
    bool json = false, quiet = false, allow_count_mismatch = false;
    std::optional<double> max_error_um;
};

void run_lengths(const StatsArgs& a, const FftFile& file) {
    if (a.max_error_um) throw Error(Errc::invalid_argument, "--max-error needs --reference (the source tractogram)");
    const LengthStats s = length_stats(decoded_fiber_lengths(file, 0));
    if (a.json)
        fmt::print("{}\n", Json{}.str("file", a.input).raw("length", length_json(s)).render());
    else
        fmt::print("{}", length_table(s));
}

void run(const StatsArgs& a) {
    const FftFile file = open_fft_input(a.input, a.ignore_trailer);
    if (a.reference.empty()) return run_lengths(a, file);
    Progress progress(a.quiet || a.json);
    const Comparison c =
        compare_to_reference(file, a.reference, a.allow_count_mismatch, [&](double f) { progress.update("stats", f); });
    progress.done();
    const FftHeader& h = file.header();
    const double ratio = c.fft_bytes ? double(c.reference_bytes) / double(c.fft_bytes) : 0.0;
    if (a.json) {
        Json j;
        j.str("file", a.input).str("reference", a.reference);
        j.integer("fibers", c.fibers).integer("points", c.points).integer("blocks", c.blocks);
        j.integer("fft_bytes", c.fft_bytes).integer("reference_bytes", c.reference_bytes).num("ratio", ratio);
        j.num("bytes_per_point", c.points ? double(c.fft_bytes) / double(c.points) : 0.0);
        j.boolean("resampled", c.resampled);
        j.raw("error", distances_json(c.error));
        if (c.resampled) j.raw("error_vs_original", distances_json(c.error_vs_original));
        j.raw("geometry", geometry_json(c.geometry));
        j.num("header_max_error_um", h.max_error_mm * 1e3).num("header_mean_error_um", h.mean_error_mm * 1e3);
        if (a.max_error_um)
            j.num("max_error_bound_um", *a.max_error_um)
                .boolean("within_bound", metrics_above(c.error, c.geometry, *a.max_error_um).empty());
        fmt::print("{}\n", j.render());
        check_error_bound(a.input, c.error, c.geometry, a.max_error_um);
        return;
    }
    fmt::print("{}: {} fibers, {} points, {} blocks of {} points\n", a.input, c.fibers, c.points, c.blocks,
               h.points_per_block);
    fmt::print("size                   {} vs {} reference: {:.2f}x smaller, {:.3f} bytes/point\n",
               human_bytes(c.fft_bytes), human_bytes(c.reference_bytes), ratio,
               c.points ? double(c.fft_bytes) / double(c.points) : 0.0);
    fmt::print("error (µm)\n");
    print_distances(c.resampled ? "  vs resampled points" : "  vs reference", c.error);
    fmt::print("  recorded in header   max {}  mean {}\n", micrometres_value(h.max_error_mm, 3),
               micrometres_value(h.mean_error_mm, 3));
    fmt::print("vs the reference polylines, both ways (µm)\n");
    print_geometry(c.geometry, "  ");
    check_error_bound(a.input, c.error, c.geometry, a.max_error_um);
}

}  // namespace

void add_stats(CLI::App& app) {
    auto args = std::make_shared<StatsArgs>();
    CLI::App* cmd = app.add_subcommand(
        "stats", "Measure a .fft file against its source (.tck, .trk, TRX): point error, distances both ways (Hausdorff), "
                 "endpoint displacement, length change; without --reference, fiber length statistics");
    cmd->add_option("input", args->input, "Input .fft file")->required()->check(CLI::ExistingFile);
    cmd->add_option("-r,--reference", args->reference,
                    "The .tck, .trk or TRX file it was made from (without it: length statistics, as MRtrix3's tckstats)")
        ->check(CLI::ExistingPath);
    cmd->add_flag("--json", args->json, "Print the report as JSON");
    cmd->add_option("--max-error", args->max_error_um,
                    "Exit with code 8 when the point error, the Hausdorff distance, an endpoint's displacement "
                    "or a length change exceeds this many µm")
        ->check(CLI::PositiveNumber);
    cmd->add_flag("-q,--quiet", args->quiet, "No progress display");
    cmd->add_flag("--allow-count-mismatch", args->allow_count_mismatch,
                  "Accept a reference whose count: header disagrees with its data");
    add_ignore_trailer_flag(cmd, args->ignore_trailer);
    cmd->callback([args] { run(*args); });
}

}  // namespace fiblet::cli
