// NIfTI-1 and NIfTI-2 images (.nii, .nii.gz) through libnifti (Debian's
// libnifti2-dev, whose nifti2_io reads both versions and gzip).
#include <nifti2_io.h>
#include <sys/stat.h>

#include <algorithm>
#include <cstdlib>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <memory>

#include "fiblet/error.hpp"
#include "image/image_readers.hpp"

namespace fiblet::detail {
namespace {

struct NiftiFree {
    void operator()(nifti_image* n) const { nifti_image_free(n); }
};
using NiftiPtr = std::unique_ptr<nifti_image, NiftiFree>;

template <class T>
T field(const std::uint8_t* p, bool swap) {
    std::uint8_t b[sizeof(T)];
    std::memcpy(b, p, sizeof(T));
    if (swap) std::reverse(b, b + sizeof(T));
    T v;
    std::memcpy(&v, b, sizeof(T));
    return v;
}

// The header fields libnifti trusts, checked first: libnifti 3.0.1 crashes
// on a NIfTI-2 dim[0] out of 1..7, and prints its own messages on stderr
// for a short header, an axis of no voxels or an unknown datatype.
void check_header(const std::string& path, bool gz) {
    std::uint8_t h[540] = {};
    znzFile f = znzopen(path.c_str(), "rb", gz ? 1 : 0);
    if (znz_isnull(f)) throw Error(Errc::io, path + ": cannot open: " + std::strerror(errno));
    const std::size_t got = znzread(h, 1, sizeof h, f);
    znzclose(f);
    auto bad = [&](const std::string& why) { throw Error(Errc::image_format, path + ": not a valid NIfTI image: " + why); };
    if (got < 4) bad("the file is too short");
    const auto size = field<std::int32_t>(h, false), swapped = field<std::int32_t>(h, true);
    const bool swap = size != 348 && size != 540;
    const std::int32_t header_bytes = swap ? swapped : size;
    if (header_bytes != 348 && header_bytes != 540)
        bad("sizeof_hdr is " + std::to_string(size) + " (348 for NIfTI-1, 540 for NIfTI-2)");
    if (got < std::size_t(header_bytes)) bad("the header is cut short");
    const bool v2 = header_bytes == 540;
    const std::int64_t ndim = v2 ? field<std::int64_t>(h + 16, swap) : field<std::int16_t>(h + 40, swap);
    if (ndim < 1 || ndim > 7) bad("dim[0] is " + std::to_string(ndim) + " (1 to 7 axes)");
    for (int a = 1; a <= ndim; ++a) {  // libnifti would print "** ERROR ... bad dim[a]" on stderr
        const std::int64_t d = v2 ? field<std::int64_t>(h + 16 + 8 * a, swap) : field<std::int16_t>(h + 40 + 2 * a, swap);
        if (d < 1) bad("dim[" + std::to_string(a) + "] is " + std::to_string(d) + " (at least 1 voxel per axis)");
    }
    const int datatype = field<std::int16_t>(h + (v2 ? 12 : 70), swap);
    if (!nifti_is_valid_datatype(datatype)) bad("unknown datatype code " + std::to_string(datatype));
}

// The header as libnifti's nifti_image, without its extensions:
// nifti_image_read reads every extension whole into memory (issue 32
// reports 1.54 GB for a 1.6 MB file), and fiblet needs none of them.
NiftiPtr read_header_only(const std::string& path) {
    int version = 0;
    std::unique_ptr<void, void (*)(void*)> raw(nifti_read_header(path.c_str(), &version, 1), &std::free);
    if (!raw) return NiftiPtr();
    if (version == 2) return NiftiPtr(nifti_convert_n2hdr2nim(*static_cast<nifti_2_header*>(raw.get()), path.c_str()));
    if (version == 1) return NiftiPtr(nifti_convert_n1hdr2nim(*static_cast<nifti_1_header*>(raw.get()), path.c_str()));
    return NiftiPtr();
}

// The first `n` voxels of `path` itself, read through znzlib (gzip or not)
// 16 MiB at a time, each chunk converted into `out` as it arrives: a gzip
// header may claim up to 1032x its file (deflate's best ratio) and be a
// lie, so memory follows the bytes that exist, not the claim, and the
// voxels' own bytes are never held whole. libnifti's own loader is not
// used: with both X.nii and X.nii.gz present it reads the data of X.nii for
// X.nii.gz (libnifti 3.0.1).
void read_voxels(const std::string& path, const nifti_image& h, std::size_t n, bool gz, const VoxelOutput& out) {
    // scl_slope / scl_inter, when the slope is finite and non-zero, scale
    // integer data only: MRtrix 3.0 (and so tckedit) reads float data as
    // stored (checked in tests/image_test.cpp).
    double slope = 1, inter = 0;
    const bool integer = h.datatype != DT_FLOAT32 && h.datatype != DT_FLOAT64;
    if (integer && std::isfinite(h.scl_slope) && h.scl_slope != 0) {
        slope = h.scl_slope;
        inter = std::isfinite(h.scl_inter) ? h.scl_inter : 0.0;
    }
    auto convert = [&]<class T>(const std::uint8_t* data, std::size_t first, std::size_t count) {
        for (std::size_t i = 0; i < count; ++i) {
            T v;
            std::memcpy(&v, data + i * sizeof(T), sizeof(T));
            out.put(first + i, float(inter + slope * double(v)));
        }
    };
    auto convert_chunk = [&](const std::uint8_t* data, std::size_t first, std::size_t count) {
        switch (h.datatype) {
            case DT_UINT8: return convert.operator()<std::uint8_t>(data, first, count);
            case DT_INT8: return convert.operator()<std::int8_t>(data, first, count);
            case DT_INT16: return convert.operator()<std::int16_t>(data, first, count);
            case DT_UINT16: return convert.operator()<std::uint16_t>(data, first, count);
            case DT_INT32: return convert.operator()<std::int32_t>(data, first, count);
            case DT_UINT32: return convert.operator()<std::uint32_t>(data, first, count);
            case DT_INT64: return convert.operator()<std::int64_t>(data, first, count);
            case DT_UINT64: return convert.operator()<std::uint64_t>(data, first, count);
            case DT_FLOAT32: return convert.operator()<float>(data, first, count);
            case DT_FLOAT64: return convert.operator()<double>(data, first, count);
            default:
                throw Error(Errc::unsupported, path + ": NIfTI datatype " + std::string(nifti_datatype_string(h.datatype)) +
                                                   " is not supported (real-valued voxels only)");
        }
    };
    convert_chunk(nullptr, 0, 0);  // an unsupported datatype fails before any read
    znzFile f = znzopen(path.c_str(), "rb", gz ? 1 : 0);
    if (znz_isnull(f)) throw Error(Errc::io, path + ": cannot open: " + std::strerror(errno));
    const std::size_t width = std::size_t(h.nbyper), chunk_voxels = (std::size_t(16) << 20) / width;
    const bool swap = h.byteorder != nifti_short_order() && h.swapsize > 1;
    std::vector<std::uint8_t> chunk;
    std::size_t got = 0;
    if (znzseek(f, znz_off_t(h.iname_offset), SEEK_SET) >= 0) {
        while (got < n) {
            const std::size_t want = std::min(chunk_voxels, n - got);
            chunk.resize(want * width);
            const std::size_t n_read = znzread(chunk.data(), 1, chunk.size(), f) / width;
            if (swap) nifti_swap_Nbytes(std::int64_t(n_read), h.swapsize, chunk.data());
            out.grow_to(got + n_read);
            convert_chunk(chunk.data(), got, n_read);
            got += n_read;
            if (n_read < want) break;
        }
    }
    znzclose(f);
    if (got != n)
        throw Error(Errc::image_format, path + ": voxel data truncated (" + std::to_string(n * width) +
                                            " bytes expected at offset " + std::to_string(h.iname_offset) + ")");
}

// MRtrix's rules (core/file/nifti_utils.cpp): the sform when sform_code is
// set (its axes normalised, the voxel sizes taken from pixdim unless they
// disagree with the axes' lengths by more than 1e-5), else the qform.
Affine3x4 rotation_and_spacing(const nifti_image& nim, std::array<double, 3>& spacing, bool& found) {
    Affine3x4 m{};
    found = true;
    if (nim.sform_code != 0) {
        bool rescale = false;
        std::array<double, 3> length{};
        for (int c = 0; c < 3; ++c) {
            length[c] = std::sqrt(nim.sto_xyz.m[0][c] * nim.sto_xyz.m[0][c] + nim.sto_xyz.m[1][c] * nim.sto_xyz.m[1][c] +
                                  nim.sto_xyz.m[2][c] * nim.sto_xyz.m[2][c]);
            if (std::abs(spacing[c] / length[c] - 1.0) > 1e-5) rescale = true;
        }
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 4; ++c) m[r][c] = nim.sto_xyz.m[r][c] / (c < 3 ? length[c] : 1.0);
        if (rescale) spacing = length;
        return m;
    }
    if (nim.qform_code != 0) {
        // Unit quaternion (b, c, d) with a = sqrt(1 - b² - c² - d²), as MRtrix computes it.
        double b = nim.quatern_b, c = nim.quatern_c, d = nim.quatern_d;
        double a = 1.0 - (b * b + c * c + d * d);
        if (a < 1e-7) {
            const double norm = std::sqrt(b * b + c * c + d * d);
            b /= norm, c /= norm, d /= norm, a = 0;
        } else {
            a = std::sqrt(a);
        }
        const double R[3][3] = {{1 - 2 * (c * c + d * d), 2 * (b * c - a * d), 2 * (b * d + a * c)},
                                {2 * (b * c + a * d), 1 - 2 * (b * b + d * d), 2 * (c * d - a * b)},
                                {2 * (b * d - a * c), 2 * (c * d + a * b), 1 - 2 * (b * b + c * c)}};
        const double qfac = nim.qfac < 0 ? -1.0 : 1.0;
        for (int r = 0; r < 3; ++r) {
            for (int col = 0; col < 3; ++col) m[r][col] = R[r][col] * (col == 2 ? qfac : 1.0);
        }
        m[0][3] = nim.qoffset_x, m[1][3] = nim.qoffset_y, m[2][3] = nim.qoffset_z;
        return m;
    }
    found = false;
    return m;
}

}  // namespace

Image read_nifti(const std::string& path, VoxelOutput out) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) throw Error(Errc::io, path + ": cannot open: " + std::strerror(errno));
    const bool gz = path.size() > 3 && path.compare(path.size() - 3, 3, ".gz") == 0;
    check_header(path, gz);
    nifti_set_debug_level(0);  // libnifti's messages would go to stderr; ours are clearer
    NiftiPtr header = read_header_only(path);
    if (!header) throw Error(Errc::image_format, path + ": not a valid NIfTI-1/NIfTI-2 image (unreadable header)");
    const nifti_image& h = *header;

    Image img;
    img.path = path;
    const int ndim = int(std::clamp<std::int64_t>(h.dim[0], 0, 7));
    for (int a = 1; a <= std::max(3, ndim); ++a) img.dims.push_back(a <= ndim ? h.dim[a] : 1);
    const std::size_t n = voxel_count(path, img.dims);
    // Data larger than the file could hold (deflate compresses at most
    // 1032:1) is a lying header, refused before libnifti allocates it.
    const double room = double(st.st_size) * (gz ? 1032.0 : 1.0);
    if (h.nbyper <= 0 || double(n) * double(h.nbyper) > room)
        throw Error(Errc::image_format, path + ": the header describes " + std::to_string(n) +
                                            " voxels, more than the file holds (truncated or malformed image)");
    if (h.iname_offset < 0) throw Error(Errc::image_format, path + ": negative data offset");
    // Voxels are stored x fastest, the volumes last: a mask reads the first.
    if (out.values) read_voxels(path, h, n, gz, out);
    else if (out.counts) read_voxels(path, h, std::size_t(img.dims[0] * img.dims[1] * img.dims[2]), gz, out);

    for (int c = 0; c < 3; ++c) img.spacing[c] = c < ndim ? std::abs(h.pixdim[c + 1]) : 1.0;
    for (double& s : img.spacing)
        if (!(std::isfinite(s) && s > 0)) s = 1.0;
    bool found = false;
    Affine3x4 m = rotation_and_spacing(h, img.spacing, found);
    if (!found) m = centred_transform(img);
    img.voxel_to_world = voxel_to_world(m, img.spacing);
    check_transform(img);
    return img;
}

}  // namespace fiblet::detail
