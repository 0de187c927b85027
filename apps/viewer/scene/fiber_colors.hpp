// Per-fiber colours read from text files, one entry per streamline in file
// order (as MRtrix3's per-streamline files: whitespace-separated, lines
// starting with '#' ignored):
//   colours: RRGGBB per streamline (no '#': it starts a comment line);
//   values:  one number per streamline (e.g. tcksift2 weights, tckstats
//            -dump lengths), mapped through a colour map.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "fiblet_viewer/scene_sources.hpp"

namespace fiblet {
class FftFile;
}

namespace fiblet::viewer {

using Rgb = std::array<float, 3>;  // 0..1

// Throws fiblet::Error{io} when unreadable, {invalid_input} on a bad token
// or when the file does not hold exactly `fibers` entries.
std::vector<Rgb> read_fiber_colors(const std::string& path, std::uint64_t fibers);
std::vector<float> read_fiber_values(const std::string& path, std::uint64_t fibers);

// The per-streamline values the .fft carries in its DATA chunk (from a .trk's
// properties or a TRX's dps/), by name ("dps/weight"): one component, every
// value finite. Throws Error{invalid_argument} naming the file's dps fields
// when there is no such field, {invalid_input} for a bad one.
std::vector<float> fiber_values_from_data(const FftFile& file, const std::string& name);
// One finite number per streamline of `file` from `source`: a text file
// (read_fiber_values) or "dps/NAME" (fiber_values_from_data) as above. What
// --fiber-values and --fiber-opacity read.
std::vector<float> read_fiber_value_source(const std::string& source, const FftFile& file);

// Values mapped through viridis over [low, high] (default: the values'
// range), clamped.
std::vector<Rgb> colors_from_values(const std::vector<float>& values, std::optional<std::array<float, 2>> range = {});

class GpuScene;
// Reads the source for `scene` (made from `file`) and sets its colours and
// its per-point values (nothing when empty).
void load_fiber_colors(const FiberColorSource& source, const FftFile& file, GpuScene& scene);

// Viridis at t in [0, 1] (clamped), from 9 samples of matplotlib's table.
Rgb viridis(float t);

}  // namespace fiblet::viewer
