// Internal: sums of many doubles in four running sums (v[i] in sum i % 4,
// then (s0 + s1) + (s2 + s3)): four independent chains of additions, where
// one chain waits an addition's latency per term. The same bits at every
// SIMD level (the order is fixed), not those of one running sum.
#pragma once

#include <cstddef>

namespace fiblet::detail {

inline double sum_in_four_lanes(const double* v, std::size_t n) {
    double s[4] = {0, 0, 0, 0};
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4)
        for (int j = 0; j < 4; ++j) s[j] += v[i + j];
    for (int j = 0; i < n; ++i, ++j) s[j] += v[i];
    return (s[0] + s[1]) + (s[2] + s[3]);
}

}  // namespace fiblet::detail
