#include "scene_file.hpp"

#include <stdlib.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "fiblet/compress.hpp"
#include "fiblet/error.hpp"

namespace fiblet::viewer {

bool looks_like_tck(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    char magic[13] = {};
    f.read(magic, 13);
    return f.gcount() == 13 && std::string(magic, 13) == "mrtrix tracks";
}

FftFile open_scene_file(const std::string& path) {
    if (!looks_like_tck(path)) return FftFile(path);
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
    compress_tck(path, fft, options);
    return FftFile(fft);  // FftFile keeps its descriptor: the file may go
}

}  // namespace fiblet::viewer
