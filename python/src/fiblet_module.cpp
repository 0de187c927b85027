// fiblet._fiblet — the compiled half of the Python module (pybind11). The
// Python package (python/fiblet/__init__.py) normalizes arguments and builds
// the user-facing objects; this file only moves data in and out of the
// library. Decoded buffers are handed to numpy without a copy (owned_array.hpp)
// and the GIL is released while the library works.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <numeric>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "fiblet/block_index.hpp"
#include "fiblet/compare.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/image_mask.hpp"
#include "fiblet/fiber_regions.hpp"
#include "fiblet/select.hpp"
#include "fiblet/streamline_io.hpp"
#include "fiblet/tractogram_format.hpp"
#include "decode_range.hpp"
#include "file_data.hpp"
#include "owned_array.hpp"
#include "gather_fibers.hpp"
#include "write_streamlines.hpp"

namespace py = pybind11;

namespace fiblet::python {
namespace {

// Decode options for `threads` (0: the library's default).
DecodeOptions decode_options(unsigned threads) {
    DecodeOptions o;
    if (threads) o.threads = threads;
    return o;
}

// Decodes `indices` (any order, repeats allowed): each run of consecutive
// indices is decoded with one call, then the runs are gathered in order.
Streamlines decode_indices(const FftFile& file, const std::vector<std::uint64_t>& indices, const DecodeOptions& o) {
    Streamlines all;
    std::vector<std::uint64_t> run_fiber;  // position in `all` of each requested fiber
    std::size_t i = 0;
    while (i < indices.size()) {
        std::size_t j = i + 1;
        while (j < indices.size() && indices[j] == indices[j - 1] + 1) ++j;
        Streamlines part = decode_fibers(file, indices[i], indices[j - 1] + 1, o);
        if (i == 0 && j == indices.size()) return part;  // one contiguous run: no gather
        const std::uint64_t base_fiber = all.size(), base_point = all.point_count();
        all.xyz.insert(all.xyz.end(), part.xyz.begin(), part.xyz.end());
        for (std::size_t k = 1; k < part.offsets.size(); ++k) all.offsets.push_back(base_point + part.offsets[k]);
        for (std::size_t k = 0; k < j - i; ++k) run_fiber.push_back(base_fiber + k);
        i = j;
    }
    return gather_fibers(view_of(all), run_fiber);
}

// Regions as the Python package passes them: ("sphere", centre, (radius, 0,
// 0), exclude), ("box", min, max, exclude) or ("mask", path, None, exclude).
struct Regions {
    std::vector<Region> include, exclude;
    bool empty() const { return include.empty() && exclude.empty(); }
};

Regions parse_regions(const py::list& regions) {
    Regions out;
    for (const py::handle& item : regions) {
        const auto t = item.cast<py::tuple>();
        if (t.size() != 4) throw Error(Errc::invalid_argument, "a region is (shape, a, b, exclude)");
        const auto shape = t[0].cast<std::string>();
        const bool exclude = t[3].cast<bool>();
        Region r;
        if (shape == "mask") {
            const auto path = t[1].cast<std::string>();
            py::gil_scoped_release release;
            r = Region::image(ImageMask::read(path));
        } else {
            const auto a = t[1].cast<std::array<double, 3>>(), b = t[2].cast<std::array<double, 3>>();
            const Vec3f va{float(a[0]), float(a[1]), float(a[2])}, vb{float(b[0]), float(b[1]), float(b[2])};
            if (shape == "sphere") r = Region::sphere(va, float(b[0]));
            else if (shape == "box") r = Region::box_between(va, vb);
            else throw Error(Errc::invalid_argument, "unknown region shape '" + shape + "'");
        }
        (exclude ? out.exclude : out.include).push_back(std::move(r));
    }
    return out;
}

// The block index of the last file queried with roi=, kept for the next
// query on the same file (same device, inode, size and modification time):
// loading it (parsing the BIDX chunk, sorting 800 k boxes on the medium
// file) costs about as much as the selection itself.
std::shared_ptr<const BlockIndex> block_index_of(const FftFile& file) {
    struct stat st {};
    if (::stat(file.path().c_str(), &st) != 0) return std::make_shared<const BlockIndex>(BlockIndex::load(file));
    const std::array<std::int64_t, 5> key{std::int64_t(st.st_dev), std::int64_t(st.st_ino), std::int64_t(st.st_size),
                                          std::int64_t(st.st_mtim.tv_sec), std::int64_t(st.st_mtim.tv_nsec)};
    static std::mutex mutex;
    static std::array<std::int64_t, 5> cached_key{};
    static std::shared_ptr<const BlockIndex> cached;
    {
        const std::lock_guard<std::mutex> lock(mutex);
        if (cached && cached_key == key && cached->blocks() == file.header().blocks) return cached;
    }
    auto index = std::make_shared<const BlockIndex>(BlockIndex::load(file));
    const std::lock_guard<std::mutex> lock(mutex);
    cached_key = key, cached = index;
    return index;
}

// The fibers among `candidates` that the regions of `q` keep, in file order, and
// their IDs: the library's selection decides through the block index (only
// the blocks near a region are decoded to test their points), then decodes
// the kept fibers with the fast block decoders.
Streamlines select_by_regions(const FftFile& file, Query q, const std::vector<FiberRange>& candidates,
                              std::vector<std::uint64_t>& ids) {
    const std::shared_ptr<const BlockIndex> index = block_index_of(file);
    q.fibers = candidates;
    std::vector<SelectedRun> runs;
    Streamlines s = select_streamlines(file, *index, q, &runs);
    ids.clear();
    for (const SelectedRun& run : runs) ids.push_back(run.fiber);  // fibers mode: one run per kept fiber
    return s;
}

// Sorted, merged ranges of a list of fiber indices.
std::vector<FiberRange> ranges_of(std::vector<std::uint64_t> ids) {
    std::sort(ids.begin(), ids.end());
    std::vector<FiberRange> out;
    for (const std::uint64_t f : ids) {
        if (!out.empty() && f <= out.back().last + 1) out.back().last = std::max(out.back().last, f);
        else out.push_back({f, f});
    }
    return out;
}

// roi=: the fibers among [begin, end), or among `indices` (any order,
// repeats), that the regions keep, in that order, and their IDs; in `range`
// when they were decoded as one, else in `s`.
void decode_with_regions(const FftFile& file, const Regions& regions, std::uint64_t begin, std::uint64_t end,
                         const std::optional<std::vector<std::uint64_t>>& indices, unsigned threads,
                         std::optional<DecodedRange>& range, Streamlines& s, std::vector<std::uint64_t>& ids) {
    ids.clear();
    if (indices ? indices->empty() : begin >= end) return;
    Query q;
    q.include = regions.include, q.exclude = regions.exclude;
    const std::vector<FiberRange> candidates = indices ? ranges_of(*indices) : std::vector<FiberRange>{{begin, end - 1}};
    // Deciding the fibers from the index and their blocks' anchors on all
    // threads, then decoding the kept ones, or select()'s passes on one:
    // the library's rule.
    const FiberRegionTest test(file, *block_index_of(file), q);
    if (test.kept_fibers_is_faster(threads)) {
        range = decode_kept(file, test, candidates, threads, ids);
    } else {
        s = select_by_regions(file, q, candidates, ids);
    }
    if (!indices) return;
    // The kept fibers in the order (and with the repeats) asked for.
    std::vector<std::uint64_t> position(file.header().fibers, UINT64_MAX), want, order;
    for (std::size_t i = 0; i < ids.size(); ++i) position[ids[i]] = i;
    for (const std::uint64_t f : *indices)
        if (position[f] != UINT64_MAX) want.push_back(f), order.push_back(position[f]);
    if (want != ids) {
        s = gather_fibers(range ? FibersView{range->xyz.as<const float>(), range->offsets} : view_of(s), order);
        range.reset();
    }
    ids = std::move(want);
}

// Decodes a file (all fibers, [begin, end), or a list of indices), keeps the
// fibers the regions select, and returns (points (N,3) float32, offsets
// (F+1) int64, fiber_ids (F) int64). A range without regions, the common
// case, is decoded straight into the memory numpy gets (decode_range).
py::tuple decode(const std::string& path, std::uint64_t begin, std::optional<std::uint64_t> end,
                 const py::object& indices_or_none, const py::list& regions_list, unsigned threads,
                 bool ignore_trailer) {
    const Regions regions = parse_regions(regions_list);
    std::optional<std::vector<std::uint64_t>> indices;
    if (!indices_or_none.is_none()) {
        const auto a = py::array_t<std::uint64_t, py::array::c_style | py::array::forcecast>::ensure(indices_or_none);
        if (!a || a.ndim() != 1) throw Error(Errc::invalid_argument, "fiber indices must be a 1-D integer array");
        indices.emplace(a.data(), a.data() + a.shape(0));
    }
    std::optional<DecodedRange> range;  // the result, when decoded as a range
    Streamlines s;                      // else this
    std::vector<std::uint64_t> ids;
    {
        py::gil_scoped_release release;
        const FftFile file(path, {.ignore_trailer = ignore_trailer});
        const std::uint64_t nfibers = file.header().fibers;
        if (indices) {
            for (std::uint64_t f : *indices)
                if (f >= nfibers)
                    throw Error(Errc::invalid_argument, path + ": fiber " + std::to_string(f) + " out of range (" +
                                                            std::to_string(nfibers) + " fibers)");
        }
        const std::uint64_t e = std::min(end.value_or(nfibers), nfibers);
        if (!regions.empty()) {
            decode_with_regions(file, regions, begin, e, indices, threads, range, s, ids);
        } else if (indices) {
            s = decode_indices(file, *indices, decode_options(threads));
            ids = std::move(*indices);
        } else {
            range = decode_range(file, begin, e, threads);
            ids.resize(range->offsets.size() - 1);
            std::iota(ids.begin(), ids.end(), begin);
        }
    }
    const auto fibers = py::ssize_t(ids.size());
    const auto points = py::ssize_t(range ? range->points : s.point_count());
    py::array_t<float> xyz = range ? to_numpy<float>(std::move(range->xyz), {points, 3})
                                   : to_numpy<float>(std::move(s.xyz), {points, 3});
    return py::make_tuple(xyz, to_numpy<std::int64_t>(range ? std::move(range->offsets) : std::move(s.offsets), {fibers + 1}),
                          to_numpy<std::int64_t>(std::move(ids), {fibers}));
}

py::dict header_dict(const FftFile& f) {
    const FftHeader& h = f.header();
    py::dict d;
    d["fibers"] = h.fibers, d["points"] = h.points, d["blocks"] = h.blocks;
    d["points_per_block"] = h.points_per_block, d["block_bytes"] = h.block_bytes();
    d["step_mm"] = double(h.step) * double(h.scaling), d["cap_ratio"] = h.ratio;
    d["scaling_mm"] = h.scaling, d["offset_mm"] = py::make_tuple(h.offset[0], h.offset[1], h.offset[2]);
    d["max_error_um"] = double(h.max_error_mm) * 1e3, d["mean_error_um"] = double(h.mean_error_mm) * 1e3;
    d["file_bytes"] = f.file_size();
    d["resampled"] = f.resampled_step_mm().has_value();
    d["properties"] = f.properties();
    return d;
}

py::dict info(const std::string& path, bool ignore_trailer) {
    return header_dict(FftFile(path, {.ignore_trailer = ignore_trailer}));
}

py::dict error_dict(const ErrorStats& e) {
    py::dict d;
    d["max_um"] = e.max_mm() * 1e3, d["mean_um"] = e.mean_mm() * 1e3, d["rms_um"] = e.rms_mm() * 1e3;
    d["p50_um"] = e.percentile_mm(50) * 1e3, d["p95_um"] = e.percentile_mm(95) * 1e3;
    d["p99_um"] = e.percentile_mm(99) * 1e3, d["worst_fiber"] = e.worst_fiber(), d["points"] = e.count();
    return d;
}

// Same keys as the "geometry" object of `fiblet stats --json`
// (fiblet/geometry_error.hpp; apps/fiblet/geometry_report.cpp).
py::dict geometry_dict(const GeometryError& g) {
    auto fiber_max = [](const FiberMax& m) {
        py::dict d;
        d["max_um"] = m.max * 1e3, d["mean_um"] = m.mean() * 1e3, d["worst_fiber"] = m.worst_fiber;
        return d;
    };
    py::dict length;
    length["max_um"] = g.length_change_mm().max * 1e3, length["mean_um"] = g.length_change_mm().mean() * 1e3;
    length["mean_signed_um"] = g.mean_length_change_mm() * 1e3;
    length["max_percent"] = g.length_change_percent().max, length["mean_percent"] = g.length_change_percent().mean();
    length["worst_fiber"] = g.length_change_mm().worst_fiber;
    py::dict d;
    d["decoded_to_input"] = error_dict(g.decoded_to_input()), d["input_to_decoded"] = error_dict(g.input_to_decoded());
    d["hausdorff_um"] = g.hausdorff_mm() * 1e3, d["hausdorff_fiber"] = g.hausdorff_fiber();
    d["endpoint"] = fiber_max(g.endpoint_mm()), d["length_change"] = length;
    return d;
}

// Same keys as `fiblet stats --json`.
py::dict stats(const std::string& fft_path, const std::string& reference) {
    std::optional<FftFile> file;
    Comparison c;
    {
        py::gil_scoped_release release;
        file.emplace(fft_path);
        c = compare_to_reference(*file, reference);
    }
    const FftHeader& h = file->header();
    py::dict d;
    d["file"] = fft_path, d["reference"] = reference;
    d["fibers"] = c.fibers, d["points"] = c.points, d["blocks"] = c.blocks;
    d["fft_bytes"] = c.fft_bytes, d["reference_bytes"] = c.reference_bytes;
    d["ratio"] = c.fft_bytes ? double(c.reference_bytes) / double(c.fft_bytes) : 0.0;
    d["bytes_per_point"] = c.points ? double(c.fft_bytes) / double(c.points) : 0.0;
    d["resampled"] = c.resampled;
    d["error"] = error_dict(c.error);
    if (c.resampled) d["error_vs_original"] = error_dict(c.error_vs_original);
    d["geometry"] = geometry_dict(c.geometry);
    d["header_max_error_um"] = double(h.max_error_mm) * 1e3, d["header_mean_error_um"] = double(h.mean_error_mm) * 1e3;
    return d;
}

// Same keys as `fiblet compress --json`.
// zstd: the seekable zstd container (.fftz) with the defaults of `fiblet compress --zstd`.
py::dict compress(const std::string& tck_path, const std::string& fft_path, std::optional<double> step_mm,
                  bool overwrite, unsigned threads, bool zstd, std::uint64_t max_memory, bool fine_index) {
    CompressOptions o;
    o.step_mm = step_mm, o.overwrite = overwrite, o.threads = threads, o.max_memory = max_memory;
    o.index_format = fine_index ? BlockIndexFormat::block_boxes : kDefaultBlockIndexFormat;
    if (zstd) o.zstd = ZstdOptions{};
    CompressReport r;
    {
        py::gil_scoped_release release;
        r = compress_file(tck_path, fft_path, o);
    }
    py::dict d;
    d["input"] = tck_path, d["output"] = fft_path;
    d["fibers"] = r.header.fibers, d["points"] = r.header.points, d["blocks"] = r.header.blocks;
    d["input_bytes"] = r.input_bytes, d["output_bytes"] = r.output_bytes;
    d["ratio"] = r.output_bytes ? double(r.input_bytes) / double(r.output_bytes) : 0.0;
    d["step_mm"] = r.step_mm, d["step_scale"] = r.step_scale, d["cap_ratio"] = r.header.ratio, d["resampled"] = r.resampled;
    d["direction_bits"] = r.header.direction_bits();
    d["bits_automatic"] = r.bits.automatic, d["bits_reason"] = r.bits.reason;
    if (r.bits.sample_fibers)
        d["bits_sample_length_change_max_um"] = r.bits.length_change_max_mm * 1e3,
        d["bits_sample_max_error_um"] = r.bits.point_error_max_mm * 1e3;
    d["max_error_um"] = r.error.max_mm() * 1e3, d["mean_error_um"] = r.error.mean_mm() * 1e3;
    if (r.resampled)
        d["max_error_vs_original_um"] = r.error_vs_original.max_mm() * 1e3,
        d["mean_error_vs_original_um"] = r.error_vs_original.mean_mm() * 1e3;
    d["geometry"] = geometry_dict(r.geometry);
    d["seconds"] = r.seconds, d["simd"] = r.simd;
    py::dict timings;
    for (const auto& [stage, seconds] : r.timings.stages()) timings[stage] = seconds;
    d["timings"] = timings;
    return d;
}

// Writes streamlines given as points (N,3) float32 and offsets (F+1) to a
// .tck, .trk or .trx file (atomically, through the library's sinks).
void write_streamlines_array(const std::string& path,
                             py::array_t<float, py::array::c_style | py::array::forcecast> points,
                             py::array_t<std::int64_t, py::array::c_style | py::array::forcecast> offsets,
                             const std::vector<std::pair<std::string, std::string>>& properties, bool overwrite) {
    if (points.ndim() != 2 || points.shape(1) != 3) throw Error(Errc::invalid_argument, "points must be an (N, 3) array");
    if (offsets.ndim() != 1 || offsets.shape(0) < 1) throw Error(Errc::invalid_argument, "offsets must be 1-D, F+1 long");
    const std::span<const std::int64_t> off(offsets.data(), std::size_t(offsets.shape(0)));
    const auto n_points = std::int64_t(points.shape(0));
    if (off.front() != 0 || off.back() != n_points)
        throw Error(Errc::invalid_argument, "offsets must start at 0 and end at the number of points");
    for (std::size_t i = 1; i < off.size(); ++i)
        if (off[i] < off[i - 1]) throw Error(Errc::invalid_argument, "offsets must not decrease");
    py::gil_scoped_release release;
    write_streamlines(path, points.data(), off, properties, overwrite);
}

// A .tck, .trk or TRX file rewritten as another of them: {fibers, points, fields_dropped}.
py::dict convert(const std::string& input, const std::string& output, bool overwrite) {
    Conversion c;
    {
        py::gil_scoped_release release;
        c = convert_streamlines(input, output, overwrite);
    }
    py::dict d;
    d["fibers"] = c.fibers, d["points"] = c.points, d["fields_dropped"] = c.fields_dropped;
    return d;
}

// Reads a .tck, .trk or TRX file through the same readers as compress:
// points (N, 3) float32 in RAS+ mm, offsets (F+1), fields {name: (rows,
// components) array}, header properties, format name.
py::dict read_streamlines(const std::string& path) {
    std::vector<float> xyz;
    std::vector<std::int64_t> offsets{0};
    std::vector<StreamlineField> fields;
    Properties properties;
    TractogramFormat format;
    {
        py::gil_scoped_release release;
        const auto source = open_streamline_source(path);
        std::vector<Vec3f> fiber;
        while (source->next(fiber)) {
            for (const Vec3f& p : fiber) xyz.insert(xyz.end(), {p.x, p.y, p.z});
            offsets.push_back(offsets.back() + std::int64_t(fiber.size()));
        }
        fields = source->take_fields();
        properties = source->properties();
        format = source->format();
    }
    py::dict d, data;
    const auto n = py::ssize_t(xyz.size() / 3);
    d["points"] = to_numpy<float>(std::move(xyz), {n, 3});
    const auto f = py::ssize_t(offsets.size());
    d["offsets"] = to_numpy<std::int64_t>(std::move(offsets), {f});
    for (const StreamlineField& field : fields) data[py::str(field.name)] = field_array(field);
    d["data"] = data;
    d["properties"] = properties;
    d["format"] = format == TractogramFormat::tck ? "tck" : format == TractogramFormat::trk ? "trk" : "trx";
    return d;
}

// What a .fft carries besides its points (file_data.hpp); with fiber_points,
// each fiber's point count, from the block index roi= uses (cached).
py::dict data(const std::string& path, bool fiber_points) {
    std::optional<FftFile> file;
    std::shared_ptr<const BlockIndex> index;
    {
        py::gil_scoped_release release;
        file.emplace(path);
        if (fiber_points) index = block_index_of(*file);
    }
    return file_data(*file, index.get());
}

// "fft", "fftz" or "other": what fiblet.read_streamlines decodes itself.
const char* container_of(const std::string& path) {
    const TractogramFormat f = detect_tractogram_format(path);
    return f == TractogramFormat::fft ? "fft" : f == TractogramFormat::fftz ? "fftz" : "other";
}

}  // namespace
}  // namespace fiblet::python

PYBIND11_MODULE(_fiblet, m) {
    using namespace fiblet::python;
    m.doc() = "fiblet's compiled core; use the `fiblet` package instead.";
    m.attr("version") = FIBLET_VERSION;

    // fiblet::Error -> fiblet.FibletError, with the stable category name
    // (errc_name: "io", "fft_format", ...) as its `category` attribute.
    static py::exception<fiblet::Error> error_type(m, "FibletError", PyExc_RuntimeError);
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const fiblet::Error& e) {
            // The option that would have allowed it, as Python's keyword names it.
            std::string message = e.what();
            if (e.remedy() == fiblet::Remedy::overwrite) message += " (overwrite=True replaces it)";
            if (e.remedy() == fiblet::Remedy::ignore_trailer) message += "; ignore_trailer=True reads the blocks without it";
            if (e.remedy() == fiblet::Remedy::max_memory) message += "; max_memory= (bytes) raises the budget";
            py::object instance = py::reinterpret_borrow<py::object>(error_type.ptr())(message);
            instance.attr("category") = fiblet::errc_name(e.code());
            PyErr_SetObject(error_type.ptr(), instance.ptr());
        }
    });

    m.def("decode", &decode, py::arg("path"), py::arg("begin"), py::arg("end"), py::arg("indices"),
          py::arg("regions"), py::arg("threads"), py::arg("ignore_trailer"));
    m.def("info", &info, py::arg("path"), py::arg("ignore_trailer"));
    m.def("stats", &stats, py::arg("fft"), py::arg("reference"));
    m.def("compress", &compress, py::arg("tck"), py::arg("fft"), py::arg("step_mm"), py::arg("overwrite"),
          py::arg("threads"), py::arg("zstd"), py::arg("max_memory"), py::arg("fine_index"));
    m.def("read_streamlines", &read_streamlines, py::arg("path"));
    m.def("data", &data, py::arg("path"), py::arg("fiber_points"));
    m.def("container", &container_of, py::arg("path"));
    m.def("write_streamlines", &write_streamlines_array, py::arg("path"), py::arg("points"), py::arg("offsets"),
          py::arg("properties"), py::arg("overwrite"));
    m.def("convert", &convert, py::arg("input"), py::arg("output"), py::arg("overwrite"));
}
