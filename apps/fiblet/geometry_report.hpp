// The symmetric error metrics (fiblet/geometry_error.hpp) as `compress` and
// `stats` print them, and the --max-error check both share.
#pragma once

#include <cstdio>

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "fiblet/error_stats.hpp"
#include "fiblet/geometry_error.hpp"

namespace fiblet::cli {

// JSON object of distance statistics (µm): max, mean, rms, p50/p95/p99.
std::string distances_json(const ErrorStats& e);
// JSON object of every metric (distances in µm, length change in µm and %).
std::string geometry_json(const GeometryError& g);
// One row of distance statistics in µm after a label padded to 22
// characters (the tables of `stats`).
void print_distances(const std::string& label, const ErrorStats& e);
// Text lines, each starting with `indent`.
void print_geometry(const GeometryError& g, const std::string& indent);
// Compact one-line-per-metric form for compress.
void print_geometry_brief(const GeometryError& g, const std::string& indent, std::FILE* to = stdout);

// The metrics above `max_um`: "point error", "Hausdorff", "endpoint",
// "length change" with their values; empty when all are within it.
std::vector<std::string> metrics_above(const ErrorStats& point_error, const GeometryError& g, double max_um);

// Thrown after the report is printed when a metric exceeds --max-error
// (exit code kErrorBound).
struct ErrorBoundExceeded : std::runtime_error {
    using std::runtime_error::runtime_error;
};
// Throws ErrorBoundExceeded naming `what` and the metrics above the bound.
void check_error_bound(const std::string& what, const ErrorStats& point_error, const GeometryError& g,
                       std::optional<double> max_um);

}  // namespace fiblet::cli
