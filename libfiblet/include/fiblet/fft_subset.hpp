// fiblet — writing a selection as a smaller .fft file, without re-encoding.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "fiblet/fft_file.hpp"
#include "fiblet/index_format.hpp"
#include "fiblet/select.hpp"

namespace fiblet {

struct SubsetReport {
    std::uint64_t fibers = 0, blocks = 0, points = 0, bytes = 0;
};

// Writes the blocks of `runs` (select_runs) as a valid .fft file, each run
// one fiber, atomically. Blocks are copied byte for byte except for their
// fiber ID, first/last flags and index in the fiber, so every point decodes
// exactly as in the source. The header keeps the source's normalization,
// step and direction code, and its recorded errors (the maximum remains an
// upper bound; the mean is the source's). The trailer keeps the source's
// PROP and RSMP chunks, the ENDS fractions and DATA arrays of the kept
// runs (a per-streamline row per run, the run's per-point rows, groups
// listing the runs of their fibers), and gets a fresh BIDX index and CSUM
// checksums (the index in `index_format`, index_format.hpp). Runs with
// coarse blocks (a level of detail) cannot be stored: Error{invalid_argument}.
SubsetReport write_fft_subset(const FftFile& source, const std::vector<SelectedRun>& runs, const std::string& path,
                              bool overwrite, BlockIndexFormat index_format = kDefaultBlockIndexFormat);

}  // namespace fiblet
