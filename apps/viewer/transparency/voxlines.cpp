#include "transparency/voxlines.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>

#include "scene/block_decoder.hpp"
#include "gl/gpu_bindings.hpp"
#include "gl/shader_program.hpp"
#include "transparency/transparent_lines.hpp"
#include "render/vec_ops.hpp"

namespace fiblet::viewer {

namespace {

float axis_of(Vec3f v, int axis) { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; }

// Both ends of every segment of every fiber (file order), the fiber's index
// in p0's w, from the GPU decoder's points (fibers' blocks are consecutive).
std::vector<float> segment_ends(const GpuScene& scene, const GpuPrograms& programs, GpuDecoder kind) {
    const std::vector<float> xyz = decode_blocks_on_gpu(scene, programs, kind, 0, scene.block_count());
    std::vector<float> ends;
    ends.reserve(std::size_t(scene.segment_count()) * 8);
    std::size_t point = 0;
    for (std::uint64_t f = 0; f < scene.fiber_count(); ++f) {
        const std::uint32_t n = scene.fiber_points(f);
        float fiber_bits = 0;
        const auto index = std::uint32_t(f);
        std::memcpy(&fiber_bits, &index, 4);
        for (std::uint32_t k = 0; k + 1 < n; ++k) {
            const float* p = &xyz[3 * (point + k)];
            ends.insert(ends.end(), {p[0], p[1], p[2], fiber_bits, p[3], p[4], p[5], 0.0f});
        }
        point += n;
    }
    return ends;
}

}  // namespace

Voxlines::Voxlines(const GpuScene& scene, const GpuPrograms& programs, GpuDecoder kind)
    : scene_generation_(scene.generation()),
      program_(build_program({"voxline_quads.vert.glsl", "transparent_lines.frag.glsl"}, gpu_binding_defines())) {
    const std::vector<float> ends = segment_ends(scene, programs, kind);
    segments_ = std::uint32_t(ends.size() / 8);
    const SceneBounds& b = scene.bounds();
    origin_ = b.min;
    auto cells = [](float lo, float hi) { return std::uint32_t(std::max(1.0f, std::ceil((hi - lo) / kVoxelMm))); };
    nx_ = cells(b.min.x, b.max.x), ny_ = cells(b.min.y, b.max.y), nz_ = cells(b.min.z, b.max.z);

    // Each segment's voxel (that of its first point), then the segments
    // grouped by voxel in file order (a counting sort).
    auto cell = [&](float v, float lo, std::uint32_t n) {
        return std::uint32_t(std::clamp(std::floor((v - lo) / kVoxelMm), 0.0f, float(n - 1)));
    };
    std::vector<std::uint32_t> voxel_of(segments_);
    std::vector<std::uint32_t> count(std::size_t(nx_) * ny_ * nz_ + 1, 0);
    for (std::uint32_t s = 0; s < segments_; ++s) {
        const float* p = &ends[8 * std::size_t(s)];
        voxel_of[s] = cell(p[0], origin_.x, nx_) + nx_ * (cell(p[1], origin_.y, ny_) + ny_ * cell(p[2], origin_.z, nz_));
        ++count[voxel_of[s] + 1];
    }
    std::partial_sum(count.begin(), count.end(), count.begin());
    for (std::uint32_t v = 0; v + 1 < count.size(); ++v)
        if (count[v + 1] > count[v]) voxels_.push_back({v, count[v], count[v + 1] - count[v]});
    std::vector<std::uint32_t> grouped(segments_);
    {
        std::vector<std::uint32_t> next(count.begin(), count.end() - 1);
        for (std::uint32_t s = 0; s < segments_; ++s) grouped[next[voxel_of[s]]++] = s;
    }

    // The three axis orders: within each voxel, by (p0 + p1) . axis.
    std::vector<std::uint32_t> orders(3 * std::size_t(segments_));
    for (int axis = 0; axis < 3; ++axis) {
        auto key = [&](std::uint32_t s) {
            const float* p = &ends[8 * std::size_t(s)];
            return p[axis] + p[4 + axis];
        };
        std::uint32_t* out = &orders[std::size_t(axis) * segments_];
        std::copy(grouped.begin(), grouped.end(), out);
        for (const Voxel& v : voxels_)
            std::stable_sort(out + v.first, out + v.first + v.count,
                             [&](std::uint32_t a, std::uint32_t c) { return key(a) < key(c); });
    }
    segment_ends_ = make_buffer(GLsizeiptr(std::max<std::size_t>(ends.size(), 8) * 4), ends.empty() ? nullptr : ends.data(), 0);
    orders_ = make_buffer(GLsizeiptr(std::max<std::size_t>(orders.size(), 1) * 4), orders.empty() ? nullptr : orders.data(), 0);
    gpu_bytes_ = std::uint64_t(ends.size() + orders.size()) * 4;
}

Vec3f Voxlines::voxel_center(std::uint32_t index) const {
    const std::uint32_t x = index % nx_, y = (index / nx_) % ny_, z = index / (nx_ * ny_);
    return {origin_.x + (float(x) + 0.5f) * kVoxelMm, origin_.y + (float(y) + 0.5f) * kVoxelMm,
            origin_.z + (float(z) + 0.5f) * kVoxelMm};
}

std::vector<std::uint32_t> Voxlines::back_to_front(const Camera& camera) const {
    const Vec3f forward = normalized(sub(camera.target, camera.position));
    std::vector<std::pair<float, std::uint32_t>> depth(voxels_.size());
    for (std::uint32_t i = 0; i < voxels_.size(); ++i)
        depth[i] = {dot(sub(voxel_center(voxels_[i].index), camera.position), forward), i};
    std::sort(depth.begin(), depth.end(), [](const auto& a, const auto& b) {
        return a.first != b.first ? a.first > b.first : a.second < b.second;
    });
    std::vector<std::uint32_t> out(depth.size());
    for (std::size_t i = 0; i < depth.size(); ++i) out[i] = depth[i].second;
    return out;
}

void Voxlines::draw(const FrameInputs& in) {
    const GLuint id = program_.get();
    TransparentLines::set_uniforms(program_, in);
    // Voxel segments carry no per-point values: they keep their colours.
    glProgramUniform1i(id, uniform(program_, "uPointValues"), 0);
    glUseProgram(id);
    in.scene.bind(program_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kVoxlineSegments, segment_ends_.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kVoxlineOrders, orders_.get());
    const GLint first = uniform(program_, "uOrderFirst"), count = uniform(program_, "uOrderCount"),
                reverse = uniform(program_, "uReverse");
    for (const std::uint32_t i : back_to_front(in.camera)) {
        const Voxel& v = voxels_[i];
        // The axis closest to the direction from the voxel to the eye; its
        // order runs from low to high coordinates, back to front when the eye
        // is on the high side.
        const Vec3f to_eye = sub(in.camera.position, voxel_center(v.index));
        int axis = 0;
        for (int a = 1; a < 3; ++a)
            if (std::abs(axis_of(to_eye, a)) > std::abs(axis_of(to_eye, axis))) axis = a;
        glProgramUniform1ui(id, first, std::uint32_t(axis) * segments_ + v.first);
        glProgramUniform1ui(id, count, v.count);
        glProgramUniform1i(id, reverse, axis_of(to_eye, axis) < 0 ? 1 : 0);
        glDrawArrays(GL_TRIANGLES, 0, GLsizei(6 * v.count));
    }
}

void VoxlineOrder::draw(const FrameInputs& in, const FrameBlocks& blocks, DrawTechnique& /*transparent lines*/) {
    blocks.timer.begin(Stage::draw);
    // Voxlines keep their own copy of every segment, built once per scene.
    if (!voxlines_ || voxlines_->scene_generation() != in.scene.generation())
        voxlines_ = std::make_unique<Voxlines>(in.scene, programs_, blocks.kind);
    voxlines_->draw(in);
    blocks.timer.end();
}

}  // namespace fiblet::viewer
