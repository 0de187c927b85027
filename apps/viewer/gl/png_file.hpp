// PNG images through libspng: RGBA8 pixels, rows from the top.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace fiblet::viewer {

struct RgbaImage {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgba;  // width * height * 4
};

// Writes `image` as an 8-bit RGB PNG (alpha dropped: the renders are
// opaque), atomically (fiblet::AtomicOutputFile). Throws fiblet::Error.
void write_png(const std::string& path, const RgbaImage& image, bool overwrite);

// Reads any PNG as RGBA8. Throws fiblet::Error.
RgbaImage read_png(const std::string& path);

}  // namespace fiblet::viewer
