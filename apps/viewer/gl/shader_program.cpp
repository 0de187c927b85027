#include "gl/shader_program.hpp"

#include <string>
#include <vector>

#include "gl/embedded_shaders.hpp"
#include "fiblet/error.hpp"

namespace fiblet::viewer {

namespace {

std::string_view find_embedded(std::string_view name) {
    for (const EmbeddedShader& s : embedded_shaders())
        if (s.name == name) return s.text;
    throw Error(Errc::unsupported, "internal: no embedded shader named " + std::string(name));
}

std::string expand_includes(std::string_view name, int depth) {
    if (depth > 8) throw Error(Errc::unsupported, "internal: shader includes nest too deep at " + std::string(name));
    const std::string_view text = find_embedded(name);
    std::string out;
    std::size_t pos = 0;
    while (pos < text.size()) {
        std::size_t end = text.find('\n', pos);
        if (end == std::string_view::npos) end = text.size();
        const std::string_view line = text.substr(pos, end - pos);
        constexpr std::string_view kInclude = "#include \"";
        if (line.substr(0, kInclude.size()) == kInclude) {
            const std::size_t close = line.find('"', kInclude.size());
            out += expand_includes(line.substr(kInclude.size(), close - kInclude.size()), depth + 1);
        } else {
            out += line;
            out += '\n';
        }
        pos = end + 1;
    }
    return out;
}

GLenum stage_of(std::string_view name) {
    auto ends_with = [&](std::string_view s) {
        return name.size() >= s.size() && name.substr(name.size() - s.size()) == s;
    };
    if (ends_with(".comp.glsl")) return GL_COMPUTE_SHADER;
    if (ends_with(".vert.glsl")) return GL_VERTEX_SHADER;
    if (ends_with(".frag.glsl")) return GL_FRAGMENT_SHADER;
    throw Error(Errc::unsupported, "internal: unknown shader stage of " + std::string(name));
}

}  // namespace

std::string shader_source(std::string_view name) { return expand_includes(name, 0); }

GlProgram build_program(std::initializer_list<std::string_view> shader_names, const std::string& defines) {
    GlProgram program(glCreateProgram());
    std::vector<GLuint> shaders;
    auto cleanup = [&] {
        for (GLuint s : shaders) glDeleteShader(s);
    };
    for (std::string_view name : shader_names) {
        std::string text = shader_source(name);
        // Defines go right after the mandatory #version line.
        const std::size_t eol = text.find('\n');
        text.insert(eol + 1, defines);
        const GLuint shader = glCreateShader(stage_of(name));
        shaders.push_back(shader);
        const char* src = text.c_str();
        glShaderSource(shader, 1, &src, nullptr);
        glCompileShader(shader);
        GLint ok = 0;
        glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
        if (!ok) {
            GLint len = 0;
            glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &len);
            std::string log(std::size_t(std::max(len, 1)), '\0');
            glGetShaderInfoLog(shader, len, nullptr, log.data());
            cleanup();
            throw Error(Errc::unsupported, "the GL driver could not compile " + std::string(name) + ":\n" + log);
        }
        glAttachShader(program.get(), shader);
    }
    glLinkProgram(program.get());
    cleanup();
    GLint ok = 0;
    glGetProgramiv(program.get(), GL_LINK_STATUS, &ok);
    if (!ok) {
        GLint len = 0;
        glGetProgramiv(program.get(), GL_INFO_LOG_LENGTH, &len);
        std::string log(std::size_t(std::max(len, 1)), '\0');
        glGetProgramInfoLog(program.get(), len, nullptr, log.data());
        throw Error(Errc::unsupported, "the GL driver could not link the shaders:\n" + log);
    }
    return program;
}

}  // namespace fiblet::viewer
