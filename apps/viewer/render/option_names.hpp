// The names of a render option's values (style, engine, transparency mode,
// colour map) for the command line, messages and the panel: one table per
// option serves the name of a value, the value of a name, the list of
// names and the values in order.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <utility>

namespace fiblet::viewer {

template <class E, std::size_t N>
struct OptionNames {
    std::array<std::pair<E, const char*>, N> table;

    const char* name(E value) const {
        for (const auto& [v, n] : table)
            if (v == value) return n;
        return "?";
    }
    std::optional<E> parse(const std::string& name) const {
        for (const auto& [v, n] : table)
            if (name == n) return v;
        return std::nullopt;
    }
    std::string names() const {  // "a, b, c"
        std::string out;
        for (const auto& [v, n] : table) out += (out.empty() ? "" : ", ") + std::string(n);
        return out;
    }
    constexpr std::array<E, N> values() const {
        std::array<E, N> out{};
        for (std::size_t i = 0; i < N; ++i) out[i] = table[i].first;
        return out;
    }
};

// option_names(std::pair{E::a, "a"}, std::pair{E::b, "b"}, ...)
template <class E, class... More>
constexpr OptionNames<E, 1 + sizeof...(More)> option_names(std::pair<E, const char*> first, More... more) {
    return {{first, more...}};
}

}  // namespace fiblet::viewer
