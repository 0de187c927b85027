// default_memory_budget(): half of the memory this process may really use —
// the machine's physical memory, or less where the process is held to less
// (`ulimit -v` / `-d`, a cgroup's memory.max in a container or a SLURM job),
// so that a budget refusal (exit 6, naming --max-memory) comes before the
// allocator's failure would.
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <string>

#include "fiblet/compress.hpp"

namespace fiblet {
namespace {

constexpr std::uint64_t kUnknown = ~std::uint64_t(0);

std::uint64_t physical_memory() {
    const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
    return pages > 0 && page > 0 ? std::uint64_t(pages) * std::uint64_t(page) : std::uint64_t(8) << 30;
}

std::uint64_t resource_limit(int resource) {
    rlimit r{};
    return ::getrlimit(resource, &r) == 0 && r.rlim_cur != RLIM_INFINITY ? std::uint64_t(r.rlim_cur) : kUnknown;
}

// cgroup v2: the process's group from /proc/self/cgroup ("0::/path"), its
// memory.max ("max" when unbounded). cgroup v1 hosts are not read.
std::uint64_t cgroup_limit() {
    std::ifstream self("/proc/self/cgroup");
    std::string line, group;
    while (std::getline(self, line))
        if (line.rfind("0::", 0) == 0) group = line.substr(3);
    if (group.empty()) return kUnknown;
    std::ifstream max("/sys/fs/cgroup" + (group == "/" ? std::string() : group) + "/memory.max");
    std::string value;
    if (!(max >> value) || value == "max") return kUnknown;
    try {
        return std::stoull(value);
    } catch (...) {
        return kUnknown;
    }
}

}  // namespace

std::uint64_t default_memory_budget() {
    const std::uint64_t usable =
        std::min({physical_memory(), resource_limit(RLIMIT_AS), resource_limit(RLIMIT_DATA), cgroup_limit()});
    return usable / 2;
}

}  // namespace fiblet
