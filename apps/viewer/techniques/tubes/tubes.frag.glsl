#version 450
// Ray casting of one tube piece (Russig, Salm and Gumhold 2020): the union
// of the spheres of radius r(t) centred on the quadratic Bézier q(t), t in
// [0, 1]. In ray space (the ray along +x from a point near the piece,
// lengths in units of the largest radius) the ray enters sphere t at
// f(t) = x(t) - sqrt(g(t)), g = r² - y² - z², wherever g >= 0. The first hit
// is the least f: at t = 0, t = 1 or where f' = 0, i.e. 2 x' sqrt(g) = g',
// whose squared form h = 4 x'² g - g'² is a polynomial of degree 6. Its
// roots in [0, 1] are isolated through its derivatives (the roots of each
// derivative split [0, 1] into intervals where the polynomial above is
// monotonic) and refined by safeguarded Newton–bisection, so no root is
// skipped and none is left half-converged (the paper's joint artefacts).
// Writes the hit's depth, Lambert + Blinn-Phong shading, and the fiber.
#include "tube_piece.glsl"
#include "surface_shading.glsl"
#include "slab_clip.glsl"
#include "occlusion_lookup.glsl"

layout(std430, binding = BINDING_TUBE_PIECES) readonly buffer Pieces { TubePiece pieces[]; };

layout(location = 0) flat in uint vPiece;
layout(location = 1) in vec3 vWorld;

layout(location = 0) out vec4 outColor;
layout(location = 1) out uint outFiber;
// Front faces are drawn: the hit lies behind them.
layout(depth_greater) out float gl_FragDepth;

// h and its derivatives, ascending powers: derivative k (degree 6 - k)
// starts at kOffset[k].
const int kOffset[7] = int[7](0, 7, 13, 18, 22, 25, 27);
float gPoly[28];

// x(t) and g(t) in ascending powers, for h and h' in factored form near the
// roots that decide the hit (the expanded coefficients can cancel there;
// the test scene agrees with the oracle either way).
vec3 gX;
float gG[5];

float evalLevel(int k, float t) {
    if (k <= 1) {
        float xp = 2.0 * gX.x * t + gX.y, xpp = 2.0 * gX.x;
        float g = (((gG[4] * t + gG[3]) * t + gG[2]) * t + gG[1]) * t + gG[0];
        float gp = ((4.0 * gG[4] * t + 3.0 * gG[3]) * t + 2.0 * gG[2]) * t + gG[1];
        float gpp = (12.0 * gG[4] * t + 6.0 * gG[3]) * t + 2.0 * gG[2];
        return k == 0 ? 4.0 * xp * xp * g - gp * gp : 8.0 * xp * xpp * g + 4.0 * xp * xp * gp - 2.0 * gp * gpp;
    }
    int off = kOffset[k];
    float v = 0.0;
    for (int i = 6 - k; i >= 0; --i) v = v * t + gPoly[off + i];
    return v;
}

// The root of derivative k in [a, b], where its values at a and b differ
// in sign: Newton steps, bisection whenever a step leaves the bracket.
float refineRoot(int k, float a, float b, float fa) {
    float t = 0.5 * (a + b);
    for (int it = 0; it < 40; ++it) {
        float f = evalLevel(k, t);
        if (f == 0.0) return t;
        if ((f < 0.0) == (fa < 0.0)) {
            a = t, fa = f;
        } else {
            b = t;
        }
        float df = evalLevel(k + 1, t);
        float next = df != 0.0 ? t - f / df : a - 1.0;
        if (!(next > a && next < b)) next = 0.5 * (a + b);
        if (abs(next - t) <= 1e-7 || b - a <= 1e-7) return next;
        t = next;
    }
    return t;
}

// Roots of h in (0, 1), ascending; returns how many.
int rootsOfH(out float roots[6]) {
    float prev[6];
    int count = 0;
    float c0 = gPoly[kOffset[5]], c1 = gPoly[kOffset[5] + 1];  // h^(5), linear
    if (c1 != 0.0) {
        float t = -c0 / c1;
        if (t > 0.0 && t < 1.0) prev[count++] = t;
    }
    for (int k = 4; k >= 0; --k) {
        float cur[6];
        int found = 0;
        float a = 0.0, fa = evalLevel(k, 0.0);
        for (int i = 0; i <= count; ++i) {
            float b = i < count ? prev[i] : 1.0;
            float fb = evalLevel(k, b);
            if ((fa < 0.0) != (fb < 0.0) && found < 6) cur[found++] = refineRoot(k, a, b, fa);
            a = b, fa = fb;
        }
        prev = cur;
        count = found;
    }
    roots = prev;
    return count;
}

// Power-basis coefficients (t², t, 1) of a quadratic Bézier coordinate.
vec3 power(float b0, float b1, float b2) { return vec3(b0 - 2.0 * b1 + b2, 2.0 * (b1 - b0), b0); }

// (p2 t² + p1 t + p0)²: coefficients of t^0..t^4.
float[5] square(vec3 p) {
    return float[5](p.z * p.z, 2.0 * p.y * p.z, p.y * p.y + 2.0 * p.x * p.z, 2.0 * p.x * p.y, p.x * p.x);
}

// Distance from the origin to the triangle a, b, c (2D).
float distanceToTriangle(vec2 a, vec2 b, vec2 c) {
    float ab = (b.x - a.x) * (-a.y) - (b.y - a.y) * (-a.x), bc = (c.x - b.x) * (-b.y) - (c.y - b.y) * (-b.x),
          ca = (a.x - c.x) * (-c.y) - (a.y - c.y) * (-c.x);
    if ((ab >= 0.0 && bc >= 0.0 && ca >= 0.0) || (ab <= 0.0 && bc <= 0.0 && ca <= 0.0)) return 0.0;
    vec2 e[3] = vec2[3](b - a, c - b, a - c), p[3] = vec2[3](a, b, c);
    float d = 1e30;
    for (int i = 0; i < 3; ++i) {
        float len2 = dot(e[i], e[i]);
        float t = len2 > 0.0 ? clamp(-dot(p[i], e[i]) / len2, 0.0, 1.0) : 0.0;
        d = min(d, length(p[i] + t * e[i]));
    }
    return d;
}

void main() {
    TubePiece q = pieces[vPiece];
    vec3 dir = normalize(vWorld - uCameraPosition);
    // Ray space: origin at the box centre's projection on the ray.
    float along = dot(q.center.xyz - uCameraPosition, dir);
    vec3 origin = uCameraPosition + along * dir;
    vec3 ey = normalize(cross(dir, abs(dir.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0)));
    vec3 ez = cross(dir, ey);
    float unit = max(max(q.c0.w, q.c1.w), q.c2.w);
    mat3 toRay = transpose(mat3(dir, ey, ez)) * (1.0 / unit);
    vec3 b0 = toRay * (q.c0.xyz - origin), b1 = toRay * (q.c1.xyz - origin), b2 = toRay * (q.c2.xyz - origin);
    // The curve lies in its control triangle: a ray farther from it than
    // the largest radius (1 here) misses, before any root finding.
    if (distanceToTriangle(b0.yz, b1.yz, b2.yz) > 1.0) discard;
    vec3 X = power(b0.x, b1.x, b2.x), Y = power(b0.y, b1.y, b2.y), Z = power(b0.z, b1.z, b2.z);
    vec3 R = power(q.c0.w / unit, q.c1.w / unit, q.c2.w / unit);

    float r2[5] = square(R), y2[5] = square(Y), z2[5] = square(Z);
    float g[5];
    for (int i = 0; i < 5; ++i) g[i] = r2[i] - y2[i] - z2[i];
    float gp[4] = float[4](g[1], 2.0 * g[2], 3.0 * g[3], 4.0 * g[4]);
    float xp2[3] = float[3](X.y * X.y, 4.0 * X.x * X.y, 4.0 * X.x * X.x);  // x'²
    for (int i = 0; i < 7; ++i) gPoly[i] = 0.0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 5; ++j) gPoly[i + j] += 4.0 * xp2[i] * g[j];
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) gPoly[i + j] -= gp[i] * gp[j];
    for (int k = 1; k < 7; ++k)
        for (int i = 0; i <= 6 - k; ++i) gPoly[kOffset[k] + i] = float(i + 1) * gPoly[kOffset[k - 1] + i + 1];

    gX = X, gG = g;
    float roots[6];
    int n = rootsOfH(roots);
    float best = 1e30, bestT = -1.0;
    for (int i = -2; i < n; ++i) {
        float t = i == -2 ? 0.0 : i == -1 ? 1.0 : roots[i];
        float gt = ((((g[4] * t + g[3]) * t + g[2]) * t + g[1]) * t + g[0]);
        if (gt < 0.0) continue;
        float f = dot(X, vec3(t * t, t, 1.0)) - sqrt(gt);
        if (f < best && along + f * unit > 0.0) best = f, bestT = t;
    }
    if (bestT < 0.0) discard;

    vec3 hit = origin + best * unit * dir;
    if (outsideSlab(hit)) discard;
    gl_FragDepth = windowDepth(hit);

    float t = bestT;
    vec3 centre = (1.0 - t) * (1.0 - t) * q.c0.xyz + 2.0 * t * (1.0 - t) * q.c1.xyz + t * t * q.c2.xyz;
    vec3 normal = normalize(hit - centre);
    vec3 tangent = 2.0 * (1.0 - t) * (q.c1.xyz - q.c0.xyz) + 2.0 * t * (q.c2.xyz - q.c1.xyz);
    uint fiber = floatBitsToUint(q.center.w);
    float value = t < 0.5 ? mix(q.values.x, q.values.y, 2.0 * t) : mix(q.values.y, q.values.z, 2.0 * t - 1.0);
    outColor = vec4(shadeSurface(normal, tangent, -dir, fiber, value) * (1.0 - rasterOcclusion(hit, normal)), fiberAlpha(fiber));
    outFiber = fiber + 1u;
}
