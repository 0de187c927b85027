#include "scene/scene_file.hpp"

#include <stdlib.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>

#include "fiblet/compress.hpp"
#include "fiblet/error.hpp"
#include "fiblet/tractogram_format.hpp"
#include "scene/fiber_colors.hpp"
#include "scene/fiber_opacity.hpp"
#include "scene/fiber_radii.hpp"

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

GpuScene first_scene(const FftFile& file, const GpuPrograms& programs, const FiberStreaming& streaming,
                     const FiberColorSource& colors, const std::string& radii_path, const std::string& opacity_source) {
    GpuScene scene(file, programs, {}, streaming.streams() ? std::optional(streaming.overview()) : std::nullopt);
    load_fiber_colors(colors, file, scene);
    if (!radii_path.empty()) load_fiber_radii(radii_path, scene);
    if (!opacity_source.empty()) load_fiber_opacities(opacity_source, file, scene);
    return scene;
}

}  // namespace fiblet::viewer
