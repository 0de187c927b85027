// Brute-force reference for the selection tests: decode every block of a
// file, then apply the documented criteria of select.hpp one fiber and one
// block at a time, with no index and no pruning.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "fiblet/decode.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/select.hpp"
#include "fiblet/view.hpp"

namespace fiblet::test {

struct DecodedBlock {
    std::uint64_t fiber = 0;
    std::size_t first_point = 0;  // into DecodedFile::points.xyz (point index)
    std::uint32_t points = 0;
    Sphere sphere{};
    bool last_of_fiber = false;
};

struct DecodedFile {
    Streamlines points;                // every fiber, fully decoded
    std::vector<DecodedBlock> blocks;  // every block, in file order
};

inline DecodedFile decode_everything(const FftFile& file) {
    DecodedFile d;
    decode_file(file, [&](std::uint64_t, const Streamlines& chunk) {
        const std::uint64_t base = d.points.point_count();
        d.points.xyz.insert(d.points.xyz.end(), chunk.xyz.begin(), chunk.xyz.end());
        for (std::size_t i = 1; i < chunk.offsets.size(); ++i) d.points.offsets.push_back(base + chunk.offsets[i]);
    });
    const FftHeader& h = file.header();
    const auto raw = file.read_blocks(0, h.blocks);
    for (std::uint64_t f = 0; f < h.fibers; ++f) {
        std::size_t at = d.points.offsets[f];
        const std::uint64_t first = file.first_block(f), count = file.block_count(f);
        for (std::uint64_t b = first; b < first + count; ++b) {
            const std::uint8_t* bytes = &raw[b * h.block_bytes()];
            const std::uint32_t n = block_flags(h, bytes).point_count;
            d.blocks.push_back({f, at, n, block_bounding_sphere(h, bytes), b + 1 == first + count});
            at += n;
        }
        EXPECT_EQ(at, d.points.offsets[f + 1]);
    }
    return d;
}

inline Vec3f point_at(const DecodedFile& d, std::size_t i) {
    return {d.points.xyz[3 * i], d.points.xyz[3 * i + 1], d.points.xyz[3 * i + 2]};
}

// Region membership written out again from its definition.
// (Image masks: ImageMask::contains, checked against tckedit in select_mask_test.cpp.)
inline bool inside(const Region& r, Vec3f p) {
    if (r.shape == Region::Shape::mask) return r.mask->contains(p);
    if (r.shape == Region::Shape::sphere) {
        const float dx = p.x - r.center.x, dy = p.y - r.center.y, dz = p.z - r.center.z;
        return dx * dx + dy * dy + dz * dz <= r.radius * r.radius;
    }
    return r.box.min.x <= p.x && p.x <= r.box.max.x && r.box.min.y <= p.y && p.y <= r.box.max.y &&
           r.box.min.z <= p.z && p.z <= r.box.max.z;
}

inline bool any_inside(const DecodedFile& d, std::size_t first, std::size_t count, const Region& r) {
    for (std::size_t i = first; i < first + count; ++i)
        if (inside(r, point_at(d, i))) return true;
    return false;
}

// The random subset rule of select.hpp, restated.
inline std::uint64_t reference_splitmix64(std::uint64_t x) {
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

struct ReferenceSelection {
    Streamlines lines;
    std::vector<SelectedRun> runs;
};

inline ReferenceSelection reference_select(const FftFile& file, const DecodedFile& d, const Query& q) {
    const FftHeader& h = file.header();
    ReferenceSelection out;
    std::vector<float>& xyz = out.lines.xyz;
    auto push = [&](Vec3f p) { xyz.push_back(p.x), xyz.push_back(p.y), xyz.push_back(p.z); };
    const Frustum frustum = q.view ? frustum_from_camera(q.view->camera) : Frustum{};
    std::uint64_t counted = 0;  // kept fibers with points so far (skip / number)
    for (std::uint64_t f = 0; f < h.fibers; ++f) {
        const std::size_t p0 = d.points.offsets[f], np = d.points.offsets[f + 1] - p0;
        bool keep = q.fibers.empty();
        for (const FiberRange& r : q.fibers) keep = keep || (r.first <= f && f <= r.last);
        const double len = np < 2 ? 0.0 : double(np - 1) * double(h.step) * double(h.scaling);
        if (q.min_length_mm && len < *q.min_length_mm) keep = false;
        if (q.max_length_mm && len > *q.max_length_mm) keep = false;
        if (q.random_fraction &&
            !(double(reference_splitmix64(q.random_seed ^ reference_splitmix64(f)) >> 11) / 9007199254740992.0 <
              *q.random_fraction))
            keep = false;
        if (keep && q.roi_mode == RoiMode::fibers) {
            // ends_only: the first and last points alone.
            auto meets = [&](const Region& r) {
                if (!q.ends_only) return any_inside(d, p0, np, r);
                return np > 0 && (inside(r, point_at(d, p0)) || inside(r, point_at(d, p0 + np - 1)));
            };
            for (const Region& r : q.include) keep = keep && meets(r);
            for (const Region& r : q.exclude) keep = keep && !meets(r);
        }
        if (q.inverse) keep = !keep;
        if (keep && np > 0 && (q.skip > 0 || q.number)) {
            const std::uint64_t i = counted++;
            keep = i >= q.skip && (!q.number || i - q.skip < *q.number);
        }
        if (!keep) continue;

        const std::uint64_t first = file.first_block(f), count = file.block_count(f);
        bool open = false;
        bool pending = false;
        Vec3f end{};
        auto close = [&] {
            if (!open) return;
            if (pending) push(end);
            out.lines.offsets.push_back(xyz.size() / 3);
            open = pending = false;
        };
        for (std::uint64_t b = first; b < first + count; ++b) {
            const DecodedBlock& blk = d.blocks[b];
            bool kept = true, coarse = false;
            if (q.view) {
                if (q.view->cull && !sphere_intersects_frustum(frustum, blk.sphere.center, blk.sphere.radius))
                    kept = false;
                if (q.view->lod &&
                    2 * projected_radius_px(q.view->camera, *q.view->lod, blk.sphere.center, blk.sphere.radius) <
                        q.view->lod_pixels)
                    coarse = true;
            }
            if (kept && q.roi_mode == RoiMode::blocks) {
                bool meets = q.include.empty();
                for (const Region& r : q.include) meets = meets || any_inside(d, blk.first_point, blk.points, r);
                for (const Region& r : q.exclude) meets = meets && !any_inside(d, blk.first_point, blk.points, r);
                kept = meets;
            }
            if (!kept) {
                close();
                continue;
            }
            if (!open) {
                out.runs.push_back({f, b, 0, 0});
                open = true;
            }
            ++out.runs.back().block_count;
            if (coarse) {
                ++out.runs.back().coarse_blocks;
                push(point_at(d, blk.first_point));
                pending = !blk.last_of_fiber || blk.points > 1;
                end = blk.last_of_fiber ? point_at(d, blk.first_point + blk.points - 1)
                                        : point_at(d, d.blocks[b + 1].first_point);
            } else {
                for (std::uint32_t k = 0; k < blk.points; ++k) push(point_at(d, blk.first_point + k));
                pending = false;
            }
        }
        close();
    }
    return out;
}

inline void expect_same_selection(const ReferenceSelection& ref, const Streamlines& got,
                                  const std::vector<SelectedRun>& runs, const std::string& what) {
    ASSERT_EQ(ref.runs.size(), runs.size()) << what;
    for (std::size_t i = 0; i < runs.size(); ++i) {
        ASSERT_EQ(ref.runs[i].fiber, runs[i].fiber) << what << " run " << i;
        ASSERT_EQ(ref.runs[i].first_block, runs[i].first_block) << what << " run " << i;
        ASSERT_EQ(ref.runs[i].block_count, runs[i].block_count) << what << " run " << i;
        ASSERT_EQ(ref.runs[i].coarse_blocks, runs[i].coarse_blocks) << what << " run " << i;
    }
    ASSERT_EQ(ref.lines.offsets, got.offsets) << what;
    // Bit-exact points: the selection decodes the same blocks the same way.
    ASSERT_EQ(ref.lines.xyz.size(), got.xyz.size()) << what;
    for (std::size_t i = 0; i < got.xyz.size(); ++i) ASSERT_EQ(ref.lines.xyz[i], got.xyz[i]) << what << " float " << i;
}

// Random queries over a file's extent.
class QueryGenerator {
public:
    QueryGenerator(const DecodedFile& d, std::uint32_t seed) : d_(d), rng_(seed) {
        lo_ = hi_ = point_at(d, 0);
        for (std::size_t i = 0; i < d.points.point_count(); ++i) {
            const Vec3f p = point_at(d, i);
            lo_ = {std::min(lo_.x, p.x), std::min(lo_.y, p.y), std::min(lo_.z, p.z)};
            hi_ = {std::max(hi_.x, p.x), std::max(hi_.y, p.y), std::max(hi_.z, p.z)};
        }
    }
    float uniform(float a, float b) { return std::uniform_real_distribution<float>(a, b)(rng_); }
    Vec3f some_point() {
        const std::size_t i = std::uniform_int_distribution<std::size_t>(0, d_.points.point_count() - 1)(rng_);
        return point_at(d_, i);
    }
    Region region() {
        const Vec3f c = some_point();  // centred on the data, so that regions meet fibers
        if (uniform(0, 1) < 0.5f) return Region::sphere(c, uniform(0.5f, 15.0f));
        const Vec3f half{uniform(0.5f, 12), uniform(0.5f, 12), uniform(0.5f, 12)};
        return Region::box_between({c.x - half.x, c.y - half.y, c.z - half.z}, {c.x + half.x, c.y + half.y, c.z + half.z});
    }
    Camera camera() {
        Camera c;
        const Vec3f mid{0.5f * (lo_.x + hi_.x), 0.5f * (lo_.y + hi_.y), 0.5f * (lo_.z + hi_.z)};
        const float size = std::max({hi_.x - lo_.x, hi_.y - lo_.y, hi_.z - lo_.z});
        const float dist = uniform(0.3f, 3.0f) * size;
        const float az = uniform(0, 6.2831853f), el = uniform(-1.2f, 1.2f);
        c.target = some_point();
        c.position = {mid.x + dist * std::cos(el) * std::cos(az), mid.y + dist * std::cos(el) * std::sin(az),
                      mid.z + dist * std::sin(el)};
        c.up = {uniform(-1, 1), uniform(-1, 1), 1};
        c.fov_y_deg = uniform(5, 70);
        c.aspect = uniform(0.5f, 2.5f);
        c.near_mm = uniform(0.5f, 0.5f * dist);
        c.far_mm = c.near_mm + uniform(0.2f, 2.0f) * dist;
        return c;
    }
    std::mt19937& rng() { return rng_; }

private:
    const DecodedFile& d_;
    std::mt19937 rng_;
    Vec3f lo_, hi_;
};

}  // namespace fiblet::test
