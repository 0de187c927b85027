// XXH64 through Debian's libxxhash-dev, compiled inline (XXH_INLINE_ALL) so
// that the library gains no link-time dependency.
#define XXH_INLINE_ALL
#include <xxhash.h>

#include "fiblet/checksum.hpp"

namespace fiblet {

static_assert(sizeof(XXH64_state_t) <= 96 && alignof(XXH64_state_t) <= 8,
              "Xxh64Stream::state_ must hold an XXH64_state_t");

namespace {
XXH64_state_t* as_state(unsigned char* p) { return reinterpret_cast<XXH64_state_t*>(p); }
const XXH64_state_t* as_state(const unsigned char* p) { return reinterpret_cast<const XXH64_state_t*>(p); }
}  // namespace

std::uint64_t xxh64(const void* data, std::size_t size) { return XXH64(data, size, 0); }

Xxh64Stream::Xxh64Stream() { reset(); }
Xxh64Stream::~Xxh64Stream() = default;
void Xxh64Stream::reset() { XXH64_reset(as_state(state_.data()), 0); }
void Xxh64Stream::update(const void* data, std::size_t size) {
    if (size > 0) XXH64_update(as_state(state_.data()), data, size);
}
std::uint64_t Xxh64Stream::digest() const { return XXH64_digest(as_state(state_.data())); }

}  // namespace fiblet
