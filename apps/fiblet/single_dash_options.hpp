// MRtrix3 writes long options with one dash (-force, -nthreads 4); CLI11
// would read `-force` as `-f -o rce`. Before parsing, fiblet rewrites
// MRtrix3's spellings of the options it has into its own, and rejects any
// other single-dash word of two or more letters with a message naming the
// option meant: a single-dash word is never split into short options.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace fiblet::cli {

// `args` without the program name. Throws Error(Errc::invalid_argument).
std::vector<std::string> translate_single_dash_options(const CLI::App& app, std::vector<std::string> args);

}  // namespace fiblet::cli
