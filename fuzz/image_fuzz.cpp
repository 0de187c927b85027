// libFuzzer harness: the NIfTI and .mif image readers (masks, ODF images).
#include "image_target.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    fiblet::fuzz::image_target(data, size);
    return 0;
}
