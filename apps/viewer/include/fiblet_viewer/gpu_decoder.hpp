// The two GPU decoders (both checked against the scalar reference decoder).
//   scan:       one workgroup per block, one invocation per point, the frames
//               combined by a log-step prefix product in shared memory (the
//               Fiblets paper's scheme; decode_blocks.comp.glsl).
//   sequential: one invocation per block, the frames multiplied one after the
//               other (decode_blocks_sequential.comp.glsl). Much faster on
//               software rasterizers, which run barriers as coroutine switches.
#pragma once

#include <optional>
#include <string>

namespace fiblet::viewer {

enum class GpuDecoder { scan, sequential };

const char* gpu_decoder_name(GpuDecoder k);
std::optional<GpuDecoder> parse_gpu_decoder(const std::string& name);

}  // namespace fiblet::viewer
