// Intel Embree (libembree-dev) as the test-only oracle of the ray-cast
// capsules: every segment of a file (CPU-decoded points) a round linear
// curve of constant radius, which is the same capsule. Include only when
// FIBLET_HAS_EMBREE.
//
// Two Embree scenes of the same curves. In `tube_`, consecutive segments
// are neighbours (Embree's default flags), and Embree splits a fiber's
// tube surface between its segments: a cylinder without the parts inside
// its neighbours' cylinders, the sphere at a joint the earlier segment's
// where it is outside both cylinders. That split has float cracks: each
// segment is intersected from its own rounded ray origin, so where two
// segments' parts meet (the sphere and the next cylinder; two cylinders
// crossing at a slight bend) both can reject a ray. Measured on CST_R
// (r 0.6 mm, 160² rays, viewer_voxel_rt_test): 11 entries 0.1–0.5 mm deep
// into a tube missed of 25,016, one of them by 259 of 271 rays along the
// same line from origins up to 100 mm apart. In `capsules_` every segment
// is a closed capsule (no neighbours: cone and both spheres), which has no
// such cracks. The queries take where the ray enters a tube from the
// closed capsules (an entry not inside another capsule of the fiber), and
// which segment owns that point of the surface from `tube_` when it finds
// the same entry (else the closed capsule's segment).
#pragma once

#include <embree3/rtcore.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <vector>

#include "viewer_test_util.hpp"

namespace fiblet::test {

class EmbreeCapsules {
public:
    struct Hit {
        float t;           // along the unit ray
        unsigned segment;  // block × points_per_block + index in the block (the viewer's numbering)
    };

    // fiber_radii: per fiber (file order), instead of radius (--fiber-radii).
    EmbreeCapsules(const FftFile& file, float radius, const std::vector<float>& fiber_radii = {}) {
        d_ = cpu_decode_blocks(file);
        const CpuDecoded& d = d_;
        const std::size_t points = d.xyz.size() / 3;
        vertices_.resize(4 * points);
        for (std::size_t i = 0; i < points; ++i) {
            const Vec3f p = d.point(i);
            vertices_[4 * i] = p.x, vertices_[4 * i + 1] = p.y, vertices_[4 * i + 2] = p.z, vertices_[4 * i + 3] = radius;
        }
        // Primitive k is segment start_[k] → start_[k] + 1 of fiber fiber_[k].
        const std::uint32_t ppb = file.header().points_per_block;
        for (std::uint64_t f = 0; f < file.header().fibers; ++f) {
            const std::uint64_t first = file.first_block(f), count = file.block_count(f);
            if (!fiber_radii.empty())
                for (std::size_t i = d.block_first[first]; i < d.block_first[first + count]; ++i)
                    vertices_[4 * i + 3] = fiber_radii[f];
            for (std::uint64_t b = first; b < first + count; ++b)
                for (std::size_t i = d.block_first[b]; i < d.block_first[b + 1]; ++i) {
                    if (i + 1 >= d.block_first[first + count]) break;
                    start_.push_back(unsigned(i));
                    fiber_.push_back(unsigned(f));
                    segment_.push_back(unsigned(b * ppb + (i - d.block_first[b])));
                    start_of_segment_[segment_.back()] = unsigned(i);
                    fiber_of_segment_[segment_.back()] = unsigned(f);
                }
        }
        device_ = rtcNewDevice(nullptr);
        tube_ = make_scene(false);
        capsules_ = make_scene(true);
    }
    ~EmbreeCapsules() {
        rtcReleaseScene(tube_);
        rtcReleaseScene(capsules_);
        rtcReleaseDevice(device_);
    }
    EmbreeCapsules(const EmbreeCapsules&) = delete;
    EmbreeCapsules& operator=(const EmbreeCapsules&) = delete;

    // Whether segments s0 and s1 follow each other in one fiber (they share
    // the sphere at their joint).
    bool consecutive(unsigned s0, unsigned s1) const {
        const auto a = start_of_segment_.find(s0), b = start_of_segment_.find(s1);
        if (a == start_of_segment_.end() || b == start_of_segment_.end()) return false;
        return a->second + 1 == b->second || b->second + 1 == a->second;
    }

    // The fiber (file order) of a segment.
    unsigned fiber(unsigned segment) const { return fiber_of_segment_.at(segment); }

    // The end points of a segment (CPU-decoded).
    std::array<Vec3f, 2> ends(unsigned segment) const {
        const unsigned i = start_of_segment_.at(segment);
        return {d_.point(i), d_.point(i + 1)};
    }

    // Whether the ray from org along the unit dir hits a capsule between
    // distances near and far (a ray starting inside a capsule hits it).
    bool occluded(const Vec3f& org, const std::array<double, 3>& dir, float near, float far) const {
        RTCRay r = ray(org, dir).ray;
        r.tnear = near, r.tfar = far;
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        rtcOccluded1(tube_, &context, &r);
        return r.tfar < 0;  // set to -inf when occluded
    }

    // Unit direction of a segment (CPU-decoded points).
    std::array<float, 3> direction(unsigned segment) const {
        const unsigned i = start_of_segment_.at(segment);
        const Vec3f a = d_.point(i), b = d_.point(i + 1);
        const float dx = b.x - a.x, dy = b.y - a.y, dz = b.z - a.z, n = std::sqrt(dx * dx + dy * dy + dz * dz);
        return {dx / n, dy / n, dz / n};
    }

    // The nearest hit (t = +inf: none).
    Hit nearest(const Vec3f& org, const std::array<double, 3>& dir) const {
        RTCRayHit rh = ray(org, dir);
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        rtcIntersect1(capsules_, &context, &rh);
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return {INFINITY, 0};
        return owner({rh.ray.tfar, rh.hit.primID}, front_hits(tube_, org, dir));
    }

    // Every entry of the ray into a fiber's tube, nearest first: the closed
    // capsules' front-facing hits (an intersection filter records each and
    // rejects it, so that the traversal goes on) that are not inside
    // another capsule of the fiber; hits of one fiber at the same distance
    // (a joint's shared surface) are one entry.
    std::vector<Hit> all(const Vec3f& org, const std::array<double, 3>& dir) const {
        const std::vector<Primitive> owners = front_hits(tube_, org, dir);
        std::vector<Primitive> hits = front_hits(capsules_, org, dir);
        std::sort(hits.begin(), hits.end(), [](const Primitive& a, const Primitive& b) { return a.t < b.t; });
        std::vector<Primitive> entries;
        for (const Primitive& h : hits) {
            bool same = false;
            for (std::size_t k = entries.size(); k-- > 0 && h.t - entries[k].t < same_entry(h.t);)
                same |= fiber_[entries[k].primitive] == fiber_[h.primitive];
            if (!same && !inside_fiber(h, org, dir)) entries.push_back(h);
        }
        std::vector<Hit> out;
        for (const Primitive& e : entries) out.push_back(owner(e, owners));
        return out;
    }

private:
    struct Primitive {
        float t;
        unsigned primitive;
    };

    // Hits of one fiber closer than this are the same entry (float noise).
    static float same_entry(float t) { return 1e-4f * (1 + t); }

    // The round linear curves; `closed`: every segment a capsule of its own.
    RTCScene make_scene(bool closed) const {
        RTCScene scene = rtcNewScene(device_);
        rtcSetSceneFlags(scene, RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);  // front_hits(): the filter in the context
        RTCGeometry curves = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE);
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(curves, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 16,
                                                              vertices_.size() / 4));
        std::copy(vertices_.begin(), vertices_.end(), v);
        auto* idx = static_cast<unsigned*>(
            rtcSetNewGeometryBuffer(curves, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, 4, start_.size()));
        std::copy(start_.begin(), start_.end(), idx);
        if (closed) {  // no neighbours (without a flags buffer Embree joins consecutive indices)
            auto* flags = static_cast<unsigned char*>(
                rtcSetNewGeometryBuffer(curves, RTC_BUFFER_TYPE_FLAGS, 0, RTC_FORMAT_UCHAR, 1, start_.size()));
            std::fill(flags, flags + start_.size(), 0);
        }
        rtcCommitGeometry(curves);
        rtcAttachGeometry(scene, curves);
        rtcReleaseGeometry(curves);
        rtcCommitScene(scene);
        return scene;
    }

    // Every front-facing hit of the ray in a scene (the geometric normal
    // against the ray).
    std::vector<Primitive> front_hits(RTCScene scene, const Vec3f& org, const std::array<double, 3>& dir) const {
        struct Context {
            RTCIntersectContext base;
            std::vector<Primitive>* hits;
            std::array<double, 3> dir;
        } context;
        rtcInitIntersectContext(&context.base);
        std::vector<Primitive> hits;
        context.hits = &hits, context.dir = dir;
        context.base.filter = [](const RTCFilterFunctionNArguments* args) {
            auto* c = reinterpret_cast<Context*>(args->context);
            auto* r = const_cast<RTCRayN*>(args->ray);
            auto* h = const_cast<RTCHitN*>(args->hit);
            const double facing = RTCHitN_Ng_x(h, args->N, 0) * c->dir[0] + RTCHitN_Ng_y(h, args->N, 0) * c->dir[1] +
                                  RTCHitN_Ng_z(h, args->N, 0) * c->dir[2];
            if (facing < 0) c->hits->push_back({RTCRayN_tfar(r, args->N, 0), RTCHitN_primID(h, args->N, 0)});
            args->valid[0] = 0;
        };
        RTCRayHit rh = ray(org, dir);
        rtcIntersect1(scene, &context.base, &rh);
        return hits;
    }

    // The segment owning an entry: the tube's hit of the same fiber at the
    // same distance, else the capsule's.
    Hit owner(const Primitive& entry, const std::vector<Primitive>& tube_hits) const {
        unsigned primitive = entry.primitive;
        float closest = same_entry(entry.t);
        for (const Primitive& h : tube_hits)
            if (fiber_[h.primitive] == fiber_[entry.primitive] && std::fabs(h.t - entry.t) < closest)
                closest = std::fabs(h.t - entry.t), primitive = h.primitive;
        return {entry.t, segment_[primitive]};
    }

    // Whether a capsule's hit lies inside another capsule of its fiber (by
    // more than float noise, 1e-6 of the distance from the eye), in double:
    // its fiber's neighbours along the fiber while they are within reach.
    bool inside_fiber(const Primitive& h, const Vec3f& org, const std::array<double, 3>& dir) const {
        const double x[3] = {org.x + double(h.t) * dir[0], org.y + double(h.t) * dir[1], org.z + double(h.t) * dir[2]};
        const double margin = 1e-6 * double(h.t);
        auto distance = [&](std::size_t k) {  // from x to primitive k's axis
            const float* a = &vertices_[4 * std::size_t(start_[k])];
            const double ab[3] = {double(a[4]) - a[0], double(a[5]) - a[1], double(a[6]) - a[2]};
            const double ax[3] = {x[0] - a[0], x[1] - a[1], x[2] - a[2]};
            const double abab = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
            const double u = abab > 0 ? std::clamp((ax[0] * ab[0] + ax[1] * ab[1] + ax[2] * ab[2]) / abab, 0.0, 1.0) : 0.0;
            double s = 0;
            for (int c = 0; c < 3; ++c) s += (ax[c] - u * ab[c]) * (ax[c] - u * ab[c]);
            return std::sqrt(s);
        };
        const double r = vertices_[4 * std::size_t(start_[h.primitive]) + 3];
        for (int step : {-1, 1})
            for (std::size_t k = h.primitive + step; k < start_.size() && fiber_[k] == fiber_[h.primitive]; k += step) {
                const double dk = distance(k);
                if (dk < r - margin) return true;
                if (dk > 4 * r + 1) break;  // the fiber has left
            }
        return false;
    }

    static RTCRayHit ray(const Vec3f& org, const std::array<double, 3>& dir) {
        RTCRayHit rh{};
        rh.ray.org_x = org.x, rh.ray.org_y = org.y, rh.ray.org_z = org.z;
        rh.ray.dir_x = float(dir[0]), rh.ray.dir_y = float(dir[1]), rh.ray.dir_z = float(dir[2]);
        rh.ray.tnear = 0, rh.ray.tfar = INFINITY, rh.ray.mask = ~0u;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        return rh;
    }

    CpuDecoded d_;
    std::vector<float> vertices_;  // x, y, z, radius per CPU-decoded point
    RTCDevice device_ = nullptr;
    RTCScene tube_ = nullptr, capsules_ = nullptr;
    std::vector<unsigned> start_, fiber_, segment_;  // per Embree primitive
    std::unordered_map<unsigned, unsigned> start_of_segment_;  // its first point, CPU-decoded numbering
    std::unordered_map<unsigned, unsigned> fiber_of_segment_;
};

}  // namespace fiblet::test
