#include "render/supersampling.hpp"

#include <string>

#include "fiblet/error.hpp"
#include "render/render_target.hpp"

namespace fiblet::viewer {

RgbaImage downsample_box(const RgbaImage& in, int f) {
    RgbaImage out{in.width / f, in.height / f, {}};
    out.rgba.resize(std::size_t(out.width) * std::size_t(out.height) * 4);
    const int n = f * f;
    for (int y = 0; y < out.height; ++y)
        for (int x = 0; x < out.width; ++x)
            for (int c = 0; c < 4; ++c) {
                int sum = 0;
                for (int dy = 0; dy < f; ++dy)
                    for (int dx = 0; dx < f; ++dx)
                        sum += in.rgba[(std::size_t(y * f + dy) * std::size_t(in.width) + std::size_t(x * f + dx)) * 4 +
                                       std::size_t(c)];
                out.rgba[(std::size_t(y) * std::size_t(out.width) + std::size_t(x)) * 4 + std::size_t(c)] =
                    std::uint8_t((sum + n / 2) / n);
            }
    return out;
}

SupersampledFrame render_supersampled(Renderer& renderer, const GpuScene& scene, const Camera& camera,
                              const RenderOptions& options, int width, int height, int factor) {
    if (factor < 1 || factor > kMaxSupersample)
        throw Error(Errc::invalid_argument,
                    "--supersample must be in 1.." + std::to_string(kMaxSupersample) + ", not " + std::to_string(factor));
    GLint largest = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &largest);
    if (std::int64_t(width) * factor > largest || std::int64_t(height) * factor > largest)
        throw Error(Errc::invalid_argument, "--supersample " + std::to_string(factor) + " makes the frame larger than " +
                                                std::to_string(largest) + " pixels a side, this GL driver's limit");
    RenderTarget target(width * factor, height * factor);
    RenderOptions o = options;
    o.line_width *= float(factor);
    const FrameStats stats = renderer.render(scene, camera, o, target);
    RgbaImage big{target.width(), target.height(), target.read_rgba()};
    return {factor == 1 ? std::move(big) : downsample_box(big, factor), stats};
}

}  // namespace fiblet::viewer
