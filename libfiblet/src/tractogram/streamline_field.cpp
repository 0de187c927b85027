// Per-streamline, per-point and group arrays: types, scopes, checks.
#include "fiblet/streamline_field.hpp"

#include <bit>
#include <cmath>
#include <cstring>
#include <set>

namespace fiblet {
namespace {

struct TypeInfo {
    FieldType type;
    const char* name;
    std::size_t size;
};
constexpr TypeInfo kTypes[] = {
    {FieldType::int8, "int8", 1},       {FieldType::int16, "int16", 2},     {FieldType::int32, "int32", 4},
    {FieldType::int64, "int64", 8},     {FieldType::uint8, "uint8", 1},     {FieldType::uint16, "uint16", 2},
    {FieldType::uint32, "uint32", 4},   {FieldType::uint64, "uint64", 8},   {FieldType::float16, "float16", 2},
    {FieldType::float32, "float32", 4}, {FieldType::float64, "float64", 8},
};

template <class T>
T load(const std::uint8_t* p) {
    T v;
    std::memcpy(&v, p, sizeof v);  // hosts are little-endian (checked in CMake)
    return v;
}

// Well-formed UTF-8 without control characters (names reach JSON, Python
// strings and file names).
bool printable_utf8(std::string_view s) {
    for (std::size_t i = 0; i < s.size();) {
        const auto c = static_cast<unsigned char>(s[i]);
        if (c < 0x20 || c == 0x7f) return false;
        const int extra = c < 0x80 ? 0 : (c >> 5) == 6 ? 1 : (c >> 4) == 14 ? 2 : (c >> 3) == 30 ? 3 : -1;
        if (extra < 0 || (extra == 1 && c < 0xc2) || i + std::size_t(extra) >= s.size()) return false;
        for (int k = 1; k <= extra; ++k)
            if ((static_cast<unsigned char>(s[i + std::size_t(k)]) >> 6) != 2) return false;
        i += std::size_t(extra) + 1;
    }
    return true;
}

bool valid_part(std::string_view s) { return is_valid_field_name_part(s); }

}  // namespace

bool is_valid_field_name_part(std::string_view s) {
    return !s.empty() && s != "." && s != ".." && s.find_first_of("/\\") == std::string_view::npos && printable_utf8(s);
}

std::optional<FieldType> field_type_from_name(std::string_view name) {
    for (const TypeInfo& t : kTypes)
        if (name == t.name) return t.type;
    return std::nullopt;
}

const char* field_type_name(FieldType t) noexcept {
    for (const TypeInfo& i : kTypes)
        if (i.type == t) return i.name;
    return "?";
}

std::size_t field_type_size(FieldType t) noexcept {
    for (const TypeInfo& i : kTypes)
        if (i.type == t) return i.size;
    return 1;
}

float half_to_float(std::uint16_t h) noexcept {
    const std::uint32_t sign = std::uint32_t(h & 0x8000) << 16;
    const int exp = (h >> 10) & 0x1f;
    const std::uint32_t mant = h & 0x3ff;
    float v;
    if (exp == 0) v = std::ldexp(float(mant), -24);                         // zero, subnormal
    else if (exp == 31) v = mant ? std::nanf("") : INFINITY;                // inf, NaN
    else v = std::ldexp(float(mant | 0x400), exp - 25);                     // normal
    return std::bit_cast<float>(std::bit_cast<std::uint32_t>(v) | sign);
}

std::uint16_t float_to_half(float f) noexcept {
    std::uint32_t x = std::bit_cast<std::uint32_t>(f);
    const auto sign = std::uint16_t((x >> 16) & 0x8000);
    x &= 0x7fffffff;
    if (x > 0x7f800000) return sign | 0x7e00;                        // NaN
    if (x >= 0x477ff000) return sign | 0x7c00;                       // ≥ 65520 (and inf): infinity
    if (x < 0x38800000)                                              // below 2^-14: subnormal (exact scaling)
        return sign | std::uint16_t(std::nearbyint(std::bit_cast<float>(x) * 16777216.0f));
    x += 0xc8000fffu + ((x >> 13) & 1);                              // rebias, round to nearest even
    return sign | std::uint16_t(x >> 13);
}

double field_value(FieldType t, const std::uint8_t* p) noexcept {
    switch (t) {
        case FieldType::int8: return load<std::int8_t>(p);
        case FieldType::int16: return load<std::int16_t>(p);
        case FieldType::int32: return load<std::int32_t>(p);
        case FieldType::int64: return double(load<std::int64_t>(p));
        case FieldType::uint8: return load<std::uint8_t>(p);
        case FieldType::uint16: return load<std::uint16_t>(p);
        case FieldType::uint32: return load<std::uint32_t>(p);
        case FieldType::uint64: return double(load<std::uint64_t>(p));
        case FieldType::float16: return half_to_float(load<std::uint16_t>(p));
        case FieldType::float32: return load<float>(p);
        case FieldType::float64: return load<double>(p);
    }
    return 0;
}

std::optional<FieldScope> StreamlineField::scope() const {
    const std::string_view n = name;
    if (n.starts_with("dps/")) return FieldScope::streamline;
    if (n.starts_with("dpv/")) return FieldScope::point;
    if (n.starts_with("groups/")) return FieldScope::group;
    if (n.starts_with("dpg/")) return FieldScope::group_data;
    return std::nullopt;
}

std::string_view StreamlineField::short_name() const {
    const auto slash = name.find('/');
    return slash == std::string::npos ? std::string_view(name) : std::string_view(name).substr(slash + 1);
}

std::string check_streamline_field(const StreamlineField& f, std::uint64_t fibers, std::uint64_t points) {
    const auto scope = f.scope();
    if (!scope) return "\"" + f.name + "\" is not under dps/, dpv/, groups/ or dpg/";
    const std::string_view rest = f.short_name();
    const auto slash = rest.find('/');
    const bool nested = *scope == FieldScope::group_data;
    if (nested ? (slash == std::string_view::npos || !valid_part(rest.substr(0, slash)) ||
                  !valid_part(rest.substr(slash + 1)))
               : !valid_part(rest))
        return "\"" + f.name + "\" is not a valid array name";
    if (f.components == 0) return "\"" + f.name + "\" has 0 components";
    if (f.bytes.size() % (f.value_size() * f.components) != 0)
        return "\"" + f.name + "\" holds " + std::to_string(f.bytes.size()) + " bytes, not whole rows of " +
               std::to_string(f.components) + " " + field_type_name(f.type);
    const std::uint64_t rows = f.rows();
    if (*scope == FieldScope::streamline && rows != fibers)
        return "\"" + f.name + "\" has " + std::to_string(rows) + " rows for " + std::to_string(fibers) + " streamlines";
    if (*scope == FieldScope::point && rows != points)
        return "\"" + f.name + "\" has " + std::to_string(rows) + " rows for " + std::to_string(points) + " points";
    if (*scope == FieldScope::group) {
        if (f.type != FieldType::uint32 || f.components != 1) return "\"" + f.name + "\" is not a uint32 list";
        for (std::uint64_t r = 0; r < rows; ++r)
            if (load<std::uint32_t>(&f.bytes[r * 4]) >= fibers)
                return "\"" + f.name + "\" names streamline " + std::to_string(load<std::uint32_t>(&f.bytes[r * 4])) +
                       " of " + std::to_string(fibers);
    }
    return "";
}

}  // namespace fiblet
