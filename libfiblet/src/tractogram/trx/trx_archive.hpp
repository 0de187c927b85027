// Internal: the files of a TRX tractogram, in a zip archive (libzip) or a
// directory, read whole or streamed.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace fiblet::detail {

class TrxEntryStream {
public:
    virtual ~TrxEntryStream() = default;
    // Reads exactly `size` bytes (throws Error{trx_format} if the entry ends first).
    virtual void read(void* out, std::size_t size) = 0;
};

class TrxArchive {
public:
    // A directory holding header.json, or a zip archive. Throws Error{io},
    // Error{trx_format} (a damaged zip).
    static std::unique_ptr<TrxArchive> open(const std::string& path);
    virtual ~TrxArchive() = default;
    // Paths of the files, relative, '/'-separated (folders left out).
    virtual std::vector<std::string> entries() const = 0;
    virtual std::uint64_t size(const std::string& entry) const = 0;
    virtual std::vector<std::uint8_t> read_all(const std::string& entry) const = 0;
    virtual std::unique_ptr<TrxEntryStream> stream(const std::string& entry) const = 0;
};

// A TRX entry name: "dpv/fa.float16", "positions.3.float32": its name
// ("dpv/fa"), its component count (1 when absent) and its dtype extension.
struct TrxEntryName {
    std::string name, dtype;
    std::uint32_t components = 1;
};
// nullopt when the name has no dtype extension or a malformed count.
std::optional<TrxEntryName> parse_trx_entry_name(const std::string& entry);

}  // namespace fiblet::detail
