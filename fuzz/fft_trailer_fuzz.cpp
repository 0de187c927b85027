// libFuzzer harness: the .fft reader as fft_file_fuzz runs it, fed by
// structure-aware mutations of the trailer, the blocks and the .fftz
// container (structure_mutator.hpp) half of the time, byte-level ones the
// other half.
#include <cstring>

#include "fuzz_targets.hpp"
#include "structure_mutator.hpp"

extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* data, std::size_t size, std::size_t max_size);

extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size, std::size_t max_size,
                                               unsigned int seed) {
    if (seed % 2) return LLVMFuzzerMutate(data, size, max_size);
    std::string b(reinterpret_cast<const char*>(data), size);
    if (!fiblet::fuzz::mutate_structure(b, seed / 2)) return LLVMFuzzerMutate(data, size, max_size);  // never throws: tested
    const std::size_t n = std::min(b.size(), max_size);
    std::memcpy(data, b.data(), n);
    return n;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    fiblet::fuzz::fft_target(data, size);
    return 0;
}
