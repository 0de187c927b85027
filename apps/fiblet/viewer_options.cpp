#include "viewer_options.hpp"

#include <algorithm>

#include <cstdlib>
#include <filesystem>
#include <limits>

#include "fiber_ranges.hpp"
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

// A per-streamline value source (--fiber-values, --fiber-opacity): an
// existing file or dps/NAME (fiblet_viewer/scene_sources.hpp).
CLI::Validator fiber_values_check() {
    return CLI::ExistingFile | CLI::Validator(
                                   [](const std::string& v) {
                                       return viewer::is_data_field_name(v) ? std::string() : "not dps/NAME";
                                   },
                                   "dps/NAME");
}

std::uint32_t fiber_id(std::uint64_t id) {
    if (id > std::numeric_limits<std::uint32_t>::max())
        throw Error(Errc::invalid_argument, "--fibers: " + std::to_string(id) + " is not a fiber ID (at most 2^32-1)");
    return std::uint32_t(id);
}

// "MIN:MAX" or "MIN,MAX" with MIN < MAX.
std::array<float, 2> parse_value_range(const std::string& text) {
    const std::size_t sep = text.find_first_of(":,");
    char *e1 = nullptr, *e2 = nullptr;
    const std::string lo = text.substr(0, sep), hi = sep == std::string::npos ? "" : text.substr(sep + 1);
    const float low = std::strtof(lo.c_str(), &e1), high = std::strtof(hi.c_str(), &e2);
    if (sep == std::string::npos || lo.empty() || hi.empty() || *e1 != '\0' || *e2 != '\0' || !(low < high))
        throw Error(Errc::invalid_argument, "--value-range: '" + text + "' is not MIN:MAX with MIN < MAX");
    return {low, high};
}

// --point-values, --colormap and their --value-range.
void set_point_values(const ViewerArgs& a, viewer::RenderOptions& o) {
    const auto map = viewer::parse_colormap(a.colormap);
    if (!map) throw Error(Errc::invalid_argument, "--colormap: '" + a.colormap + "' is not viridis, magma or coolwarm");
    o.colormap = *map;
    o.point_values = !a.point_values.empty();
    if (o.point_values && !a.value_range.empty()) o.value_range = parse_value_range(a.value_range);
    // The colour bar's name: NAME of dpv/NAME, else the file's stem.
    const bool data = a.point_values.rfind("dpv/", 0) == 0 && !std::filesystem::exists(a.point_values);
    o.value_name = data ? a.point_values.substr(4) : std::filesystem::path(a.point_values).stem().string();
    o.color_bar = !a.no_color_bar;
}

// --opacity and --transparency: the default order is sorted; voxlines
// draw lines only.
// "lines, tubes, capsules" -> its words: the set a value must be one of
// (CLI::IsMember), which the help and the bash completion then list.
CLI::IsMember one_of(const std::string& names) {
    std::vector<std::string> words;
    for (std::size_t at = 0; at < names.size();) {
        const std::size_t end = std::min(names.find(',', at), names.size());
        words.push_back(names.substr(at, end - at));
        at = names.find_first_not_of(", ", end);
        if (at == std::string::npos) break;
    }
    return CLI::IsMember(words);
}

void set_transparency(const ViewerArgs& a, viewer::RenderOptions& o) {
    if (!(a.opacity > 0 && a.opacity <= 1)) throw Error(Errc::invalid_argument, "--opacity must be in (0, 1]");
    o.opacity = a.opacity;
    const bool lines = o.style == viewer::DrawStyle::lines;
    if (a.transparency.empty()) {
        o.transparency = viewer::TransparencyMode::sorted;
        return;
    }
    const auto mode = viewer::parse_transparency_mode(a.transparency);
    if (!mode)
        throw Error(Errc::invalid_argument, "--transparency: '" + a.transparency + "' is not one of " +
                                                viewer::transparency_mode_names());
    if (!lines && *mode == viewer::TransparencyMode::voxlines)
        throw Error(Errc::invalid_argument, "--transparency voxlines draws lines; --style " +
                                                std::string(viewer::draw_style_name(o.style)) +
                                                " blends sorted or unsorted");
    o.transparency = *mode;
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
    cmd->add_option("--fiber-colors", a.fiber_colors,
                    "Colour each streamline from a text file: RRGGBB per streamline, in file order ('#' lines "
                    "ignored)")
        ->check(CLI::ExistingFile);
    cmd->add_option("--fiber-values", a.fiber_values,
                    "Colour each streamline by a value, through viridis: a text file (one number per streamline, as "
                    "MRtrix3's per-streamline files) or dps/NAME, the per-streamline data the .fft carries (a .trk's "
                    "properties, a TRX's dps/)")
        ->check(fiber_values_check());
    cmd->add_option("--point-values", a.point_values,
                    "Colour each point by a value (lines, tubes, capsules; not voxlines or voxel-rt): an MRtrix3 track scalar file (.tsf, as tcksample writes; "
                    "one value per point of every streamline) or dpv/NAME, the per-point data the .fft carries")
        ->check(CLI::ExistingFile | CLI::Validator(
                                        [](const std::string& v) {
                                            return v.rfind("dpv/", 0) == 0 && v.size() > 4 ? std::string() : "not dpv/NAME";
                                        },
                                        "dpv/NAME"));
    cmd->add_option("--colormap", a.colormap, "Colour map of --point-values")
        ->check(one_of("viridis, magma, coolwarm"))
        ->capture_default_str();
    cmd->add_flag("--no-color-bar", a.no_color_bar, "No colour bar of --point-values (drawn at the bottom edge)");
    cmd->add_option("--value-range", a.value_range, "MIN:MAX (or MIN,MAX) of --fiber-values or --point-values mapped to "
                                                    "the colour map (default: the values' range)");
    cmd->add_option("--background", a.background, "Background colour: RRGGBB, black, white, gray")
        ->capture_default_str();
    cmd->add_flag("--no-lighting", a.no_lighting, "Flat colours instead of illuminated lines");
    cmd->add_option("--line-width", a.line_width, "Line width in pixels")->capture_default_str();
    cmd->add_option("--style", a.style, "How fibers are drawn: " + viewer::draw_style_names() +
                                            " (tubes: ray-cast spline tubes; capsules: a ray-cast capsule per "
                                            "segment; docs/viewer.md)")
        ->check(one_of(viewer::draw_style_names()))
        ->capture_default_str();
    cmd->add_option("--radius", a.radius, "Tube and capsule radius in mm (--style tubes, capsules; --engine voxel-rt)")
        ->capture_default_str();
    cmd->add_option("--engine", a.engine,
                    "What draws: " + viewer::render_engine_names() +
                        " (raster: the --style techniques; voxel-rt: every segment a capsule of --radius, ray "
                        "traced through a voxel grid; docs/viewer.md)")
        ->check(one_of(viewer::render_engine_names()))
        ->capture_default_str();
    cmd->add_option("--grid", a.grid, "Voxels per side of the voxel ray tracer's cubic grid, 4..512 (--engine voxel-rt)")
        ->capture_default_str();
    cmd->add_flag("--ao", a.ao,
                  "Ambient occlusion from 12 cones through a voxel occupancy (--engine voxel-rt: of every segment; "
                  "raster: of one chord per block, nothing decoded)");
    cmd->add_flag("--shadows", a.shadows, "A shadow ray towards the light (--engine voxel-rt)");
    cmd->add_flag("--no-empty-space-skipping", a.no_empty_space_skipping,
                  "Rays walk the grid voxel by voxel instead of skipping the empty cells of its mip pyramid, for "
                  "comparison: the same image, slower (--engine voxel-rt)");
    cmd->add_option("--fiber-radii", a.fiber_radii,
                    "Tube and capsule radius per streamline from a text file (mm, one per streamline, in file "
                    "order), instead of --radius (also --engine voxel-rt)")
        ->check(CLI::ExistingFile);
    cmd->add_option("--gpu-memory", a.gpu_memory_mb,
                    "GPU memory (MiB) the fibers may take; a file beyond it is held in part: the fibers the view "
                    "sees, thinned evenly to fit (default: half of what the driver reports free, else 1024)")
        ->check(CLI::PositiveNumber);
    cmd->add_option("--opacity", a.opacity,
                    "Opacity of every streamline, in (0, 1]; below 1 they blend, ordered by --transparency "
                    "(--engine voxel-rt: every capsule a ray enters composited in depth order)")
        ->capture_default_str();
    cmd->add_option("--fiber-opacity", a.fiber_opacity,
                    "Opacity per streamline, in [0, 1], times --opacity (below 1 they blend): a text file (one "
                    "number per streamline, in file order) or dps/NAME, as --fiber-values (also --engine voxel-rt)")
        ->check(fiber_values_check());
    cmd->add_option("--transparency", a.transparency,
                    "How streamlines blend when --opacity < 1 or with --fiber-opacity: sorted (~1 mm chunks sorted back to front on the "
                    "GPU; the default; lines, tubes, capsules), voxlines (10 mm voxels back to front, precomputed "
                    "axis orders inside; lines), unsorted (plain blending)")
        ->check(one_of(viewer::transparency_mode_names()));
    cmd->add_option("--supersample", a.supersample,
                    "Anti-aliasing of the PNG (render) or screenshots (view): draw N times larger per axis and "
                    "average, 1..8")
        ->capture_default_str();
    cmd->add_flag("--no-culling", a.no_culling, "Do not skip blocks outside the view frustum");
    cmd->add_flag("--no-lod", a.no_lod, "Draw every block in full, however small on screen");
    cmd->add_option("--lod-pixels", a.lod_pixels, "Blocks smaller than this on screen (diameter) are one segment")
        ->capture_default_str();
    cmd->add_option("--fibers", a.fibers, "Only fibers whose ID is in FIRST-LAST (inclusive, 0-based; FIRST:LAST too)");
    cmd->add_option("--highlight", a.highlight,
                    "Fiber IDs drawn as they are while every other fiber is dimmed (as picking does in the window; "
                    "IDs and ranges as --fibers, at most " + std::to_string(viewer::kMaxHighlightedFibers) + ")");
    cmd->add_option("--min-length", a.min_length, "Only fibers at least this long (mm)");
    cmd->add_option("--max-length", a.max_length, "Only fibers at most this long (mm)");
    cmd->add_option("--decoder", a.decoder,
                    "GPU decoder: scan (prefix product, a workgroup per block), sequential (an invocation per "
                    "block), or auto (sequential on software renderers, else scan)")
        ->capture_default_str();
    cmd->add_option("--odf", a.odf,
                    "Draw ODF glyphs of a slice of this SH image (NIfTI or .mif, 4-D, lmax 0..12; e.g. FODs), "
                    "ray traced (docs/viewer.md)")
        ->check(CLI::ExistingFile);
    cmd->add_option("--odf-slice", a.odf_slice, "Slice of the --odf image: AXIS:INDEX (voxel axis x, y or z; default "
                                                "the middle z slice)");
    cmd->add_option("--odf-scale", a.odf_scale, "Glyph size: the largest glyph of the slice spans this many voxels")
        ->capture_default_str();
    cmd->add_option("--odf-lmax", a.odf_lmax, "Draw the glyphs up to this even SH degree (default: the image's)");
    cmd->add_option("--sh-basis", a.sh_basis, "SH basis of the --odf image: mrtrix (MRtrix3, tournier) or "
                                              "descoteaux07 (dipy's legacy)")
        ->capture_default_str();
    cmd->add_option("--image", a.image, "Draw a greyscale slice of this image under the fibers (NIfTI or .mif; the "
                                        "first volume of a 4-D image)")
        ->check(CLI::ExistingFile);
    cmd->add_option("--slice", a.slice, "Slice of the --image: AXIS:INDEX (voxel axis x, y or z; default the middle "
                                        "z slice)");
    cmd->add_option("--slab", a.slab, "Only fibers within a slab this thick (mm) around the slice (--image's, else "
                                      "--odf's)");
}

viewer::OverlaySources overlay_sources_from(const ViewerArgs& a) {
    viewer::OverlaySources s;
    s.odf_path = a.odf, s.image_path = a.image;
    if (!a.odf_slice.empty()) s.odf_slice = viewer::parse_slice_spec(a.odf_slice, "--odf-slice");
    if (!a.slice.empty()) s.image_slice = viewer::parse_slice_spec(a.slice, "--slice");
    if (!(a.odf_scale > 0 && a.odf_scale <= 100)) throw Error(Errc::invalid_argument, "--odf-scale must be in (0, 100]");
    s.odf_scale = a.odf_scale;
    if (a.odf_lmax != -1 && (a.odf_lmax < 0 || a.odf_lmax % 2 || a.odf_lmax > viewer::kMaxShLmax))
        throw Error(Errc::invalid_argument, "--odf-lmax must be even, 0..12");
    s.odf_lmax = a.odf_lmax;
    const auto basis = viewer::parse_sh_basis(a.sh_basis);
    if (!basis) throw Error(Errc::invalid_argument, "--sh-basis: '" + a.sh_basis + "' is not mrtrix or descoteaux07");
    s.sh_basis = *basis;
    if (!(a.slab >= 0)) throw Error(Errc::invalid_argument, "--slab must be a thickness in mm");
    s.slab_mm = a.slab;
    if (s.odf_path.empty() && (!a.odf_slice.empty() || a.odf_lmax != -1))
        throw Error(Errc::invalid_argument, "--odf-slice and --odf-lmax need --odf");
    if (s.image_path.empty() && !a.slice.empty()) throw Error(Errc::invalid_argument, "--slice needs --image");
    if (s.slab_mm > 0 && !s.any()) throw Error(Errc::invalid_argument, "--slab needs --image or --odf");
    return s;
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

std::uint64_t gpu_budget_bytes(const ViewerArgs& a) { return std::uint64_t(a.gpu_memory_mb * 1048576.0); }

viewer::RenderOptions render_options_from(const ViewerArgs& a) {
    viewer::RenderOptions o;
    o.frustum_culling = !a.no_culling;
    o.level_of_detail = !a.no_lod;
    if (!(a.lod_pixels > 0)) throw Error(Errc::invalid_argument, "--lod-pixels must be positive");
    o.lod_pixels = a.lod_pixels;
    if (!(a.line_width >= 1 && a.line_width <= 64)) throw Error(Errc::invalid_argument, "--line-width must be in 1..64");
    o.line_width = a.line_width;
    o.lighting = !a.no_lighting;
    const auto style = viewer::parse_draw_style(a.style);
    if (!style) throw Error(Errc::invalid_argument, "--style: '" + a.style + "' is not one of " + viewer::draw_style_names());
    o.style = *style;
    if (!(a.radius > 0 && a.radius <= 100)) throw Error(Errc::invalid_argument, "--radius must be in (0, 100] mm");
    o.tube_radius_mm = a.radius;
    const auto engine = viewer::parse_render_engine(a.engine);
    if (!engine)
        throw Error(Errc::invalid_argument, "--engine: '" + a.engine + "' is not one of " + viewer::render_engine_names());
    o.engine = *engine;
    if (a.grid < 4 || a.grid > 512) throw Error(Errc::invalid_argument, "--grid must be in 4..512");
    if (o.engine != viewer::RenderEngine::voxel_rt && a.shadows)
        throw Error(Errc::invalid_argument, "--shadows needs --engine voxel-rt");
    o.voxel_grid = a.grid;
    o.ambient_occlusion = a.ao;
    o.shadows = a.shadows;
    o.empty_space_skipping = !a.no_empty_space_skipping;
    if (a.supersample < 1 || a.supersample > viewer::kMaxSupersample)
        throw Error(Errc::invalid_argument, "--supersample must be in 1.." + std::to_string(viewer::kMaxSupersample));
    o.color_by_direction = a.color == "direction";
    if (!o.color_by_direction) o.fixed_color = parse_color(a.color, "--color");
    o.background = parse_color(a.background, "--background");
    if (!a.fibers.empty()) {
        // The same syntax as extract's; the GPU filter holds one range.
        const std::vector<FiberRange> ranges = parse_fiber_ranges("--fibers", a.fibers);
        if (ranges.size() != 1) throw Error(Errc::invalid_argument, "--fibers: the viewer takes one range FIRST-LAST");
        o.id_min = fiber_id(ranges[0].first), o.id_max = fiber_id(ranges[0].last);
    }
    if (!a.highlight.empty()) {
        for (const FiberRange& r : parse_fiber_ranges("--highlight", a.highlight))
            for (std::uint64_t f = r.first; f <= r.last && o.highlighted_fibers.size() <= viewer::kMaxHighlightedFibers; ++f)
                o.highlighted_fibers.push_back(fiber_id(f));
        std::sort(o.highlighted_fibers.begin(), o.highlighted_fibers.end());
        o.highlighted_fibers.erase(std::unique(o.highlighted_fibers.begin(), o.highlighted_fibers.end()),
                                   o.highlighted_fibers.end());
        if (o.highlighted_fibers.size() > viewer::kMaxHighlightedFibers)
            throw Error(Errc::invalid_argument, "--highlight: at most " + std::to_string(viewer::kMaxHighlightedFibers) +
                                                    " fibers (extract or --fibers draws larger subsets)");
    }
    if (a.min_length < 0 || a.max_length < 0) throw Error(Errc::invalid_argument, "fiber lengths must be positive");
    o.min_length_mm = a.min_length;
    if (a.decoder != "auto") {
        o.decoder = viewer::parse_gpu_decoder(a.decoder);
        if (!o.decoder) throw Error(Errc::invalid_argument, "--decoder: '" + a.decoder + "' is not auto, scan or sequential");
    }
    if (a.max_length > 0) o.max_length_mm = a.max_length;
    set_transparency(a, o);
    o.fiber_colors = !fiber_color_source(a).empty();
    set_point_values(a, o);
    o.fiber_radii = !a.fiber_radii.empty();
    o.fiber_opacity = !a.fiber_opacity.empty();
    return o;
}

viewer::FiberColorSource fiber_color_source(const ViewerArgs& a) {
    const int sources = !a.fiber_colors.empty() + !a.fiber_values.empty() + !a.point_values.empty();
    if (sources > 1)
        throw Error(Errc::invalid_argument, "--fiber-colors, --fiber-values and --point-values exclude each other");
    if (!a.value_range.empty() && a.fiber_values.empty() && a.point_values.empty())
        throw Error(Errc::invalid_argument, "--value-range needs --fiber-values or --point-values");
    viewer::FiberColorSource s{a.fiber_colors, a.fiber_values, std::nullopt, a.point_values};
    if (!a.value_range.empty()) s.value_range = parse_value_range(a.value_range);
    return s;
}

}  // namespace fiblet::cli
