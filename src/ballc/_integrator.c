/* See _integrator.h.  A line-by-line port of scipy.integrate.Radau (scipy 1.17,
 * scipy/integrate/_ivp/radau.py) and of solve_ivp's event and output logic
 * (scipy/integrate/_ivp/ivp.py), for dense Jacobians and linear events.
 * Comments name the scipy function each part mirrors. */
#ifdef RADAU5_PROFILE
#define _POSIX_C_SOURCE 199309L   /* clock_gettime under -std=c99 */
#endif
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "_dop853.h"
#include "_lu.h"
#include "_integrator.h"

#define NEWTON_MAXITER 6   /* Maximum number of Newton iterations. */
#define MIN_FACTOR 0.2     /* Minimum allowed decrease in a step size. */
#define MAX_FACTOR 10.0    /* Maximum allowed increase in a step size. */
#define EPS DBL_EPSILON

/* Compiled with -DRADAU5_PROFILE (benchmarks/profile_step.py): time-stamp-counter
 * ticks of the right-hand side, Jacobian (with partition), factorisations and
 * solves, and of the whole radau5_solve, in result->prof.  Otherwise no-ops. */
#ifdef RADAU5_PROFILE
#include <time.h>
#include <x86intrin.h>
static __thread double *prof_acc;
#define PROF_START unsigned long long prof_t0_ = __rdtsc()
#define PROF_STOP(k) (prof_acc[k] += (double)(__rdtsc() - prof_t0_))
#else
#define PROF_START (void)0
#define PROF_STOP(k) (void)0
#endif

typedef double _Complex cplx;

/* radau.py module constants (computed as scipy computes them). */
typedef struct {
    double C[3], E[3], T[3][3], TI[3][3], P[3][3];
    double mu_real;
    cplx mu_complex, ti_complex[3];
} constants_t;

static void init_constants(constants_t *k)
{
    const double S6 = sqrt(6.0);
    k->C[0] = (4 - S6) / 10; k->C[1] = (4 + S6) / 10; k->C[2] = 1;
    k->E[0] = (-13 - 7 * S6) / 3; k->E[1] = (-13 + 7 * S6) / 3; k->E[2] = -1.0 / 3;
    k->mu_real = 3 + pow(3, 2.0 / 3) - pow(3, 1.0 / 3);
    k->mu_complex = (3 + 0.5 * (pow(3, 1.0 / 3) - pow(3, 2.0 / 3)))
                    - 0.5 * I * (pow(3, 5.0 / 6) + pow(3, 7.0 / 6));
    const double T[3][3] = {
        {0.09443876248897524, -0.14125529502095421, 0.03002919410514742},
        {0.25021312296533332, 0.20412935229379994, -0.38294211275726192},
        {1, 1, 0}};
    const double TI[3][3] = {
        {4.17871859155190428, 0.32768282076106237, 0.52337644549944951},
        {-4.17871859155190428, -0.32768282076106237, 0.47662355450055044},
        {0.50287263494578682, -2.57192694985560522, 0.59603920482822492}};
    const double P[3][3] = {
        {13.0 / 3 + 7 * S6 / 3, -23.0 / 3 - 22 * S6 / 3, 10.0 / 3 + 5 * S6},
        {13.0 / 3 - 7 * S6 / 3, -23.0 / 3 + 22 * S6 / 3, 10.0 / 3 - 5 * S6},
        {1.0 / 3, -8.0 / 3, 10.0 / 3}};
    memcpy(k->T, T, sizeof T);
    memcpy(k->TI, TI, sizeof TI);
    memcpy(k->P, P, sizeof P);
    for (int j = 0; j < 3; j++) k->ti_complex[j] = TI[1][j] + I * TI[2][j];
}

/* Everything the integration carries from step to step. */
typedef struct {
    const radau5_problem *p;
    radau5_result *r;
    constants_t k;
    int n;
    double direction, newton_tol;
    /* step control (radau5_problem.controller): the tolerances in use (transformed with
     * RADAU5_CTRL_TOL), the Newton iteration cap, and Hairer's predictive-controller
     * memory (h and error of the last accepted step) */
    int ctrl, newton_maxiter;
    double rtol, *atol;
    double h_acc, err_acc;
    int have_acc;
    /* solver state (Radau attributes) */
    double t, t_old, h_abs, h_abs_old, error_norm_old;
    double t_bound;                       /* where steps stop: p->t_bound, or an event's
                                           * time while stepping to it (step_to_event) */
    double dense_end;                     /* the end of the step the interpolant Q covers */
    long i_eval;                          /* the next of p->t_eval to store */
    double jac_t;                         /* where J was evaluated */
    int have_h_abs_old, have_error_norm_old, have_sol, current_jac, lu_valid;
    double *y, *f, *y_old, *J, *Z, *Q;      /* Z, Q: of the last accepted step */
    double *LU_real; int *piv_real;       /* nc x nc: the coupled block (see partition) */
    cplx *LU_complex; int *piv_complex;
    /* Structure of J (partition): the coupled states (columns of J with a nonzero entry)
     * and the outputs (zero columns: nothing depends on them).  Ordered [coupled,
     * outputs], M = mu/h I - J is lower block-triangular, [[M_cc, 0], [-J_oc, mu/h I]]:
     * only M_cc is factored; the outputs follow by substitution. */
    int nc, no, *cidx, *oidx;
    double *Joc;                          /* J_oc's nonzeros, row by row (CSR) */
    int *joc_col, *joc_start;             /* their coupled column; row o: [start[o], start[o+1]) */
    double lu_mr; cplx lu_mc;             /* mu_real / h, mu_complex / h of the factors */
    double *xc; cplx *xcc;                /* nc: gathered right-hand sides */
    double *inv_scale;                    /* 1 / scale of the step start (Newton norm) */
    /* scratch */
    double *y_new, *f_new, *scale, *Z0, *Znew, *W, *F, *dW, *tmp, *err, *ZE;
    cplx *ctmp;
    /* DOP853 (problem.method): the stages of the last step (DOP853_STAGES_EXTENDED x n),
     * its dense output's terms (DOP853_DENSE_TERMS x n) once computed (dense_ready) */
    int dop853, dense_ready, k_stale;     /* k_stale: K was overwritten by attempts that
                                           * were not accepted (a failed step) */
    double *K, *Fdense;
    int stiff_steps, nonstiff_steps;      /* Hairer's stiffness test (step_dop853) */
    /* events */
    double *g, *g_new, *roots, *ev_y;   /* ev_y: scratch state of event evaluations */
    int *active;
    int *ev_count;                      /* occurrences of each event in this call */
    size_t cap_out, cap_hits, cap_dense;
} solver_t;

/* common.norm: RMS norm (two partial sums: half the chain of dependent additions). */
static double rms(const double *x, int n)
{
    double s0 = 0, s1 = 0;
    int i = 0;
    for (; i + 1 < n; i += 2) {
        s0 += x[i] * x[i];
        s1 += x[i + 1] * x[i + 1];
    }
    if (i < n) s0 += x[i] * x[i];
    return sqrt((s0 + s1) / n);
}

static int call_fun(solver_t *s, double t, const double *y, double *f)
{
    PROF_START;
    s->r->nfev++;
    int rc = s->p->fun(s->p->ctx, t, y, f);
    if (!s->p->outputs_checked) {
        double finite = 0.0;   /* x - x: 0 for a finite x, NaN otherwise; no branch per entry */
        for (int i = 0; i < s->n; i++) finite += f[i] - f[i];
        if (finite != 0.0) rc = -1;
    }
    PROF_STOP(RADAU5_PROF_FUN);
    return rc == 0 ? 0 : -1;
}

/* Split the states into coupled ones (a nonzero entry in their column of J) and
 * outputs (a zero column), and gather J_oc.  The split is exact for this J: the
 * Newton matrix built from it is block-triangular, whatever made the column zero. */
static void partition(solver_t *s)
{
    const int n = s->n;
    s->nc = s->no = 0;
    for (int j = 0; j < n; j++) {
        int zero = 1;
        for (int i = 0; i < n && zero; i++) zero = s->J[i * n + j] == 0.0;
        if (zero) s->oidx[s->no++] = j;
        else s->cidx[s->nc++] = j;
    }
    int k = 0;   /* J_oc is sparse (x, y: one velocity each; idle deflections: none) */
    for (int a = 0; a < s->no; a++) {
        s->joc_start[a] = k;
        for (int b = 0; b < s->nc; b++) {
            double v = s->J[s->oidx[a] * n + s->cidx[b]];
            if (v != 0.0) {
                s->Joc[k] = v;
                s->joc_col[k++] = b;
            }
        }
    }
    s->joc_start[s->no] = k;
}

static int call_jac(solver_t *s, double t, const double *y)
{
    PROF_START;
    s->r->njev++;
    s->jac_t = t;
    int rc = s->p->jac(s->p->ctx, t, y, s->J);
    for (int i = 0; i < s->n * s->n && rc == 0 && !s->p->outputs_checked; i++)
        if (!isfinite(s->J[i])) rc = -1;
    if (rc == 0) partition(s);
    PROF_STOP(RADAU5_PROF_JAC);
    return rc == 0 ? 0 : -1;
}

/* LU of the coupled block of MU_REAL / h I - J and MU_COMPLEX / h I - J (row-major,
 * as J; see _lu.h and partition). */
static int factor(solver_t *s, double h)
{
    PROF_START;
    const int n = s->n, nc = s->nc;
    double mr = s->k.mu_real / h;
    cplx mc = s->k.mu_complex / h;
    for (int a = 0; a < nc; a++)
        for (int b = 0; b < nc; b++) {
            double v = -s->J[s->cidx[a] * n + s->cidx[b]];
            s->LU_real[a * nc + b] = v + (a == b ? mr : 0.0);
            s->LU_complex[a * nc + b] = v + (a == b ? mc : 0.0);
        }
    s->lu_mr = mr;
    s->lu_mc = mc;
    int info_r = ballc_lu_factor(nc, s->LU_real, s->piv_real);
    int info_c = ballc_lu_factor_complex(nc, s->LU_complex, s->piv_complex);
    s->r->nlu += 2;
    s->lu_valid = 1;
    PROF_STOP(RADAU5_PROF_FACTOR);
    return (info_r == BALLC_LU_OK && info_c == BALLC_LU_OK) ? 0 : -1;
}

/* (mu/h I - J) x = b, b (n) overwritten by x: the coupled block by LU, then each
 * output o from its row, mu/h x_o - J_oc x_c = b_o. */
static void solve_real(solver_t *s, double *b)
{
    PROF_START;
    const int nc = s->nc, no = s->no;
    if (no == 0) {
        ballc_lu_solve(nc, s->LU_real, s->piv_real, b);
    } else {
        double *x = s->xc;
        for (int a = 0; a < nc; a++) x[a] = b[s->cidx[a]];
        ballc_lu_solve(nc, s->LU_real, s->piv_real, x);
        for (int a = 0; a < nc; a++) b[s->cidx[a]] = x[a];
        for (int o = 0; o < no; o++) {
            double v = b[s->oidx[o]];
            for (int q = s->joc_start[o]; q < s->joc_start[o + 1]; q++)
                v += s->Joc[q] * x[s->joc_col[q]];
            b[s->oidx[o]] = v / s->lu_mr;
        }
    }
    PROF_STOP(RADAU5_PROF_SOLVE);
}

static void solve_complex(solver_t *s, cplx *b)
{
    PROF_START;
    const int nc = s->nc, no = s->no;
    if (no == 0) {
        ballc_lu_solve_complex(nc, s->LU_complex, s->piv_complex, b);
    } else {
        cplx *x = s->xcc;
        for (int a = 0; a < nc; a++) x[a] = b[s->cidx[a]];
        ballc_lu_solve_complex(nc, s->LU_complex, s->piv_complex, x);
        for (int a = 0; a < nc; a++) b[s->cidx[a]] = x[a];
        cplx inverse = 1.0 / s->lu_mc;
        for (int o = 0; o < no; o++) {
            cplx v = b[s->oidx[o]];
            for (int q = s->joc_start[o]; q < s->joc_start[o + 1]; q++)
                v += s->Joc[q] * x[s->joc_col[q]];
            b[s->oidx[o]] = v * inverse;
        }
    }
    PROF_STOP(RADAU5_PROF_SOLVE);
}

/* radau.solve_collocation_system: Z (3 x n) starts as Z0 and ends as the solution. */
static int solve_collocation(solver_t *s, double t, double h, double *restrict Z,
                             int *n_iter, double *rate_out, int *have_rate_out,
                             double *theta_out)
{
    const int maxiter = s->newton_maxiter;
    const constants_t *k = &s->k;
    const int n = s->n;
    double M_real = k->mu_real / h;
    cplx M_complex = k->mu_complex / h;
    /* distinct buffers: restrict lets the compiler vectorise the stage loops */
    double *restrict W = s->W, *restrict F = s->F, *restrict dW = s->dW, *restrict yi = s->tmp;
    const double *restrict inv_scale = s->inv_scale;
    cplx *restrict fc = s->ctmp;
    /* the transformation matrices as locals: the stage loops below then keep them in
     * registers (through k the compiler reloads them for every element) */
    const double T00 = k->T[0][0], T01 = k->T[0][1], T02 = k->T[0][2],
                 T10 = k->T[1][0], T11 = k->T[1][1], T12 = k->T[1][2],
                 T20 = k->T[2][0], T21 = k->T[2][1], T22 = k->T[2][2];
    const double Ti00 = k->TI[0][0], Ti01 = k->TI[0][1], Ti02 = k->TI[0][2],
                 Ti10 = k->TI[1][0], Ti11 = k->TI[1][1], Ti12 = k->TI[1][2],
                 Ti20 = k->TI[2][0], Ti21 = k->TI[2][1], Ti22 = k->TI[2][2];
    for (int c = 0; c < n; c++) {
        double z0 = Z[c], z1 = Z[n + c], z2 = Z[2 * n + c];
        W[c] = Ti00 * z0 + Ti01 * z1 + Ti02 * z2;
        W[n + c] = Ti10 * z0 + Ti11 * z1 + Ti12 * z2;
        W[2 * n + c] = Ti20 * z0 + Ti21 * z1 + Ti22 * z2;
    }
    const cplx tc0 = k->ti_complex[0], tc1 = k->ti_complex[1], tc2 = k->ti_complex[2];
    double dW_norm_old = 0, rate = 0, theta = 0, rate_prev = 0;
    int have_old = 0, have_rate = 0, converged = 0, it;
    for (it = 0; it < maxiter; it++) {
        int finite = 1;
        for (int i = 0; i < 3 && finite; i++) {
            for (int c = 0; c < n; c++) yi[c] = s->y[c] + Z[i * n + c];
            if (call_fun(s, t + h * k->C[i], yi, F + i * n) != 0) finite = 0;
        }
        if (!finite) break;
        for (int c = 0; c < n; c++) {
            double f0 = F[c], f1 = F[n + c], f2 = F[2 * n + c];
            dW[c] = f0 * Ti00 + f1 * Ti01 + f2 * Ti02 - M_real * W[c];
            fc[c] = f0 * tc0 + f1 * tc1 + f2 * tc2 - M_complex * (W[n + c] + I * W[2 * n + c]);
        }
        solve_real(s, dW);
        solve_complex(s, fc);
        double sum0 = 0, sum1 = 0, sum2 = 0;   /* one partial sum per stage: three short
                                                * chains of dependent additions, not one */
        for (int c = 0; c < n; c++) {
            double v0 = dW[c] * inv_scale[c], v1 = creal(fc[c]), v2 = cimag(fc[c]);
            dW[n + c] = v1;
            dW[2 * n + c] = v2;
            v1 *= inv_scale[c];
            v2 *= inv_scale[c];
            sum0 += v0 * v0;
            sum1 += v1 * v1;
            sum2 += v2 * v2;
        }
        double dW_norm = sqrt((sum0 + sum1 + sum2) / (3 * n));
        if (!isfinite(dW_norm)) break;
        if (have_old) {
            rate = dW_norm / dW_norm_old;
            /* RADAU5's theta: the first ratio, then the geometric mean of the last two */
            theta = have_rate ? sqrt(rate * rate_prev) : rate;
            rate_prev = rate;
            have_rate = 1;
        }
        if (have_rate && (rate >= 1 ||
                          pow(rate, maxiter - it) / (1 - rate) * dW_norm > s->newton_tol))
            break;
        for (int i = 0; i < 3 * n; i++) W[i] += dW[i];
        for (int c = 0; c < n; c++) {
            double w0 = W[c], w1 = W[n + c], w2 = W[2 * n + c];
            Z[c] = T00 * w0 + T01 * w1 + T02 * w2;
            Z[n + c] = T10 * w0 + T11 * w1 + T12 * w2;
            Z[2 * n + c] = T20 * w0 + T21 * w1 + T22 * w2;
        }
        if (dW_norm == 0 || (have_rate && rate / (1 - rate) * dW_norm < s->newton_tol)) {
            converged = 1;
            break;
        }
        dW_norm_old = dW_norm;
        have_old = 1;
    }
    *n_iter = (it < maxiter ? it : maxiter - 1) + 1;
    *rate_out = rate;
    *have_rate_out = have_rate;
    *theta_out = theta;
    return converged;
}

/* radau.predict_factor */
static double predict_factor(double h_abs, double h_abs_old, int have_h_abs_old,
                             double error_norm, double error_norm_old, int have_error_norm_old)
{
    double multiplier;
    if (!have_error_norm_old || !have_h_abs_old || error_norm == 0)
        multiplier = 1;
    else
        multiplier = h_abs / h_abs_old * pow(error_norm_old / error_norm, 0.25);
    return fmin(1, multiplier) * pow(error_norm, -0.25);   /* inf when error_norm == 0 */
}

/* The last accepted step's dense output terms, r->dense_terms rows of n: Radau's Q
 * (x, x^2, x^3), or DOP853's F (once prepare_dense has computed them). */
static const double *dense_terms(const solver_t *s)
{
    return s->dop853 ? s->Fdense : s->Q;
}

/* RadauDenseOutput (or Dop853DenseOutput: its terms computed by prepare_dense) of the
 * last accepted step at time tt. */
static void dense(const solver_t *s, double tt, double *out)
{
    const int n = s->n;
    double x = (tt - s->t_old) / (s->dense_end - s->t_old);
    if (s->dop853) {
        dop853_eval(n, x, s->y_old, s->Fdense, out);
        return;
    }
    double p1 = x, p2 = x * x, p3 = x * x * x;
    for (int c = 0; c < n; c++)
        out[c] = s->y_old[c] + s->Q[c] * p1 + s->Q[n + c] * p2 + s->Q[2 * n + c] * p3;
}

/* The next attempt's step from t: *h_abs in the direction of integration, cut at
 * t_bound; sets *h and *t_new, and *h_abs to the cut size.  Returns 0 (message set)
 * when *h_abs is below min_step (as scipy's solvers). */
static int attempt_size(solver_t *s, double t, double min_step, double *h_abs, double *h,
                        double *t_new)
{
    if (*h_abs < min_step) {
        snprintf(s->r->message, sizeof s->r->message,
                 "Required step size is less than spacing between numbers.");
        return 0;
    }
    *h = *h_abs * s->direction;
    *t_new = t + *h;
    if (s->direction * (*t_new - s->t_bound) > 0) *t_new = s->t_bound;
    *h = *t_new - t;
    *h_abs = fabs(*h);
    return 1;
}

/* Radau._step_impl.  Returns 1 on success, 0 on failure (message set). */
static int step_radau(solver_t *s)
{
    const radau5_problem *p = s->p;
    const constants_t *k = &s->k;
    const int n = s->n;
    const double t = s->t;
    double *y = s->y;

    double min_step = 10 * fabs(nextafter(t, s->direction * INFINITY) - t);
    double h_abs, h_abs_old = 0, error_norm_old = 0;
    int have_h_abs_old = 0, have_error_norm_old = 0;
    if (s->h_abs > p->max_step) {
        h_abs = p->max_step;
    } else if (s->h_abs < min_step) {
        h_abs = min_step;
    } else {
        h_abs = s->h_abs;
        h_abs_old = s->h_abs_old; have_h_abs_old = s->have_h_abs_old;
        error_norm_old = s->error_norm_old; have_error_norm_old = s->have_error_norm_old;
    }

    const int ctrl = s->ctrl;
    int rejected = 0, converged = 0, n_iter = 0, have_rate = 0;
    double rate = 0, theta = 0, h = 0, t_new = t, error_norm = 0, safety = 0;
    double *Z = s->Znew, *y_new = s->y_new, *err = s->err, *ZE = s->ZE;
    for (;;) {   /* while not step_accepted */
        if (!attempt_size(s, t, min_step, &h_abs, &h, &t_new)) return 0;

        if (!s->have_sol) {
            memset(s->Z0, 0, 3 * n * sizeof(double));
        } else {
            for (int i = 0; i < 3; i++) {
                dense(s, t + h * k->C[i], s->Z0 + i * n);
                for (int c = 0; c < n; c++) s->Z0[i * n + c] -= y[c];
            }
        }
        for (int c = 0; c < n; c++) {
            s->scale[c] = s->atol[c] + fabs(y[c]) * s->rtol;
            s->inv_scale[c] = 1.0 / s->scale[c];
        }

        converged = 0;
        int tried_ahead = 0;
        while (!converged) {
            int lu_ok = 1;
            if (!s->lu_valid) lu_ok = factor(s, h) == 0;
            memcpy(Z, s->Z0, 3 * n * sizeof(double));
            converged = lu_ok && solve_collocation(s, t, h, Z, &n_iter, &rate, &have_rate,
                                                  &theta);
            if (!lu_ok) n_iter = 0;
            if (!converged) {
                /* The first step of a segment whose Newton fails with the Jacobian of its
                 * start: try once more with the Jacobian at the explicit Euler prediction
                 * of the step's end.  A contact law can be singular where a segment starts
                 * (the compliant law's yield: stiffness ~ n/t from contact start), where
                 * the start's Jacobian holds none of the stiffness every later point has;
                 * halving h then never helps.  Only where the caller asks (problem
                 * jacobian_ahead: segments with a compliant contact). */
                if (s->p->jacobian_ahead && s->current_jac && !s->have_sol && !tried_ahead
                    && h != 0) {
                    tried_ahead = 1;
                    for (int c = 0; c < n; c++) err[c] = y[c] + h * s->f[c];
                    if (call_jac(s, t + h, err) == 0) {
                        s->lu_valid = 0;
                        continue;
                    }
                    if (call_jac(s, t, y) != 0) {
                        snprintf(s->r->message, sizeof s->r->message,
                                 "the Jacobian cannot be evaluated at t = %.17g", t);
                        return 0;
                    }
                    s->lu_valid = 0;
                }
                if (s->current_jac) break;
                if (call_jac(s, t, y) != 0) {
                    snprintf(s->r->message, sizeof s->r->message,
                             "the Jacobian cannot be evaluated at t = %.17g", t);
                    return 0;
                }
                s->current_jac = 1;
                s->lu_valid = 0;
            }
        }
        if (!converged) {
            h_abs *= 0.5;
            s->lu_valid = 0;
            continue;
        }

        const double E0 = k->E[0] / h, E1 = k->E[1] / h, E2 = k->E[2] / h;
        for (int c = 0; c < n; c++) {
            y_new[c] = y[c] + Z[2 * n + c];
            ZE[c] = Z[c] * E0 + Z[n + c] * E1 + Z[2 * n + c] * E2;
            err[c] = s->f[c] + ZE[c];
        }
        solve_real(s, err);
        for (int c = 0; c < n; c++) {
            if (!(ctrl & RADAU5_CTRL_SCALE))
                s->scale[c] = s->atol[c] + fmax(fabs(y[c]), fabs(y_new[c])) * s->rtol;
            s->tmp[c] = err[c] / s->scale[c];
        }
        error_norm = rms(s->tmp, n);
        safety = 0.9 * (2 * s->newton_maxiter + 1) / (2 * s->newton_maxiter + n_iter);

        if (rejected && error_norm > 1) {
            for (int c = 0; c < n; c++) s->tmp[c] = y[c] + err[c];
            if (call_fun(s, t, s->tmp, err) != 0) {
                error_norm = INFINITY;   /* scipy would go on with NaN; reject instead */
            } else {
                for (int c = 0; c < n; c++) err[c] += ZE[c];
                solve_real(s, err);
                for (int c = 0; c < n; c++) s->tmp[c] = err[c] / s->scale[c];
                error_norm = rms(s->tmp, n);
            }
        }
        if (!(error_norm <= 1)) {
            double fac = (ctrl & RADAU5_CTRL_PRED)   /* RADAU5: the standard factor alone */
                         ? pow(error_norm, -0.25)
                         : predict_factor(h_abs, h_abs_old, have_h_abs_old, error_norm,
                                          error_norm_old, have_error_norm_old);
            h_abs *= fmax(MIN_FACTOR, safety * fac);
            s->lu_valid = 0;
            rejected = 1;
            s->r->nreject++;
            continue;
        }
        /* f at the new point: needed for the next step's error estimate. */
        if (call_fun(s, t_new, y_new, s->f_new) != 0) {
            h_abs *= 0.5;   /* not in scipy (it would carry NaN): treat as a failed step */
            s->lu_valid = 0;
            rejected = 1;
            s->r->nreject++;
            continue;
        }
        break;   /* step_accepted */
    }

    int recompute_jac = (ctrl & RADAU5_CTRL_JAC) ? (have_rate && theta > 1e-3)
                                                 : (n_iter > 2 && have_rate && rate > 1e-3);
    const double max_factor = (ctrl & RADAU5_CTRL_LIMITS) ? 8.0 : MAX_FACTOR;
    double fac;
    if (ctrl & RADAU5_CTRL_PRED) {
        /* RADCOR: standard factor, and Gustafsson's from the last accepted step (plain
         * safety), each within the limits; the smaller one */
        double e = fmax(error_norm, 1e-10);
        fac = fmin(max_factor, fmax(MIN_FACTOR, safety * pow(e, -0.25)));
        if (s->have_acc) {
            double gus = 0.9 * h_abs / s->h_acc * pow(s->err_acc / (e * e), 0.25);
            fac = fmin(fac, fmin(max_factor, fmax(MIN_FACTOR, gus)));
        }
        s->h_acc = h_abs;
        s->err_acc = fmax(0.01, e);
        s->have_acc = 1;
    } else {
        fac = predict_factor(h_abs, h_abs_old, have_h_abs_old, error_norm,
                             error_norm_old, have_error_norm_old);
        fac = fmin(max_factor, safety * fac);
    }
    if ((ctrl & RADAU5_CTRL_LIMITS) && rejected && fac > 1)
        fac = 1;   /* RADCOR: no growth right after a rejection */
    int hold = (ctrl & RADAU5_CTRL_HOLD) ? (fac >= 1 && fac <= 1.2) : (fac < 1.2);
    if (!recompute_jac && hold)
        fac = 1;
    else
        s->lu_valid = 0;

    if (recompute_jac && t_new == s->t_bound)
        recompute_jac = 0;   /* the last step: nothing would use it (a new run starts anew) */
    if (recompute_jac) {
        if (call_jac(s, t_new, y_new) != 0) {
            snprintf(s->r->message, sizeof s->r->message,
                     "the Jacobian cannot be evaluated at t = %.17g", t_new);
            return 0;
        }
        s->current_jac = 1;
    } else {
        s->current_jac = 0;
    }
    s->h_abs_old = s->h_abs;
    s->have_h_abs_old = 1;
    s->error_norm_old = error_norm;
    s->have_error_norm_old = 1;
    s->h_abs = h_abs * fac;

    memcpy(s->y_old, y, n * sizeof(double));
    memcpy(y, y_new, n * sizeof(double));
    memcpy(s->f, s->f_new, n * sizeof(double));
    memcpy(s->Z, Z, 3 * n * sizeof(double));
    s->t_old = t;
    s->t = t_new;
    s->dense_end = t_new;
    /* _compute_dense_output: Q = Z^T P (n x 3), stored transposed: row j holds the x^(j+1)
     * coefficients of the n states (the layout of the stored dense output) */
    for (int c = 0; c < n; c++)
        for (int j = 0; j < 3; j++)
            s->Q[j * n + c] = Z[c] * k->P[0][j] + Z[n + c] * k->P[1][j] + Z[2 * n + c] * k->P[2][j];
    s->have_sol = 1;
    s->r->nstep++;
    return 1;
}

/* The function the DOP853 stages call: call_fun (counted, checked, profiled). */
static int dop853_call(void *ctx, double t, const double *y, double *f)
{
    solver_t *s = ctx;
    return call_fun(s, t, y, f);
}

/* RungeKutta._step_impl with DOP853's error norm.  Returns 1 on success, 0 on failure
 * (message set).  A step whose stages cannot be evaluated is rejected with its size
 * halved (scipy would carry the NaN on). */
static int step_dop853(solver_t *s)
{
    const radau5_problem *p = s->p;
    const int n = s->n;
    const double t = s->t;
    double *y = s->y, *y_new = s->y_new, *K = s->K;
    const double exponent = -1.0 / (DOP853_ERROR_ORDER + 1);
    double min_step = 10 * fabs(nextafter(t, s->direction * INFINITY) - t);
    double h_abs = s->h_abs > p->max_step ? p->max_step
                   : (s->h_abs < min_step ? min_step : s->h_abs);
    int rejected = 0;
    double h = 0, t_new = t;
    memcpy(K, s->f, n * sizeof(double));
    s->k_stale = 1;   /* until an attempt is accepted: K no longer holds the last step's */
    for (;;) {
        if (!attempt_size(s, t, min_step, &h_abs, &h, &t_new)) return 0;
        if (dop853_attempt(dop853_call, s, n, t, h, y, K, y_new, s->tmp) != 0) {
            h_abs *= 0.5;
            rejected = 1;
            s->r->nreject++;
            continue;
        }
        for (int c = 0; c < n; c++)
            s->scale[c] = s->atol[c] + fmax(fabs(y[c]), fabs(y_new[c])) * s->rtol;
        double error_norm = dop853_error_norm(n, K, h, s->scale, s->err, s->ZE);
        if (error_norm < 1) {
            double factor = error_norm == 0 ? MAX_FACTOR
                            : fmin(MAX_FACTOR, 0.9 * pow(error_norm, exponent));
            if (rejected) factor = fmin(1, factor);
            h_abs *= factor;
            break;
        }
        h_abs *= fmax(MIN_FACTOR, 0.9 * pow(error_norm, exponent));
        rejected = 1;
        s->r->nreject++;
    }
    /* Hairer's stiffness test (dop853.f, after each accepted step here): h lambda
     * estimated from the last two stages at c = 1, K[11] at the stage argument (s->tmp,
     * as dop853_attempt left it) and K[12] at y_new; 15 estimates in a row beyond the
     * stability boundary (6.1) mean the steps are bounded by stability, not accuracy */
    double num = 0, den = 0;
    for (int c = 0; c < n; c++) {
        double dk = K[DOP853_STAGES * n + c] - K[(DOP853_STAGES - 1) * n + c];
        double dy = y_new[c] - s->tmp[c];
        num += dk * dk;
        den += dy * dy;
    }
    if (den > 0 && fabs(h) * sqrt(num / den) > 6.1) {
        s->nonstiff_steps = 0;
        if (++s->stiff_steps == 15 && isnan(s->r->stiff_at)) s->r->stiff_at = t;
    } else if (++s->nonstiff_steps == 6) {
        s->stiff_steps = 0;
    }
    s->h_abs = h_abs;
    memcpy(s->y_old, y, n * sizeof(double));
    memcpy(y, y_new, n * sizeof(double));
    memcpy(s->f, K + DOP853_STAGES * n, n * sizeof(double));
    s->t_old = t;
    s->t = t_new;
    s->dense_end = t_new;
    s->dense_ready = 0;
    s->k_stale = 0;
    s->have_sol = 1;
    s->r->nstep++;
    return 1;
}

static int step(solver_t *s)
{
    return s->dop853 ? step_dop853(s) : step_radau(s);
}

/* The last step's dense output made ready for dense(): DOP853 computes its extra stages
 * here, once per step and only for the steps whose dense output is used (Radau's is
 * part of the step).  Returns 0, or -1 (message set) when they cannot be evaluated. */
static int prepare_dense(solver_t *s)
{
    if (!s->dop853 || s->dense_ready) return 0;
    if (s->k_stale) {   /* a step failed after this one without its dense output made */
        snprintf(s->r->message, sizeof s->r->message,
                 "the dense output of the step from t = %.17g was lost to a failed step",
                 s->t_old);
        return -1;
    }
    if (dop853_dense(dop853_call, s, s->n, s->t_old, s->t - s->t_old, s->y_old, s->y, s->K,
                     s->Fdense, s->tmp) != 0) {
        snprintf(s->r->message, sizeof s->r->message,
                 "the right-hand side cannot be evaluated for the dense output of the step "
                 "from t = %.17g", s->t_old);
        return -1;
    }
    s->dense_ready = 1;
    return 0;
}

/* common.select_initial_step with the error estimator's order (Radau 3, DOP853 7). */
static double initial_step(solver_t *s)
{
    const radau5_problem *p = s->p;
    const int n = s->n;
    double interval = fabs(p->t_bound - p->t0);
    if (interval == 0) return 0;
    double d0 = 0, d1 = 0, d2 = 0;
    for (int c = 0; c < n; c++) {
        s->scale[c] = s->atol[c] + fabs(s->y[c]) * s->rtol;
        d0 += (s->y[c] / s->scale[c]) * (s->y[c] / s->scale[c]);
        d1 += (s->f[c] / s->scale[c]) * (s->f[c] / s->scale[c]);
    }
    d0 = sqrt(d0 / n);
    d1 = sqrt(d1 / n);
    double h0 = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
    h0 = fmin(h0, interval);
    for (int c = 0; c < n; c++) s->tmp[c] = s->y[c] + h0 * s->direction * s->f[c];
    if (call_fun(s, p->t0 + h0 * s->direction, s->tmp, s->f_new) == 0) {
        for (int c = 0; c < n; c++) {
            double v = (s->f_new[c] - s->f[c]) / s->scale[c];
            d2 += v * v;
        }
        d2 = sqrt(d2 / n) / h0;
    }
    const int order = s->dop853 ? DOP853_ERROR_ORDER : 3;
    double h1 = (d1 <= 1e-15 && d2 <= 1e-15) ? fmax(1e-6, h0 * 1e-3)
                                             : pow(0.01 / fmax(d1, d2), 1.0 / (order + 1));
    return fmin(fmin(100 * h0, h1), fmin(interval, p->max_step));
}

/* ---- output buffers ---- */

/* *buffer grown to hold ``count`` items of ``size`` bytes; 0, or -1 when memory ran
 * out (the old buffer is kept, so what was stored can still be returned). */
static int grow(void *buffer, size_t count, size_t size)
{
    void **slot = buffer;
    void *grown = realloc(*slot, count * size);
    if (!grown) return -1;
    *slot = grown;
    return 0;
}

/* Room for one more item in buffers of capacity *cap holding *used items: doubled
 * (from ``first``) when full.  Each buffer i holds ``sizes[i]`` bytes per item. */
static int reserve(size_t *cap, long used, size_t first, int k, void **buffers[],
                   const size_t sizes[])
{
    if ((size_t)used < *cap) return 0;
    size_t next = *cap ? 2 * *cap : first;
    for (int i = 0; i < k; i++)
        if (grow(buffers[i], next, sizes[i]) != 0) return -1;
    *cap = next;
    return 0;
}

static int store_point(solver_t *s, double t, const double *y)
{
    radau5_result *r = s->r;
    void **buffers[] = {(void **)&r->t_out, (void **)&r->y_out};
    const size_t sizes[] = {sizeof(double), s->n * sizeof(double)};
    if (reserve(&s->cap_out, r->n_out, 256, 2, buffers, sizes) != 0) return -1;
    r->t_out[r->n_out] = t;
    memcpy(r->y_out + r->n_out * s->n, y, s->n * sizeof(double));
    r->n_out++;
    return 0;
}

static int store_hit(solver_t *s, int event, double t, const double *y)
{
    radau5_result *r = s->r;
    void **buffers[] = {(void **)&r->hit_event, (void **)&r->hit_t, (void **)&r->hit_y};
    const size_t sizes[] = {sizeof(int), sizeof(double), s->n * sizeof(double)};
    if (reserve(&s->cap_hits, r->n_hits, 16, 3, buffers, sizes) != 0) return -1;
    r->hit_event[r->n_hits] = event;
    r->hit_t[r->n_hits] = t;
    memcpy(r->hit_y + r->n_hits * s->n, y, s->n * sizeof(double));
    r->n_hits++;
    return 0;
}

/* The last accepted step's interpolant, for dense output over the whole run.  Returns
 * 0, -1 on out of memory, -2 when the dense output cannot be computed (message set). */
static int store_dense(solver_t *s)
{
    radau5_result *r = s->r;
    const int n = s->n;
    if (prepare_dense(s) != 0) return -2;
    void **buffers[] = {(void **)&r->dense_t, (void **)&r->dense_c};
    const int terms = r->dense_terms;
    const size_t sizes[] = {2 * sizeof(double), (1 + terms) * (size_t)n * sizeof(double)};
    if (reserve(&s->cap_dense, r->n_dense, 256, 2, buffers, sizes) != 0) return -1;
    r->dense_t[2 * r->n_dense] = s->t_old;
    r->dense_t[2 * r->n_dense + 1] = s->t;
    double *c = r->dense_c + (size_t)r->n_dense * (1 + terms) * n;
    memcpy(c, s->y_old, n * sizeof(double));
    memcpy(c + n, dense_terms(s), (size_t)terms * n * sizeof(double));
    r->n_dense++;
    return 0;
}

/* ---- events ---- */

/* g_e(t, y): c . y + offset, or the system's event function + offset, as solve_ivp
 * evaluates an event (no gating: the driver keeps segments from starting on an event's
 * zero; see simulate.py).  NaN when the system cannot evaluate it. */
static int is_nonlinear(const solver_t *s, int e)
{
    return s->p->ev_nonlinear != NULL && s->p->ev_nonlinear[e];
}

static double event_value(const solver_t *s, int e, double t, const double *y)
{
    double g = s->p->ev_offset[e];
    if (is_nonlinear(s, e)) {
        double v;
        if (s->p->ev_fun == NULL || s->p->ev_fun(s->p->ctx, e, t, y, &v) != 0) return NAN;
        return g + v;
    }
    const double *c = s->p->ev_coef + (size_t)e * s->n;
    for (int i = 0; i < s->n; i++) g += c[i] * y[i];
    return g;
}

/* A function of t whose root brentq finds. */
typedef double (*scalar_fn)(void *ctx, double t);

/* A linear event on the last step's dense output: c . y_old + offset plus the dense
 * output's terms dotted with c, a polynomial in x = (t - t_old) / h (Radau: a cubic,
 * a[j] the coefficient of x^(j+1); DOP853: dop853_eval_scalar's nested form). */
typedef struct { double a0, a[DOP853_DENSE_TERMS], t_old, h; int dop853; } poly_t;

static double poly_at(void *ctx, double tt)
{
    const poly_t *q = ctx;
    double x = (tt - q->t_old) / q->h;
    if (q->dop853) return dop853_eval_scalar(x, q->a0, q->a);
    return q->a0 + x * (q->a[0] + x * (q->a[1] + x * q->a[2]));
}

/* A system event on the last step's dense output. */
typedef struct { solver_t *s; int e; } dense_event_t;

static void dense(const solver_t *s, double tt, double *out);

static double dense_event_at(void *ctx, double tt)
{
    const dense_event_t *q = ctx;
    dense(q->s, tt, q->s->ev_y);
    return event_value(q->s, q->e, tt, q->s->ev_y);
}

/* scipy.optimize.brentq (scipy/optimize/Zeros/brentq.c) with rtol = 4 eps as in
 * solve_ivp's solve_event_equation, but xtol = 4 eps times the step instead of 4 eps
 * (seconds): a root inside a step shorter than ~1e-15 s (a 10-um steel ball's contact
 * lasts 1e-8 s, its slip stops within 1e-16 s) is still located, not put at an end. */
static double brentq(scalar_fn f, void *q, double xa, double xb)
{
    const double xtol = 4 * EPS * fabs(xb - xa), rtol = 4 * EPS;
    double xpre = xa, xcur = xb, xblk = 0, fblk = 0, spre = 0, scur = 0;
    double fpre = f(q, xpre), fcur = f(q, xcur);
    if (fpre == 0) return xpre;
    if (fcur == 0) return xcur;
    if (signbit(fpre) == signbit(fcur))   /* rounding at a bracket end: take the nearer */
        return fabs(fpre) < fabs(fcur) ? xpre : xcur;
    for (int i = 0; i < 100; i++) {
        if (fpre != 0 && fcur != 0 && signbit(fpre) != signbit(fcur)) {
            xblk = xpre;
            fblk = fpre;
            spre = scur = xcur - xpre;
        }
        if (fabs(fblk) < fabs(fcur)) {
            xpre = xcur; xcur = xblk; xblk = xpre;
            fpre = fcur; fcur = fblk; fblk = fpre;
        }
        double delta = (xtol + rtol * fabs(xcur)) / 2;
        double sbis = (xblk - xcur) / 2;
        if (fcur == 0 || fabs(sbis) < delta) return xcur;
        if (fabs(spre) > delta && fabs(fcur) < fabs(fpre)) {
            double stry;
            if (xpre == xblk) {
                stry = -fcur * (xcur - xpre) / (fcur - fpre);
            } else {
                double dpre = (fpre - fcur) / (xpre - xcur);
                double dblk = (fblk - fcur) / (xblk - xcur);
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre));
            }
            if (2 * fabs(stry) < fmin(fabs(spre), 3 * fabs(sbis) - delta)) {
                spre = scur;
                scur = stry;
            } else {
                spre = sbis;
                scur = sbis;
            }
        } else {
            spre = sbis;
            scur = sbis;
        }
        xpre = xcur;
        fpre = fcur;
        xcur += fabs(scur) > delta ? scur : (sbis > 0 ? delta : -delta);
        fcur = f(q, xcur);
    }
    return xcur;
}

static double event_root(solver_t *s, int e)
{
    if (is_nonlinear(s, e)) {
        dense_event_t q = {s, e};
        return brentq(dense_event_at, &q, s->t_old, s->t);
    }
    const int n = s->n;
    const double *c = s->p->ev_coef + (size_t)e * n;
    poly_t q = {s->p->ev_offset[e], {0}, s->t_old, s->t - s->t_old, s->dop853};
    for (int i = 0; i < n; i++) q.a0 += c[i] * s->y_old[i];
    const double *rows = dense_terms(s);
    for (int j = 0; j < s->r->dense_terms; j++)
        for (int i = 0; i < n; i++) q.a[j] += c[i] * rows[j * n + i];
    return brentq(poly_at, &q, s->t_old, s->t);
}

/* ivp.find_active_events + handle_events after a step.  Returns 1 when a terminal
 * event stopped the integration (then *t_stop is its time), 0 otherwise, -1 on
 * out of memory, -2 when the dense output cannot be computed (message set).  As
 * solve_ivp (scipy >= 1.12): every event that changed sign in the step counts one
 * occurrence, and an event with ev_terminal = k > 0 stops the integration at its k-th
 * occurrence (the earliest such root of the step when several reach theirs). */
static int handle_events(solver_t *s, double *t_stop)
{
    const radau5_problem *p = s->p;
    int m = 0, terminate = 0;
    for (int e = 0; e < p->n_events; e++) {
        double g = s->g[e], gn = s->g_new[e];
        int up = g <= 0 && gn >= 0, down = g >= 0 && gn <= 0;
        int dir = p->ev_direction[e];
        if ((up && dir > 0) || (down && dir < 0) || ((up || down) && dir == 0))
            s->active[m++] = e;
    }
    if (m == 0) return 0;
    if (prepare_dense(s) != 0) return -2;
    for (int i = 0; i < m; i++) {
        int e = s->active[i];
        s->roots[i] = event_root(s, e);
        s->ev_count[e]++;
        if (p->ev_terminal[e] > 0 && s->ev_count[e] >= p->ev_terminal[e]) terminate = 1;
    }
    if (terminate) {
        /* order by time (in the direction of integration), keep up to the first terminal */
        for (int i = 1; i < m; i++) {
            int a = s->active[i];
            double rt = s->roots[i];
            int j = i - 1;
            while (j >= 0 && s->direction * (s->roots[j] - rt) > 0) {
                s->active[j + 1] = s->active[j];
                s->roots[j + 1] = s->roots[j];
                j--;
            }
            s->active[j + 1] = a;
            s->roots[j + 1] = rt;
        }
        for (int i = 0; i < m; i++) {
            int e = s->active[i];
            if (p->ev_terminal[e] > 0 && s->ev_count[e] >= p->ev_terminal[e]) {
                m = i + 1;
                break;
            }
        }
    }
    for (int i = 0; i < m; i++) {
        dense(s, s->roots[i], s->tmp);
        if (store_hit(s, s->active[i], s->roots[i], s->tmp) != 0) return -1;
    }
    if (terminate) *t_stop = s->roots[m - 1];
    return terminate;
}

/* Store the points of t_eval up to t_upto from the last step's dense output.  Returns
 * 0, -1 on out of memory, -2 when the dense output cannot be computed (message set). */
static int store_eval(solver_t *s, double t_upto)
{
    const radau5_problem *p = s->p;
    while (s->i_eval < p->n_eval && s->direction * (p->t_eval[s->i_eval] - t_upto) <= 0) {
        if (prepare_dense(s) != 0) return -2;
        dense(s, p->t_eval[s->i_eval], s->err);
        if (store_point(s, p->t_eval[s->i_eval], s->err) != 0) return -1;
        s->i_eval++;
    }
    return 0;
}

/* Step to a terminal event's time: integrate again from the start of the step that
 * crossed it, t_old, to exactly t_stop (usually one step, with the full error control).
 * The state there is a step's end point, of the method's order 5 (with the error
 * estimate's control), where the dense output it replaces is a cubic of order 3
 * between the nodes and carries no error control at all: at loose tolerances across a
 * contact's end (where the Hertz force's higher derivatives are singular) it was off
 * by 100 times the tolerance.  On success y_stop (n) is overwritten with the new state
 * and the interpolant of the crossing step is replaced by those of the new steps;
 * when a step fails y_stop is kept (the dense value) and so is the old interpolant of
 * the dense output (t_eval points already stored from new steps stay; any later ones
 * up to t_stop from the interpolant in hand: the last new step's, else the crossing
 * step's).
 * The next step size (h_next) stays the one chosen before.  The crossing step is no
 * predictor here: past the event the equations may jump (the slip law's orientation
 * flips where u . d < 0, just past a slip's approach event), and a polynomial through
 * the jump sent Newton astray (measured: 13-15 halvings instead of one step), so the
 * first new step starts from zero stage increments, with a Jacobian taken at its start
 * if the one in hand was taken past it.  Returns 1 when refined, 0 when kept, -1 when
 * out of memory. */
static int step_to_event(solver_t *s, double t_stop, double *y_stop)
{
    const int n = s->n;
    if (!(s->direction * (t_stop - s->t_old) > 0 && s->direction * (s->t - t_stop) > 0))
        return 0;   /* at a step's end point already */
    const double h_next = s->h_abs;
    const long n_dense = s->r->n_dense;
    s->t = s->t_old;
    s->have_sol = 0;   /* zero predictor: see above */
    memcpy(s->y, s->y_old, n * sizeof(double));
    int ok = call_fun(s, s->t, s->y, s->f) == 0;
    if (ok && !s->dop853 && s->direction * (s->jac_t - s->t) > 0) {
        /* J was evaluated at the crossing step's end, past the event (the mode's
         * equations may have turned sharply there, e.g. a slip direction swinging
         * through zero): take it at the start again */
        ok = call_jac(s, s->t, s->y) == 0;
        s->current_jac = 1;
    }
    s->t_bound = t_stop;
    s->h_abs = fabs(t_stop - s->t);
    s->lu_valid = 0;
    while (ok && s->direction * (t_stop - s->t) > 0) {
        ok = step(s);
        int rc = 0;
        if (ok && s->p->dense_output) rc = store_dense(s);
        if (ok && rc == 0 && s->p->t_eval != NULL) rc = store_eval(s, s->t);
        if (rc == -1) return -1;
        if (rc != 0) ok = 0;   /* the dense output failed: as a failed step */
    }
    s->t_bound = s->p->t_bound;
    s->h_abs = h_next;
    radau5_result *r = s->r;
    if (!ok) {   /* keep the dense value; drop the pieces of the new steps */
        r->n_dense = n_dense;
        return 0;
    }
    memcpy(y_stop, s->y, n * sizeof(double));
    if (s->p->dense_output) {   /* the new steps' pieces replace the crossing step's */
        const size_t width = (1 + (size_t)r->dense_terms) * n;
        memmove(r->dense_t + 2 * (n_dense - 1), r->dense_t + 2 * n_dense,
                2 * (size_t)(r->n_dense - n_dense) * sizeof(double));
        memmove(r->dense_c + (n_dense - 1) * width, r->dense_c + n_dense * width,
                (size_t)(r->n_dense - n_dense) * width * sizeof(double));
        r->n_dense--;
    }
    return 1;
}

/* ---- driver (solve_ivp's loop) ---- */

void radau5_free(radau5_result *r)
{
    free(r->t_out); free(r->y_out);
    free(r->hit_event); free(r->hit_t); free(r->hit_y);
    free(r->dense_t); free(r->dense_c);
    r->t_out = r->y_out = r->hit_t = r->hit_y = r->dense_t = r->dense_c = NULL;
    r->n_dense = 0;
    r->hit_event = NULL;
    r->n_out = r->n_hits = 0;
}

int radau5_solve(const radau5_problem *p, radau5_result *r)
{
    memset(r, 0, sizeof *r);
    r->stiff_at = NAN;
    const int n = p->n, m = p->n_events;
    r->status = RADAU5_FAILED;
    if (n <= 0 || m < 0) {
        snprintf(r->message, sizeof r->message, "n = %d and n_events = %d: need n > 0, n_events >= 0", n, m);
        return RADAU5_BAD_PROBLEM;
    }
    if (p->method != RADAU5_METHOD_RADAU && p->method != RADAU5_METHOD_DOP853) {
        snprintf(r->message, sizeof r->message, "method = %d: need RADAU5_METHOD_RADAU (0) "
                 "or RADAU5_METHOD_DOP853 (1)", p->method);
        return RADAU5_BAD_PROBLEM;
    }
    if (p->method == RADAU5_METHOD_RADAU && p->jac == NULL) {
        snprintf(r->message, sizeof r->message, "Radau needs a Jacobian: jac is NULL");
        return RADAU5_BAD_PROBLEM;
    }

#ifdef RADAU5_PROFILE
    prof_acc = r->prof;
    struct timespec prof_ts0, prof_ts1;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &prof_ts0);
    unsigned long long prof_total0 = __rdtsc();
    r->profiled = 1;
#endif
    solver_t s;
    memset(&s, 0, sizeof s);
    s.p = p;
    s.r = r;
    s.n = n;
    s.dop853 = p->method == RADAU5_METHOD_DOP853;
    r->dense_terms = s.dop853 ? DOP853_DENSE_TERMS : 3;
    init_constants(&s.k);
    s.direction = p->t_bound >= p->t0 ? 1.0 : -1.0;
    s.ctrl = p->controller;
    s.newton_maxiter = (s.ctrl & RADAU5_CTRL_NIT7) ? 7 : NEWTON_MAXITER;
    s.rtol = (s.ctrl & RADAU5_CTRL_TOL) ? 0.1 * pow(p->rtol, 2.0 / 3) : p->rtol;
    s.newton_tol = fmax(10 * EPS / s.rtol, fmin(0.03, sqrt(s.rtol)));

    /* one block of doubles, one of complex, one of ints */
    size_t nd = (size_t)n * (1 + 1 + 1 + 1 + 1 + 1 + 1 + 1 + 1) /* y f y_old y_new f_new scale tmp err ZE */
         + (size_t)n * n * 2                                /* J, LU_real */
         + (size_t)n * 3 * 7                                /* Z Q Z0 Znew W F dW */
         + (size_t)m * 3 + (size_t)n                        /* g g_new roots, ev_y */
         + (size_t)n * n + (size_t)n                        /* Joc, xc */
         + (size_t)n                                        /* atol */
         + (size_t)n                                        /* inv_scale */
         + (size_t)n * (DOP853_STAGES_EXTENDED + DOP853_DENSE_TERMS);   /* K, F */
    double *dblock = calloc(nd, sizeof(double));
    cplx *cblock = calloc((size_t)n * n + 2 * (size_t)n, sizeof(cplx));
    int *iblock = calloc(5 * (size_t)n + 3 * (size_t)m + 3 + (size_t)n * n, sizeof(int));
    int rc = 0;
    if (!dblock || !cblock || !iblock) goto oom;
    double *d = dblock;
    s.y = d; d += n; s.f = d; d += n; s.y_old = d; d += n; s.y_new = d; d += n;
    s.f_new = d; d += n; s.scale = d; d += n; s.tmp = d; d += n; s.err = d; d += n;
    s.ZE = d; d += n;
    s.J = d; d += n * n; s.LU_real = d; d += n * n;
    s.Z = d; d += 3 * n; s.Q = d; d += 3 * n; s.Z0 = d; d += 3 * n; s.Znew = d; d += 3 * n;
    s.W = d; d += 3 * n; s.F = d; d += 3 * n; s.dW = d; d += 3 * n;
    s.g = d; d += m; s.g_new = d; d += m; s.roots = d; d += m; s.ev_y = d; d += n;
    s.Joc = d; d += n * n; s.xc = d; d += n;
    s.atol = d; d += n;
    s.inv_scale = d; d += n;
    s.K = d; d += (size_t)n * DOP853_STAGES_EXTENDED;
    s.Fdense = d; d += (size_t)n * DOP853_DENSE_TERMS;
    for (int c = 0; c < n; c++) s.atol[c] = s.rtol * (p->atol[c] / p->rtol);
    if (!(s.ctrl & RADAU5_CTRL_TOL)) memcpy(s.atol, p->atol, n * sizeof(double));
    s.LU_complex = cblock; s.ctmp = cblock + (size_t)n * n; s.xcc = s.ctmp + n;
    s.piv_real = iblock; s.piv_complex = iblock + n;
    s.active = iblock + 2 * n;
    s.ev_count = iblock + 2 * n + 2 * m;   /* zero: calloc */
    s.cidx = s.ev_count + m; s.oidx = s.cidx + n;
    s.joc_start = s.oidx + n; s.joc_col = s.joc_start + n + 1;

    s.t = p->t0;
    s.t_bound = p->t_bound;
    memcpy(s.y, p->y0, n * sizeof(double));
    if (p->t_eval == NULL) {
        if (store_point(&s, s.t, s.y) != 0) goto oom;
    }
    if (call_fun(&s, s.t, s.y, s.f) != 0) {
        snprintf(r->message, sizeof r->message,
                 "the right-hand side cannot be evaluated at the initial state (t = %.17g)", s.t);
        r->status = RADAU5_FAILED;
        goto done;
    }
    for (int e = 0; e < m; e++) s.g[e] = event_value(&s, e, s.t, s.y);
    s.h_abs = p->first_step > 0 ? p->first_step : initial_step(&s);
    if (!s.dop853 && call_jac(&s, s.t, s.y) != 0) {
        snprintf(r->message, sizeof r->message,
                 "the Jacobian cannot be evaluated at the initial state (t = %.17g)", s.t);
        r->status = RADAU5_FAILED;
        goto done;
    }
    s.current_jac = 1;
    if (s.t == p->t_bound) {   /* empty interval: nothing to integrate */
        r->status = RADAU5_REACHED;
        snprintf(r->message, sizeof r->message,
                 "The solver successfully reached the end of the integration interval.");
        goto done;
    }

    for (;;) {
        if (p->max_nfev > 0 && r->nfev >= p->max_nfev) {
            r->status = RADAU5_FAILED;
            snprintf(r->message, sizeof r->message,
                     "gave up at t = %.9g after %ld right-hand-side evaluations (max_nfev)",
                     s.t, r->nfev);
            break;
        }
        if (!step(&s)) {
            r->status = RADAU5_FAILED;
            break;
        }
        int rc = p->dense_output ? store_dense(&s) : 0;
        if (rc == -1) goto oom;
        if (rc != 0) break;   /* status RADAU5_FAILED, message set */
        int finished = s.direction * (s.t - p->t_bound) >= 0;
        double t_out = s.t;
        const double *y_out = s.y;
        int terminate = 0;
        if (m > 0) {
            PROF_START;
            for (int e = 0; e < m; e++) s.g_new[e] = event_value(&s, e, s.t, s.y);
            terminate = handle_events(&s, &t_out);
            PROF_STOP(RADAU5_PROF_EVENTS);
            if (terminate == -1) goto oom;
            if (terminate < 0) break;   /* status RADAU5_FAILED, message set */
            if (terminate) {   /* handle_events stored the hit's state, from the dense output */
                double *hit = r->hit_y + (size_t)(r->n_hits - 1) * n;
                const int e_hit = r->hit_event[r->n_hits - 1];
                int refined = 0;
                if (p->refine_events && (refined = step_to_event(&s, t_out, hit)) < 0) goto oom;
                y_out = hit;
                if (refined == 1 && p->rearm != NULL && p->ev_rearm != NULL
                        && p->ev_rearm[e_hit] && p->rearm(p->ctx, e_hit, s.t, s.y) == 1) {
                    /* re-armed: no stop and no hit; go on from the event's state (the
                     * solver's, a step's end) with the new event */
                    r->n_hits--;
                    r->n_rearmed++;
                    terminate = 0;
                    y_out = s.y;
                    finished = s.direction * (s.t - p->t_bound) >= 0;
                    for (int e = 0; e < m; e++) s.g_new[e] = event_value(&s, e, s.t, s.y);
                }
            }
            memcpy(s.g, s.g_new, m * sizeof(double));
        }
        if (p->t_eval == NULL) {
            if (store_point(&s, t_out, y_out) != 0) goto oom;
        } else if ((rc = store_eval(&s, t_out)) != 0) {
            if (rc == -1) goto oom;
            break;   /* status RADAU5_FAILED, message set */
        }
        if (terminate) {
            r->status = RADAU5_EVENT;
            snprintf(r->message, sizeof r->message, "A termination event occurred.");
            break;
        }
        if (finished) {
            r->status = RADAU5_REACHED;
            snprintf(r->message, sizeof r->message,
                     "The solver successfully reached the end of the integration interval.");
            break;
        }
    }
    goto done;
oom:
    rc = RADAU5_OUT_OF_MEMORY;
    r->status = RADAU5_FAILED;
    snprintf(r->message, sizeof r->message, "out of memory");
done:
    r->h_next = s.h_abs;
#ifdef RADAU5_PROFILE
    r->prof[RADAU5_PROF_TOTAL] += (double)(__rdtsc() - prof_total0);
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &prof_ts1);
    r->prof[RADAU5_PROF_TOTAL_NS] += 1e9 * (double)(prof_ts1.tv_sec - prof_ts0.tv_sec)
                                     + (double)(prof_ts1.tv_nsec - prof_ts0.tv_nsec);
#endif
    free(dblock);
    free(cblock);
    free(iblock);
    return rc;
}

/* The method's constants as the solver uses them, for tests/test_radau5_constants.py
 * (compared with scipy.integrate._ivp.radau).  out[RADAU5_N_CONSTANTS], see the header
 * for the layout. */
void radau5_constants(double *out)
{
    constants_t k;
    init_constants(&k);
    double *o = out;
    for (int i = 0; i < 3; i++) *o++ = k.C[i];
    for (int i = 0; i < 3; i++) *o++ = k.E[i];
    for (int i = 0; i < 3; i++) for (int j = 0; j < 3; j++) *o++ = k.T[i][j];
    for (int i = 0; i < 3; i++) for (int j = 0; j < 3; j++) *o++ = k.TI[i][j];
    for (int i = 0; i < 3; i++) for (int j = 0; j < 3; j++) *o++ = k.P[i][j];
    *o++ = k.mu_real;
    *o++ = creal(k.mu_complex);
    *o++ = cimag(k.mu_complex);
    for (int j = 0; j < 3; j++) *o++ = creal(k.ti_complex[j]);
    for (int j = 0; j < 3; j++) *o++ = cimag(k.ti_complex[j]);
    *o++ = NEWTON_MAXITER;
    *o++ = MIN_FACTOR;
    *o++ = MAX_FACTOR;
}
