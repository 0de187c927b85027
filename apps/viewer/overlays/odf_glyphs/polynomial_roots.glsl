// firstRoot of polynomial_roots.hpp in float (the same steps, in order).
const int kMaxPolynomialDegree = 26;

void polynomialAndDerivative(in float q[kMaxPolynomialDegree + 1], int degree, float x, out float value, out float slope) {
    value = q[degree];
    slope = 0.0;
    for (int j = degree - 1; j >= 0; --j) {
        slope = slope * x + value;
        value = value * x + q[j];
    }
}

float bracketedNewton(in float q[kMaxPolynomialDegree + 1], int degree, float a, float b, float qa, float tolerance) {
    float x = 0.5 * (a + b);
    for (int i = 0; i < 64; ++i) {
        float v, s;
        polynomialAndDerivative(q, degree, x, v, s);
        if ((v < 0.0) == (qa < 0.0)) a = x;
        else b = x;
        float next = s != 0.0 ? x - v / s : 0.5 * (a + b);
        if (!(next > a && next < b)) next = 0.5 * (a + b);
        float step = next - x;
        x = next;
        if (abs(step) <= tolerance) break;
    }
    return x;
}

// The least sign-changing root of c[0..degree] in [lo, hi]; false when none.
bool firstRoot(in float c[kMaxPolynomialDegree + 1], int degree, float lo, float hi, float tolerance, out float root) {
    float q[kMaxPolynomialDegree + 1];
    float previous[kMaxPolynomialDegree], current[kMaxPolynomialDegree];
    int previousCount = 0;
    root = 0.0;
    for (int m = degree - 1; m >= 0; --m) {
        int d = degree - m;
        float binomial = 1.0;
        for (int j = 0; j <= d; ++j) {
            if (j > 0) binomial = binomial * float(j + m) / float(j);
            q[j] = binomial * c[j + m];
        }
        int count = 0;
        float a = lo, qa, qb, slope;
        polynomialAndDerivative(q, d, a, qa, slope);
        for (int i = 0; i <= previousCount; ++i) {
            float b = i < previousCount ? previous[i] : hi;
            polynomialAndDerivative(q, d, b, qb, slope);
            if ((qa < 0.0) != (qb < 0.0) && b > a) {
                float r = bracketedNewton(q, d, a, b, qa, tolerance);
                if (m == 0) {
                    root = r;
                    return true;
                }
                current[count++] = r;
            }
            a = b;
            qa = qb;
        }
        previous = current;
        previousCount = count;
    }
    return false;
}
