#include "io/open_inputs.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <mutex>
#include <utility>
#include <vector>

#include "fiblet/error.hpp"

namespace fiblet::detail {
namespace {

// (dev, ino) of every open input, once per reader: a file opened twice is
// registered twice and stays registered until both readers are gone.
struct Registry {
    std::mutex mutex;
    std::vector<std::pair<dev_t, ino_t>> files;
};

Registry& registry() {
    static Registry r;  // readers may live in static objects: constructed on first use
    return r;
}

}  // namespace

InputRegistration::InputRegistration(int fd) {
    struct stat st {};
    if (fd < 0 || ::fstat(fd, &st) != 0) return;
    dev_ = st.st_dev, ino_ = st.st_ino, active_ = true;
    Registry& r = registry();
    const std::lock_guard lock(r.mutex);
    r.files.emplace_back(dev_, ino_);
}

InputRegistration::~InputRegistration() { release(); }

InputRegistration::InputRegistration(InputRegistration&& o) noexcept { *this = std::move(o); }

InputRegistration& InputRegistration::operator=(InputRegistration&& o) noexcept {
    if (this != &o) {
        release();
        dev_ = o.dev_, ino_ = o.ino_, active_ = std::exchange(o.active_, false);
    }
    return *this;
}

void InputRegistration::release() noexcept {
    if (!active_) return;
    active_ = false;
    Registry& r = registry();
    const std::lock_guard lock(r.mutex);
    const auto it = std::find(r.files.begin(), r.files.end(), std::make_pair(dev_, ino_));
    if (it != r.files.end()) r.files.erase(it);
}

void refuse_open_input(dev_t dev, ino_t ino, const std::string& output) {
    Registry& r = registry();
    const std::lock_guard lock(r.mutex);
    if (std::find(r.files.begin(), r.files.end(), std::make_pair(dev, ino)) != r.files.end())
        throw Error(Errc::invalid_argument,
                    output + ": the output is an input of this command (the same file, through a link or not): "
                             "refusing to replace it; choose another output name");
}

}  // namespace fiblet::detail
