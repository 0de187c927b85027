// The viewer's GLSL sources (apps/viewer/shaders), embedded at build time.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace fiblet::viewer {

struct EmbeddedShader {
    std::string_view name;  // file name, e.g. "decode_blocks.comp.glsl"
    std::string_view text;
};
const std::vector<EmbeddedShader>& embedded_shaders();

// The source of shader `name` with its `#include "file.glsl"` lines replaced
// by those files (GLSL has no includes of its own). Throws if one is missing.
std::string shader_source(std::string_view name);

}  // namespace fiblet::viewer
