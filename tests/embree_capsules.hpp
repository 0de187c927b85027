// Intel Embree (libembree-dev) as the test-only oracle of the ray-cast
// capsules: every segment of a file (CPU-decoded points) a round linear
// curve of constant radius, which is the same capsule. Include only when
// FIBLET_HAS_EMBREE.
#pragma once

#include <embree3/rtcore.h>

#include <algorithm>
#include <array>
#include <cmath>
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
        device_ = rtcNewDevice(nullptr);
        scene_ = rtcNewScene(device_);
        rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);  // all(): the filter in the context
        RTCGeometry curves = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE);
        const std::size_t points = d.xyz.size() / 3;
        auto* v = static_cast<float*>(
            rtcSetNewGeometryBuffer(curves, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 16, points));
        for (std::size_t i = 0; i < points; ++i) {
            const Vec3f p = d.point(i);
            v[4 * i] = p.x, v[4 * i + 1] = p.y, v[4 * i + 2] = p.z, v[4 * i + 3] = radius;
        }
        std::vector<unsigned> starts;  // segment i joins points i and i + 1 of one fiber
        const std::uint32_t ppb = file.header().points_per_block;
        for (std::uint64_t f = 0; f < file.header().fibers; ++f) {
            const std::uint64_t first = file.first_block(f), count = file.block_count(f);
            if (!fiber_radii.empty())
                for (std::size_t i = d.block_first[first]; i < d.block_first[first + count]; ++i)
                    v[4 * i + 3] = fiber_radii[f];
            for (std::uint64_t b = first; b < first + count; ++b)
                for (std::size_t i = d.block_first[b]; i < d.block_first[b + 1]; ++i) {
                    if (i + 1 >= d.block_first[first + count]) break;
                    starts.push_back(unsigned(i));
                    segment_.push_back(unsigned(b * ppb + (i - d.block_first[b])));
                    start_of_segment_[segment_.back()] = unsigned(i);
                }
        }
        auto* idx = static_cast<unsigned*>(
            rtcSetNewGeometryBuffer(curves, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, 4, starts.size()));
        std::copy(starts.begin(), starts.end(), idx);
        rtcCommitGeometry(curves);
        rtcAttachGeometry(scene_, curves);
        rtcReleaseGeometry(curves);
        rtcCommitScene(scene_);
    }
    ~EmbreeCapsules() {
        rtcReleaseScene(scene_);
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
        rtcOccluded1(scene_, &context, &r);
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
        rtcIntersect1(scene_, &context, &rh);
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return {INFINITY, 0};
        return {rh.ray.tfar, segment_[rh.hit.primID]};
    }

    // Every entry of the ray into a fiber's tube, nearest first: an
    // intersection filter records each front-facing hit (the geometric
    // normal against the ray) and rejects it, so that the traversal goes on;
    // hits of one fiber at the same distance (a joint's shared surface) are
    // one entry.
    std::vector<Hit> all(const Vec3f& org, const std::array<double, 3>& dir) const {
        struct Context {
            RTCIntersectContext base;
            std::vector<Hit>* hits;
            const std::vector<unsigned>* segment;
            std::array<double, 3> dir;
        } context;
        rtcInitIntersectContext(&context.base);
        std::vector<Hit> hits;
        context.hits = &hits, context.segment = &segment_, context.dir = dir;
        context.base.filter = [](const RTCFilterFunctionNArguments* args) {
            auto* c = reinterpret_cast<Context*>(args->context);
            auto* r = const_cast<RTCRayN*>(args->ray);
            auto* h = const_cast<RTCHitN*>(args->hit);
            const double facing = RTCHitN_Ng_x(h, args->N, 0) * c->dir[0] + RTCHitN_Ng_y(h, args->N, 0) * c->dir[1] +
                                  RTCHitN_Ng_z(h, args->N, 0) * c->dir[2];
            if (facing < 0) c->hits->push_back({RTCRayN_tfar(r, args->N, 0), (*c->segment)[RTCHitN_primID(h, args->N, 0)]});
            args->valid[0] = 0;
        };
        RTCRayHit rh = ray(org, dir);
        rtcIntersect1(scene_, &context.base, &rh);
        std::sort(hits.begin(), hits.end(), [](const Hit& a, const Hit& b) { return a.t < b.t; });
        std::vector<Hit> entries;
        for (const Hit& h : hits) {
            bool same = false;
            for (std::size_t k = entries.size(); k-- > 0 && h.t - entries[k].t < 1e-4f * (1 + h.t);)
                same |= entries[k].segment == h.segment || consecutive(entries[k].segment, h.segment);
            if (!same) entries.push_back(h);
        }
        return entries;
    }

private:
    static RTCRayHit ray(const Vec3f& org, const std::array<double, 3>& dir) {
        RTCRayHit rh{};
        rh.ray.org_x = org.x, rh.ray.org_y = org.y, rh.ray.org_z = org.z;
        rh.ray.dir_x = float(dir[0]), rh.ray.dir_y = float(dir[1]), rh.ray.dir_z = float(dir[2]);
        rh.ray.tnear = 0, rh.ray.tfar = INFINITY, rh.ray.mask = ~0u;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        return rh;
    }

    CpuDecoded d_;
    RTCDevice device_ = nullptr;
    RTCScene scene_ = nullptr;
    std::vector<unsigned> segment_;  // per Embree primitive
    std::unordered_map<unsigned, unsigned> start_of_segment_;  // its first point, CPU-decoded numbering
};

}  // namespace fiblet::test
