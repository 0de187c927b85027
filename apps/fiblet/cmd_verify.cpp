// fiblet verify FILE... — structure and integrity checksums of .fft files.
#include <fmt/core.h>

#include <optional>

#include "cli_common.hpp"
#include "fiblet/checksum.hpp"

namespace fiblet::cli {
namespace {

struct VerifyArgs {
    std::vector<std::string> inputs;
    bool require_checksum = false, quiet = false, json = false, ignore_trailer = false;
};

void run(const VerifyArgs& a) {
    std::optional<Error> first_failure;
    std::vector<std::string> json;
    for (const std::string& in : a.inputs) {
        Progress progress(a.quiet || a.json);
        try {
            const VerifyReport r = verify_fft_file(in, [&](double f) { progress.update("verify", f); },
                                                     {.ignore_trailer = a.ignore_trailer});
            progress.done();
            if (a.json) {
                json.push_back(Json{}
                                   .str("file", in)
                                   .str("status", r.has_checksum ? "ok" : "no_checksum")
                                   .integer("blocks", r.blocks)
                                   .integer("groups", r.groups)
                                   .integer("points", r.points)
                                   .boolean("index_checked", r.index_checked)
                                   .integer("bytes_read", r.bytes_read)
                                   .integer("ignored_trailing_bytes", r.ignored_trailing_bytes)
                                   .render());
            } else if (!a.quiet || !r.has_checksum) {
                const std::string index = r.index_checked ? ", index boxes" : "";
                if (r.has_checksum)
                    fmt::print("{}: OK: structure, {} points{} valid; XXH64 of header, LUT, trailer and {} blocks in "
                               "{} groups match\n",
                               in, r.points, index, r.blocks, r.groups);
                else if (r.ignored_trailing_bytes)
                    fmt::print("{}: blocks readable ({} blocks, {} points); trailer ignored: nothing verified by "
                               "checksum\n",
                               in, r.blocks, r.points);
                else
                    fmt::print("{}: no checksum (structure, {} points{} valid: {} blocks; nothing after the blocks, "
                               "as the official encoder writes)\n",
                               in, r.points, index, r.blocks);
            }
            if (!r.has_checksum && a.require_checksum) {
                const Error e(Errc::checksum, in + ": no checksum and --require-checksum given");
                fmt::print(stderr, "fiblet: error: {}\n", cli_message(e));
                if (!first_failure) first_failure = e;
            }
        } catch (const Error& e) {
            progress.done();
            if (a.json) json.push_back(Json{}.str("file", in).str("status", errc_name(e.code())).str("error", e.what()).render());
            fmt::print(stderr, "fiblet: error: {}\n", cli_message(e));
            if (!first_failure) first_failure = e;
        }
    }
    if (a.json) {
        std::string all = "[";
        for (std::size_t i = 0; i < json.size(); ++i) all += (i ? ",\n " : "") + json[i];
        fmt::print("{}\n", a.inputs.size() == 1 && json.size() == 1 ? json[0] : all + "]");
    }
    if (first_failure) {
        if (a.inputs.size() == 1) throw Error(first_failure->code(), "verification failed");
        throw Error(first_failure->code(), "some files failed verification (see above)");
    }
}

}  // namespace

void add_verify(CLI::App& app) {
    auto args = std::make_shared<VerifyArgs>();
    CLI::App* cmd = app.add_subcommand("verify", "Check the structure and the integrity checksums of .fft files");
    cmd->add_option("inputs", args->inputs, "Input .fft files")->required()->check(CLI::ExistingFile);
    cmd->add_flag("--require-checksum", args->require_checksum,
                  "Fail (exit 7) on files that carry no checksum");
    cmd->add_flag("-q,--quiet", args->quiet, "Print only problems");
    cmd->add_flag("--json", args->json, "Print the result as JSON");
    cmd->add_flag("--ignore-trailer", args->ignore_trailer,
                  "Check only the header, LUT and blocks of a file whose trailer is damaged (no checksum is then "
                  "verified; exits 7 with --require-checksum)");
    cmd->callback([args] { run(*args); });
}

}  // namespace fiblet::cli
