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
