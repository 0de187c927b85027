// fiblet extract IN.fft -o OUT.tck|OUT.fft [criteria] — selective decoding.
#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <optional>
#include <sstream>

#include "cli_common.hpp"
#include "fiber_ranges.hpp"
#include "fiblet/block_index.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/fft_subset.hpp"
#include "fiblet/fiber_regions.hpp"
#include "fiblet/image_mask.hpp"
#include "fiblet/select.hpp"
#include "fiblet/tck.hpp"

namespace fiblet::cli {
namespace {

struct ExtractArgs {
    bool ignore_trailer = false;
    std::string input, output;
    std::string fibers;
    bool fibers_given = false;  // --fibers "" is an error, not "all fibers"
    std::optional<double> min_length, max_length, random_fraction;
    std::uint64_t seed = 0;
    std::vector<std::string> include, exclude;
    std::string mode = "fibers";
    bool ends_only = false, inverse = false;
    std::uint64_t skip = 0;
    std::optional<std::uint64_t> number;
    std::string camera_position, camera_target, camera_up = "0,1,0", lod;
    float fov = 45, aspect = 16.0f / 9.0f, near_mm = 1, far_mm = 2000, lod_pixels = kDefaultLodPixels;
    bool no_cull = false, compute_index = false, force = false, quiet = false, json = false;
    bool fine_index = false;  // a .fft output's block index: version 4
};

[[noreturn]] void usage(const std::string& what) { throw Error(Errc::invalid_argument, what); }

std::vector<double> numbers(const std::string& option, const std::string& text) {
    std::vector<double> v;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) {
        std::size_t used = 0;
        double x = 0;
        try {
            x = std::stod(item, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used == 0 || used != item.size() || !std::isfinite(x))
            usage(option + ": '" + item + "' is not a number (expected comma-separated numbers)");
        v.push_back(x);
    }
    return v;
}

Vec3f vec3(const std::string& option, const std::string& text) {
    const auto v = numbers(option, text);
    if (v.size() != 3) usage(option + " takes x,y,z");
    return {float(v[0]), float(v[1]), float(v[2])};
}

bool looks_like_image(const std::string& text) {
    for (const char* ext : {".nii", ".nii.gz", ".mif", ".mih", ".mif.gz"})
        if (text.ends_with(ext)) return true;
    return std::filesystem::exists(text);
}

// x,y,z,r: a sphere (as tckedit); x0,y0,z0,x1,y1,z1: a box; an image path: a
// mask (as tckedit, which also tries numbers first, then an image).
Region region(const std::string& option, const std::string& text) {
    if (text.find_first_not_of("0123456789+-.,eE ") != std::string::npos && looks_like_image(text))
        return Region::image(ImageMask::read(text));
    const auto v = numbers(option, text);
    if (v.size() == 4) return Region::sphere({float(v[0]), float(v[1]), float(v[2])}, float(v[3]));
    if (v.size() == 6) {
        // Two opposite corners, in either order (tests/select_cli_test.cpp): never an inverted box.
        const Vec3f a{float(v[0]), float(v[1]), float(v[2])}, b{float(v[3]), float(v[4]), float(v[5])};
        return Region::box_between({std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)},
                                   {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)});
    }
    usage(option + " takes x,y,z,radius (sphere), x0,y0,z0,x1,y1,z1 (box) or a mask image (.nii, .nii.gz, .mif)");
}

Query build_query(const ExtractArgs& a) {
    Query q;
    if (a.fibers_given) q.fibers = parse_fiber_ranges("--fibers", a.fibers);
    q.min_length_mm = a.min_length;
    q.max_length_mm = a.max_length;
    q.random_fraction = a.random_fraction;
    q.random_seed = a.seed;
    for (const auto& s : a.include) q.include.push_back(region("--include", s));
    for (const auto& s : a.exclude) q.exclude.push_back(region("--exclude", s));
    q.roi_mode = a.mode == "blocks" ? RoiMode::blocks : RoiMode::fibers;
    if (q.roi_mode == RoiMode::blocks && (a.ends_only || a.inverse))
        usage("--ends-only and --inverse decide whole fibers: not with --mode blocks");
    q.ends_only = a.ends_only, q.inverse = a.inverse, q.skip = a.skip, q.number = a.number;
    if (a.camera_position.empty() != a.camera_target.empty())
        usage("--camera-position and --camera-target go together");
    if (!a.camera_position.empty()) {
        ViewSelection v;
        v.camera.position = vec3("--camera-position", a.camera_position);
        v.camera.target = vec3("--camera-target", a.camera_target);
        v.camera.up = vec3("--camera-up", a.camera_up);
        v.camera.fov_y_deg = a.fov, v.camera.aspect = a.aspect, v.camera.near_mm = a.near_mm, v.camera.far_mm = a.far_mm;
        v.cull = !a.no_cull;
        if (!a.lod.empty()) {
            const auto x = a.lod.find('x');
            const auto w = x == std::string::npos ? std::vector<double>{} : numbers("--lod", a.lod.substr(0, x));
            const auto h = x == std::string::npos ? std::vector<double>{} : numbers("--lod", a.lod.substr(x + 1));
            if (w.size() != 1 || h.size() != 1 || !(w[0] >= 1 && h[0] >= 1 && w[0] < 1e6 && h[0] < 1e6))
                usage("--lod takes the viewport size as WIDTHxHEIGHT pixels, e.g. 1920x1080");
            v.lod = Viewport{int(w[0]), int(h[0])};
            v.lod_pixels = a.lod_pixels;
        }
        q.view = v;
    } else if (!a.lod.empty() || a.no_cull) {
        usage("--lod and --no-cull need a camera (--camera-position, --camera-target)");
    }
    return q;
}

// An include region that meets no block keeps nothing: most often a mask or
// coordinates in another space than the tractogram's (voxels, not mm).
void warn_about_regions_missing(const ExtractArgs& a, const Query& q, const BlockIndex& index) {
    for (std::size_t i = 0; i < q.include.size(); ++i) {
        const std::vector<std::uint64_t> near = blocks_near(index, q.include[i]);
        if (std::any_of(near.begin(), near.end(), [](std::uint64_t w) { return w != 0; })) continue;
        fmt::print(stderr,
                   "fiblet: warning: --include {} lies where {} has no point: no fiber can be kept{}\n", a.include[i],
                   a.input,
                   q.roi_mode == RoiMode::fibers ? " (is it in the tractogram's world space, in mm, as the .tck?)" : "");
    }
}

void run(const ExtractArgs& a) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::string ext = std::filesystem::path(a.output).extension().string();
    if (ext != ".tck" && ext != ".fft") usage("-o: the output must be a .tck or a .fft file");
    const Query query = build_query(a);
    if (ext == ".fft" && query.has_level_of_detail())
        usage("--lod produces segments that a .fft file cannot hold: write a .tck");
    const FftFile file = open_fft_input(a.input, a.ignore_trailer);
    const FftHeader& h = file.header();
    if (ext == ".tck" && !file.streamline_fields().empty() && !a.quiet)  // a .fft output carries them (write_fft_subset)
        fmt::print(stderr, "fiblet: note: the {} data arrays of {} (DATA chunk) have no place in a .tck: extract to a .fft to keep them\n",
                   file.streamline_fields().size(), a.input);
    const auto t_open = std::chrono::steady_clock::now();
    const BlockIndex index = a.compute_index ? BlockIndex::compute(file) : BlockIndex::load(file);
    const auto t_index = std::chrono::steady_clock::now();
    if (!a.quiet) warn_about_regions_missing(a, query, index);

    SelectionStats stats;
    std::uint64_t bytes = 0;
    if (ext == ".tck") {
        TckHeader header;
        header.properties = file.properties();
        set_decoded_step_size(header, file);
        TckWriter writer(a.output, header.properties, a.force);
        Progress progress(a.quiet || a.json);
        stats = select(file, index, query, [&](const SelectedChunk& chunk) {
            for (std::size_t i = 0; i < chunk.size(); ++i)
                write_decoded_fiber(writer, chunk.xyz_of(i), chunk.points_of(i), a.input, chunk.runs[i].fiber);
            if (!chunk.runs.empty() && h.fibers)
                progress.update("extract", double(chunk.runs.back().fiber + 1) / double(h.fibers));
        });
        writer.finish();
        progress.done();
        bytes = std::filesystem::file_size(a.output);
    } else {
        // Regions alone: decided on all cores where the library's rule says so.
        std::optional<std::vector<SelectedRun>> runs = kept_fiber_runs(file, index, query, 0, &stats);
        const bool on_all_cores = runs.has_value();
        if (!runs) runs = select_runs(file, index, query, &stats);
        const SubsetReport report = write_fft_subset(file, *runs, a.output, a.force, index_format_for(a.fine_index));
        if (on_all_cores) stats.points = report.points;
        bytes = report.bytes;
    }
    const auto t1 = std::chrono::steady_clock::now();
    auto secs = [](auto from, auto to) { return std::chrono::duration<double>(to - from).count(); };
    const char* source = index.source() == BlockIndex::Source::chunk ? "stored" : "computed";
    if (a.json) {
        Json j;
        j.str("input", a.input).str("output", a.output).str("index", source);
        j.integer("fibers", stats.fibers).integer("streamlines", stats.runs).integer("blocks", stats.blocks);
        j.integer("coarse_blocks", stats.coarse_blocks).integer("points", stats.points);
        j.integer("source_blocks", h.blocks).integer("blocks_tested", stats.blocks_tested).integer("blocks_read", stats.blocks_read);
        j.integer("blocks_decoded", stats.blocks_decoded).integer("output_bytes", bytes);
        j.num("index_seconds", secs(t_open, t_index)).num("select_seconds", secs(t_index, t1));
        j.num("seconds", secs(t0, t1));
        fmt::print("{}\n", j.render());
    } else if (!a.quiet) {
        if (a.number && stats.fibers < *a.number)
            fmt::print(stderr, "fiblet: note: {} fibers kept, fewer than --number {}\n", stats.fibers, *a.number);
        fmt::print("{} -> {}: {} of {} fibers as {} streamlines, {} points\n", a.input, a.output, stats.fibers,
                   h.fibers, stats.runs, stats.points);
        fmt::print("  blocks kept {} of {} ({:.2f}%){}, read {}, decoded {}\n", stats.blocks, h.blocks,
                   h.blocks ? 100.0 * double(stats.blocks) / double(h.blocks) : 0.0,
                   stats.coarse_blocks ? fmt::format(" ({} as one segment)", stats.coarse_blocks) : "",
                   stats.blocks_read, stats.blocks_decoded);
        fmt::print("  index {} in {:.3f} s, selection {:.3f} s, total {:.3f} s\n", source, secs(t_open, t_index),
                   secs(t_index, t1), secs(t0, t1));
    }
}

}  // namespace

void add_extract(CLI::App& app) {
    auto args = std::make_shared<ExtractArgs>();
    CLI::App* cmd = app.add_subcommand(
        "extract", "Decode only part of a .fft file: fiber subset, regions of interest, view frustum, level of detail");
    cmd->add_option("input", args->input, "Input .fft file")->required()->check(CLI::ExistingFile);
    cmd->add_option("-o,--output", args->output, "Output .tck (points) or .fft (a subset file)")->required();
    CLI::Option* fibers =
        cmd->add_option("--fibers", args->fibers, "Fiber IDs and inclusive ranges, e.g. 0,5,10-20 (0-based; FIRST:LAST also reads as a range)");
    cmd->add_option("--min-length", args->min_length, "Keep fibers at least this long (mm), as tckedit -minlength");
    cmd->add_option("--max-length", args->max_length, "Keep fibers at most this long (mm), as tckedit -maxlength");
    cmd->add_option("--random-fraction", args->random_fraction, "Keep this fraction of the fibers, at random");
    cmd->add_option("--seed", args->seed, "Seed of --random-fraction (default 0)");
    cmd->add_option("--include", args->include,
                    "Include region: x,y,z,radius (sphere), x0,y0,z0,x1,y1,z1 (box) or a mask image "
                    "(.nii, .nii.gz, .mif; tckedit's rule: the nearest voxel's value rounds to non-zero); repeatable");
    cmd->add_option("--exclude", args->exclude, "Exclude region, same forms; repeatable");
    cmd->add_option("--mode", args->mode, "fibers: keep whole fibers (tckedit); blocks: keep the blocks in the regions")
        ->check(CLI::IsMember({"fibers", "blocks"}));
    cmd->add_flag("--ends-only", args->ends_only,
                  "Test only each fiber's first and last points against the regions, as tckedit -ends_only");
    cmd->add_flag("--inverse", args->inverse,
                  "Keep the fibers that fail at least one fiber criterion (IDs, length, random subset, regions) "
                  "instead, as tckedit -inverse");
    cmd->add_option("--skip", args->skip, "Leave out the first N fibers kept (in file order), as tckedit -skip");
    cmd->add_option("--number", args->number, "Keep at most N fibers (after --skip), as tckedit -number");
    cmd->add_option("--camera-position", args->camera_position, "Camera position x,y,z (mm): frustum culling");
    cmd->add_option("--camera-target", args->camera_target, "Point the camera looks at, x,y,z (mm)");
    cmd->add_option("--camera-up", args->camera_up, "Camera up vector x,y,z (default 0,1,0)");
    cmd->add_option("--fov", args->fov, "Vertical field of view in degrees (default 45)");
    cmd->add_option("--aspect", args->aspect, "Viewport width / height (default 16/9)");
    cmd->add_option("--near", args->near_mm, "Near clip distance in mm (default 1)");
    cmd->add_option("--far", args->far_mm, "Far clip distance in mm (default 2000)");
    cmd->add_flag("--no-cull", args->no_cull, "Keep blocks outside the frustum (with --lod)");
    cmd->add_option("--lod", args->lod, "Level of detail for a viewport WIDTHxHEIGHT (pixels): .tck output only");
    cmd->add_option("--lod-pixels", args->lod_pixels, "Blocks under this many pixels become one segment (default 4)");
    cmd->add_flag("--compute-index", args->compute_index, "Compute the block index by decoding, ignoring a stored one");
    add_fine_index_flag(cmd, args->fine_index);
    cmd->add_flag("-f,--force", args->force, "Overwrite an existing output");
    cmd->add_flag("-q,--quiet", args->quiet, "Print nothing but errors");
    cmd->add_flag("--json", args->json, "Print the summary as JSON");
    add_ignore_trailer_flag(cmd, args->ignore_trailer);
    cmd->callback([args, fibers] {
        args->fibers_given = fibers->count() > 0;
        run(*args);
    });
}

}  // namespace fiblet::cli
