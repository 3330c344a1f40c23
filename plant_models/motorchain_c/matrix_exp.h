/* Dense matrix exponential shared by the plants' exact zero-order-hold steps
 * (motorchain_c/physics.c, flexlink_c/beam.c): one home for it, header-only so that
 * each plant compiles it with its own sizes and no extra source file.
 *
 * Matrices are row-major with leading dimension ld (n <= ld): entry (r, c) of a is
 * a[r * ld + c]. */
#ifndef PLANT_MATRIX_EXP_H
#define PLANT_MATRIX_EXP_H

#include <math.h>
#include <string.h>

/* c = a b (n × n); c may be a or b. t: scratch (n × ld). */
static inline void mx_matmul(double *c, const double *a, const double *b, int n, int ld,
                             double *t) {
    for (int r = 0; r < n; r++)
        for (int col = 0; col < n; col++) {
            double s = 0.0;
            for (int k = 0; k < n; k++) s += a[r * ld + k] * b[k * ld + col];
            t[r * ld + col] = s;
        }
    for (int r = 0; r < n; r++) memcpy(c + r * ld, t + r * ld, sizeof(double) * n);
}

static inline void mx_swap_rows(double *a, int i, int j, int ld) {
    for (int c = 0; c < ld; c++) {
        double tmp = a[i * ld + c];
        a[i * ld + c] = a[j * ld + c];
        a[j * ld + c] = tmp;
    }
}

/* Solve a x = b in place (b, n columns, becomes x); Gaussian elimination with partial
 * pivoting. -1 when a is singular or not finite. */
static inline int mx_solve(double *a, double *b, int n, int ld) {
    for (int col = 0; col < n; col++) {
        int pivot = col;
        for (int r = col + 1; r < n; r++)
            if (fabs(a[r * ld + col]) > fabs(a[pivot * ld + col])) pivot = r;
        if (a[pivot * ld + col] == 0.0 || !isfinite(a[pivot * ld + col])) return -1;
        if (pivot != col) {
            mx_swap_rows(a, col, pivot, ld);
            mx_swap_rows(b, col, pivot, ld);
        }
        double inv = 1.0 / a[col * ld + col];
        for (int r = col + 1; r < n; r++) {
            double f = a[r * ld + col] * inv;
            if (f != 0.0) {
                for (int c = col; c < n; c++) a[r * ld + c] -= f * a[col * ld + c];
                for (int c = 0; c < n; c++) b[r * ld + c] -= f * b[col * ld + c];
            }
        }
    }
    for (int col = n - 1; col >= 0; col--) {
        double inv = 1.0 / a[col * ld + col];
        for (int c = 0; c < n; c++) b[col * ld + c] *= inv;
        for (int r = 0; r < col; r++) {
            double f = a[r * ld + col];
            if (f != 0.0)
                for (int c = 0; c < n; c++) b[r * ld + c] -= f * b[col * ld + c];
        }
    }
    return 0;
}

/* e = expm(a_in), scaling and squaring with a (6, 6) Padé approximant (as
 * fmu_src/flexchain/linalg.expm). work: 5 matrices of ld × ld. -1 if it failed. */
static inline int mx_expm(double *e, const double *a_in, int n, int ld, double *work) {
    const size_t m = (size_t)ld * (size_t)ld;
    double *a = work, *x = work + m, *num = work + 2 * m, *den = work + 3 * m, *t = work + 4 * m;
    double norm = 0.0;
    for (int r = 0; r < n; r++) {
        double s = 0.0;
        for (int c = 0; c < n; c++) s += fabs(a_in[r * ld + c]);
        if (s > norm || isnan(s)) norm = s;
    }
    if (!isfinite(norm)) return -1;
    int s = norm > 0.5 ? (int)ceil(log2(norm / 0.5)) : 0;
    if (s < 0) s = 0;
    double scale = pow(0.5, s);
    for (int r = 0; r < n; r++)
        for (int c = 0; c < n; c++) {
            a[r * ld + c] = scale * a_in[r * ld + c];
            x[r * ld + c] = a[r * ld + c];
        }
    const int q = 6;
    double coef = 0.5;
    for (int r = 0; r < n; r++)
        for (int c = 0; c < n; c++) {
            double id = r == c ? 1.0 : 0.0;
            num[r * ld + c] = id + coef * a[r * ld + c];
            den[r * ld + c] = id + -coef * a[r * ld + c];
        }
    int positive = 1;
    for (int k = 2; k <= q; k++) {
        coef = coef * (q - k + 1) / (k * (2 * q - k + 1));
        mx_matmul(x, a, x, n, ld, t);
        double sign = positive ? coef : -coef;
        for (int r = 0; r < n; r++)
            for (int c = 0; c < n; c++) {
                num[r * ld + c] = num[r * ld + c] + coef * x[r * ld + c];
                den[r * ld + c] = den[r * ld + c] + sign * x[r * ld + c];
            }
        positive = !positive;
    }
    if (mx_solve(den, num, n, ld) != 0) return -1;
    for (int r = 0; r < n; r++) memcpy(e + r * ld, num + r * ld, sizeof(double) * n);
    for (int i = 0; i < s; i++) mx_matmul(e, e, e, n, ld, t);
    return 0;
}

/* Balance a in place (Parlett and Reinsch, as LAPACK's dgebal without permutations):
 * a ← D⁻¹ a D with D = diag(d) of powers of two (exact in floating point), so that each
 * row and column weigh alike. A stiff system's matrix in mixed units (metres and
 * radians, positions and velocities) has a norm far above its spectral radius; balanced,
 * the exponential needs fewer squarings, each of which doubles its rounding error. */
static inline void mx_balance(double *a, double *d, int n, int ld) {
    for (int i = 0; i < n; i++) d[i] = 1.0;
    for (int done = 0; !done;) {
        done = 1;
        for (int i = 0; i < n; i++) {
            double c = 0.0, r = 0.0;
            for (int j = 0; j < n; j++)
                if (j != i) {
                    c += fabs(a[j * ld + i]);
                    r += fabs(a[i * ld + j]);
                }
            if (c == 0.0 || r == 0.0 || !isfinite(c + r)) continue;
            double f = 1.0, g = r / 2.0, s = c + r;
            while (c < g) {
                f *= 2.0;
                c *= 4.0;
            }
            g = r * 2.0;
            while (c > g) {
                f /= 2.0;
                c /= 4.0;
            }
            if ((c + r) / f < 0.95 * s) {
                done = 0;
                d[i] *= f;
                for (int j = 0; j < n; j++) a[i * ld + j] /= f;
                for (int j = 0; j < n; j++) a[j * ld + i] *= f;
            }
        }
    }
}

/* e = expm(a) of a balanced copy (mx_balance): e = D expm(D⁻¹ a D) D⁻¹. a is
 * overwritten; d: n doubles of scratch; work: 5 matrices of ld × ld. */
static inline int mx_expm_balanced(double *e, double *a, double *d, int n, int ld,
                                   double *work) {
    mx_balance(a, d, n, ld);
    if (mx_expm(e, a, n, ld, work) != 0) return -1;
    for (int r = 0; r < n; r++)
        for (int c = 0; c < n; c++) e[r * ld + c] *= d[r] / d[c];
    return 0;
}

#endif
