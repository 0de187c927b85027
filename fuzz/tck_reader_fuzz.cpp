// libFuzzer harness: the .tck reader, whose result must not depend on the
// read size, a rewind, or allow_count_mismatch on valid files.
#include "fuzz_targets.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    fiblet::fuzz::tck_target(data, size);
    return 0;
}
