#include "geometry_report.hpp"

#include <fmt/core.h>

#include "cli_common.hpp"

namespace fiblet::cli {

std::string distances_json(const ErrorStats& e) {
    return Json{}
        .num("max_um", e.max_mm() * 1e3)
        .num("mean_um", e.mean_mm() * 1e3)
        .num("rms_um", e.rms_mm() * 1e3)
        .num("p50_um", e.percentile_mm(50) * 1e3)
        .num("p95_um", e.percentile_mm(95) * 1e3)
        .num("p99_um", e.percentile_mm(99) * 1e3)
        .integer("worst_fiber", e.worst_fiber())
        .integer("points", e.count())
        .render();
}

namespace {

std::string fiber_max_json(const FiberMax& m, double scale, const char* unit) {
    return Json{}
        .num(std::string("max_") + unit, m.max * scale)
        .num(std::string("mean_") + unit, m.mean() * scale)
        .integer("worst_fiber", m.worst_fiber)
        .render();
}

void print_distances(const std::string& label, const ErrorStats& e) {
    fmt::print("{:<24}max {:.3f}  mean {:.3f}  rms {:.3f}  p50 {:.2f}  p95 {:.2f}  p99 {:.2f}  (worst fiber {})\n",
               label, e.max_mm() * 1e3, e.mean_mm() * 1e3, e.rms_mm() * 1e3, e.percentile_mm(50) * 1e3,
               e.percentile_mm(95) * 1e3, e.percentile_mm(99) * 1e3, e.worst_fiber());
}

}  // namespace

std::string geometry_json(const GeometryError& g) {
    return Json{}
        .raw("decoded_to_input", distances_json(g.decoded_to_input()))
        .raw("input_to_decoded", distances_json(g.input_to_decoded()))
        .num("hausdorff_um", g.hausdorff_mm() * 1e3)
        .integer("hausdorff_fiber", g.hausdorff_fiber())
        .raw("endpoint", fiber_max_json(g.endpoint_mm(), 1e3, "um"))
        .raw("length_change", Json{}
                                  .num("max_um", g.length_change_mm().max * 1e3)
                                  .num("mean_um", g.length_change_mm().mean() * 1e3)
                                  .num("mean_signed_um", g.mean_length_change_mm() * 1e3)
                                  .num("max_percent", g.length_change_percent().max)
                                  .num("mean_percent", g.length_change_percent().mean())
                                  .integer("worst_fiber", g.length_change_mm().worst_fiber)
                                  .render())
        .render();
}

void print_geometry(const GeometryError& g, const std::string& indent) {
    print_distances(indent + "decoded -> input", g.decoded_to_input());
    print_distances(indent + "input -> decoded", g.input_to_decoded());
    fmt::print("{}{:<22}max {:.3f}  (fiber {})\n", indent, "Hausdorff", g.hausdorff_mm() * 1e3, g.hausdorff_fiber());
    fmt::print("{}{:<22}max {:.3f}  mean {:.3f}  (worst fiber {})\n", indent, "endpoints moved",
               g.endpoint_mm().max * 1e3, g.endpoint_mm().mean() * 1e3, g.endpoint_mm().worst_fiber);
    fmt::print("{}{:<22}max {:.3f} ({:.4f} %)  mean {:.3f} ({:.4f} %), signed mean {:+.3f}  (worst fiber {})\n",
               indent, "length change", g.length_change_mm().max * 1e3, g.length_change_percent().max,
               g.length_change_mm().mean() * 1e3, g.length_change_percent().mean(), g.mean_length_change_mm() * 1e3,
               g.length_change_mm().worst_fiber);
}

void print_geometry_brief(const GeometryError& g, const std::string& indent) {
    fmt::print("{}vs input polylines, both ways: Hausdorff {:.2f} µm; decoded -> input mean {:.2f} µm, "
               "input -> decoded mean {:.2f} µm\n",
               indent, g.hausdorff_mm() * 1e3, g.decoded_to_input().mean_mm() * 1e3,
               g.input_to_decoded().mean_mm() * 1e3);
    fmt::print("{}endpoints moved: max {:.2f} µm, mean {:.2f} µm; length change: max {:.2f} µm ({:.4f} %), "
               "mean {:.2f} µm ({:.4f} %)\n",
               indent, g.endpoint_mm().max * 1e3, g.endpoint_mm().mean() * 1e3, g.length_change_mm().max * 1e3,
               g.length_change_percent().max, g.length_change_mm().mean() * 1e3, g.length_change_percent().mean());
}

std::vector<std::string> metrics_above(const ErrorStats& point_error, const GeometryError& g, double max_um) {
    std::vector<std::string> above;
    auto check = [&](const char* name, double mm) {
        if (!(mm * 1e3 <= max_um)) above.push_back(fmt::format("{} {:.3f} µm", name, mm * 1e3));
    };
    check("point error", point_error.max_mm());
    check("Hausdorff", g.hausdorff_mm());
    check("endpoint", g.endpoint_mm().max);
    check("length change", g.length_change_mm().max);
    return above;
}

void check_error_bound(const std::string& what, const ErrorStats& point_error, const GeometryError& g,
                       std::optional<double> max_um) {
    if (!max_um) return;
    const std::vector<std::string> above = metrics_above(point_error, g, *max_um);
    if (above.empty()) return;
    std::string list;
    for (const std::string& a : above) list += (list.empty() ? "" : ", ") + a;
    throw ErrorBoundExceeded(fmt::format("{}: above --max-error {} µm: {}", what, *max_um, list));
}

}  // namespace fiblet::cli
