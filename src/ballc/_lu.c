/* See _lu.h.  Right-looking elimination (k, i, j order), row-major: the update of
 * row i by pivot row k runs over contiguous memory, which the compiler vectorises
 * (SSE2 at -O2: two doubles, or one complex, per instruction; the result of each
 * element is the same as in scalar code).  The order of every operation is fixed
 * by these loops, so results do not depend on the machine's BLAS or on threads.
 * Multipliers: a(i, k) / pivot for real matrices, a(i, k) * (1 / pivot) for
 * complex ones (as LAPACK's zgetf2; saves a complex division per entry).  Entries
 * that are exactly zero (multipliers, solution components) skip their update. */
#include <math.h>
#include <stddef.h>

#include "_lu.h"

/* y[j] -= l * x[j] for j < m: one row of the elimination update (the hot loop). */
static void row_update(int m, double l, const double *restrict x, double *restrict y)
{
    int j = 0;
    for (; j + 1 < m; j += 2) {   /* in pairs: one SSE2 vector per iteration */
        y[j] -= l * x[j];
        y[j + 1] -= l * x[j + 1];
    }
    if (j < m) y[j] -= l * x[j];
}

/* The same for complex rows, seen as (re, im) pairs of doubles (C99 6.2.5: a
 * double _Complex has the representation of double[2]). */
static void row_update_complex(int m, double lr, double li, const double *restrict x,
                               double *restrict y)
{
    for (int j = 0; j < 2 * m; j += 2) {
        double xr = x[j], xi = x[j + 1];
        y[j] -= lr * xr - li * xi;
        y[j + 1] -= lr * xi + li * xr;
    }
}

int ballc_lu_factor(int n, double *a, int *piv)
{
    for (int k = 0; k < n; k++) {
        /* pivot: the first largest |a(i, k)|, i >= k */
        int p = k;
        double big = fabs(a[(size_t)k * n + k]);
        for (int i = k + 1; i < n; i++) {
            double v = fabs(a[(size_t)i * n + k]);
            if (v > big) {
                big = v;
                p = i;
            }
        }
        piv[k] = p;
        if (a[(size_t)p * n + k] == 0.0) return k + 1;
        double *rk = a + (size_t)k * n;
        if (p != k) {
            double *rp = a + (size_t)p * n;
            for (int j = 0; j < n; j++) {
                double t = rk[j];
                rk[j] = rp[j];
                rp[j] = t;
            }
        }
        for (int i = k + 1; i < n; i++) {
            double *ri = a + (size_t)i * n;
            double l = ri[k] / rk[k];
            ri[k] = l;
            if (l != 0.0) row_update(n - k - 1, l, rk + k + 1, ri + k + 1);
        }
        rk[k] = 1.0 / rk[k];   /* the solves multiply by it (see _lu.h) */
    }
    return BALLC_LU_OK;
}

int ballc_lu_factor_complex(int n, double _Complex *a, int *piv)
{
    for (int k = 0; k < n; k++) {
        int p = k;
        double _Complex akk = a[(size_t)k * n + k];
        double big = fabs(creal(akk)) + fabs(cimag(akk));
        for (int i = k + 1; i < n; i++) {
            double _Complex v = a[(size_t)i * n + k];
            double size = fabs(creal(v)) + fabs(cimag(v));
            if (size > big) {
                big = size;
                p = i;
            }
        }
        piv[k] = p;
        double _Complex d = a[(size_t)p * n + k];
        if (creal(d) == 0.0 && cimag(d) == 0.0) return k + 1;
        double _Complex *rk = a + (size_t)k * n;
        if (p != k) {
            double _Complex *rp = a + (size_t)p * n;
            for (int j = 0; j < n; j++) {
                double _Complex t = rk[j];
                rk[j] = rp[j];
                rp[j] = t;
            }
        }
        double _Complex rinv = 1.0 / rk[k];   /* one complex division per column */
        for (int i = k + 1; i < n; i++) {
            double _Complex *ri = a + (size_t)i * n;
            double _Complex l = ri[k] * rinv;
            ri[k] = l;
            if (creal(l) != 0.0 || cimag(l) != 0.0)
                row_update_complex(n - k - 1, creal(l), cimag(l), (const double *)(rk + k + 1),
                                   (double *)(ri + k + 1));
        }
        rk[k] = rinv;   /* the solves multiply by it (see _lu.h) */
    }
    return BALLC_LU_OK;
}

/* b := P b, the swaps in factorisation order; then L y = b (unit diagonal) and U x = y
 * row by row: each b[i] takes its row's terms in the order of j (ascending for L,
 * descending for U) in one register, then (U) its reciprocal pivot.  A term whose b[j]
 * is exactly zero is skipped (its -0 or +0 would flip the sign of a zero b[i]).  For the
 * sizes here (n <= ~13) this is faster than eliminating column by column (strided
 * loads, a loop per column); each b[i] gets the same operations in the same order. */
void ballc_lu_solve(int n, const double *lu, const int *piv, double *b)
{
    for (int k = 0; k < n; k++) {
        int p = piv[k];
        if (p != k) {
            double t = b[k];
            b[k] = b[p];
            b[p] = t;
        }
    }
    for (int i = 1; i < n; i++) {
        const double *row = lu + (size_t)i * n;
        double bi = b[i];
        for (int j = 0; j < i; j++)
            if (b[j] != 0.0) bi -= row[j] * b[j];
        b[i] = bi;
    }
    for (int i = n - 1; i >= 0; i--) {   /* the diagonal holds 1 / U(i, i) */
        const double *row = lu + (size_t)i * n;
        double bi = b[i];
        for (int j = n - 1; j > i; j--)
            if (b[j] != 0.0) bi -= row[j] * b[j];
        b[i] = bi * row[i];
    }
}

void ballc_lu_solve_complex(int n, const double _Complex *lu, const int *piv,
                            double _Complex *b)
{
    for (int k = 0; k < n; k++) {
        int p = piv[k];
        if (p != k) {
            double _Complex t = b[k];
            b[k] = b[p];
            b[p] = t;
        }
    }
    for (int i = 1; i < n; i++) {
        const double _Complex *row = lu + (size_t)i * n;
        double _Complex bi = b[i];
        for (int j = 0; j < i; j++)
            if (creal(b[j]) != 0.0 || cimag(b[j]) != 0.0) bi -= row[j] * b[j];
        b[i] = bi;
    }
    for (int i = n - 1; i >= 0; i--) {
        const double _Complex *row = lu + (size_t)i * n;
        double _Complex bi = b[i];
        for (int j = n - 1; j > i; j--)
            if (creal(b[j]) != 0.0 || cimag(b[j]) != 0.0) bi -= row[j] * b[j];
        b[i] = bi * row[i];
    }
}
