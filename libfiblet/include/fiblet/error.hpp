// fiblet — error reporting.
//
// Every failure the library can meet on bad input or a failing system call is
// reported as a fiblet::Error carrying a category, so that callers (the CLI,
// the Python module, a pipeline) can map it to an exit code without parsing
// the message. Messages name the file and what is wrong with it.
#pragma once

#include <stdexcept>
#include <string>

namespace fiblet {

enum class Errc : int {
    io = 1,            // open/read/write/rename failed (errno text in the message)
    tck_format = 2,    // malformed .tck header or data
    fft_format = 3,    // malformed .fft header or data
    invalid_input = 4, // well-formed file whose content cannot be encoded (NaN, ...)
    invalid_argument = 5, // bad option value given by the caller
    exists = 6,        // output exists and overwriting was not allowed
    unsupported = 7,   // valid but not supported (e.g. an unknown datatype)
    checksum = 8,      // integrity check failed
    interrupted = 9,   // stopped by a signal
    image_format = 10, // malformed voxel image (NIfTI, .mif)
    trk_format = 11,   // malformed TrackVis .trk header or data
    trx_format = 12,   // malformed TRX archive, header.json or array
};

// Short stable name of a category ("tck_format", ...), for --json output.
const char* errc_name(Errc c) noexcept;

// The caller's option that would have allowed what failed, named by the
// library option it is (CompressOptions::overwrite, FftOpenOptions::
// ignore_trailer, TckReadOptions::allow_count_mismatch, CompressOptions::
// max_memory). The message says
// nothing of it: each front end names it in its own terms (the CLI's
// --force, Python's overwrite=True).
enum class Remedy : int { none, overwrite, ignore_trailer, allow_count_mismatch, max_memory };

class Error : public std::runtime_error {
public:
    Error(Errc code, const std::string& message, Remedy remedy = Remedy::none)
        : std::runtime_error(message), code_(code), remedy_(remedy) {}
    Errc code() const noexcept { return code_; }
    Remedy remedy() const noexcept { return remedy_; }

private:
    Errc code_;
    Remedy remedy_;
};

}  // namespace fiblet
