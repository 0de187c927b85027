// fiblet decompress IN.fft -o OUT.tck
#include <fmt/core.h>

#include <chrono>

#include "cli_common.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/tck.hpp"

namespace fiblet::cli {
namespace {

struct DecompressArgs {
    std::string input, output;
    bool force = false, quiet = false, json = false;
};

void run(const DecompressArgs& a) {
    const auto t0 = std::chrono::steady_clock::now();
    const FftFile file(a.input);
    const FftHeader& h = file.header();
    // The source's header properties (kept in the trailer), with the step
    // the points now have.
    auto props = file.properties();
    TckHeader header;
    header.properties = props;
    header.set("step_size", fmt::format("{:.9g}", double(h.step) * double(h.scaling)));
    TckWriter writer(a.output, header.properties, a.force);
    Progress progress(a.quiet);
    decode_file(file, [&](std::uint64_t first, const Streamlines& chunk) {
        for (std::size_t i = 0; i < chunk.size(); ++i)
            writer.write(&chunk.xyz[3 * chunk.offsets[i]], chunk.offsets[i + 1] - chunk.offsets[i]);
        progress.update("decompress", h.fibers ? double(first + chunk.size()) / double(h.fibers) : 1.0);
    });
    writer.finish();
    progress.done();
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (a.json) {
        fmt::print("{}\n", Json{}
                               .str("input", a.input)
                               .str("output", a.output)
                               .integer("fibers", h.fibers)
                               .integer("points", h.points)
                               .num("seconds", s)
                               .render());
    } else if (!a.quiet) {
        fmt::print("{} -> {}: {} fibers, {} points in {:.2f} s\n", a.input, a.output, h.fibers, h.points, s);
    }
}

}  // namespace

void add_decompress(CLI::App& app) {
    auto args = std::make_shared<DecompressArgs>();
    CLI::App* cmd = app.add_subcommand("decompress", "Decode a .fft file back into a .tck file");
    cmd->add_option("input", args->input, "Input .fft file")->required()->check(CLI::ExistingFile);
    cmd->add_option("-o,--output", args->output, "Output .tck file")->required();
    cmd->add_flag("-f,--force", args->force, "Overwrite an existing output");
    cmd->add_flag("-q,--quiet", args->quiet, "Print nothing but errors");
    cmd->add_flag("--json", args->json, "Print the summary as JSON");
    cmd->callback([args] { run(*args); });
}

}  // namespace fiblet::cli
