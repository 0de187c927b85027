// libFuzzer harness: the .fft reader (header, LUT, trailer, checksums) and
// decoding whole files and ranges with every decoder against the scalar
// reference.
#include "fuzz_targets.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    fiblet::fuzz::fft_target(data, size);
    return 0;
}
