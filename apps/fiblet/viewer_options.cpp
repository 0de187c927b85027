#include "viewer_options.hpp"

#include <cstdlib>
#include <limits>

#include "fiblet/error.hpp"

namespace fiblet::cli {

namespace {

// "RRGGBB" / "#RRGGBB" or a few names.
std::array<float, 3> parse_color(std::string text, const char* option) {
    if (text == "black") return {0, 0, 0};
    if (text == "white") return {1, 1, 1};
    if (text == "gray" || text == "grey") return {0.5f, 0.5f, 0.5f};
    if (!text.empty() && text[0] == '#') text.erase(0, 1);
    char* end = nullptr;
    const unsigned long v = std::strtoul(text.c_str(), &end, 16);
    if (text.size() != 6 || *end != '\0')
        throw Error(Errc::invalid_argument,
                    std::string(option) + ": '" + text + "' is not a colour (RRGGBB in hex, black, white, gray)");
    return {float((v >> 16) & 255) / 255.0f, float((v >> 8) & 255) / 255.0f, float(v & 255) / 255.0f};
}

std::uint32_t parse_u32(const std::string& text, const char* what) {
    char* end = nullptr;
    const unsigned long long v = std::strtoull(text.c_str(), &end, 10);
    if (text.empty() || *end != '\0' || text[0] == '-' || v > std::numeric_limits<std::uint32_t>::max())
        throw Error(Errc::invalid_argument, std::string(what) + ": '" + text + "' is not a fiber ID");
    return std::uint32_t(v);
}

}  // namespace

void add_viewer_options(CLI::App* cmd, ViewerArgs& a) {
    cmd->add_option("input", a.input, "A .fft file (or a .tck, .trk or TRX file, compressed on the fly)")
        ->required()
        ->check(CLI::ExistingPath);
    cmd->add_option("--camera", a.camera,
                    "View: left, right, front, back, top, bottom, oblique; or EX,EY,EZ[,TX,TY,TZ[,UX,UY,UZ]] in mm")
        ->capture_default_str();
    cmd->add_option("--fov", a.fov, "Vertical field of view, degrees")->capture_default_str();
    cmd->add_option("--zoom", a.zoom, "Move a named view closer (>1) or farther (<1)")->capture_default_str();
    cmd->add_option("--color", a.color, "Line colour: direction (|direction| as RGB) or RRGGBB")->capture_default_str();
    cmd->add_option("--background", a.background, "Background colour: RRGGBB, black, white, gray")
        ->capture_default_str();
    cmd->add_flag("--no-lighting", a.no_lighting, "Flat colours instead of illuminated lines");
    cmd->add_option("--line-width", a.line_width, "Line width in pixels")->capture_default_str();
    cmd->add_flag("--no-culling", a.no_culling, "Do not skip blocks outside the view frustum");
    cmd->add_flag("--no-lod", a.no_lod, "Draw every block in full, however small on screen");
    cmd->add_option("--lod-pixels", a.lod_pixels, "Blocks smaller than this on screen (diameter) are one segment")
        ->capture_default_str();
    cmd->add_option("--fibers", a.fibers, "Only fibers whose ID is in FIRST:LAST (inclusive)");
    cmd->add_option("--min-length", a.min_length, "Only fibers at least this long (mm)");
    cmd->add_option("--max-length", a.max_length, "Only fibers at most this long (mm)");
    cmd->add_option("--decoder", a.decoder,
                    "GPU decoder: scan (prefix product, a workgroup per block), sequential (an invocation per "
                    "block), or auto (sequential on software renderers, else scan)")
        ->capture_default_str();
}

void parse_size(const std::string& text, int& width, int& height) {
    const std::size_t x = text.find('x');
    char *e1 = nullptr, *e2 = nullptr;
    if (x != std::string::npos) {
        const std::string w = text.substr(0, x), h = text.substr(x + 1);
        const long lw = std::strtol(w.c_str(), &e1, 10), lh = std::strtol(h.c_str(), &e2, 10);
        if (!w.empty() && !h.empty() && *e1 == '\0' && *e2 == '\0' && lw >= 1 && lh >= 1 && lw <= 8192 && lh <= 8192) {
            width = int(lw), height = int(lh);
            return;
        }
    }
    throw Error(Errc::invalid_argument, "--size: '" + text + "' is not WIDTHxHEIGHT (1..8192 pixels a side)");
}

viewer::RenderOptions render_options_from(const ViewerArgs& a) {
    viewer::RenderOptions o;
    o.frustum_culling = !a.no_culling;
    o.level_of_detail = !a.no_lod;
    if (!(a.lod_pixels > 0)) throw Error(Errc::invalid_argument, "--lod-pixels must be positive");
    o.lod_pixels = a.lod_pixels;
    if (!(a.line_width >= 1 && a.line_width <= 64)) throw Error(Errc::invalid_argument, "--line-width must be in 1..64");
    o.line_width = a.line_width;
    o.lighting = !a.no_lighting;
    o.color_by_direction = a.color == "direction";
    if (!o.color_by_direction) o.fixed_color = parse_color(a.color, "--color");
    o.background = parse_color(a.background, "--background");
    if (!a.fibers.empty()) {
        const std::size_t colon = a.fibers.find(':');
        if (colon == std::string::npos) throw Error(Errc::invalid_argument, "--fibers takes FIRST:LAST");
        o.id_min = parse_u32(a.fibers.substr(0, colon), "--fibers");
        o.id_max = parse_u32(a.fibers.substr(colon + 1), "--fibers");
        if (o.id_min > o.id_max) throw Error(Errc::invalid_argument, "--fibers: FIRST is after LAST");
    }
    if (a.min_length < 0 || a.max_length < 0) throw Error(Errc::invalid_argument, "fiber lengths must be positive");
    o.min_length_mm = a.min_length;
    if (a.decoder != "auto") {
        o.decoder = viewer::parse_decoder(a.decoder);
        if (!o.decoder) throw Error(Errc::invalid_argument, "--decoder: '" + a.decoder + "' is not auto, scan or sequential");
    }
    if (a.max_length > 0) o.max_length_mm = a.max_length;
    return o;
}

}  // namespace fiblet::cli
