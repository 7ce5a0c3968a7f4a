/* Small dense LU with partial pivoting (row interchanges), real and complex.
 *
 * For the Newton systems of radau5 (n ~ 10-20; meant for n up to ~64): plain C99
 * loops in one fixed order, no BLAS and no threads, so a given binary gives the
 * same bits for the same input wherever and however it runs.
 *
 * Storage: row-major, a[i * n + j] = A(i, j), factored in place as LAPACK's getrf
 * does: P A = L U with L unit lower triangular (its multipliers below the
 * diagonal) and U upper triangular (above it), except that the diagonal holds the
 * reciprocal pivots 1 / U(k, k): a solve's back substitution then multiplies where a
 * division (~15 cycles, on the substitution's critical path) would stand.  piv[k] (0-based) is the
 * row swapped with row k at step k, applied to the whole row (as LAPACK's ipiv,
 * minus one).
 *
 * Pivot: the first row i >= k with the largest |A(i, k)| among the remaining
 * rows; for complex entries the size is |re| + |im| (LAPACK's izamax does the
 * same).  Inputs must be finite.
 */
#ifndef BALLC_LU_H
#define BALLC_LU_H

#include <complex.h>

/* Return codes of the factorisations. */
#define BALLC_LU_OK 0
/* > 0: k + 1 when the pivot of column k is exactly zero (the matrix is singular);
 * the factorisation stops there and a, piv are left partly factored. */

/* Factor the n x n matrix a in place; piv: n ints.  Returns BALLC_LU_OK or k + 1. */
int ballc_lu_factor(int n, double *a, int *piv);
int ballc_lu_factor_complex(int n, double _Complex *a, int *piv);

/* Solve A x = b for one right-hand side with a, piv from a successful factor;
 * b (n) is overwritten by x. */
void ballc_lu_solve(int n, const double *lu, const int *piv, double *b);
void ballc_lu_solve_complex(int n, const double _Complex *lu, const int *piv,
                            double _Complex *b);

#endif
