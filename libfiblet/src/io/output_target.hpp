// Internal: what an output path names, decided before anything is written.
//
//  - nothing yet, or a regular file: written atomically (a temporary next to
//    it, renamed over it when complete);
//  - a symbolic link: followed, and its final target written atomically, so
//    the link stays a link (a dangling link is refused: nothing to follow);
//  - a character device (/dev/null, /dev/full, a terminal): written through,
//    in place; a device is never replaced by a regular file;
//  - a FIFO, socket, block device or directory: refused. fiblet's writers
//    seek back to finish a file (counts in the header), which a pipe cannot
//    take, and a block device is a disk, not an output.
// Any file that is an input of the running command is refused (open_inputs.hpp).
#pragma once

#include <string>

namespace fiblet::detail {

struct OutputTarget {
    std::string path;            // the file the bytes end up in (a symlink resolved)
    bool write_through = false;  // an existing character device: open it, no temporary, no rename
    bool exists = false;         // something is there already
};

// Throws Error{invalid_argument} for a refused destination, Error{io} when
// it cannot be examined.
OutputTarget resolve_output_target(const std::string& path);

// Checks `target` again just before it is replaced (it may have changed
// since resolve_output_target): still not an input, still not a device.
void recheck_output_target(const OutputTarget& target, const std::string& shown_name);

// A temporary name next to `path` ending in `suffix`, its last component
// shortened to fit NAME_MAX of the directory (a legal 255-byte output name
// must not fail because of the suffix).
std::string temporary_name_for(const std::string& path, const std::string& suffix);

}  // namespace fiblet::detail
