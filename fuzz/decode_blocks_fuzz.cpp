// libFuzzer harness: the block decoders on raw blocks under arbitrary (valid)
// file parameters, without a file's LUT to satisfy, so the fuzzer spends its
// time in the decoding kernels.
#include "fuzz_targets.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    fiblet::fuzz::blocks_target(data, size);
    return 0;
}
