// fiblet — command-line front end. Each subcommand lives in its own file and
// uses only the library's public API.
#include <fmt/core.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <system_error>
#include <vector>

#include "cli_common.hpp"
#include "geometry_report.hpp"
#include "mrtrix_output_order.hpp"
#include "signal_cleanup.hpp"
#include "single_dash_options.hpp"
#include "unknown_options.hpp"

namespace {

// Reports and returns the command's status, after making sure what it
// printed reached stdout: a report written to a full disk or a closed pipe
// is a failed command (exit 3), never a silent success with no output.
int finish(int status) {
    errno = 0;
    if (std::fflush(stdout) != 0 || std::ferror(stdout)) {
        const int e = errno;
        std::fprintf(stderr, "fiblet: error: cannot write to standard output: %s\n",
                     e ? std::strerror(e) : "write error");
        return status == fiblet::cli::kOk ? fiblet::cli::kIo : status;
    }
    return status;
}

int run(CLI::App& app, int argc, char** argv) {
    using namespace fiblet::cli;
    try {
        std::vector<std::string> args = translate_single_dash_options(app, {argv + 1, argv + argc});
        reject_unknown_options(app, args);  // before CLI11 checks the operands
        args = mrtrix_output_order(app, std::move(args));
        std::vector<char*> translated{argv[0]};
        for (std::string& a : args) translated.push_back(a.data());
        app.parse(int(translated.size()), translated.data());
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        app.exit(e);
        return kUsage;
    } catch (const ErrorBoundExceeded& e) {
        fmt::print(stderr, "fiblet: {}\n", e.what());
        return kErrorBound;
    } catch (const fiblet::Error& e) {
        fmt::print(stderr, "fiblet: error: {}\n", cli_message(e));
        return exit_code_for(e.code());
    } catch (const std::system_error& e) {
        // fmt reports a failed write to stdout this way.
        if (std::ferror(stdout)) return kIo;  // finish() says what failed
        fmt::print(stderr, "fiblet: internal error: {}\n", e.what());
        return kInternal;
    } catch (const std::exception& e) {
        fmt::print(stderr, "fiblet: internal error: {}\n", e.what());
        return kInternal;
    }
    return kOk;
}

}  // namespace

int main(int argc, char** argv) {
    using namespace fiblet::cli;
    CLI::App app{"fiblet: compress MRtrix3 .tck tractograms into fiblets (.fft) and decode them fast"};
    app.set_version_flag("--version", std::string("fiblet ") + FIBLET_VERSION);
    app.require_subcommand(1);
    app.fallthrough(false);
    add_compress(app);
    add_decompress(app);
    add_stats(app);
    add_info(app);
    add_extract(app);
    add_verify(app);
#ifdef FIBLET_WITH_VIEWER
    add_render(app);
    add_view(app);
#endif
    add_help(app);

    fiblet::cli::install_signal_cleanup();
    return finish(run(app, argc, argv));
}
