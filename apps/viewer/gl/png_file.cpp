#include "gl/png_file.hpp"

#include <spng.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <memory>

#include "fiblet/error.hpp"
#include "fiblet/output_file.hpp"

namespace fiblet::viewer {

namespace {
struct SpngDeleter {
    void operator()(spng_ctx* c) const { spng_ctx_free(c); }
};
using SpngContext = std::unique_ptr<spng_ctx, SpngDeleter>;

void check(int rc, const std::string& what) {
    if (rc != 0) throw Error(Errc::invalid_input, what + ": " + spng_strerror(rc));
}
}  // namespace

void write_png(const std::string& path, const RgbaImage& image, bool overwrite) {
    if (image.width < 1 || image.height < 1 ||
        image.rgba.size() != std::size_t(image.width) * std::size_t(image.height) * 4)
        throw Error(Errc::invalid_argument, "internal: bad image for " + path);
    std::vector<std::uint8_t> rgb(std::size_t(image.width) * std::size_t(image.height) * 3);
    for (std::size_t i = 0, n = rgb.size() / 3; i < n; ++i)
        for (int c = 0; c < 3; ++c) rgb[3 * i + std::size_t(c)] = image.rgba[4 * i + std::size_t(c)];

    SpngContext ctx(spng_ctx_new(SPNG_CTX_ENCODER));
    if (!ctx) throw Error(Errc::io, "cannot create a PNG encoder");
    const std::string what = "cannot encode " + path;
    check(spng_set_option(ctx.get(), SPNG_ENCODE_TO_BUFFER, 1), what);
    check(spng_set_option(ctx.get(), SPNG_IMG_COMPRESSION_LEVEL, 9), what);  // renders are written once
    spng_ihdr ihdr{};
    ihdr.width = std::uint32_t(image.width), ihdr.height = std::uint32_t(image.height);
    ihdr.bit_depth = 8, ihdr.color_type = SPNG_COLOR_TYPE_TRUECOLOR;
    check(spng_set_ihdr(ctx.get(), &ihdr), what);
    check(spng_encode_image(ctx.get(), rgb.data(), rgb.size(), SPNG_FMT_PNG, SPNG_ENCODE_FINALIZE), what);
    std::size_t size = 0;
    int rc = 0;
    std::unique_ptr<void, decltype(&std::free)> png(spng_get_png_buffer(ctx.get(), &size, &rc), &std::free);
    check(rc, what);

    AtomicOutputFile out(path, overwrite);
    out.write(png.get(), size);
    out.commit();
}

RgbaImage read_png(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw Error(Errc::io, "cannot open " + path);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    SpngContext ctx(spng_ctx_new(0));
    if (!ctx) throw Error(Errc::io, "cannot create a PNG decoder");
    const std::string what = "cannot decode " + path;
    check(spng_set_png_buffer(ctx.get(), bytes.data(), bytes.size()), what);
    spng_ihdr ihdr{};
    check(spng_get_ihdr(ctx.get(), &ihdr), what);
    std::size_t size = 0;
    check(spng_decoded_image_size(ctx.get(), SPNG_FMT_RGBA8, &size), what);
    RgbaImage image{int(ihdr.width), int(ihdr.height), std::vector<std::uint8_t>(size)};
    check(spng_decode_image(ctx.get(), image.rgba.data(), size, SPNG_FMT_RGBA8, SPNG_DECODE_TRNS), what);
    return image;
}

}  // namespace fiblet::viewer
