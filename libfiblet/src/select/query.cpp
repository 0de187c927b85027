// The criteria of a query taken one at a time: regions, fiber length, the
// random subset, and the validation of a query's values.
#include "select/query_checks.hpp"

#include <cmath>
#include <string>

#include "core/vec_math.hpp"
#include "fiblet/error.hpp"
#include "fiblet/select.hpp"

namespace fiblet {

Region Region::sphere(Vec3f center, float radius) {
    Region r;
    r.shape = Shape::sphere;
    r.center = center;
    r.radius = radius;
    return r;
}

Region Region::box_between(Vec3f min, Vec3f max) {
    Region r;
    r.shape = Shape::box;
    r.box = {min, max};
    return r;
}

Region Region::image(std::shared_ptr<const ImageMask> mask) {
    Region r;
    r.shape = Shape::mask;
    r.mask = std::move(mask);
    return r;
}

std::uint64_t splitmix64(std::uint64_t x) {
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

bool in_random_subset(std::uint64_t fiber, double fraction, std::uint64_t seed) {
    // The top 53 bits as a double in [0, 1): exact, so fraction 1 keeps all.
    return double(splitmix64(seed ^ splitmix64(fiber)) >> 11) * 0x1p-53 < fraction;
}

double fiber_length_mm(const FftHeader& h, std::uint64_t points) {
    return points < 2 ? 0.0 : double(points - 1) * double(h.step) * double(h.scaling);
}

namespace detail {

namespace {
[[noreturn]] void bad_query(const std::string& what) { throw Error(Errc::invalid_argument, "invalid query: " + what); }
bool finite(Vec3f v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

void check_region(const Region& r) {
    if (r.shape == Region::Shape::mask) {
        if (!r.mask) bad_query("an image region needs its mask");
    } else if (r.shape == Region::Shape::sphere) {
        if (!finite(r.center) || !(std::isfinite(r.radius) && r.radius >= 0))
            bad_query("a sphere needs a finite centre and a radius >= 0");
    } else if (!finite(r.box.min) || !finite(r.box.max) || r.box.min.x > r.box.max.x || r.box.min.y > r.box.max.y ||
               r.box.min.z > r.box.max.z) {
        bad_query("a box needs finite corners with min <= max on every axis");
    }
}
}  // namespace

void check_query(const Query& q) {
    for (const FiberRange& r : q.fibers)
        if (r.first > r.last) bad_query("fiber range " + std::to_string(r.first) + "-" + std::to_string(r.last));
    for (const auto& len : {q.min_length_mm, q.max_length_mm})
        if (len && !(std::isfinite(*len) && *len >= 0)) bad_query("lengths must be finite and >= 0");
    if (q.min_length_mm && q.max_length_mm && *q.min_length_mm > *q.max_length_mm)
        bad_query("the minimum length exceeds the maximum length");
    if (q.random_fraction && !(*q.random_fraction >= 0 && *q.random_fraction <= 1))
        bad_query("the random fraction must be in [0, 1]");
    for (const Region& r : q.include) check_region(r);
    for (const Region& r : q.exclude) check_region(r);
    if (q.roi_mode == RoiMode::blocks && (q.ends_only || q.inverse))
        bad_query("ends-only and inverse tests decide whole fibers: fibers mode only");
    if (q.roi_mode == RoiMode::fibers && q.include.size() > kMaxIncludeRegions)
        bad_query("at most " + std::to_string(kMaxIncludeRegions) + " include regions");
    if (q.view) {
        const Camera& c = q.view->camera;
        if (!finite(c.position) || !finite(c.target) || !finite(c.up)) bad_query("camera vectors must be finite");
        const Vec3f back = c.position - c.target;
        const Vec3f side = cross(c.up, back);
        if (!(dot(back, back) > 0)) bad_query("the camera position equals its target");
        if (!(dot(side, side) > 1e-12f * dot(back, back) * dot(c.up, c.up)))
            bad_query("the camera's up vector is zero or parallel to its view direction");
        if (!(c.fov_y_deg > 0 && c.fov_y_deg < 180)) bad_query("the field of view must be in (0, 180) degrees");
        if (!(std::isfinite(c.aspect) && c.aspect > 0)) bad_query("the aspect ratio must be positive");
        if (!(std::isfinite(c.near_mm) && c.near_mm > 0 && std::isfinite(c.far_mm) && c.far_mm > c.near_mm))
            bad_query("the clip distances need 0 < near < far");
        if (q.view->lod) {
            if (q.view->lod->width <= 0 || q.view->lod->height <= 0) bad_query("the viewport must be positive");
            if (!(std::isfinite(q.view->lod_pixels) && q.view->lod_pixels >= 0))
                bad_query("the level-of-detail threshold must be >= 0 pixels");
        }
    }
}

}  // namespace detail
}  // namespace fiblet
