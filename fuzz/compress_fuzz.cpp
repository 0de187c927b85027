// libFuzzer harness: the whole compression of small valid .tck inputs and a
// decode of what it wrote (slower than the others: compress is a pipeline).
#include "fuzz_targets.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    fiblet::fuzz::compress_target(data, size);
    return 0;
}
