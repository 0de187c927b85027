// fiblet decompress IN.fft -o OUT.tck|OUT.trk|OUT.trx [-j N] [--decoder NAME]
#include <fmt/core.h>

#include <chrono>

#include "cli_common.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/streamline_io.hpp"
#include "fiblet/tck.hpp"

namespace fiblet::cli {
namespace {

struct DecompressArgs {
    bool ignore_trailer = false;
    std::string input, output, decoder = "auto";
    unsigned threads = 0;
    bool force = false, quiet = false, json = false;
};

void run(const DecompressArgs& a) {
    const auto t0 = std::chrono::steady_clock::now();
    const FftFile file = open_fft_input(a.input, a.ignore_trailer);
    const FftHeader& h = file.header();
    // The source's header properties (kept in the trailer), with the step
    // the points now have.
    auto props = file.properties();
    TckHeader header;
    header.properties = props;
    header.set("step_size", fmt::format("{:.9g}", double(h.step) * double(h.scaling)));
    SinkHeader sink_header{header.properties, space_from_properties(props, a.input), file.streamline_fields(),
                           h.fibers, h.points};
    const TractogramFormat out_format = format_from_extension(a.output);  // .trk, .trx; else a .tck
    const bool points_only = out_format != TractogramFormat::trk && out_format != TractogramFormat::trx;
    if (points_only && !sink_header.fields.empty() && !a.quiet)
        fmt::print(stderr, "fiblet: note: {} data arrays of {} not written: a .tck holds points only (write a .trk or .trx)\n",
                   sink_header.fields.size(), a.input);
    if (points_only) sink_header.fields.clear();
    DecodeOptions options;
    options.decoder = parse_decoder(a.decoder);
    options.threads = a.threads;
    const std::string decoder = decoder_name(options.decoder);
    const auto sink = open_streamline_sink(a.output, sink_header, a.force);
    Progress progress(a.quiet);
    decode_file(
        file,
        [&](std::uint64_t first, const Streamlines& chunk) {
            for (std::size_t i = 0; i < chunk.size(); ++i)
                write_decoded_fiber(*sink, &chunk.xyz[3 * chunk.offsets[i]], chunk.offsets[i + 1] - chunk.offsets[i],
                                    a.input, first + i);
            progress.update("decompress", h.fibers ? double(first + chunk.size()) / double(h.fibers) : 1.0);
        },
        options);
    sink->finish();
    progress.done();
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (a.json) {
        fmt::print("{}\n", Json{}
                               .str("input", a.input)
                               .str("output", a.output)
                               .integer("fibers", h.fibers)
                               .integer("points", h.points)
                               .str("decoder", decoder)
                               .num("seconds", s)
                               .render());
    } else if (!a.quiet) {
        fmt::print("{} -> {}: {} fibers, {} points in {:.2f} s\n", a.input, a.output, h.fibers, h.points, s);
    }
}

}  // namespace

void add_decompress(CLI::App& app) {
    auto args = std::make_shared<DecompressArgs>();
    CLI::App* cmd = app.add_subcommand("decompress", "Decode a .fft file back into a .tck, .trk or .trx file");
    cmd->add_option("input", args->input, "Input .fft file")->required()->check(CLI::ExistingFile);
    cmd->add_option("-o,--output", args->output,
                    "Output .tck, .trk or .trx file (by its extension; .trk/.trx get the source's space and data)")
        ->required();
    cmd->add_option("-j,--threads", args->threads, "Decoding threads (default: all cores)");
    cmd->add_option("--decoder", args->decoder,
                    "auto (the fastest), scalar, lanes, warp, or one with its SIMD level: " +
                        [] {
                            std::string all;
                            for (const std::string& n : available_decoders()) all += (all.empty() ? "" : ", ") + n;
                            return all;
                        }())
        ->default_str("auto");
    cmd->add_flag("-f,--force", args->force, "Overwrite an existing output");
    cmd->add_flag("-q,--quiet", args->quiet, "Print nothing but errors");
    cmd->add_flag("--json", args->json, "Print the summary as JSON");
    add_ignore_trailer_flag(cmd, args->ignore_trailer);
    cmd->callback([args] { run(*args); });
}

}  // namespace fiblet::cli
