#include "fiblet/error.hpp"

namespace fiblet {

const char* errc_name(Errc c) noexcept {
    switch (c) {
        case Errc::io: return "io";
        case Errc::tck_format: return "tck_format";
        case Errc::fft_format: return "fft_format";
        case Errc::invalid_input: return "invalid_input";
        case Errc::invalid_argument: return "invalid_argument";
        case Errc::exists: return "exists";
        case Errc::unsupported: return "unsupported";
        case Errc::checksum: return "checksum";
        case Errc::interrupted: return "interrupted";
        case Errc::image_format: return "image_format";
        case Errc::trk_format: return "trk_format";
        case Errc::trx_format: return "trx_format";
    }
    return "unknown";
}

}  // namespace fiblet
