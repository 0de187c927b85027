// fiblet — data attached to streamlines: per-streamline values (.trk
// properties, TRX dps), per-point values (.trk scalars, TRX dpv), groups of
// streamlines (TRX groups) and per-group values (TRX dpg).
//
// One array is stored as TRX stores it: little-endian, row-major, `rows`
// rows of `components` values of one type. Its name is its path in a TRX
// file without the extension: "dps/weight", "dpv/fa", "groups/CST_L",
// "dpg/CST_L/mean_fa". The first part says what a row is.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace fiblet {

// The TRX dtypes (the "bit" dtype is not supported).
enum class FieldType : std::uint8_t {
    int8 = 1, int16, int32, int64, uint8, uint16, uint32, uint64, float16, float32, float64,
};

std::optional<FieldType> field_type_from_name(std::string_view name);  // "float32" -> float32
const char* field_type_name(FieldType t) noexcept;
std::size_t field_type_size(FieldType t) noexcept;
// float16, float32 or float64.
inline bool is_float_type(FieldType t) noexcept {
    return t == FieldType::float16 || t == FieldType::float32 || t == FieldType::float64;
}
// One little-endian value of type `t` at `p`, as a double (float16 included).
double field_value(FieldType t, const std::uint8_t* p) noexcept;
float half_to_float(std::uint16_t h) noexcept;
// The nearest float16 (ties to even; beyond its range: ±infinity).
std::uint16_t float_to_half(float f) noexcept;
// A double as float32, out-of-range values to ±infinity (a plain cast of
// them is undefined behaviour).
inline float narrow_to_float(double v) noexcept {
    constexpr double kMax = 3.4028234663852886e38;
    return v > kMax ? INFINITY : v < -kMax ? -INFINITY : float(v);
}

enum class FieldScope { streamline, point, group, group_data };

struct StreamlineField {
    std::string name;               // "dps/weight", "dpv/fa", "groups/CST", "dpg/CST/mean"
    FieldType type = FieldType::float32;
    std::uint32_t components = 1;
    std::vector<std::uint8_t> bytes;

    // From the first part of the name (nullopt for any other).
    std::optional<FieldScope> scope() const;
    // The name without its scope: "fa" for "dpv/fa".
    std::string_view short_name() const;
    std::size_t value_size() const { return field_type_size(type); }
    std::uint64_t values() const { return bytes.size() / value_size(); }
    std::uint64_t rows() const { return components ? values() / components : 0; }
    // Value `c` of row `r`, as a double.
    double at(std::uint64_t r, std::uint32_t c) const {
        return field_value(type, &bytes[(r * components + c) * value_size()]);
    }
};

// A part of a field name ("fa" in "dpv/fa"): non-empty, printable UTF-8,
// no '/' or '\\', never "." or "..".
bool is_valid_field_name_part(std::string_view part);

// Checks a field against a tractogram of `fibers` streamlines and `points`
// points: a known scope, a name TRX can store, rows matching the scope,
// group indices below `fibers`. Returns an empty string or what is wrong.
std::string check_streamline_field(const StreamlineField& f, std::uint64_t fibers, std::uint64_t points);

}  // namespace fiblet
