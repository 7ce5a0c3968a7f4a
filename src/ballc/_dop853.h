/* dop853: the explicit Runge-Kutta pair of order 8(5,3) of Dormand & Prince (Hairer's
 * DOP853), as scipy.integrate.DOP853 implements it (scipy/integrate/_ivp/rk.py and
 * dop853_coefficients.py): the same coefficients, the same combined error estimate and
 * the same 7th-order dense output, and the integrator's DOP853 step built from them
 * (dop853_step: RungeKutta._step_impl's step-size control and Hairer's stiffness test).
 * The loop, events and output are radau5_solve's (_integrator.c, problem.method =
 * RADAU5_METHOD_DOP853).
 */
#ifndef BALLC_DOP853_H
#define BALLC_DOP853_H

#define DOP853_STAGES 12            /* K[0..11] and the FSAL row K[12] = f(t + h, y_new) */
#define DOP853_STAGES_EXTENDED 16   /* + 3 stages for the dense output */
#define DOP853_DENSE_TERMS 7        /* F[0..6], see dop853_eval */
#define DOP853_ERROR_ORDER 7        /* order of the error estimator (step-size exponent) */

typedef int (*dop853_fun)(void *ctx, double t, const double *y, double *f);

/* One attempted step from (t, y) of size h.  K (DOP853_STAGES_EXTENDED x n, row-major)
 * holds f(t, y) in row 0 on entry; rows 1..11 get the stages and row 12 f(t + h, y_new).
 * y_new (n) = y + h sum_i B_i K_i; ytmp (n) is scratch.  Returns 0, or the first
 * nonzero return of fun (the step cannot be taken). */
int dop853_attempt(dop853_fun fun, void *ctx, int n, double t, double h, const double *y,
                   double *K, double *y_new, double *ytmp);

/* scipy's DOP853._estimate_error_norm: |h| |e5|^2 / sqrt((|e5|^2 + 0.01 |e3|^2) count),
 * where e5 = K^T E5 / scale and e3 = K^T E3 / scale over rows 0..12 of K (count = n in
 * scipy; radau5_problem.norm_states); e5, e3 (n) are scratch (they get K^T E5 and K^T E3). */
double dop853_error_norm(int n, int count, const double *K, double h, const double *scale,
                         double *e5, double *e3);

/* The accepted step (t_old, y_old) -> (t_old + h, y)'s dense output: the 3 extra stages
 * (rows 13..15 of K, whose rows 0..12 are the step's) and F (DOP853_DENSE_TERMS x n).
 * Returns 0, or the first nonzero return of fun. */
int dop853_dense(dop853_fun fun, void *ctx, int n, double t_old, double h,
                 const double *y_old, const double *y, double *K, double *F, double *ytmp);

/* y(x) = y_old + x (F0 + (1 - x) (F1 + x (F2 + (1 - x) (F3 + x (F4 + (1 - x) (F5 + x F6))))))
 * at x = (t - t_old) / h, for state c: F[j * n + c]; out (n). */
void dop853_eval(int n, double x, const double *y_old, const double *F, double *out);

/* The same polynomial for one scalar: a0 + x (a[0] + (1 - x) (a[1] + ...)). */
double dop853_eval_scalar(double x, double a0, const double *a);

/* The coefficients (tests only): A (16 x 16), B (12), C (16), E3 (13), E5 (13), D (4 x 16),
 * in that order, DOP853_N_CONSTANTS values. */
#define DOP853_N_CONSTANTS (256 + 12 + 16 + 13 + 13 + 64)
void dop853_constants(double *out);

/* The loop's entry points (the solver: _integrator_private.h). */
struct ballc_solver;
/* RungeKutta._step_impl with DOP853's error norm: one accepted step from s->t.  Returns
 * 1 on success, 0 on failure (message set).  A step whose stages cannot be evaluated is
 * rejected with its size halved (scipy would carry the NaN on). */
int dop853_step(struct ballc_solver *s);
/* The last accepted step's dense output terms (s->Fdense), once per step.  Returns 0, or
 * -1 (message set) when they cannot be evaluated or were lost to a failed step. */
int dop853_prepare_dense(struct ballc_solver *s);

#endif
