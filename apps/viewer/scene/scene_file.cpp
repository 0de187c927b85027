#include "scene/scene_file.hpp"

#include <stdlib.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>

#include "fiblet/compress.hpp"
#include "fiblet/error.hpp"
#include "fiblet/tractogram_format.hpp"

namespace fiblet::viewer {

FftFile open_scene_file(const std::string& path) {
    if (!is_streamline_format(detect_tractogram_format(path))) return FftFile(path);  // a .tck, .trk or TRX is compressed
    const char* tmp = std::getenv("TMPDIR");
    std::string dir = std::string(tmp && *tmp ? tmp : "/tmp") + "/fiblet-view-XXXXXX";
    if (!::mkdtemp(dir.data())) throw Error(Errc::io, "cannot create a temporary directory in " + dir);
    struct RemoveDir {
        std::string path;
        ~RemoveDir() {
            std::error_code ec;
            std::filesystem::remove_all(path, ec);
        }
    } cleanup{dir};
    const std::string fft = dir + "/scene.fft";
    CompressOptions options;
    compress_file(path, fft, options);
    return FftFile(fft);  // FftFile keeps its descriptor: the file may go
}

}  // namespace fiblet::viewer
