#include "geometry_report.hpp"

#include <fmt/core.h>

#include <cmath>

#include "cli_common.hpp"

namespace fiblet::cli {

namespace {

// A percentile is the edge of a 0.01 µm bin (or the max): in µm, a number of
// hundredths, printed as such (4.5, not the 4.500000000000001 of mm * 1e3).
double percentile_um(const ErrorStats& e, double p) {
    const double mm = e.percentile_mm(p);
    return mm == e.max_mm() ? mm * 1e3 : std::round(mm * 1e5) / 100.0;
}

}  // namespace

std::string distances_json(const ErrorStats& e) {
    return Json{}
        .num("max_um", e.max_mm() * 1e3)
        .num("mean_um", e.mean_mm() * 1e3)
        .num("rms_um", e.rms_mm() * 1e3)
        .num("p50_um", percentile_um(e, 50))
        .num("p95_um", percentile_um(e, 95))
        .num("p99_um", percentile_um(e, 99))
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

}  // namespace

void print_distances(const std::string& label, const ErrorStats& e) {
    fmt::print("{:<22} max {}  mean {}  rms {}  p50 {}  p95 {}  p99 {}  (worst fiber {})\n", label,
               micrometres_value(e.max_mm(), 3), micrometres_value(e.mean_mm(), 3), micrometres_value(e.rms_mm(), 3),
               micrometres_value(e.percentile_mm(50)), micrometres_value(e.percentile_mm(95)),
               micrometres_value(e.percentile_mm(99)), e.worst_fiber());
}

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
    fmt::print("{:<22} max {}  (fiber {})\n", indent + "Hausdorff", micrometres_value(g.hausdorff_mm(), 3),
               g.hausdorff_fiber());
    fmt::print("{:<22} max {}  mean {}  (worst fiber {})\n", indent + "endpoints moved",
               micrometres_value(g.endpoint_mm().max, 3), micrometres_value(g.endpoint_mm().mean(), 3),
               g.endpoint_mm().worst_fiber);
    const double signed_mm = g.mean_length_change_mm();
    fmt::print("{:<22} max {} ({:.4f} %)  mean {} ({:.4f} %), signed mean {}{}  (worst fiber {})\n",
               indent + "length change", micrometres_value(g.length_change_mm().max, 3), g.length_change_percent().max,
               micrometres_value(g.length_change_mm().mean(), 3), g.length_change_percent().mean(),
               signed_mm < 0 ? "-" : "+", micrometres_value(std::fabs(signed_mm), 3), g.length_change_mm().worst_fiber);
}

void print_geometry_brief(const GeometryError& g, const std::string& indent, std::FILE* to) {
    fmt::print(to, "{}vs input polylines, both ways: Hausdorff {}; decoded -> input mean {}, input -> decoded mean {}\n",
               indent, micrometres(g.hausdorff_mm()), micrometres(g.decoded_to_input().mean_mm()),
               micrometres(g.input_to_decoded().mean_mm()));
    fmt::print(to, "{}endpoints moved: max {}, mean {}; length change: max {} ({:.4f} %), mean {} ({:.4f} %)\n", indent,
               micrometres(g.endpoint_mm().max), micrometres(g.endpoint_mm().mean()),
               micrometres(g.length_change_mm().max), g.length_change_percent().max,
               micrometres(g.length_change_mm().mean()), g.length_change_percent().mean());
}

std::vector<std::string> metrics_above(const ErrorStats& point_error, const GeometryError& g, double max_um) {
    std::vector<std::string> above;
    auto check = [&](const char* name, double mm) {
        if (!(mm * 1e3 <= max_um)) above.push_back(fmt::format("{} {}", name, micrometres(mm, 3)));
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
