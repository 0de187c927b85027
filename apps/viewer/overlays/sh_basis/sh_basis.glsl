// shValue of sh_basis.hpp in GLSL (the same recurrence, float): Σ c_i Y_i(u)
// in MRtrix3's basis (Condon–Shortley phase in pmm). The including shader defines
// `float shCoefficient(uint i)` before including this file.
float shValue(uint base, int lmax, vec3 u) {
    float pmm = 0.28209479177387814;
    float re = 1.0, im = 0.0;
    float sum = 0.0;
    for (int m = 0; m <= lmax; ++m) {
        if (m > 0) {
            pmm *= -sqrt(float(2 * m + 1) / float(2 * m));
            float r = re * u.x - im * u.y;
            im = re * u.y + im * u.x;
            re = r;
        }
        float p2 = 0.0, p1 = 0.0;
        for (int l = m; l <= lmax; ++l) {
            float p;
            if (l == m) p = pmm;
            else if (l == m + 1) p = sqrt(float(2 * m + 3)) * u.z * pmm;
            else {
                float ll = float(l), mm = float(m);
                float a = sqrt((4.0 * ll * ll - 1.0) / (ll * ll - mm * mm));
                float b = sqrt(((ll - 1.0) * (ll - 1.0) - mm * mm) / (4.0 * (ll - 1.0) * (ll - 1.0) - 1.0));
                p = a * (u.z * p1 - b * p2);
            }
            p2 = p1;
            p1 = p;
            if ((l & 1) != 0) continue;
            uint centre = base + uint(l * (l + 1) / 2);
            if (m == 0) sum += shCoefficient(centre) * p;
            else sum += 1.4142135623730951 * p * (re * shCoefficient(centre + uint(m)) + im * shCoefficient(centre - uint(m)));
        }
    }
    return sum;
}

// shValueAndGradient of sh_basis.hpp (sh_value_and_gradient): f(u) and its
// gradient on the sphere (tangent at u), the recurrence differentiated.
float shValueAndGradient(uint base, int lmax, vec3 u, out vec3 gradient) {
    float pmm = 0.28209479177387814;
    float re = 1.0, im = 0.0;
    float sum = 0.0;
    vec3 g = vec3(0.0);
    for (int m = 0; m <= lmax; ++m) {
        float re1 = re, im1 = im;  // (x + iy)^(m - 1) once m > 0
        if (m > 0) {
            pmm *= -sqrt(float(2 * m + 1) / float(2 * m));
            float r = re * u.x - im * u.y;
            im = re * u.y + im * u.x;
            re = r;
        }
        float p2 = 0.0, p1 = 0.0, d2 = 0.0, d1 = 0.0;
        for (int l = m; l <= lmax; ++l) {
            float p, d;
            if (l == m) {
                p = pmm;
                d = 0.0;
            } else if (l == m + 1) {
                float s = sqrt(float(2 * m + 3));
                p = s * u.z * pmm;
                d = s * pmm;
            } else {
                float ll = float(l), mm = float(m);
                float a = sqrt((4.0 * ll * ll - 1.0) / (ll * ll - mm * mm));
                float b = sqrt(((ll - 1.0) * (ll - 1.0) - mm * mm) / (4.0 * (ll - 1.0) * (ll - 1.0) - 1.0));
                p = a * (u.z * p1 - b * p2);
                d = a * (p1 + u.z * d1 - b * d2);
            }
            p2 = p1;
            p1 = p;
            d2 = d1;
            d1 = d;
            if ((l & 1) != 0) continue;
            uint centre = base + uint(l * (l + 1) / 2);
            if (m == 0) {
                float cl = shCoefficient(centre);
                sum += cl * p;
                g.z += cl * d;
            } else {
                float cp = shCoefficient(centre + uint(m)), cm = shCoefficient(centre - uint(m));
                float w = 1.4142135623730951 * (re * cp + im * cm), pm = 1.4142135623730951 * float(m) * p;
                sum += p * w;
                g.z += d * w;
                g.x += pm * (re1 * cp + im1 * cm);
                g.y += pm * (re1 * cm - im1 * cp);
            }
        }
    }
    gradient = g - dot(g, u) * u;
    return sum;
}
