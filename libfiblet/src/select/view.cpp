#include "fiblet/view.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/points_avx2.hpp"
#include "core/vec_math.hpp"
#include "index/block_spheres.hpp"

namespace fiblet {
using namespace detail;

namespace {
struct Basis {
    Vec3f right, up, back;  // camera axes; the camera looks along -back
};
Basis camera_basis(const Camera& c) {
    const Vec3f back = normalize(c.position - c.target);
    const Vec3f right = normalize(cross(c.up, back));
    return {right, cross(back, right), back};
}
}  // namespace

Mat4 view_matrix(const Camera& c) {
    const Basis b = camera_basis(c);
    return {b.right.x, b.up.x, b.back.x, 0, b.right.y, b.up.y, b.back.y, 0, b.right.z, b.up.z, b.back.z, 0,
            -dot(b.right, c.position), -dot(b.up, c.position), -dot(b.back, c.position), 1};
}

Mat4 projection_matrix(const Camera& c) {
    const float f = 1.0f / std::tan(c.fov_y_deg * float(M_PI) / 360.0f);
    const float n = c.near_mm, fa = c.far_mm;
    return {f / c.aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (fa + n) / (n - fa), -1, 0, 0, 2 * fa * n / (n - fa), 0};
}

Mat4 view_projection_matrix(const Camera& c) {
    const Mat4 p = projection_matrix(c), v = view_matrix(c);
    Mat4 m{};
    for (int col = 0; col < 4; ++col)
        for (int row = 0; row < 4; ++row) {
            float s = 0;
            for (int k = 0; k < 4; ++k) s += p[k * 4 + row] * v[col * 4 + k];
            m[col * 4 + row] = s;
        }
    return m;
}

Frustum frustum_from_camera(const Camera& c) {
    // Planes built geometrically from the camera basis (exact, and the same
    // on the GPU side, which receives these six planes as uniforms).
    const Basis b = camera_basis(c);
    const Vec3f fwd{-b.back.x, -b.back.y, -b.back.z};
    const float ty = std::tan(c.fov_y_deg * float(M_PI) / 360.0f), tx = ty * c.aspect;
    auto through_eye = [&](Vec3f n) {
        n = normalize(n);
        return Plane{n, -dot(n, c.position)};
    };
    Frustum f;
    f.planes[0] = through_eye(tx * fwd + b.right);  // left
    f.planes[1] = through_eye(tx * fwd - b.right);  // right
    f.planes[2] = through_eye(ty * fwd + b.up);     // bottom
    f.planes[3] = through_eye(ty * fwd - b.up);     // top
    f.planes[4] = Plane{fwd, -dot(fwd, c.position) - c.near_mm};
    f.planes[5] = Plane{-1.0f * fwd, dot(fwd, c.position) + c.far_mm};
    return f;
}

bool sphere_intersects_frustum(const Frustum& f, Vec3f center, float radius) {
    for (const Plane& p : f.planes)
        if (dot(p.n, center) + p.d < -radius) return false;
    return true;
}

bool box_intersects_frustum(const Frustum& f, const Aabb& box, float margin) {
    for (const Plane& p : f.planes) {
        // The box corner farthest along the plane's inward normal.
        const Vec3f c{p.n.x >= 0 ? box.max.x : box.min.x, p.n.y >= 0 ? box.max.y : box.min.y,
                      p.n.z >= 0 ? box.max.z : box.min.z};
        if (dot(p.n, c) + p.d < -margin) return false;
    }
    return true;
}

LevelOfDetail::LevelOfDetail(const Camera& c, const Viewport& v, float lod_pixels)
    : position_(c.position),
      back_(camera_basis(c).back),
      tan_half_fov_(std::tan(c.fov_y_deg * float(M_PI) / 360.0f)),
      half_height_(0.5f * float(v.height)),
      lod_pixels_(lod_pixels) {}

float LevelOfDetail::radius_px(Vec3f center, float radius) const {
    const float depth = -dot(back_, center - position_);  // distance along the view direction
    if (depth <= radius) return std::numeric_limits<float>::infinity();
    return radius / (depth * tan_half_fov_) * half_height_;
}

float projected_radius_px(const Camera& c, const Viewport& v, Vec3f center, float radius) {
    return LevelOfDetail(c, v).radius_px(center, radius);
}

bool block_is_coarse(const Camera& c, const Viewport& v, Vec3f center, float radius, float lod_pixels) {
    return LevelOfDetail(c, v, lod_pixels).coarse(center, radius);
}

namespace {
// block_bounding_sphere's arithmetic, inlined into both of its callers below
// (libfiblet builds with -ffp-contract=off: the same operations give the
// same floats in either).
inline Sphere sphere_of(const FftHeader& h, Vec3f a0, Vec3f a1, std::uint32_t n) {
    if (n < 2) return {a0, 0.0f};
    // In double: the squares of a file's extent overflow a float beyond ~1e19 mm.
    const double dx = double(a1.x) - a0.x, dy = double(a1.y) - a0.y, dz = double(a1.z) - a0.z;
    const auto r = float(std::sqrt(dx * dx + dy * dy + dz * dz) + double(n - 2) * h.step * h.scaling);
    const float padded = r * (1 + 1e-5f) + 1e-5f * h.scaling;
    // A foreign file whose blocks span near the float range: saturate, as
    // the index chunk holds finite radii and float distances that far are inf.
    return {a0, std::min(padded, std::numeric_limits<float>::max())};
}

template <class View>
inline Sphere sphere_of_block(const FftHeader& h, const std::uint8_t* bytes) {
    const View v{bytes};
    const auto a = v.anchors_normalized();
    return sphere_of(h, h.to_world(a[0], a[1], a[2]), h.to_world(a[3], a[4], a[5]), v.point_count());
}
}  // namespace

Sphere block_bounding_sphere(const FftHeader& h, const std::uint8_t* bytes) {
    return h.direction_bits() == 16 ? sphere_of_block<BlockView16>(h, bytes) : sphere_of_block<BlockView>(h, bytes);
}

Sphere block_bounding_sphere(const FftHeader& h, Vec3f a0, Vec3f a1, std::uint32_t n) { return sphere_of(h, a0, a1, n); }

namespace detail {
namespace {
#ifdef FIBLET_POINTS_AVX2
// sphere_of_block<BlockView> for blocks [0, n / 4 * 4), four at a time:
// the same float and double operations in the same order (vdivps, vsqrtpd
// and the conversions round as their scalar forms do; min(FLT_MAX, r) as
// std::min(r, FLT_MAX), which keeps a NaN), so the same bits. The six
// anchor words (BlockView::anchor_words: pairs stored most significant byte
// first, the second of a pair in the first two bytes) come out of one
// 16-byte load by two byte shuffles. Returns the blocks done.
// Two blocks' anchor words (shuffled by `pick`) as world coordinates
// (FftHeader::to_world of unpack_unorm16), one block a half.
__attribute__((target("avx2"))) inline __m256 anchor_words_world(const std::uint8_t* a, const std::uint8_t* b,
                                                                 __m128i pick, __m256 unorm, __m256 half,
                                                                 __m256 scaling, __m256 offset) {
    const __m128i wa = _mm_shuffle_epi8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(a)), pick);
    const __m128i wb = _mm_shuffle_epi8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(b)), pick);
    const __m256 v = _mm256_div_ps(_mm256_cvtepi32_ps(_mm256_set_m128i(wb, wa)), unorm);
    return _mm256_sub_ps(_mm256_mul_ps(_mm256_sub_ps(v, half), scaling), offset);
}

__attribute__((target("avx2"))) std::size_t spheres_avx2(const FftHeader& h, const std::uint8_t* const* blocks,
                                                         std::size_t n, Sphere* out) {
    const __m128i first = _mm_setr_epi8(3, 2, -1, -1, 1, 0, -1, -1, 7, 6, -1, -1, 5, 4, -1, -1);  // x0 y0 z0 x1
    const __m128i second = _mm_setr_epi8(11, 10, -1, -1, 9, 8, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1);  // y1 z1
    const __m256 unorm = _mm256_set1_ps(65535.0f), half = _mm256_set1_ps(0.5f), scaling = _mm256_set1_ps(h.scaling);
    const float ox = h.offset[0], oy = h.offset[1], oz = h.offset[2];
    const __m256 offset_first = _mm256_setr_ps(ox, oy, oz, ox, ox, oy, oz, ox);
    const __m256 offset_second = _mm256_setr_ps(oy, oz, 0, 0, oy, oz, 0, 0);
    const __m256d step = _mm256_set1_pd(double(h.step)), scaling_d = _mm256_set1_pd(double(h.scaling));
    const __m128 grow = _mm_set1_ps(1 + 1e-5f), pad = _mm_set1_ps(1e-5f * h.scaling);
    const __m128 largest = _mm_set1_ps(std::numeric_limits<float>::max());
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4) {
        for (std::size_t j = i + 8; j < std::min(i + 12, n); ++j) __builtin_prefetch(blocks[j]);
        const std::uint8_t *b0 = blocks[i], *b1 = blocks[i + 1], *b2 = blocks[i + 2], *b3 = blocks[i + 3];
        const __m256 f01 = anchor_words_world(b0, b1, first, unorm, half, scaling, offset_first),
                     f23 = anchor_words_world(b2, b3, first, unorm, half, scaling, offset_first),
                     s01 = anchor_words_world(b0, b1, second, unorm, half, scaling, offset_second),
                     s23 = anchor_words_world(b2, b3, second, unorm, half, scaling, offset_second);
        __m128 x0 = _mm256_castps256_ps128(f01), y0 = _mm256_extractf128_ps(f01, 1), z0 = _mm256_castps256_ps128(f23),
               x1 = _mm256_extractf128_ps(f23, 1);
        _MM_TRANSPOSE4_PS(x0, y0, z0, x1);  // rows were blocks 0..3
        __m128 y1 = _mm256_castps256_ps128(s01), z1 = _mm256_extractf128_ps(s01, 1), s2 = _mm256_castps256_ps128(s23),
               s3 = _mm256_extractf128_ps(s23, 1);
        _MM_TRANSPOSE4_PS(y1, z1, s2, s3);
        const __m256d dx = _mm256_sub_pd(_mm256_cvtps_pd(x1), _mm256_cvtps_pd(x0)),
                      dy = _mm256_sub_pd(_mm256_cvtps_pd(y1), _mm256_cvtps_pd(y0)),
                      dz = _mm256_sub_pd(_mm256_cvtps_pd(z1), _mm256_cvtps_pd(z0));
        const __m128i count = _mm_setr_epi32(BlockView{b0}.point_count(), BlockView{b1}.point_count(),
                                             BlockView{b2}.point_count(), BlockView{b3}.point_count());
        const __m256d along = _mm256_mul_pd(_mm256_mul_pd(_mm256_cvtepi32_pd(_mm_sub_epi32(count, _mm_set1_epi32(2))), step),
                                            scaling_d);
        const __m128 r = _mm256_cvtpd_ps(_mm256_add_pd(_mm256_sqrt_pd(detail::norm2(dx, dy, dz)), along));
        __m128 radius = _mm_min_ps(largest, _mm_add_ps(_mm_mul_ps(r, grow), pad));
        radius = _mm_andnot_ps(_mm_castsi128_ps(_mm_cmplt_epi32(count, _mm_set1_epi32(2))), radius);  // n < 2: 0
        _MM_TRANSPOSE4_PS(x0, y0, z0, radius);  // rows: the spheres
        _mm_storeu_ps(&out[i].center.x, x0), _mm_storeu_ps(&out[i + 1].center.x, y0);
        _mm_storeu_ps(&out[i + 2].center.x, z0), _mm_storeu_ps(&out[i + 3].center.x, radius);
    }
    return i;
}
#endif
}  // namespace

void block_spheres(const FftHeader& h, const std::uint8_t* const* blocks, std::size_t n, Sphere* out) {
    static_assert(sizeof(Sphere) == 4 * sizeof(float), "spheres are stored as four floats");
    // Blocks may be scattered (a memory mapping): fetch a few ahead.
    auto all = [&](auto view, std::size_t i) {
        using View = decltype(view);
        for (; i < n; ++i) {
            if (i + 8 < n) __builtin_prefetch(blocks[i + 8]);
            out[i] = sphere_of_block<View>(h, blocks[i]);
        }
    };
    if (h.direction_bits() == 16) return all(BlockView16{}, 0);
    std::size_t done = 0;
#ifdef FIBLET_POINTS_AVX2
    if (use_avx2_loops()) done = spheres_avx2(h, blocks, n, out);
#endif
    all(BlockView{}, done);
}
}  // namespace detail

}  // namespace fiblet
