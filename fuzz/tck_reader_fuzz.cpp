// libFuzzer harness: the .tck reader (any chunk size, rewind), then the whole
// compression of small valid inputs and a decode of what it wrote.
#include "fuzz_targets.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    fiblet::fuzz::tck_target(data, size);
    return 0;
}
