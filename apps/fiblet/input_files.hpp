// Which files a compress/decompress run reads and writes, as zstd names
// them: -o for one input, else the input's name with the new extension, next
// to it or in --output-dir; with -r, a directory stands for the files below
// it (the tree mirrored in --output-dir), except a directory that is itself
// an input (a TRX directory: named *.trx or holding a header.json).
#pragma once

#include <string>
#include <vector>

namespace fiblet::cli {

struct FileJob {
    std::string input, output;
};

struct FileJobOptions {
    std::vector<std::string> input_extensions;  // what -r picks up below a directory, e.g. {".tck"}
    std::vector<std::string> directory_inputs;  // directories that are themselves inputs (TRX: {".trx"})
    std::string directory_marker;               // ... or that hold this file, whatever their name (TRX: header.json)
    std::string output_extension;               // e.g. ".fft"
    std::string output, output_dir;             // -o, --output-dir
    bool recursive = false;                     // -r
};

// `-` (standard input) needs -o. Throws Error(Errc::invalid_argument) for a
// directory without -r, -o with several inputs, or a directory holding no input; creates --output-dir and
// the folders the mirrored tree needs in it.
std::vector<FileJob> plan_file_jobs(const std::vector<std::string>& operands, const FileJobOptions& options);

}  // namespace fiblet::cli
