// libFuzzer harness: the .trk and TRX readers (and format recognition)
// through open_streamline_source; see streamline_source_target.
#include "fuzz_targets.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    fiblet::fuzz::streamline_source_target(data, size);
    return 0;
}
