// fiblet compress IN.tck|IN.trk|IN.trx [IN2 ...] [-o OUT.fft | --output-dir DIR] [-r DIR]
#include <fmt/core.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <optional>

#include "cli_common.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/encode.hpp"
#include "geometry_report.hpp"
#include "input_files.hpp"
#include "stdio_files.hpp"

namespace fiblet::cli {
namespace {

struct CompressArgs {
    std::vector<std::string> inputs;
    std::string output, output_dir;
    std::string reference;  // a NIfTI/.mif image: the space of .tck sources
    std::optional<double> step;
    unsigned threads = 0;
    // Encoder choices.
    std::string bits = "8";  // 8, 16 or auto
    std::uint32_t block_points = 0;
    int effort = kDefaultEffort;
    std::optional<unsigned> beam, radius, retry_beam, lookahead;
    std::optional<double> cap_ratio, step_scale;
    std::optional<double> turn_percentile;
    std::optional<std::size_t> tuning_points;
    // The seekable zstd container.
    bool zstd = false, no_transpose = false;
    bool no_index = false, fine_index = false;
    int zstd_level = ZstdOptions{}.level;
    std::uint32_t zstd_group = ZstdOptions{}.group_blocks;
    bool force = false, quiet = false, json = false, allow_count_mismatch = false, recursive = false;
    std::optional<double> max_error_um;
    std::uint64_t max_memory = 0;  // 0: the library's default
};

std::string describe_errors(const ErrorStats& e) {
    return fmt::format("max {}, mean {}, p99 {}", micrometres(e.max_mm()), micrometres(e.mean_mm()),
                       micrometres(e.percentile_mm(99)));
}

std::string report_json(const std::string& in, const std::string& out, const CompressReport& r,
                        std::optional<double> a_max_error) {
    Json j;
    j.str("input", in).str("output", out);
    j.integer("fibers", r.header.fibers).integer("points", r.header.points).integer("blocks", r.header.blocks);
    j.integer("input_bytes", r.input_bytes).integer("output_bytes", r.output_bytes);
    j.num("ratio", r.output_bytes ? double(r.input_bytes) / double(r.output_bytes) : 0.0);
    j.num("step_mm", r.step_mm).num("step_scale", r.step_scale).num("cap_ratio", r.header.ratio);
    j.boolean("resampled", r.resampled).integer("direction_bits", r.header.direction_bits());
    j.boolean("bits_automatic", r.bits.automatic).str("bits_reason", r.bits.reason);
    if (r.bits.sample_fibers)
        j.num("bits_sample_length_change_max_um", r.bits.length_change_max_mm * 1e3)
            .num("bits_sample_max_error_um", r.bits.point_error_max_mm * 1e3);
    j.num("max_error_um", r.error.max_mm() * 1e3).num("mean_error_um", r.error.mean_mm() * 1e3);
    if (r.resampled)
        j.num("max_error_vs_original_um", r.error_vs_original.max_mm() * 1e3)
            .num("mean_error_vs_original_um", r.error_vs_original.mean_mm() * 1e3);
    j.raw("geometry", geometry_json(r.geometry));
    if (a_max_error) j.boolean("within_bound", metrics_above(r.error, r.geometry, *a_max_error).empty());
    j.num("seconds", r.seconds).str("simd", r.simd);
    Json timings;
    for (const auto& [stage, seconds] : r.timings.stages()) timings.num(stage, seconds);
    j.raw("timings", timings.render());
    return j.render();
}

void print_report(std::FILE* to, const std::string& in, const std::string& out, const CompressReport& r) {
    fmt::print(to, "{} -> {}\n", in, out);
    fmt::print(to, "  {} fibers, {} points, {} blocks of {} points ({} B)\n", r.header.fibers, r.header.points,
               r.header.blocks, r.header.points_per_block, r.header.block_bytes());
    fmt::print(to, "  step {:.6g} mm{}, decoder step x{:.5f}, cap ratio {:.4f}\n", r.step_mm,
               r.resampled ? " (variable spacing in the input: resampled to this fixed step)" : "", r.step_scale,
               r.header.ratio);
    fmt::print(to, "  {}\n", r.bits.reason);
    fmt::print(to, "  {} -> {} ({:.2f}x smaller)\n", human_bytes(r.input_bytes), human_bytes(r.output_bytes),
               double(r.input_bytes) / double(r.output_bytes));
    fmt::print(to, "  error vs {}: {}\n", r.resampled ? "resampled points" : "input", describe_errors(r.error));
    print_geometry_brief(r.geometry, "  ", to);
    fmt::print(to, "  {:.2f} s ({:.1f} M points/s)\n", r.seconds, r.header.points / r.seconds / 1e6);
}

// 8-bit codes changed a fiber's length by more than the file's point error
// (smooth fibers at fine steps zig-zag across the code grid: docs/encode.md,
// "Why smooth fibers need 16 bits"): say so and what keeps them. Under
// --bits auto this means the sample the bits were chosen on missed them.
void note_lengths_not_kept(const std::string& out, const CompressReport& r) {
    const double length_um = r.geometry.length_change_mm().max * 1e3, error_um = double(r.header.max_error_mm) * 1e3;
    if (r.header.direction_bits() != 8 || !(length_um > error_um * (1 + 1e-6))) return;
    fmt::print(stderr,
               "fiblet: note: {}: a fiber's length changed by {:.3g} µm, more than the {:.3g} µm point error (fiber {}{}): "
               "{} keeps lengths\n",
               out, length_um, error_um, r.geometry.length_change_mm().worst_fiber,
               r.bits.automatic ? "; the sample the bits were chosen on kept its lengths" : "",
               r.bits.automatic ? "--bits 16" : "--bits auto (16 bits where 8 would not)");
}

// A .fft larger than its input: sparse input (a few points per streamline,
// millimetres apart) resampled to a much finer step. Say so and what keeps
// about the input's points.
void note_larger_than_input(const std::string& in, const std::string& out, const CompressReport& r) {
    if (!(r.output_bytes > r.input_bytes)) return;
    fmt::print(stderr, "fiblet: note: {} ({}) is larger than {} ({})", out, human_bytes(r.output_bytes), in,
               human_bytes(r.input_bytes));
    if (r.header.points > r.scan.points && r.scan.step_mean > r.step_mm)
        fmt::print(stderr,
                   ": its {} points were resampled to {} at a {:.3g} mm step (the input's spacing averages {:.3g} mm); "
                   "--step {:.3g} keeps about the input's point count",
                   r.scan.points, r.header.points, r.step_mm, r.scan.step_mean, r.scan.step_mean);
    fmt::print(stderr, "\n");
}

// The container follows the output's name, as fiblet.save does: -o x.fftz
// is the zstd container (as -z), -o x.fft the plain one; any other name
// would hold bytes its extension does not say. Standard output (-) and
// devices take -z.
bool zstd_container(const CompressArgs& a) {
    std::error_code ec;
    const auto type = std::filesystem::status(a.output, ec).type();  // a device (/dev/null) has no name to keep
    if (a.output.empty() || a.output == "-" || type == std::filesystem::file_type::character ||
        type == std::filesystem::file_type::fifo)
        return a.zstd;
    std::string ext = std::filesystem::path(a.output).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (ext == ".fftz") return true;
    if (ext != ".fft")
        throw Error(Errc::invalid_argument,
                    "-o " + a.output + ": compress writes a .fft (or, with --zstd, a .fftz); name the output so");
    if (a.zstd) throw Error(Errc::invalid_argument, "--zstd writes the .fftz container: name the output " +
                                                        std::filesystem::path(a.output).replace_extension(".fftz").string());
    return false;
}

void run(const CompressArgs& args) {
    CompressArgs a = args;
    a.zstd = zstd_container(a);
    std::optional<TractogramSpace> reference_space;
    if (!a.reference.empty()) reference_space = space_of_image(a.reference);
    const auto jobs = plan_file_jobs(
        a.inputs, {{".tck", ".trk", ".trx"}, {".trx"}, "header.json", a.zstd ? ".fftz" : ".fft", a.output, a.output_dir,
                   a.recursive});
    std::vector<std::string> json;
    std::optional<Error> first_failure;
    std::size_t above_bound = 0;
    for (const auto& [in, out] : jobs) {
        Progress progress(a.quiet);
        CompressOptions o;
        o.step_mm = a.step;
        o.overwrite = a.force;
        o.threads = a.threads;
        o.allow_count_mismatch = a.allow_count_mismatch;
        o.max_memory = a.max_memory;
        o.reference_space = reference_space;
        o.direction_bits = a.bits == "auto" ? std::nullopt : std::optional<unsigned>(unsigned(std::stoul(a.bits)));
        o.points_per_block = a.block_points;
        o.search = search_for_effort(a.effort);
        if (a.beam) o.search.beam_width = *a.beam;
        if (a.radius) o.search.radius = *a.radius;
        if (a.retry_beam) o.search.retry_beam_width = *a.retry_beam;
        if (a.lookahead) o.search.lookahead = *a.lookahead;
        o.cap_ratio = a.cap_ratio;
        o.step_scale = a.step_scale;
        o.turn_percentile = a.turn_percentile;
        if (a.tuning_points) o.tuning_points = *a.tuning_points;
        if (a.zstd) o.zstd = ZstdOptions{a.zstd_level, a.zstd_group, !a.no_transpose};
        o.block_index = !a.no_index;
        o.index_format = index_format_for(a.fine_index);
        const std::string name = std::filesystem::path(in).filename().string();
        o.progress = [&](const char* phase, double f) { progress.update(name + ": " + phase, f); };
        try {
            std::optional<SpoolFile> stdin_spool, stdout_spool;
            const std::string out_path = writable_path(out, a.zstd ? ".fftz" : ".fft", stdout_spool);
            o.overwrite = a.force || stdout_spool;
            const CompressReport r = [&] {
                try {
                    return compress_file(readable_path(in, ".tck", stdin_spool), out_path, o);
                } catch (const Error& e) {
                    throw named_for_user(e, stdin_spool, stdout_spool);
                }
            }();
            progress.done();
            if (stdout_spool) stdout_spool->copy_to_stdout();
            if (a.json) {
                json.push_back(report_json(in, out, r, a.max_error_um));
            } else if (!a.quiet) {
                print_report(report_stream(out), in, out, r);
            }
            if (!a.quiet) note_lengths_not_kept(out, r), note_larger_than_input(in, out, r);
            if (a.max_error_um && !metrics_above(r.error, r.geometry, *a.max_error_um).empty()) {
                try {
                    check_error_bound(out, r.error, r.geometry, a.max_error_um);
                } catch (const ErrorBoundExceeded& e) {
                    fmt::print(stderr, "fiblet: {}\n", e.what());
                }
                ++above_bound;
            }
        } catch (const Error& e) {
            progress.done();
            fmt::print(stderr, "fiblet: error: {}\n", cli_message(e));
            if (!first_failure) first_failure = e;
        }
    }
    if (a.json) {
        if (jobs.size() == 1 && json.size() == 1) fmt::print(report_stream(a.output), "{}\n", json[0]);
        else {
            std::string all = "[";
            for (std::size_t i = 0; i < json.size(); ++i) all += (i ? ",\n " : "") + json[i];
            fmt::print(report_stream(a.output), "{}]\n", all);
        }
    }
    if (first_failure) {
        if (jobs.size() == 1) throw Error(first_failure->code(), "compression failed");
        throw Error(first_failure->code(), "some inputs failed (see above)");
    }
    if (above_bound)
        throw ErrorBoundExceeded(std::to_string(above_bound) + " of " + std::to_string(jobs.size()) +
                                 " outputs above --max-error (kept; see above)");
}

}  // namespace

void add_compress(CLI::App& app) {
    auto args = std::make_shared<CompressArgs>();
    CLI::App* cmd = app.add_subcommand("compress", "Compress tractograms (.tck, .trk, TRX) into .fft fiblet files");
    cmd->add_option("inputs", args->inputs,
                    "Input .tck, .trk or .trx files (TRX: a zip or a directory; with -r, directories; - for standard input)")
        ->required()
        ->check(existing_path_or_stdin());
    cmd->add_flag("-r,--recursive", args->recursive,
                  "Compress every .tck, .trk and .trx below the directories given (tree mirrored in --output-dir)");
    cmd->add_option("-o,--output", args->output,
                    "Output .fft file (one input; - for standard output, the report then on stderr). MRtrix3's order "
                    "`fiblet compress IN OUT.fft` means -o OUT.fft when OUT.fft (or .fftz) does not exist yet and "
                    "neither -o, --output-dir nor -r is given");
    cmd->add_option("--output-dir", args->output_dir, "Directory for the outputs (several inputs); created if missing");
    cmd->add_option("--reference", args->reference,
                    "A NIfTI or .mif image whose space (affine, dimensions) a .tck source is stored with, so that "
                    ".trk/.trx outputs get it (as tckconvert's and DIPY's reference; .trk/TRX sources carry their own)")
        ->check(CLI::ExistingFile);
    cmd->add_option("--step", args->step, "Fixed step in mm (default: measured; variable spacing is resampled)");
    add_threads_option(cmd, args->threads, "Encoding");
    cmd->add_option("--bits", args->bits,
                    "Bits per direction: 8 (default: .fft version 2, the official layout), 16 (formats/fft16.md: "
                    "15-bit codes in packed blocks; with --zstd, version 16) or auto: 8 unless 8-bit codes would "
                    "change the sampled fibers' lengths by more than their point error (smooth fibers at fine "
                    "steps; docs/encode.md)")
        ->check(CLI::IsMember({"auto", "8", "16"}));
    cmd->add_option("--block-points", args->block_points, "Points per block (default 60 for 8 bits; 254 for 16, 126 for 16 with --zstd)");
    cmd->add_option("-e,--effort", args->effort,
                    "Code search effort 0..4 (default 1): slower searches give smaller errors, same decoder")
        ->check(CLI::Range(0, kMaxEffort));
    cmd->add_option("--retry-beam", args->retry_beam, "Beam width for re-searching the worst blocks (0 = none)")
        ->check(CLI::Range(0u, 64u));
    cmd->add_option("--beam", args->beam, "Code search: sequences kept per step (1 = greedy)")->check(CLI::Range(1u, 64u));
    cmd->add_option("--lookahead", args->lookahead,
                    "Code search (beam 1): judge each code by the errors of the next N points too (0 = greedy)")
        ->check(CLI::Range(0u, 6u));
    cmd->add_option("--search-radius", args->radius, "Code search: candidate codes within this many levels")
        ->check(CLI::Range(1u, 3u));
    cmd->add_option("--cap-ratio", args->cap_ratio, "Cap ratio of the direction code (default: from the data)");
    cmd->add_option("--turn-percentile", args->turn_percentile,
                    "Size the cap for this percentile of the turning angles (default: tuned)")
        ->check(CLI::Range(50.0, 100.0));
    cmd->add_option("--tuning-points", args->tuning_points, "Points in the sample the cap and step are tuned on");
    cmd->add_option("--step-scale", args->step_scale, "Decoder step / sampling step (default: tuned on a sample)");
    cmd->add_flag("--no-index", args->no_index,
                  "Leave out the block index (BIDX chunk, under 1 % of the file; extract and render compute it on load)");
    add_fine_index_flag(cmd, args->fine_index);
    cmd->add_flag("-z,--zstd", args->zstd,
                  "Write the seekable zstd container (.fftz, formats/fftz.md): smaller, still random access "
                  "(-o x.fftz implies it)");
    cmd->add_option("--zstd-level", args->zstd_level, "zstd level (default 1; 3: 0.8 % smaller, compress ~8 % slower; 17: 4.6 % smaller, its stage ~20x slower)")->check(CLI::Range(1, 22));
    cmd->add_option("--zstd-group", args->zstd_group, "Blocks per zstd frame, the unit of random access (default 4096)")
        ->check(CLI::Range(1u, 1u << 24));
    cmd->add_flag("--no-transpose", args->no_transpose,
                  "Store block groups as in the .fft (zstd -d then gives back the .fft; slightly larger)");
    cmd->add_option("--max-error", args->max_error_um,
                    "Exit with code 8 (outputs kept) when the point error, the Hausdorff distance, an endpoint's "
                    "displacement or a length change exceeds this many µm")
        ->check(CLI::PositiveNumber);
    cmd->add_flag("-f,--force", args->force, "Overwrite existing outputs");
    cmd->add_flag("-q,--quiet", args->quiet, "Print nothing but errors");
    cmd->add_flag("--json", args->json, "Print the report as JSON");
    cmd->add_flag("--allow-count-mismatch", args->allow_count_mismatch,
                  "Accept a .tck whose count: (a .trk whose n_count) disagrees with its data");
    cmd->add_option("--max-memory", args->max_memory,
                    "Memory a source's arrays (TRX offsets, dps/dpv/groups/dpg), the per-point arrays of resampled "
                    "streamlines and the per-streamline tables (~32 bytes each) may take, e.g. 8G or 512M (default: "
                    "half the memory the process may use: physical, ulimit -v/-d or the cgroup's limit); beyond it "
                    "compress stops before allocating them, exit 6")
        ->transform(CLI::AsSizeValue(false))
        ->check(CLI::PositiveNumber);
    cmd->callback([args] { run(*args); });
}

}  // namespace fiblet::cli
