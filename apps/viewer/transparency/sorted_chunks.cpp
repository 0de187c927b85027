#include "transparency/sorted_chunks.hpp"

#include <algorithm>
#include <cmath>

#include "gl/gpu_bindings.hpp"
#include "gl/shader_program.hpp"
#include "render/vec_ops.hpp"

namespace fiblet::viewer {

namespace {

GlProgram compute_program(const char* name) { return build_program({name}, gpu_binding_defines()); }

// Depths (mm along `forward` from the eye) of the nearest and farthest corner of the scene's box.
std::pair<float, float> depth_range(const SceneBounds& b, const Camera& camera, Vec3f forward) {
    float lo = INFINITY, hi = -INFINITY;
    for (int corner = 0; corner < 8; ++corner) {
        const Vec3f p{corner & 1 ? b.max.x : b.min.x, corner & 2 ? b.max.y : b.min.y, corner & 4 ? b.max.z : b.min.z};
        const float d = dot(sub(p, camera.position), forward);
        lo = std::min(lo, d), hi = std::max(hi, d);
    }
    return {lo, hi};
}

}  // namespace

SortedChunks::SortedChunks()
    : keys_(compute_program("chunk_keys.comp.glsl")),
      count_(compute_program("chunk_count.comp.glsl")),
      scan_(compute_program("chunk_scan.comp.glsl")),
      scatter_(compute_program("chunk_scatter.comp.glsl")) {
    histogram_ = make_buffer(GLsizeiptr(kBuckets) * kLanes * 4, nullptr, GL_DYNAMIC_STORAGE_BIT);
}

void SortedChunks::ensure_buffers(std::uint32_t scene_chunks) {
    if (capacity_ >= scene_chunks) return;
    capacity_ = std::max(scene_chunks, 1u);
    chunk_keys_ = make_buffer(GLsizeiptr(capacity_) * 4, nullptr, 0);
    sorted_blocks_ = make_buffer(GLsizeiptr(capacity_) * 4, nullptr, 0);
    sorted_chunks_ = make_buffer(GLsizeiptr(capacity_) * 4, nullptr, 0);
}

void SortedChunks::draw(const FrameInputs& in, const FrameBlocks& blocks, DrawTechnique& technique) {
    technique.begin_frame(in);
    if (blocks.count == 0) return;
    // Timed as one draw stage: its decodes interleave with the sort.
    blocks.timer.begin(Stage::draw);
    chunks_per_block_ = (in.scene.header().points_per_block + kChunkSegments - 1) / kChunkSegments;
    const std::uint32_t scene_chunks = in.scene.block_count() * chunks_per_block_;
    ensure_buffers(scene_chunks);
    key_chunks(in, blocks);
    sort_chunks(scene_chunks);
    draw_sorted(in, blocks, blocks.count * chunks_per_block_, technique);
    blocks.timer.end();
}

void SortedChunks::key_chunks(const FrameInputs& in, const FrameBlocks& blocks) {
    const BlockDecoder& decoder = blocks.decoder;
    const GLuint id = keys_.get();
    const Camera& camera = in.camera;
    const Vec3f forward = normalized(sub(camera.target, camera.position));
    const auto [near_depth, far_depth] = depth_range(in.scene.bounds(), camera, forward);
    glProgramUniform1i(id, uniform(keys_, "uUseList"), in.use_list ? 1 : 0);
    glProgramUniform1ui(id, uniform(keys_, "uChunkSegments"), kChunkSegments);
    glProgramUniform1ui(id, uniform(keys_, "uChunksPerBlock"), chunks_per_block_);
    glProgramUniform3f(id, uniform(keys_, "uCameraPosition"), camera.position.x, camera.position.y, camera.position.z);
    glProgramUniform3f(id, uniform(keys_, "uViewDirection"), forward.x, forward.y, forward.z);
    glProgramUniform1f(id, uniform(keys_, "uNearDepth"), near_depth);
    glProgramUniform1f(id, uniform(keys_, "uFarDepth"), far_depth);
    glProgramUniform1ui(id, uniform(keys_, "uBuckets"), kBuckets);
    const GLuint no_key = 0xffffffffu;  // chunk_count.comp.glsl's NO_KEY: blocks this frame does not draw
    glClearNamedBufferData(chunk_keys_.get(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &no_key);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
    for (std::uint32_t first = 0; first < blocks.count; first += decoder.capacity()) {
        const std::uint32_t count = std::min(decoder.capacity(), blocks.count - first);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kFineList, blocks.fine_list);
        decoder.decode(in.scene, blocks.kind, in.use_list, first, count);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        glUseProgram(id);
        in.scene.bind(keys_);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kPoints, decoder.points_buffer());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kChunkKeys, chunk_keys_.get());
        glProgramUniform1ui(id, uniform(keys_, "uFirst"), first);
        glProgramUniform1ui(id, uniform(keys_, "uCount"), count);
        glDispatchCompute((count * chunks_per_block_ + 63) / 64, 1, 1);
        // The next batch's decode overwrites the points this pass reads.
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    }
}

void SortedChunks::sort_chunks(std::uint32_t chunks) {
    const GLuint zero = 0;
    glClearNamedBufferData(histogram_.get(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kChunkKeys, chunk_keys_.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kChunkHistogram, histogram_.get());
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);

    glUseProgram(count_.get());
    glProgramUniform1ui(count_.get(), uniform(count_, "uChunks"), chunks);
    glProgramUniform1ui(count_.get(), uniform(count_, "uLanes"), kLanes);
    glDispatchCompute(kLanes / 64, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);

    glUseProgram(scan_.get());
    glProgramUniform1ui(scan_.get(), uniform(scan_, "uSize"), kBuckets * kLanes);
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);

    glUseProgram(scatter_.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kSortedBlocks, sorted_blocks_.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kSortedChunks, sorted_chunks_.get());
    glProgramUniform1ui(scatter_.get(), uniform(scatter_, "uChunks"), chunks);
    glProgramUniform1ui(scatter_.get(), uniform(scatter_, "uLanes"), kLanes);
    glProgramUniform1ui(scatter_.get(), uniform(scatter_, "uChunksPerBlock"), chunks_per_block_);
    glDispatchCompute(kLanes / 64, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

void SortedChunks::draw_sorted(const FrameInputs& in, const FrameBlocks& blocks, std::uint32_t chunks,
                               DrawTechnique& technique) {
    const BlockDecoder& decoder = blocks.decoder;
    // Each sorted place decodes its chunk's whole block into its own slot
    // (a block is decoded once per chunk: the price of keeping nothing); the
    // technique then reads the places' entries as its list.
    for (std::uint32_t first = 0; first < chunks; first += decoder.capacity()) {
        const std::uint32_t count = std::min(decoder.capacity(), chunks - first);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kFineList, sorted_blocks_.get());
        decoder.decode(in.scene, blocks.kind, true, first, count, technique.needs_tangents());
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kFineList, sorted_chunks_.get());
        technique.draw_chunks(in, {decoder.points_buffer(), decoder.tangents_buffer(), first, count}, kChunkSegments,
                              chunks_per_block_);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    }
}

}  // namespace fiblet::viewer
