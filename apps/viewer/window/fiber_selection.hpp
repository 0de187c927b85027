// The picked fibers the window highlights (RenderOptions::highlighted_fibers):
// a click selects the fiber under the cursor (or none), a shift-click adds it
// to the selection or takes it out; the selection is saved as the fiber
// list `fiblet extract --fibers` and `--highlight` read.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace fiblet::viewer {

// `picked`: the fiber's index in the file, or none (a click on the
// background). Keeps `selection` sorted, unique and within
// kMaxHighlightedFibers (a fiber added past it is ignored: false).
bool update_selection(std::vector<std::uint32_t>& selection, std::optional<std::uint64_t> picked, bool add);

// "3,17,42-45\n": ascending IDs, runs as ranges.
std::string fiber_list(const std::vector<std::uint32_t>& selection);

// Writes fiber_list to `path` atomically; throws fiblet::Error{io}.
void save_selection(const std::string& path, const std::vector<std::uint32_t>& selection);

}  // namespace fiblet::viewer
