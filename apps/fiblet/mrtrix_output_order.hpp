// MRtrix3 puts the output last among the operands (`tckedit in.tck
// out.tck`); fiblet takes it with -o. `fiblet compress IN OUT.fft` (two
// operands, the last a .fft or .fftz name that does not exist yet, and no
// -o, --output-dir or -r) is read as `fiblet compress IN -o OUT.fft`: a
// .fft is never an input of compress, and a name that does not exist could
// only have been an input that fails. Anything else is left as it is
// (`compress a.tck b.tck` compresses both).
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace fiblet::cli {

// `args` without the program name, single-dash spellings already translated.
std::vector<std::string> mrtrix_output_order(const CLI::App& app, std::vector<std::string> args);

}  // namespace fiblet::cli
