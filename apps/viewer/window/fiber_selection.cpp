#include "window/fiber_selection.hpp"

#include <algorithm>

#include "fiblet/output_file.hpp"
#include "fiblet_viewer/render_options.hpp"

namespace fiblet::viewer {

bool update_selection(std::vector<std::uint32_t>& selection, std::optional<std::uint64_t> picked, bool add) {
    if (!picked || *picked > 0xffffffffu) {
        if (!add) selection.clear();  // a click on the background clears; a shift-click there keeps
        return true;
    }
    const auto fiber = std::uint32_t(*picked);
    const auto at = std::lower_bound(selection.begin(), selection.end(), fiber);
    const bool present = at != selection.end() && *at == fiber;
    if (!add) {
        selection.assign(1, fiber);
        return true;
    }
    if (present) {
        selection.erase(at);
        return true;
    }
    if (selection.size() >= kMaxHighlightedFibers) return false;
    selection.insert(at, fiber);
    return true;
}

std::string fiber_list(const std::vector<std::uint32_t>& selection) {
    std::string out;
    for (std::size_t i = 0; i < selection.size();) {
        std::size_t j = i;
        while (j + 1 < selection.size() && selection[j + 1] == selection[j] + 1) ++j;
        out += (out.empty() ? "" : ",") + std::to_string(selection[i]);
        if (j > i) out += "-" + std::to_string(selection[j]);
        i = j + 1;
    }
    return out + "\n";
}

void save_selection(const std::string& path, const std::vector<std::uint32_t>& selection) {
    AtomicOutputFile out(path, true);
    const std::string text = fiber_list(selection);
    out.write(text.data(), text.size());
    out.commit();
}

}  // namespace fiblet::viewer
