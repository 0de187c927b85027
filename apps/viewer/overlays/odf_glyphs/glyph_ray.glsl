// traceGlyph of glyph_ray.hpp in float (the same steps). Needs sh_basis.glsl
// and polynomial_roots.glsl included first.
const int kMaxLmax = 12;
uniform int uLmax;
// glyph_inverse_vandermonde(uLmax), row-major (uLmax + 1)².
uniform float uInverseVandermonde[(kMaxLmax + 1) * (kMaxLmax + 1)];
uniform float uTraceRadius;  // kGlyphTraceRadius

float powi(float x, int n) {
    float r = 1.0;
    for (int i = 0; i < n; ++i) r *= x;
    return r;
}

// glyph_normal of glyph_ray.hpp: −∇F at x ≠ 0 in closed form, normalized
// (the zero vector at x = 0).
vec3 glyphNormal(uint base, int k, vec3 x) {
    float r = length(x);
    if (!(r > 0.0)) return vec3(0.0);
    vec3 u = x / r, g;
    float f = shValueAndGradient(base, k, u, g);
    vec3 n = (float(k + 1) * r * r - float(k) * f * f) * u - f * g;
    float len = length(n);
    return len > 0.0 ? n / len : n;
}

// First hit of o + t d (unit d, glyph units, coefficients from `base`)
// with t >= tMin: its t and outward unit normal.
bool traceGlyph(uint base, vec3 o, vec3 d, float tMin, float tolerance, out float t, out vec3 normal) {
    int k = uLmax;
    t = 0.0;
    normal = vec3(0.0);
    float t0 = -dot(o, d);
    vec3 closest = o + t0 * d;
    float rho = length(closest);
    if (rho >= uTraceRadius) return false;
    vec3 e1;
    if (rho > 1e-7) e1 = closest / rho;
    else e1 = normalize(cross(abs(d.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0), d));
    vec3 e2 = d, e3 = cross(e1, e2);

    float f[kMaxLmax + 1], a[kMaxLmax + 1], c[kMaxLmax + 1];
    for (int i = 0; i <= k; ++i) {
        float alpha = 3.14159265358979 * float(i) / float(k + 1);
        f[i] = shValue(base, k, cos(alpha) * e1 + sin(alpha) * e2);
    }
    for (int j = 0; j <= k; ++j) {
        a[j] = 0.0;
        for (int i = 0; i <= k; ++i) a[j] += uInverseVandermonde[j * (k + 1) + i] * f[i];
    }
    float power = 1.0;
    for (int j = k; j >= 0; --j) {
        c[j] = a[j] * power;
        power *= rho;
    }
    int degree = 2 * k + 2;
    float poly[kMaxPolynomialDegree + 1];
    for (int i = 0; i <= kMaxPolynomialDegree; ++i) poly[i] = 0.0;
    for (int i = 0; i <= k; ++i)
        for (int j = 0; j <= k; ++j) poly[i + j] += c[i] * c[j];
    float binomial = 1.0, rho2 = rho * rho;
    for (int i = 0; i <= k + 1; ++i) {
        if (i > 0) binomial = binomial * float(k + 2 - i) / float(i);
        poly[2 * i] -= binomial * powi(rho2, k + 1 - i);
    }
    float halfChord = sqrt(max(0.0, uTraceRadius * uTraceRadius - rho2));
    float lo = max(-halfChord, tMin - t0), hi = halfChord;
    if (!(lo < hi)) return false;
    float s;
    if (!firstRoot(poly, degree, lo, hi, tolerance, s)) return false;
    t = t0 + s;

    normal = glyphNormal(base, k, rho * e1 + s * e2);
    return true;
}
