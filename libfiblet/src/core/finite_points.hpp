// Internal: the first point of a streamline that is not finite. Every
// reader refuses such points (a NaN or infinite coordinate, or a value
// beyond the float range once in RAS+ mm) where it reads them, so that
// nothing downstream — compress's step, a written file — ever holds one.
#pragma once

#include <cmath>
#include <optional>
#include <span>
#include <string>

#include "fiblet/geometry.hpp"

namespace fiblet::detail {

inline std::optional<std::size_t> first_non_finite(std::span<const Vec3f> points) {
    for (std::size_t k = 0; k < points.size(); ++k)
        if (!(std::isfinite(points[k].x) && std::isfinite(points[k].y) && std::isfinite(points[k].z))) return k;
    return std::nullopt;
}

// "point K (0-based) is not finite: (x, y, z)" for a message after the streamline's label.
inline std::string non_finite_point_message(std::span<const Vec3f> points, std::size_t k) {
    const Vec3f& p = points[k];
    return "point " + std::to_string(k) + " (0-based) is not finite: (" + std::to_string(p.x) + ", " +
           std::to_string(p.y) + ", " + std::to_string(p.z) + ")";
}

}  // namespace fiblet::detail
