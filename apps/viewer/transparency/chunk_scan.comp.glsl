#version 450
// Sorted transparency, step 3: the histogram (bucket-major, then lane)
// becomes each (bucket, lane)'s first place in the sorted order: an
// exclusive prefix sum, by one workgroup (each invocation a contiguous run,
// a scan of the runs' totals in shared memory).
layout(local_size_x = 1024) in;

layout(std430, binding = BINDING_CHUNK_HISTOGRAM) buffer Histogram { uint histogram[]; };

uniform uint uSize;

shared uint sTotals[1024];

void main() {
    uint t = gl_LocalInvocationIndex;
    uint per = (uSize + 1023u) / 1024u;
    uint begin = min(t * per, uSize), end = min(begin + per, uSize);
    uint sum = 0u;
    for (uint i = begin; i < end; ++i) sum += histogram[i];
    sTotals[t] = sum;
    barrier();
    for (uint d = 1u; d < 1024u; d <<= 1) {
        uint before = t >= d ? sTotals[t - d] : 0u;
        barrier();
        sTotals[t] += before;
        barrier();
    }
    uint offset = sTotals[t] - sum;
    for (uint i = begin; i < end; ++i) {
        uint count = histogram[i];
        histogram[i] = offset;
        offset += count;
    }
}
