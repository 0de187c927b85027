// fiblet decompress IN.fft [IN2.fft ...] [-o OUT.tck|OUT.trk|OUT.trx | --output-dir DIR] [-r DIR] [-j N] [--decoder NAME]
#include <fmt/core.h>

#include <chrono>
#include <filesystem>
#include <optional>

#include "cli_common.hpp"
#include "input_files.hpp"
#include "stdio_files.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/source_dtypes.hpp"
#include "fiblet/streamline_io.hpp"
#include "fiblet/tck.hpp"
#include "fiblet/tractogram_space.hpp"

namespace fiblet::cli {
namespace {

struct DecompressArgs {
    bool ignore_trailer = false;
    std::vector<std::string> inputs;
    std::string output, output_dir, decoder = "auto", reference;
    std::optional<TractogramSpace> reference_space;  // read from `reference` once
    unsigned threads = 0;
    bool force = false, quiet = false, json = false, recursive = false;
};

// [{"array", "from", "to", "why"}, ...]: the arrays not written in their source dtype.
std::string dtype_changes_json(const std::vector<DtypeChange>& changes) {
    std::string out;
    for (const DtypeChange& c : changes)
        out += (out.empty() ? "" : ", ") + Json{}
                                               .str("array", c.array)
                                               .str("from", field_type_name(c.from))
                                               .str("to", field_type_name(c.to))
                                               .str("why", c.why)
                                               .render();
    return "[" + out + "]";
}

// Decodes one file through the spools of `-` (if any); returns its JSON
// report (empty without --json).
std::string decompress_through(const DecompressArgs& a, const std::string& input, const std::string& output,
                               std::optional<SpoolFile>& stdin_spool, std::optional<SpoolFile>& stdout_spool) {
    const auto t0 = std::chrono::steady_clock::now();
    const FftFile file = open_fft_input(readable_path(input, ".fft", stdin_spool), a.ignore_trailer);
    const FftHeader& h = file.header();
    // The source's header properties (kept in the trailer), with the step
    // the points now have.
    auto props = file.properties();
    TckHeader header;
    header.properties = props;
    set_decoded_step_size(header, file);
    SinkHeader sink_header{header.properties, space_from_properties(props, input), file.streamline_fields(),
                           h.fibers, h.points};
    const TractogramFormat out_format = format_from_extension(output);  // .trk, .trx; else a .tck
    const bool points_only = out_format != TractogramFormat::trk && out_format != TractogramFormat::trx;
    if (a.reference_space) {
        if (sink_header.space)
            throw Error(Errc::invalid_argument, input + " carries its own space (from its .trk or TRX source): "
                                                        "--reference is for files made from a .tck");
        sink_header.space = a.reference_space;
    } else if (!points_only && !sink_header.space && !a.quiet) {
        fmt::print(stderr,
                   "fiblet: warning: {} carries no space (made from a .tck): {} gets an identity affine and 1x1x1 "
                   "dimensions, which TRX and DIPY tools treat as out of bounds; --reference IMAGE gives it the "
                   "image's (as tckconvert and DIPY)\n",
                   input, output);
    }
    if (points_only && !sink_header.fields.empty() && !a.quiet)
        fmt::print(stderr, "fiblet: note: {} data arrays of {} not written: a .tck holds points only (write a .trk or .trx)\n",
                   sink_header.fields.size(), input);
    if (points_only) sink_header.fields.clear();
    // Arrays back in their source dtypes where the output holds them; the rest is said.
    const std::vector<DtypeChange> changes = restore_source_dtypes(sink_header, out_format);
    if (points_only)  // the recorded dtypes are no .tck header lines
        std::erase_if(sink_header.properties, [](const auto& kv) { return is_source_dtype_property(kv.first); });
    if (!a.quiet)
        for (const DtypeChange& c : changes)
            fmt::print(stderr, "fiblet: note: {}: {} was {} in the source, written as {} ({})\n", input, c.array,
                       field_type_name(c.from), field_type_name(c.to), c.why);
    DecodeOptions options;
    options.decoder = parse_decoder(a.decoder);
    options.threads = a.threads;
    options.overlap_sink = true;  // format and write one chunk while the next is decoded
    const std::string decoder = decoder_name(options.decoder);
    const std::string out_path = writable_path(output, ".tck", stdout_spool);
    const auto sink = open_streamline_sink(out_path, sink_header, a.force || stdout_spool);
    const bool proven_finite = decodes_finite(h);  // then no pass over the points checks them
    Progress progress(a.quiet);
    decode_file(
        file,
        [&](std::uint64_t first, const Streamlines& chunk) {
            write_decoded_chunk(*sink, chunk, input, first, proven_finite);
            progress.update("decompress", h.fibers ? double(first + chunk.size()) / double(h.fibers) : 1.0);
        },
        options);
    sink->finish();
    progress.done();
    if (stdout_spool) stdout_spool->copy_to_stdout();
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (a.json)
        return Json{}
            .str("input", input)
            .str("output", output)
            .integer("fibers", h.fibers)
            .integer("points", h.points)
            .str("decoder", decoder)
            .raw("dtype_changes", dtype_changes_json(changes))
            .num("seconds", s)
            .render();
    if (!a.quiet)
        fmt::print(report_stream(output), "{} -> {}: {} fibers, {} points in {:.2f} s\n", input, output, h.fibers,
                   h.points, s);
    return {};
}

std::string decompress_one(const DecompressArgs& a, const std::string& input, const std::string& output) {
    std::optional<SpoolFile> stdin_spool, stdout_spool;
    try {
        return decompress_through(a, input, output, stdin_spool, stdout_spool);
    } catch (const Error& e) {
        throw named_for_user(e, stdin_spool, stdout_spool);
    }
}

// An output writes what it names (out.fft would otherwise get a .tck's
// bytes): a .fft/.fftz or a file of unknown extension is refused before any work;
// other tractogram formats are the sink's to refuse.
void check_output_name(const std::string& output) {
    if (output.empty() || output == "-") return;
    const TractogramFormat f = format_from_extension(output);
    if (f == TractogramFormat::fft || f == TractogramFormat::fftz)
        throw Error(Errc::invalid_argument, output + ": decompress writes .tck, .trk or .trx files; fiblet extract IN -o " +
                                           "OUT.fft writes a .fft (of a .fft or .fftz)");
    std::error_code ec;
    const bool device = std::filesystem::exists(output, ec) && !std::filesystem::is_regular_file(output, ec);
    if (f == TractogramFormat::unknown && !device)  // /dev/null and pipes take the .tck stream as before
        throw Error(Errc::invalid_argument,
                    output + ": decompress writes .tck, .trk or .trx files, named by their extension");
}

// Every input is tried; with several, a failed one is reported and the
// first failure's code is the exit status (as compress does).
void run(const DecompressArgs& args) {
    DecompressArgs a = args;
    if (!a.reference.empty()) a.reference_space = space_of_image(a.reference);
    const auto jobs = plan_file_jobs(a.inputs, {{".fft", ".fftz"}, {}, "", ".tck", a.output, a.output_dir, a.recursive});
    check_output_name(a.output);  // after the plan, which names an output that is an input
    std::vector<std::string> json;
    std::optional<Error> first_failure;
    for (const auto& [in, out] : jobs) {
        try {
            json.push_back(decompress_one(a, in, out));
        } catch (const Error& e) {
            if (jobs.size() == 1) throw;
            fmt::print(stderr, "fiblet: error: {}\n", cli_message(e));
            if (!first_failure) first_failure = e;
        }
    }
    if (a.json) {
        std::string all;
        for (const std::string& j : json) all += (all.empty() ? "" : ",\n ") + j;
        fmt::print(report_stream(a.output), "{}\n", jobs.size() == 1 && json.size() == 1 ? json[0] : "[" + all + "]");
    }
    if (first_failure) throw Error(first_failure->code(), "some inputs failed (see above)");
}

}  // namespace

void add_decompress(CLI::App& app) {
    auto args = std::make_shared<DecompressArgs>();
    CLI::App* cmd = app.add_subcommand("decompress", "Decode a .fft file back into a .tck, .trk or .trx file");
    cmd->add_option("inputs", args->inputs, "Input .fft/.fftz files (with -r, directories; - for standard input)")
        ->required()
        ->check(existing_path_or_stdin());
    cmd->add_option("-o,--output", args->output,
                    "Output .tck, .trk or .trx file (one input; by its extension, .trk/.trx get the source's space and "
                    "data; default: the input's name with .tck; - for standard output as .tck, the report then on "
                    "stderr)");
    cmd->add_option("--output-dir", args->output_dir, "Directory for the outputs (several inputs); created if missing");
    cmd->add_option("--reference", args->reference,
                    "A NIfTI or .mif image whose space (affine, dimensions) .trk/.trx outputs get, for files made "
                    "from a .tck (as tckconvert's and DIPY's reference)")
        ->check(CLI::ExistingFile);
    cmd->add_flag("-r,--recursive", args->recursive,
                  "Decompress every .fft/.fftz below the directories given (tree mirrored in --output-dir)");
    add_threads_option(cmd, args->threads, "Decoding");
    cmd->add_option("--decoder", args->decoder,
                    "auto (the fastest this CPU runs), scalar, lanes, warp, or one with its SIMD level: " +
                        [] {
                            std::string all;
                            for (const std::string& n : compiled_decoders()) all += (all.empty() ? "" : ", ") + n;
                            return all;
                        }() +
                        " (the CPU must have the level)")
        ->default_str("auto");
    cmd->add_flag("-f,--force", args->force, "Overwrite an existing output");
    cmd->add_flag("-q,--quiet", args->quiet, "Print nothing but errors");
    cmd->add_flag("--json", args->json, "Print the summary as JSON");
    add_ignore_trailer_flag(cmd, args->ignore_trailer);
    cmd->callback([args] { run(*args); });
}

}  // namespace fiblet::cli
