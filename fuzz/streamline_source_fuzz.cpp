// libFuzzer harness: the .trk and TRX readers (and format recognition)
// through open_streamline_source, and for what they read, compress: whatever
// it accepts must read back (see streamline_source_target).
#include "fuzz_targets.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    fiblet::fuzz::streamline_source_target(data, size);
    return 0;
}
