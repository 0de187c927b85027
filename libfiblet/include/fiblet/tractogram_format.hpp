// fiblet — recognising a tractogram file by its content (then its name).
//
// Every command that opens a file first asks what it is, so that a file of
// another format gets a message naming that format ("a TrackVis .trk file")
// instead of a parse error from the wrong reader.
#pragma once

#include <cstdint>
#include <string>

namespace fiblet {

enum class TractogramFormat {
    tck,        // MRtrix3 tracks: "mrtrix tracks" first line
    trk,        // TrackVis: "TRACK" magic
    trx,        // TRX: a zip archive or a directory holding header.json
    fft,        // fiblet/Fiblets .fft (version 2 or 16 little-endian first word)
    fftz,       // fiblet's seekable zstd container
    // Recognised, not supported:
    vtk,        // VTK legacy ("# vtk DataFile")
    vtp,        // VTK XML
    tck_image,  // an MRtrix image (.mif/.mih), not tracks
    nifti,      // a NIfTI image
    gzip,       // a gzip stream (.tt.gz, .trk.gz, ...): decompress it first
    zip_other,  // a zip archive without header.json (not TRX)
    unknown,
};

// What `path` holds: by its first bytes, then (for directories and empty
// files) by its name. Never throws for an unreadable file: unknown.
TractogramFormat detect_tractogram_format(const std::string& path);

// "a TrackVis .trk file", "a TRX tractogram", ... (for messages).
const char* tractogram_format_description(TractogramFormat f) noexcept;

// Whether compress can read it / decompress can write it.
bool is_streamline_format(TractogramFormat f) noexcept;  // tck, trk, trx

// Bytes on disk: a file's size, or the sum over a (TRX) directory's files; 0
// when it cannot be read.
std::uint64_t tractogram_bytes(const std::string& path);

// The format an output name asks for, from its extension (.tck, .trk, .trx,
// .fft, .fftz, .vtk, ...); unknown for anything else.
TractogramFormat format_from_extension(const std::string& path);

}  // namespace fiblet
