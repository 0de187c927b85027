#include "scene/gpu_scene.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>

#include "fiblet/block_index.hpp"
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

std::uint64_t next_generation() {
    static std::atomic<std::uint64_t> last{0};
    return ++last;
}

// Runs of consecutive fibers: [first, end) pairs over ascending indices.
template <class F>
void for_each_fiber_run(const std::vector<std::uint64_t>& fibers, const F& f) {
    for (std::size_t i = 0; i < fibers.size();) {
        std::size_t j = i + 1;
        while (j < fibers.size() && fibers[j] == fibers[j - 1] + 1) ++j;
        f(fibers[i], fibers[j - 1] + 1);
        i = j;
    }
}

}  // namespace

GpuScene::GpuScene(const FftFile& file, const GpuPrograms& programs, std::optional<GpuDecoder> decoder,
                   std::optional<FiberSubset> subset)
    : header_(file.header()), decoder_(decoder.value_or(default_decoder())) {
    make_constant_buffers();
    reside(file, programs, std::move(subset));
}

GpuScene::GpuScene(const GpuScene& a, const FftFile& file, const GpuPrograms& programs, std::optional<FiberSubset> subset)
    : header_(a.header_), decoder_(a.decoder_), fiber_rgba_(a.fiber_rgba_), has_fiber_colors_(a.has_fiber_colors_),
      has_fiber_opacities_(a.has_fiber_opacities_), file_point_values_(a.file_point_values_),
      has_point_values_(a.has_point_values_), point_value_range_(a.point_value_range_),
      fiber_radii_mm_(a.fiber_radii_mm_), min_radius_(a.min_radius_), max_radius_(a.max_radius_) {
    make_constant_buffers();
    reside(file, programs, std::move(subset));
}

// The direction code's frames, and one-element buffers for the attributes
// a scene may not have (a binding must hold a buffer).
void GpuScene::make_constant_buffers() {
    const float no_colors[4] = {1, 1, 1, 1};
    fiber_colors_ = make_buffer(16, no_colors, 0);
    fiber_radii_ = make_buffer(16, no_colors, 0);
    point_values_ = make_buffer(16, no_colors, 0);
    const std::vector<float> frames = local_frames(DecodeContext(header_));
    local_frames_ = make_buffer(GLsizeiptr(frames.size() * 4), frames.data(), 0);
}

void GpuScene::reside(const FftFile& file, const GpuPrograms& programs, std::optional<FiberSubset> subset) {
    if (subset && !subset->index) throw Error(Errc::invalid_argument, "a fiber subset needs its file's block index");
    if (subset)
        for (std::size_t i = 0; i < subset->fibers.size(); ++i)
            if (subset->fibers[i] >= header_.fibers || (i > 0 && subset->fibers[i] <= subset->fibers[i - 1]))
                throw Error(Errc::invalid_argument, "a fiber subset must hold ascending fibers of its file");
    file_fibers_ = subset ? std::move(subset->fibers) : std::vector<std::uint64_t>();
    index_ = subset ? std::move(subset->index) : nullptr;
    generation_ = next_generation();
    load_geometry(file, programs);
    upload_attributes();
}

void GpuScene::load_geometry(const FftFile& file, const GpuPrograms& programs) {
    const FftHeader& h = header_;
    const std::uint32_t bb = h.block_bytes();
    const std::uint64_t fibers = holds_every_fiber() ? h.fibers : file_fibers_.size();
    // The held fibers' blocks: one run of consecutive fibers (the whole file) or more.
    auto for_each_run = [&](const auto& f) {
        if (holds_every_fiber())
            f(file.block_end(0), file.block_end(h.fibers));
        else
            for_each_fiber_run(file_fibers_, [&](std::uint64_t first, std::uint64_t end) {
                f(file.block_end(first), file.block_end(end));
            });
    };
    std::uint64_t block_total = 0;
    for_each_run([&](std::uint64_t b0, std::uint64_t b1) { block_total += b1 - b0; });
    check_fits(block_total * bb, "blocks");
    std::vector<std::uint8_t> blocks(std::size_t(block_total) * bb);
    std::size_t at = 0;
    for_each_run([&](std::uint64_t b0, std::uint64_t b1) {
        file.read_blocks(b0, b1 - b0, blocks.data() + at);
        at += std::size_t(b1 - b0) * bb;
    });
    const std::uint32_t block_n = std::uint32_t(block_total);
    const DecodeContext ctx(h);
    count_block_points(ctx, blocks.data(), block_n);  // validates every point count

    // Per-block fiber index and per-fiber tables, from the LUT (validated by
    // FftFile: a fiber's blocks are contiguous and in fiber order).
    std::vector<std::uint32_t> block_fiber(block_n);
    std::vector<std::uint32_t> last_blocks;
    fiber_ids_.assign(fibers, 0);
    fiber_points_.assign(fibers, 0);
    block_points_.resize(block_n);
    segments_ = 0;
    for (std::uint32_t b = 0; b < block_n; ++b)
        block_points_[b] = std::uint16_t(block_flags(h, &blocks[std::size_t(b) * bb]).point_count);
    std::uint64_t first = 0;
    for (std::uint64_t f = 0; f < fibers; ++f) {
        const std::uint64_t count = file.block_count(file_fiber(f));
        for (std::uint64_t b = first; b < first + count; ++b) {
            block_fiber[b] = std::uint32_t(f);
            fiber_points_[f] += block_points_[b];
        }
        fiber_ids_[f] = count ? block_flags(h, &blocks[first * bb]).fiber_id : std::uint32_t(file_fiber(f));
        if (count) last_blocks.push_back(std::uint32_t(first + count - 1));
        if (fiber_points_[f] > 1) segments_ += fiber_points_[f] - 1;
        first += count;
    }

    // Bounds: the union of the blocks' bounding spheres (no decoding).
    bounds_ = SceneBounds{};
    sample_points_.clear();
    if (block_n > 0) {
        const float inf = std::numeric_limits<float>::infinity();
        bounds_.min = {inf, inf, inf}, bounds_.max = {-inf, -inf, -inf};
        const std::uint32_t sample_stride = (block_n + 65535) / 65536;
        for (std::uint32_t b = 0; b < block_n; ++b) {
            const Sphere s = block_bounding_sphere(h, &blocks[std::size_t(b) * bb]);
            if (b % sample_stride == 0) sample_points_.push_back(s.center);  // the block's first point
            bounds_.min = {std::min(bounds_.min.x, s.center.x - s.radius), std::min(bounds_.min.y, s.center.y - s.radius),
                           std::min(bounds_.min.z, s.center.z - s.radius)};
            bounds_.max = {std::max(bounds_.max.x, s.center.x + s.radius), std::max(bounds_.max.y, s.center.y + s.radius),
                           std::max(bounds_.max.z, s.center.z + s.radius)};
        }
    }
    // A part of a file is framed, clipped and voxelized as the whole file.
    if (index_)
        if (const std::optional<Aabb> all = index_->bounds()) bounds_.min = all->min, bounds_.max = all->max;

    check_fits(fibers * 16, "fiber end points");
    blocks_ = make_buffer(GLsizeiptr(blocks.size()), blocks.data(), 0);
    block_fiber_ = make_buffer(GLsizeiptr(block_fiber.size() * 4), block_fiber.data(), 0);
    fiber_points_buffer_ = make_buffer(GLsizeiptr(fiber_points_.size() * 4), fiber_points_.data(), 0);
    fiber_ends_ = make_buffer(GLsizeiptr(fibers * 16), nullptr, 0);
    end_fraction_.assign(fibers, 1.0f);
    if (const auto& ends = file.end_fractions())
        for (std::uint64_t f = 0; f < fibers; ++f) end_fraction_[f] = end_fraction((*ends)[file_fiber(f)]);
    check_fits(fibers * 4, "fiber end fractions");
    fiber_end_fraction_ = make_buffer(GLsizeiptr(std::max<std::uint64_t>(fibers, 1) * 4),
                                      fibers ? end_fraction_.data() : nullptr, 0);

    // The last point of every fiber, decoded on the GPU over the list of last blocks.
    if (!last_blocks.empty()) {
        const GlBuffer list = make_buffer(GLsizeiptr(last_blocks.size() * 4), last_blocks.data(), 0);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kFineList, list.get());
        dispatch_decode(programs, decoder_, *this, true, 0, std::uint32_t(last_blocks.size()), true);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
        glFinish();  // `list` is released on return
    }
}

std::vector<std::uint32_t> GpuScene::scene_fibers(const std::vector<std::uint32_t>& file_indices) const {
    std::vector<std::uint32_t> out;
    for (const std::uint32_t f : file_indices) {
        if (holds_every_fiber()) {
            if (f < fiber_count()) out.push_back(f);
            continue;
        }
        const auto it = std::lower_bound(file_fibers_.begin(), file_fibers_.end(), std::uint64_t(f));
        if (it != file_fibers_.end() && *it == f) out.push_back(std::uint32_t(it - file_fibers_.begin()));
    }
    std::sort(out.begin(), out.end());
    return out;
}

std::vector<std::uint32_t> GpuScene::file_fiber_point_counts() const {
    if (holds_every_fiber()) return fiber_points_;
    std::vector<std::uint32_t> out(header_.fibers);
    for (std::uint64_t f = 0; f < out.size(); ++f) out[f] = std::uint32_t(index_->fiber_points(f));
    return out;
}

double GpuScene::fiber_length_mm(std::uint64_t index) const {
    const std::uint32_t n = fiber_points_[index];
    // The last step is shortened to the fiber's true end (ENDS chunk) when
    // its last block's last point is direction-coded.
    const std::uint32_t last_block = n ? (n - 1) % header_.points_per_block + 1 : 0;
    const double steps = n > 1 ? double(n - 2) + (last_block >= 3 ? end_fraction_[index] : 1.0) : 0.0;
    return steps * double(header_.step) * double(header_.scaling);
}

// The held fibers' share of per-file-fiber values, `width` floats a fiber.
std::vector<float> GpuScene::held_fiber_values(const std::vector<float>& per_file_fiber, std::size_t width) const {
    if (holds_every_fiber()) return per_file_fiber;
    std::vector<float> out(file_fibers_.size() * width);
    for (std::size_t f = 0; f < file_fibers_.size(); ++f)
        std::copy_n(&per_file_fiber[file_fibers_[f] * width], width, &out[f * width]);
    return out;
}

void GpuScene::upload_attributes() {
    if (!fiber_rgba_.empty()) {
        const std::vector<float> rgba = held_fiber_values(fiber_rgba_, 4);
        check_fits(rgba.size() * 4, "fiber colours");
        fiber_colors_ = make_buffer(GLsizeiptr(std::max<std::size_t>(rgba.size(), 4) * 4), rgba.size() ? rgba.data() : nullptr, 0);
    }
    if (!fiber_radii_mm_.empty()) {
        const std::vector<float> radii = held_fiber_values(fiber_radii_mm_, 1);
        check_fits(radii.size() * 4, "fiber radii");
        fiber_radii_ = make_buffer(GLsizeiptr(std::max<std::size_t>(radii.size(), 1) * 4), radii.size() ? radii.data() : nullptr, 0);
    }
    if (has_point_values_) upload_point_values();
}

void GpuScene::set_fiber_colors(const std::vector<std::array<float, 3>>& rgb) {
    if (rgb.size() != file_fiber_count())
        throw Error(Errc::invalid_argument, fmt::format("{} fiber colours for {} fibers", rgb.size(), file_fiber_count()));
    if (rgb.empty()) return;
    if (fiber_rgba_.empty()) fiber_rgba_.assign(file_fiber_count() * 4, 1.0f);
    for (std::size_t f = 0; f < rgb.size(); ++f)
        for (std::size_t k = 0; k < 3; ++k) fiber_rgba_[4 * f + k] = rgb[f][k];
    upload_attributes();
    has_fiber_colors_ = true;
}

void GpuScene::set_fiber_opacities(const std::vector<float>& alpha) {
    if (alpha.size() != file_fiber_count())
        throw Error(Errc::invalid_argument, fmt::format("{} fiber opacities for {} fibers", alpha.size(), file_fiber_count()));
    for (const float a : alpha)
        if (!(a >= 0 && a <= 1)) throw Error(Errc::invalid_argument, fmt::format("fiber opacity {} is not in [0, 1]", a));
    if (alpha.empty()) return;
    if (fiber_rgba_.empty()) fiber_rgba_.assign(file_fiber_count() * 4, 1.0f);
    for (std::size_t f = 0; f < alpha.size(); ++f) fiber_rgba_[4 * f + 3] = alpha[f];
    upload_attributes();
    has_fiber_opacities_ = true;
}

void GpuScene::set_fiber_radii(const std::vector<float>& mm) {
    if (mm.size() != file_fiber_count())
        throw Error(Errc::invalid_argument, fmt::format("{} fiber radii for {} fibers", mm.size(), file_fiber_count()));
    for (const float r : mm)
        if (!(r > 0) || !std::isfinite(r)) throw Error(Errc::invalid_argument, fmt::format("fiber radius {} is not positive", r));
    if (mm.empty()) return;
    fiber_radii_mm_ = mm;
    upload_attributes();
    const auto [lo, hi] = std::minmax_element(mm.begin(), mm.end());
    min_radius_ = *lo, max_radius_ = *hi;
}

void GpuScene::set_point_values(std::vector<float> values) {
    std::uint64_t points = 0;
    for (const std::uint32_t n : file_fiber_point_counts()) points += n;
    if (values.size() != points)
        throw Error(Errc::invalid_argument, fmt::format("{} point values for {} points", values.size(), points));
    if (values.empty()) return;
    const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
    point_value_range_ = {*lo, *hi};
    file_point_values_ = std::move(values);
    has_point_values_ = true;
    upload_point_values();
}

// Point k of block b in slot b * points_per_block + k: the blocks hold the
// fibers' points in order, block after block.
void GpuScene::upload_point_values() {
    const std::uint32_t ppb = header_.points_per_block;
    std::vector<float> slots(std::size_t(block_count()) * ppb, 0.0f);
    std::uint64_t next = 0;  // the file point of the next held fiber
    std::uint64_t scanned = 0;  // file fibers whose points `next` has passed
    const std::vector<std::uint32_t> file_points = holds_every_fiber() ? std::vector<std::uint32_t>() : file_fiber_point_counts();
    std::uint32_t b = 0;
    for (std::uint64_t f = 0; f < fiber_count(); ++f) {
        for (const std::uint64_t to = file_fiber(f); scanned < to; ++scanned) next += file_points[scanned];
        std::uint32_t left = fiber_points_[f];
        for (; left > 0; ++b)
            for (std::uint32_t k = 0; k < block_points_[b]; ++k, --left) slots[std::size_t(b) * ppb + k] = file_point_values_[next++];
        ++scanned;
    }
    check_fits(slots.size() * 4, "point values");
    point_values_ = make_buffer(GLsizeiptr(std::max<std::size_t>(slots.size(), 1) * 4), slots.size() ? slots.data() : nullptr, 0);
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
