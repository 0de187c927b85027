// The reference space of a tractogram: axis codes, the .trk voxmm -> RAS+
// affine (as nibabel), and its PROP form.
#include "fiblet/tractogram_space.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "fiblet/error.hpp"
#include "fiblet/streamline_field.hpp"

namespace fiblet {
namespace {

using Mat4 = Eigen::Matrix<double, 4, 4, Eigen::RowMajor>;

Mat4 to_matrix(const Affine& a) { return Eigen::Map<const Mat4>(a.data()); }
Affine to_affine(const Mat4& m) {
    Affine a;
    Eigen::Map<Mat4>(a.data()) = m;
    return a;
}

// An orientation as nibabel's: for each voxel axis, the world axis (0 = x
// L->R, 1 = y P->A, 2 = z I->S) and its sign.
struct Orientation {
    std::array<int, 3> axis;
    std::array<int, 3> flip;
};

constexpr char kLabels[3][2] = {{'L', 'R'}, {'P', 'A'}, {'I', 'S'}};

std::optional<Orientation> orientation_of_codes(const std::string& codes) {
    if (codes.size() != 3) return std::nullopt;
    Orientation o{};
    bool used[3] = {false, false, false};
    for (int i = 0; i < 3; ++i) {
        const char c = char(std::toupper(static_cast<unsigned char>(codes[std::size_t(i)])));
        int found = -1;
        for (int a = 0; a < 3; ++a)
            for (int s = 0; s < 2; ++s)
                if (kLabels[a][s] == c) found = a, o.flip[std::size_t(i)] = s ? 1 : -1;
        if (found < 0 || used[found]) return std::nullopt;
        used[found] = true;
        o.axis[std::size_t(i)] = found;
    }
    return o;
}

// nibabel.orientations.io_orientation: the closest orthogonal matrix to the
// normalized rotation-zoom part (by SVD), then for each voxel axis the world
// axis of its largest component.
std::optional<Orientation> orientation_of_affine(const Affine& a) {
    Eigen::Matrix3d rzs = to_matrix(a).topLeftCorner<3, 3>();
    for (int c = 0; c < 3; ++c) {
        const double zoom = rzs.col(c).norm();
        if (zoom != 0) rzs.col(c) /= zoom;
    }
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(rzs, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Eigen::Vector3d s = svd.singularValues();
    const double tol = s.maxCoeff() * 3 * std::numeric_limits<double>::epsilon();
    Eigen::Matrix3d r = Eigen::Matrix3d::Zero();
    for (int k = 0; k < 3; ++k)
        if (s(k) > tol) r += svd.matrixU().col(k) * svd.matrixV().col(k).transpose();
    Orientation o{};
    for (int in = 0; in < 3; ++in) {
        int out;
        const double v = r.col(in).cwiseAbs().maxCoeff(&out);
        if (!(v > 1e-8)) return std::nullopt;
        o.axis[std::size_t(in)] = out;
        o.flip[std::size_t(in)] = r(out, in) < 0 ? -1 : 1;
        r.row(out).setZero();
    }
    return o;
}

// nibabel's ornt_transform then inv_ornt_aff: voxel indices in the header's
// order -> indices in the affine's order.
Mat4 reorient(const Orientation& from, const Orientation& to, const std::array<int, 3>& dims) {
    std::array<int, 3> axis{}, flip{};
    for (int end = 0; end < 3; ++end)
        for (int start = 0; start < 3; ++start)
            if (to.axis[std::size_t(end)] == from.axis[std::size_t(start)]) {
                axis[std::size_t(start)] = end;
                flip[std::size_t(start)] = to.flip[std::size_t(end)] == from.flip[std::size_t(start)] ? 1 : -1;
            }
    Mat4 reorder = Mat4::Zero(), undo_flip = Mat4::Identity();
    for (int k = 0; k < 3; ++k) {
        reorder(k, axis[std::size_t(k)]) = 1;
        const double centre = -(dims[std::size_t(k)] - 1) / 2.0;
        undo_flip(k, k) = flip[std::size_t(k)];
        undo_flip(k, 3) = flip[std::size_t(k)] * centre - centre;
    }
    reorder(3, 3) = 1;
    return undo_flip * reorder;
}

std::string join(const double* v, int n) {
    std::string s;
    char buf[40];
    for (int i = 0; i < n; ++i) {
        std::snprintf(buf, sizeof buf, "%.17g", v[i]);
        s += (i ? " " : "") + std::string(buf);
    }
    return s;
}

std::vector<double> numbers(const std::string& text, std::size_t n, const std::string& key, const std::string& name) {
    std::istringstream in(text);
    std::vector<double> v;
    double x;
    while (in >> x) v.push_back(x);
    if (!in.eof() || v.size() != n)
        throw Error(Errc::invalid_input, name + ": property " + key + " must hold " + std::to_string(n) + " numbers");
    for (double d : v)
        if (!std::isfinite(d)) throw Error(Errc::invalid_input, name + ": property " + key + " holds a non-finite number");
    return v;
}

}  // namespace

TractogramSpace TractogramSpace::from_affine(const Affine& a, std::array<int, 3> dimensions) {
    TractogramSpace s;
    s.voxel_to_rasmm = a;
    s.dimensions = dimensions;
    const Mat4 m = to_matrix(a);
    for (int c = 0; c < 3; ++c) s.voxel_sizes[std::size_t(c)] = m.col(c).head<3>().norm();
    if (auto codes = affine_axis_codes(a)) s.voxel_order = *codes;
    return s;
}

std::optional<std::string> affine_axis_codes(const Affine& a) {
    const auto o = orientation_of_affine(a);
    if (!o) return std::nullopt;
    std::string codes;
    for (int i = 0; i < 3; ++i) codes += kLabels[o->axis[std::size_t(i)]][o->flip[std::size_t(i)] > 0];
    return codes;
}

Affine trk_voxmm_to_rasmm(const TractogramSpace& s) {
    Mat4 m = Mat4::Identity();
    for (int k = 0; k < 3; ++k) {
        if (!(s.voxel_sizes[std::size_t(k)] > 0))
            throw Error(Errc::invalid_input, "voxel sizes must be positive (a .trk stores points in voxmm)");
        m(k, k) = 1.0 / s.voxel_sizes[std::size_t(k)];
        m(k, 3) = -0.5;  // TrackVis: 0 at a voxel's corner; RAS+ mm: at its centre
    }
    const auto from = orientation_of_codes(s.voxel_order);
    if (!from) throw Error(Errc::invalid_input, "voxel order \"" + s.voxel_order + "\" is not three axis codes");
    const auto to = orientation_of_affine(s.voxel_to_rasmm);
    if (!to) throw Error(Errc::invalid_input, "the voxel-to-RAS affine has no clear axis directions");
    const Mat4 full = to_matrix(s.voxel_to_rasmm) * reorient(*from, *to, s.dimensions) * m;
    Affine a = to_affine(full);
    for (double& v : a) v = double(narrow_to_float(v));  // nibabel returns it as float32
    return a;
}

Affine affine_inverse(const Affine& a) {
    const Mat4 m = to_matrix(a);
    const Eigen::Matrix4d col_major = m;
    const Eigen::FullPivLU<Eigen::Matrix4d> lu(col_major);
    if (!lu.isInvertible()) throw Error(Errc::invalid_input, "the voxel-to-RAS affine is singular");
    return to_affine(Mat4(lu.inverse()));
}

bool is_space_property(const std::string& key) noexcept {
    return key == "voxel_to_rasmm" || key == "dimensions" || key == "voxel_sizes" || key == "voxel_order";
}

void add_space_properties(std::vector<std::pair<std::string, std::string>>& properties, const TractogramSpace& s) {
    const double dims[3] = {double(s.dimensions[0]), double(s.dimensions[1]), double(s.dimensions[2])};
    properties.emplace_back("voxel_to_rasmm", join(s.voxel_to_rasmm.data(), 16));
    properties.emplace_back("dimensions", join(dims, 3));
    properties.emplace_back("voxel_sizes", join(s.voxel_sizes.data(), 3));
    properties.emplace_back("voxel_order", s.voxel_order);
}

std::optional<TractogramSpace> space_from_properties(
    const std::vector<std::pair<std::string, std::string>>& properties, const std::string& name) {
    const std::string* found[4] = {};
    const char* keys[4] = {"voxel_to_rasmm", "dimensions", "voxel_sizes", "voxel_order"};
    for (const auto& [k, v] : properties)
        for (int i = 0; i < 4; ++i)
            if (k == keys[i] && !found[i]) found[i] = &v;
    if (!found[0]) return std::nullopt;
    TractogramSpace s;
    const auto a = numbers(*found[0], 16, keys[0], name);
    std::copy(a.begin(), a.end(), s.voxel_to_rasmm.begin());
    if (found[1]) {
        const auto d = numbers(*found[1], 3, keys[1], name);
        for (int k = 0; k < 3; ++k) {
            if (!(d[std::size_t(k)] >= 0 && d[std::size_t(k)] <= 65535 && d[std::size_t(k)] == std::floor(d[std::size_t(k)])))
                throw Error(Errc::invalid_input, name + ": property dimensions must be integers in [0, 65535]");
            s.dimensions[std::size_t(k)] = int(d[std::size_t(k)]);
        }
    }
    if (found[2]) {
        const auto v = numbers(*found[2], 3, keys[2], name);
        std::copy(v.begin(), v.end(), s.voxel_sizes.begin());
    } else {
        s = TractogramSpace::from_affine(s.voxel_to_rasmm, s.dimensions);
    }
    if (found[3]) s.voxel_order = *found[3];
    return s;
}

}  // namespace fiblet
