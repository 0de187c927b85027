#include "scene/gpu_scene.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "fiblet/decode.hpp"
#include "fiblet/direction_code.hpp"
#include "fiblet/error.hpp"
#include "fiblet/view.hpp"
#include "scene/block_decoder.hpp"
#include "gl/gpu_bindings.hpp"
#include "gl/shader_program.hpp"

namespace fiblet::viewer {

float SceneBounds::radius() const {
    const float dx = max.x - min.x, dy = max.y - min.y, dz = max.z - min.z;
    return 0.5f * std::sqrt(dx * dx + dy * dy + dz * dz);
}

std::uint64_t max_storage_buffer_bytes() {
    GLint64 v = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &v);
    return std::uint64_t(v);
}

namespace {

// The frames of the file's direction code as mat3[] with each column padded
// to a vec4 (std140 and std430 alike), from the decoders' own tables:
// DirectionTable's 256 for 8-bit blocks, DirectionTable16's levels^2 for
// 16-bit blocks.
std::vector<float> local_frames(const DecodeContext& ctx) {
    std::vector<float> out;
    auto add = [&](const Frame& f) {
        for (const Vec3f& c : f.c) out.insert(out.end(), {c.x, c.y, c.z, 0.0f});
    };
    if (ctx.table16) {
        out.reserve(std::size_t(ctx.table16->code_count()) * 12);
        for (std::uint32_t k = 0; k < ctx.table16->code_count(); ++k) add(ctx.table16->frame(std::uint16_t(k)));
    } else {
        out.reserve(256 * 12);
        for (int k = 0; k < 256; ++k) add(ctx.table.frame(std::uint8_t(k)));
    }
    return out;
}

void check_fits(std::uint64_t bytes, const char* what) {
    const std::uint64_t limit = max_storage_buffer_bytes();
    if (bytes > limit)
        throw Error(Errc::unsupported, fmt::format("the {} take {:.1f} MiB, more than this GL driver's largest storage "
                                                   "buffer ({:.1f} MiB)",
                                                   what, bytes / 1048576.0, limit / 1048576.0));
}

}  // namespace

GpuScene::GpuScene(const FftFile& file, const GpuPrograms& programs, std::optional<GpuDecoder> decoder)
    : header_(file.header()) {
    const FftHeader& h = header_;
    const std::uint32_t bb = h.block_bytes();
    check_fits(std::uint64_t(h.blocks) * bb, "blocks");
    const std::vector<std::uint8_t> blocks = file.read_blocks(0, h.blocks);
    const DecodeContext ctx(h);
    count_block_points(ctx, blocks.data(), h.blocks);  // validates every point count

    // Per-block fiber index and per-fiber tables, from the LUT (validated by
    // FftFile: a fiber's blocks are contiguous and in fiber order).
    const std::uint64_t fibers = h.fibers;
    std::vector<std::uint32_t> block_fiber(h.blocks);
    std::vector<std::uint32_t> last_blocks;
    fiber_ids_.resize(fibers);
    fiber_points_.assign(fibers, 0);
    block_points_.resize(h.blocks);
    for (std::uint32_t b = 0; b < h.blocks; ++b)
        block_points_[b] = std::uint16_t(block_flags(h, &blocks[std::size_t(b) * bb]).point_count);
    for (std::uint64_t f = 0; f < fibers; ++f) {
        const std::uint64_t first = file.first_block(f), count = file.block_count(f);
        for (std::uint64_t b = first; b < first + count; ++b) {
            block_fiber[b] = std::uint32_t(f);
            fiber_points_[f] += block_points_[b];
        }
        fiber_ids_[f] = count ? block_flags(h, &blocks[first * bb]).fiber_id : std::uint32_t(f);
        if (count) last_blocks.push_back(std::uint32_t(first + count - 1));
        if (fiber_points_[f] > 1) segments_ += fiber_points_[f] - 1;
    }

    // Bounds: the union of the blocks' bounding spheres (no decoding).
    if (h.blocks > 0) {
        const float inf = std::numeric_limits<float>::infinity();
        bounds_.min = {inf, inf, inf}, bounds_.max = {-inf, -inf, -inf};
        const std::uint32_t sample_stride = (h.blocks + 65535) / 65536;
        for (std::uint32_t b = 0; b < h.blocks; ++b) {
            const Sphere s = block_bounding_sphere(h, &blocks[std::size_t(b) * bb]);
            if (b % sample_stride == 0) sample_points_.push_back(s.center);  // the block's first point
            bounds_.min = {std::min(bounds_.min.x, s.center.x - s.radius), std::min(bounds_.min.y, s.center.y - s.radius),
                           std::min(bounds_.min.z, s.center.z - s.radius)};
            bounds_.max = {std::max(bounds_.max.x, s.center.x + s.radius), std::max(bounds_.max.y, s.center.y + s.radius),
                           std::max(bounds_.max.z, s.center.z + s.radius)};
        }
    }

    check_fits(fibers * 16, "fiber end points");
    blocks_ = make_buffer(GLsizeiptr(blocks.size()), blocks.data(), 0);
    block_fiber_ = make_buffer(GLsizeiptr(block_fiber.size() * 4), block_fiber.data(), 0);
    fiber_points_buffer_ = make_buffer(GLsizeiptr(fiber_points_.size() * 4), fiber_points_.data(), 0);
    fiber_ends_ = make_buffer(GLsizeiptr(fibers * 16), nullptr, 0);
    end_fraction_.assign(fibers, 1.0f);
    if (const auto& ends = file.end_fractions())
        for (std::uint64_t f = 0; f < fibers; ++f) end_fraction_[f] = end_fraction((*ends)[f]);
    check_fits(fibers * 4, "fiber end fractions");
    fiber_end_fraction_ = make_buffer(GLsizeiptr(std::max<std::uint64_t>(fibers, 1) * 4),
                                      fibers ? end_fraction_.data() : nullptr, 0);
    const float no_colors[4] = {1, 1, 1, 1};
    fiber_colors_ = make_buffer(16, no_colors, 0);
    fiber_radii_ = make_buffer(16, no_colors, 0);
    point_values_ = make_buffer(16, no_colors, 0);
    const std::vector<float> frames = local_frames(ctx);
    local_frames_ = make_buffer(GLsizeiptr(frames.size() * 4), frames.data(), 0);

    // The last point of every fiber, decoded on the GPU over the list of last blocks.
    if (!last_blocks.empty()) {
        const GlBuffer list = make_buffer(GLsizeiptr(last_blocks.size() * 4), last_blocks.data(), 0);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kFineList, list.get());
        dispatch_decode(programs, decoder.value_or(default_decoder()), *this, true, 0, std::uint32_t(last_blocks.size()), true);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
        glFinish();  // `list` is released on return
    }
}

double GpuScene::fiber_length_mm(std::uint64_t index) const {
    const std::uint32_t n = fiber_points_[index];
    // The last step is shortened to the fiber's true end (ENDS chunk) when
    // its last block's last point is direction-coded.
    const std::uint32_t last_block = n ? (n - 1) % header_.points_per_block + 1 : 0;
    const double steps = n > 1 ? double(n - 2) + (last_block >= 3 ? end_fraction_[index] : 1.0) : 0.0;
    return steps * double(header_.step) * double(header_.scaling);
}

void GpuScene::upload_fiber_colors() {
    if (fiber_rgba_.empty()) fiber_rgba_.assign(fiber_count() * 4, 1.0f);
    check_fits(fiber_rgba_.size() * 4, "fiber colours");
    fiber_colors_ = make_buffer(GLsizeiptr(fiber_rgba_.size() * 4), fiber_rgba_.data(), 0);
}

void GpuScene::set_fiber_colors(const std::vector<std::array<float, 3>>& rgb) {
    if (rgb.size() != fiber_count())
        throw Error(Errc::invalid_argument, fmt::format("{} fiber colours for {} fibers", rgb.size(), fiber_count()));
    if (rgb.empty()) return;
    if (fiber_rgba_.empty()) fiber_rgba_.assign(fiber_count() * 4, 1.0f);
    for (std::size_t f = 0; f < rgb.size(); ++f)
        for (std::size_t k = 0; k < 3; ++k) fiber_rgba_[4 * f + k] = rgb[f][k];
    upload_fiber_colors();
    has_fiber_colors_ = true;
}

void GpuScene::set_fiber_opacities(const std::vector<float>& alpha) {
    if (alpha.size() != fiber_count())
        throw Error(Errc::invalid_argument, fmt::format("{} fiber opacities for {} fibers", alpha.size(), fiber_count()));
    for (const float a : alpha)
        if (!(a >= 0 && a <= 1)) throw Error(Errc::invalid_argument, fmt::format("fiber opacity {} is not in [0, 1]", a));
    if (alpha.empty()) return;
    if (fiber_rgba_.empty()) fiber_rgba_.assign(fiber_count() * 4, 1.0f);
    for (std::size_t f = 0; f < alpha.size(); ++f) fiber_rgba_[4 * f + 3] = alpha[f];
    upload_fiber_colors();
    has_fiber_opacities_ = true;
}

void GpuScene::set_fiber_radii(const std::vector<float>& mm) {
    if (mm.size() != fiber_count())
        throw Error(Errc::invalid_argument, fmt::format("{} fiber radii for {} fibers", mm.size(), fiber_count()));
    for (const float r : mm)
        if (!(r > 0) || !std::isfinite(r)) throw Error(Errc::invalid_argument, fmt::format("fiber radius {} is not positive", r));
    if (mm.empty()) return;
    check_fits(mm.size() * 4, "fiber radii");
    fiber_radii_ = make_buffer(GLsizeiptr(mm.size() * 4), mm.data(), 0);
    fiber_radii_mm_ = mm;
    const auto [lo, hi] = std::minmax_element(mm.begin(), mm.end());
    min_radius_ = *lo, max_radius_ = *hi;
}

void GpuScene::set_point_values(const std::vector<float>& values) {
    std::uint64_t points = 0;
    for (const std::uint32_t n : fiber_points_) points += n;
    if (values.size() != points)
        throw Error(Errc::invalid_argument, fmt::format("{} point values for {} points", values.size(), points));
    if (values.empty()) return;
    // The blocks hold the fibers' points in order, block after block.
    const std::uint32_t ppb = header_.points_per_block;
    std::vector<float> slots(std::size_t(header_.blocks) * ppb, 0.0f);
    std::size_t next = 0;
    for (std::uint32_t b = 0; b < header_.blocks; ++b)
        for (std::uint32_t k = 0; k < block_points_[b] && next < values.size(); ++k) slots[std::size_t(b) * ppb + k] = values[next++];
    check_fits(slots.size() * 4, "point values");
    point_values_ = make_buffer(GLsizeiptr(slots.size() * 4), slots.data(), 0);
    const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
    point_value_range_ = {*lo, *hi};
    has_point_values_ = true;
}

std::vector<Vec3f> GpuScene::read_fiber_ends() const {
    std::vector<float> xyzw(fiber_count() * 4);
    if (!xyzw.empty()) glGetNamedBufferSubData(fiber_ends_.get(), 0, GLsizeiptr(xyzw.size() * 4), xyzw.data());
    std::vector<Vec3f> out(fiber_count());
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = {xyzw[4 * i], xyzw[4 * i + 1], xyzw[4 * i + 2]};
    return out;
}

void GpuScene::bind(const GlProgram& program) const {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kBlocks, blocks_.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kBlockFiber, block_fiber_.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kFiberPoints, fiber_points_buffer_.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kFiberEnds, fiber_ends_.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kFiberEndFraction, fiber_end_fraction_.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kFiberColors, fiber_colors_.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kFiberRadii, fiber_radii_.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kPointValues, point_values_.get());
    if (header_.direction_bits() == 16)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kWideFrames, local_frames_.get());
    else
        glBindBufferBase(GL_UNIFORM_BUFFER, binding::kLocalFrames, local_frames_.get());
    const GLuint p = program.get();
    glProgramUniform1ui(p, uniform(program, "uBlockCount"), header_.blocks);
    glProgramUniform1ui(p, uniform(program, "uBlockWords"), header_.block_bytes() / 4);
    glProgramUniform1ui(p, uniform(program, "uPointsPerBlock"), header_.points_per_block);
    glProgramUniform1f(p, uniform(program, "uScaling"), header_.scaling);
    glProgramUniform3f(p, uniform(program, "uOffset"), header_.offset[0], header_.offset[1], header_.offset[2]);
    glProgramUniform1f(p, uniform(program, "uStep"), header_.step);
    glProgramUniform1i(p, uniform(program, "uWideBlocks"), header_.direction_bits() == 16 ? 1 : 0);
    glProgramUniform1i(p, uniform(program, "uAxisFromAnchorIntegers"), header_.packed() ? 1 : 0);
}

std::uint64_t GpuScene::gpu_bytes() const {
    std::uint64_t bytes = 0;
    for (const GlBuffer* b : {&blocks_, &block_fiber_, &fiber_points_buffer_, &fiber_ends_, &fiber_end_fraction_,
                              &local_frames_, &fiber_colors_, &point_values_, &fiber_radii_})
        bytes += buffer_bytes(*b);
    return bytes;
}

}  // namespace fiblet::viewer
