# FIBLET_HAS_DECODER_CHOICE: whether decode.hpp offers a choice of decoders
# (DecodeOptions::decoder, parse_decoder, available_decoders), so that the
# fuzz targets run every decoder this CPU has. A compile-only check.
include(CheckCXXSourceCompiles)
unset(FIBLET_HAS_DECODER_CHOICE CACHE)  # re-check at each configure: decode.hpp changes under it
set(CMAKE_REQUIRED_INCLUDES ${PROJECT_SOURCE_DIR}/libfiblet/include)
set(CMAKE_REQUIRED_FLAGS "-std=c++20")
check_cxx_source_compiles("
#include <fiblet/decode.hpp>
int main() {
    fiblet::DecodeOptions o;
    decltype(fiblet::parse_decoder(\"scalar\")) d{};
    o.decoder = d;
    decltype(fiblet::available_decoders()) names;
    decltype(fiblet::decode_blocks(std::declval<const fiblet::DecodeContext&>(), nullptr, 0, nullptr, d, 1)) n{};
    return int(names.size() + n);
}" FIBLET_HAS_DECODER_CHOICE)
unset(CMAKE_REQUIRED_INCLUDES)
unset(CMAKE_REQUIRED_FLAGS)
if(FIBLET_HAS_DECODER_CHOICE)
  set(FIBLET_DECODER_CHOICE_DEFINITION FIBLET_HAS_DECODER_CHOICE=1)
else()
  set(FIBLET_DECODER_CHOICE_DEFINITION FIBLET_HAS_DECODER_CHOICE=0)
endif()
