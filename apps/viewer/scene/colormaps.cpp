#include "scene/colormaps.hpp"

#include <algorithm>
#include <cmath>

#include "render/option_names.hpp"

namespace fiblet::viewer {

namespace {

// matplotlib's maps sampled at i / 16 (data, three decimals).
constexpr ColormapAnchors kViridis{{{0.267f, 0.005f, 0.329f}, {0.282f, 0.095f, 0.417f}, {0.279f, 0.175f, 0.483f},
                                    {0.259f, 0.252f, 0.525f}, {0.230f, 0.322f, 0.546f}, {0.199f, 0.388f, 0.555f},
                                    {0.173f, 0.449f, 0.558f}, {0.149f, 0.508f, 0.557f}, {0.128f, 0.567f, 0.551f},
                                    {0.121f, 0.626f, 0.533f}, {0.158f, 0.684f, 0.502f}, {0.246f, 0.739f, 0.452f},
                                    {0.369f, 0.789f, 0.383f}, {0.516f, 0.831f, 0.294f}, {0.678f, 0.864f, 0.190f},
                                    {0.846f, 0.887f, 0.100f}, {0.993f, 0.906f, 0.144f}}};
constexpr ColormapAnchors kMagma{{{0.001f, 0.000f, 0.014f}, {0.040f, 0.031f, 0.134f}, {0.113f, 0.065f, 0.277f},
                                  {0.212f, 0.062f, 0.419f}, {0.317f, 0.072f, 0.485f}, {0.415f, 0.110f, 0.505f},
                                  {0.513f, 0.148f, 0.508f}, {0.614f, 0.182f, 0.499f}, {0.716f, 0.215f, 0.475f},
                                  {0.817f, 0.256f, 0.436f}, {0.904f, 0.320f, 0.388f}, {0.961f, 0.418f, 0.360f},
                                  {0.987f, 0.536f, 0.382f}, {0.996f, 0.654f, 0.446f}, {0.997f, 0.770f, 0.535f},
                                  {0.992f, 0.884f, 0.640f}, {0.987f, 0.991f, 0.750f}}};
constexpr ColormapAnchors kCoolwarm{{{0.230f, 0.299f, 0.754f}, {0.304f, 0.407f, 0.845f}, {0.384f, 0.510f, 0.918f},
                                     {0.468f, 0.606f, 0.969f}, {0.554f, 0.690f, 0.996f}, {0.641f, 0.761f, 0.998f},
                                     {0.724f, 0.815f, 0.976f}, {0.801f, 0.850f, 0.930f}, {0.867f, 0.864f, 0.863f},
                                     {0.926f, 0.826f, 0.771f}, {0.960f, 0.767f, 0.674f}, {0.970f, 0.690f, 0.575f},
                                     {0.957f, 0.598f, 0.477f}, {0.921f, 0.491f, 0.383f}, {0.865f, 0.371f, 0.296f},
                                     {0.791f, 0.231f, 0.216f}, {0.706f, 0.016f, 0.150f}}};

constexpr auto kMaps = option_names(std::pair{ColormapName::viridis, "viridis"}, std::pair{ColormapName::magma, "magma"},
                                    std::pair{ColormapName::coolwarm, "coolwarm"});
constexpr auto kMapList = kMaps.values();

}  // namespace

std::optional<ColormapName> parse_colormap(const std::string& name) { return kMaps.parse(name); }
const char* colormap_name(ColormapName map) { return kMaps.name(map); }
std::span<const ColormapName> colormaps() { return kMapList; }

const ColormapAnchors& colormap_anchors(ColormapName map) {
    switch (map) {
    case ColormapName::magma: return kMagma;
    case ColormapName::coolwarm: return kCoolwarm;
    default: return kViridis;
    }
}

std::array<float, 3> colormap_color(ColormapName map, float t) {
    const ColormapAnchors& a = colormap_anchors(map);
    const float x = std::clamp(std::isfinite(t) ? t : 0.0f, 0.0f, 1.0f) * float(kColormapAnchors - 1);
    const int i = std::min(int(x), kColormapAnchors - 2);
    const float f = x - float(i);
    std::array<float, 3> c;
    for (std::size_t k = 0; k < 3; ++k) c[k] = a[std::size_t(i)][k] * (1 - f) + a[std::size_t(i) + 1][k] * f;
    return c;
}

float colormap_position(float value, float low, float high) {
    return high > low ? std::clamp((value - low) / (high - low), 0.0f, 1.0f) : 0.5f;
}

}  // namespace fiblet::viewer
