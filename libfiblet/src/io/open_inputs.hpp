// Internal: the files this process is reading, so that no output replaces
// one of them. Every reader (FftFile, TckReader) registers the file it holds
// open; every output (AtomicOutputFile) checks its destination here. One
// check for all commands: `-o` naming the input, a symlink or a hard link to
// it, is refused instead of destroying the input with --force.
#pragma once

#include <sys/types.h>

#include <string>

namespace fiblet::detail {

// Registers the file open on `fd` for the lifetime of this object.
class InputRegistration {
public:
    InputRegistration() = default;
    explicit InputRegistration(int fd);
    ~InputRegistration();
    InputRegistration(InputRegistration&& o) noexcept;
    InputRegistration& operator=(InputRegistration&& o) noexcept;
    InputRegistration(const InputRegistration&) = delete;
    InputRegistration& operator=(const InputRegistration&) = delete;

private:
    void release() noexcept;
    dev_t dev_ = 0;
    ino_t ino_ = 0;
    bool active_ = false;
};

// Throws Error{invalid_argument} if the file (dev, ino) is an open input.
// `output` names the output in the message.
void refuse_open_input(dev_t dev, ino_t ino, const std::string& output);

}  // namespace fiblet::detail
