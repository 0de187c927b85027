// fiblet verify FILE... — structure and integrity checksums of .fft files.
#include <fmt/core.h>

#include <optional>

#include "cli_common.hpp"
#include "fiblet/checksum.hpp"

namespace fiblet::cli {
namespace {

struct VerifyArgs {
    std::vector<std::string> inputs;
    bool require_checksum = false, quiet = false, json = false;
};

void run(const VerifyArgs& a) {
    std::optional<Error> first_failure;
    std::vector<std::string> json;
    for (const std::string& in : a.inputs) {
        Progress progress(a.quiet || a.json);
        try {
            const VerifyReport r = verify_fft_file(in, [&](double f) { progress.update("verify", f); });
            progress.done();
            if (a.json) {
                json.push_back(Json{}
                                   .str("file", in)
                                   .str("status", r.has_checksum ? "ok" : "no_checksum")
                                   .integer("blocks", r.blocks)
                                   .integer("groups", r.groups)
                                   .integer("bytes_read", r.bytes_read)
                                   .integer("unrecognized_trailing_bytes", r.unrecognized_trailing_bytes)
                                   .render());
            } else if (!a.quiet || !r.has_checksum) {
                if (r.has_checksum)
                    fmt::print("{}: OK: structure valid; XXH64 of header, LUT, trailer and {} blocks in {} groups match\n",
                               in, r.blocks, r.groups);
                else
                    fmt::print("{}: no checksum (structure valid: {} blocks; written by another encoder?)\n", in,
                               r.blocks);
                if (r.unrecognized_trailing_bytes)
                    fmt::print("{}: warning: {} bytes after the last block are not a fiblet trailer (damaged?)\n", in,
                               r.unrecognized_trailing_bytes);
            }
            if (!r.has_checksum && a.require_checksum) {
                const Error e(Errc::checksum, in + ": no checksum and --require-checksum given");
                fmt::print(stderr, "fiblet: error: {}\n", e.what());
                if (!first_failure) first_failure = e;
            }
        } catch (const Error& e) {
            progress.done();
            if (a.json) json.push_back(Json{}.str("file", in).str("status", errc_name(e.code())).str("error", e.what()).render());
            fmt::print(stderr, "fiblet: error: {}\n", e.what());
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
    cmd->callback([args] { run(*args); });
}

}  // namespace fiblet::cli
