#include "scene/block_decoder.hpp"

#include <algorithm>

#include "gl/gl_info.hpp"
#include "gl/gpu_bindings.hpp"
#include "gl/shader_program.hpp"

namespace fiblet::viewer {

const char* gpu_decoder_name(GpuDecoder k) { return k == GpuDecoder::scan ? "scan" : "sequential"; }

std::optional<GpuDecoder> parse_gpu_decoder(const std::string& name) {
    if (name == "scan") return GpuDecoder::scan;
    if (name == "sequential") return GpuDecoder::sequential;
    return std::nullopt;
}

GpuDecoder default_decoder() { return is_software_renderer() ? GpuDecoder::sequential : GpuDecoder::scan; }

namespace {
// GL guarantees 65535 workgroups per dispatch dimension (the scan decoder
// runs one per block); 32768 blocks of 60 points are 32 MB of points, well
// under every driver's storage limit.
constexpr std::uint32_t kMaxBatchBlocks = 32768;
constexpr std::uint32_t kMaxPassBlocks = 65535;
constexpr std::uint32_t kPointBytes = 16;  // vec4
}  // namespace

void dispatch_decode(const GpuPrograms& programs, GpuDecoder kind, const GpuScene& scene, bool use_list,
                     std::uint32_t first, std::uint32_t count, bool ends_only, bool tangents) {
    const GlProgram& p = programs.decoder(kind, scene.header().direction_bits() == 16);
    glUseProgram(p.get());
    scene.bind(p);
    glProgramUniform1i(p.get(), uniform(p, "uUseList"), use_list ? 1 : 0);
    glProgramUniform1i(p.get(), uniform(p, "uEndsOnly"), ends_only ? 1 : 0);
    glProgramUniform1i(p.get(), uniform(p, "uWriteTangents"), tangents && !ends_only ? 1 : 0);
    for (std::uint32_t done = 0; done < count;) {
        const std::uint32_t n = std::min(kMaxPassBlocks, count - done);
        glProgramUniform1ui(p.get(), uniform(p, "uFirst"), first + done);
        glProgramUniform1ui(p.get(), uniform(p, "uCount"), n);
        glDispatchCompute(kind == GpuDecoder::scan ? n : (n + 63) / 64, 1, 1);
        done += n;
        if (!ends_only) break;  // slots start at 0: one pass fills the points buffer
    }
}

BlockDecoder::BlockDecoder(const GpuPrograms& programs, std::uint32_t points_per_block)
    : programs_(programs), points_per_block_(points_per_block) {
    const std::uint64_t slot_bytes = std::uint64_t(points_per_block + 1) * kPointBytes;
    capacity_ = std::uint32_t(std::min<std::uint64_t>(kMaxBatchBlocks, max_storage_buffer_bytes() / slot_bytes));
    points_ = make_buffer(GLsizeiptr(capacity_ * slot_bytes), nullptr, 0);
}

void BlockDecoder::decode(const GpuScene& scene, GpuDecoder kind, bool use_list, std::uint32_t first,
                          std::uint32_t count, bool tangents) const {
    if (count == 0) return;
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kPoints, points_.get());
    if (tangents && !tangents_) {
        const std::uint64_t slot_bytes = std::uint64_t(points_per_block_ + 1) * kPointBytes;
        tangents_ = make_buffer(GLsizeiptr(capacity_ * slot_bytes), nullptr, 0);
    }
    if (tangents) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kTangents, tangents_.get());
    dispatch_decode(programs_, kind, scene, use_list, first, std::min(count, capacity_), false, tangents);
}

namespace {
// Decodes blocks [first, first + count) and reads back the points (or the
// tangents) of each block, xyz one after the other.
std::vector<float> decode_and_read(const GpuScene& scene, const GpuPrograms& programs, GpuDecoder kind,
                                   std::uint32_t first, std::uint32_t count, bool tangents) {
    const std::uint32_t ppb = scene.header().points_per_block;
    const BlockDecoder decoder(programs, ppb);
    std::vector<float> xyz;
    std::vector<float> slots;
    for (std::uint32_t done = 0; done < count;) {
        const std::uint32_t batch = std::min(decoder.capacity(), count - done);
        decoder.decode(scene, kind, false, first + done, batch, tangents);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        slots.resize(std::size_t(batch) * (ppb + 1) * 4);
        const GLuint buffer = tangents ? decoder.tangents_buffer() : decoder.points_buffer();
        glGetNamedBufferSubData(buffer, 0, GLsizeiptr(slots.size() * 4), slots.data());
        for (std::uint32_t i = 0; i < batch; ++i) {
            const float* slot = &slots[std::size_t(i) * (ppb + 1) * 4];
            for (std::uint32_t k = 0; k < scene.block_points(first + done + i); ++k)
                xyz.insert(xyz.end(), {slot[4 * k], slot[4 * k + 1], slot[4 * k + 2]});
        }
        done += batch;
    }
    return xyz;
}
}  // namespace

std::vector<float> decode_blocks_on_gpu(const GpuScene& scene, const GpuPrograms& programs, GpuDecoder kind,
                                        std::uint32_t first, std::uint32_t count) {
    return decode_and_read(scene, programs, kind, first, count, false);
}

std::vector<float> decode_tangents_on_gpu(const GpuScene& scene, const GpuPrograms& programs, GpuDecoder kind,
                                          std::uint32_t first, std::uint32_t count) {
    return decode_and_read(scene, programs, kind, first, count, true);
}

}  // namespace fiblet::viewer
