#ifdef FIBLET_XXH3_DISPATCH
// libxxhash's run-time dispatch: its widest vector code this CPU runs
// (the same digest from every one of them).
#define XXH_STATIC_LINKING_ONLY
#include <xxh_x86dispatch.h>
#else
#define XXH_INLINE_ALL
#include <xxhash.h>
#endif

#include "core/pass_digest.hpp"

namespace fiblet::detail {

struct PassDigest::State {
    XXH3_state_t xxh3;
};

PassDigest::PassDigest() : state_(std::make_unique<State>()) { reset(); }
PassDigest::~PassDigest() = default;
void PassDigest::reset() { XXH3_64bits_reset(&state_->xxh3); }
void PassDigest::update(const void* data, std::size_t size) {
    if (size > 0) XXH3_64bits_update(&state_->xxh3, data, size);
}
std::uint64_t PassDigest::digest() const { return XXH3_64bits_digest(&state_->xxh3); }

}  // namespace fiblet::detail
