// fiblet — command-line front end. Each subcommand lives in its own file and
// uses only the library's public API.
#include <fmt/core.h>

#include <exception>

#include "cli_common.hpp"
#include "geometry_report.hpp"
#include "fiblet/output_file.hpp"

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

    fiblet::install_signal_cleanup();
    try {
        app.parse(argc, argv);
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
        fmt::print(stderr, "fiblet: error: {}\n", e.what());
        return exit_code_for(e.code());
    } catch (const std::exception& e) {
        fmt::print(stderr, "fiblet: internal error: {}\n", e.what());
        return kInternal;
    }
    return kOk;
}
