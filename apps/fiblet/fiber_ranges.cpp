#include "fiber_ranges.hpp"

#include <sstream>

#include "fiblet/error.hpp"

namespace fiblet::cli {

std::vector<FiberRange> parse_fiber_ranges(const std::string& option, const std::string& text) {
    std::vector<FiberRange> out;
    std::stringstream ss(text);
    std::string item;
    const auto usage = [&](const std::string& what) { throw Error(Errc::invalid_argument, option + ": " + what); };
    auto id = [&](const std::string& s) {
        if (s.empty() || s.find_first_not_of("0123456789") != std::string::npos)
            usage("'" + item + "' is not an ID or a range FIRST-LAST");
        try {
            return std::uint64_t(std::stoull(s));
        } catch (const std::exception&) {
            usage("'" + item + "' is out of range");
        }
        return std::uint64_t(0);
    };
    while (std::getline(ss, item, ',')) {
        const auto sep = item.find_first_of("-:");
        if (sep == std::string::npos) {
            const std::uint64_t f = id(item);
            out.push_back({f, f});
        } else {
            out.push_back({id(item.substr(0, sep)), id(item.substr(sep + 1))});
            if (out.back().first > out.back().last) usage("'" + item + "' is an inverted range (FIRST > LAST)");
        }
    }
    if (out.empty() || text.back() == ',') usage("empty list or empty item in '" + text + "'");
    return out;
}

}  // namespace fiblet::cli
