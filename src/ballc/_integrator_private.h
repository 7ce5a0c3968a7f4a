/* The integrator's private interface: the state the loop (_integrator.c) and the
 * methods' steps (_radau_iia.c, _dop853.c) share, and the small helpers they both use
 * (static inline: each file compiles its own copy, as when they were one file).  Not
 * part of the public API (_integrator.h); not for the Cython bridge. */
#ifndef BALLC_INTEGRATOR_PRIVATE_H
#define BALLC_INTEGRATOR_PRIVATE_H

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "_dop853.h"
#include "_integrator.h"
#include "_radau_iia.h"

#define NEWTON_MAXITER 6   /* Maximum number of Newton iterations. */
#define MIN_FACTOR 0.2     /* Minimum allowed decrease in a step size. */
#define MAX_FACTOR 10.0    /* Maximum allowed increase in a step size. */
#define EPS DBL_EPSILON

/* Compiled with -DRADAU5_PROFILE (benchmarks/profile_step.py): time-stamp-counter
 * ticks of the right-hand side, Jacobian (with partition), factorisations and
 * solves, and of the whole radau5_solve, in result->prof.  Otherwise no-ops. */
#ifdef RADAU5_PROFILE
#include <x86intrin.h>
extern __thread double *ballc_prof_acc;   /* the result's prof (_integrator.c) */
#define PROF_START unsigned long long prof_t0_ = __rdtsc()
#define PROF_STOP(k) (ballc_prof_acc[k] += (double)(__rdtsc() - prof_t0_))
#else
#define PROF_START (void)0
#define PROF_STOP(k) (void)0
#endif

typedef double _Complex cplx;
typedef radau_iia_constants constants_t;

/* Everything the integration carries from step to step. */
typedef struct ballc_solver {
    const radau5_problem *p;
    radau5_result *r;
    constants_t k;
    int n;
    int n_norm;                         /* the RMS norms' divisor (problem.norm_states) */
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
    int stiff_steps, nonstiff_steps;      /* Hairer's stiffness test (dop853_step) */
    /* The interpolant in hand (the last accepted step's) is DOP853's: set by the step
     * that was accepted.  Equal to dop853 except with RADAU5_METHOD_AUTO, where the
     * method may change between steps. */
    int dense_dop853;
    /* RADAU5_METHOD_AUTO (_integrator.c: auto_switch): the method may change before a
     * step; calm_steps: Radau steps in a row with h rho(J) < AUTO_CALM_BOUND;
     * probe_steps: DOP853 steps since the last probe, which began at probe_t;
     * stiff_probe: the last probe found the steps stiff;
     * rho: the estimate for the Jacobian of njev number rho_njev (-1: none yet);
     * pw: 2 n scratch of the power iteration */
    int auto_mode, calm_steps, probe_steps, stiff_probe;
    double probe_t;
    long rho_njev;
    double rho, *pw;
    size_t cap_switch;
    /* events */
    double *g, *g_new, *roots, *ev_y;   /* ev_y: scratch state of event evaluations */
    int *active;
    int *ev_count;                      /* occurrences of each event in this call */
    size_t cap_out, cap_hits, cap_dense;
} solver_t;

/* common.norm: RMS norm (two partial sums: half the chain of dependent additions) of
 * x's n values, the sum divided by ``count`` (solver_t.n_norm). */
static inline double rms(const double *x, int n, int count)
{
    double s0 = 0, s1 = 0;
    int i = 0;
    for (; i + 1 < n; i += 2) {
        s0 += x[i] * x[i];
        s1 += x[i + 1] * x[i + 1];
    }
    if (i < n) s0 += x[i] * x[i];
    return sqrt((s0 + s1) / count);
}

static inline int call_fun(solver_t *s, double t, const double *y, double *f)
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

/* The last accepted step's dense output terms, r->dense_terms rows of n: Radau's Q
 * (x, x^2, x^3), or DOP853's F (once prepare_dense has computed them). */
static inline const double *dense_terms(const solver_t *s)
{
    return s->dense_dop853 ? s->Fdense : s->Q;
}

/* The number of dense-output terms of the interpolant in hand: 7 (DOP853) or 3. */
static inline int dense_terms_count(const solver_t *s)
{
    return s->dense_dop853 ? DOP853_DENSE_TERMS : 3;
}

/* RadauDenseOutput (or Dop853DenseOutput: its terms computed by prepare_dense) of the
 * last accepted step at time tt (whichever method took it: dense_dop853). */
static inline void dense(const solver_t *s, double tt, double *out)
{
    const int n = s->n;
    double x = (tt - s->t_old) / (s->dense_end - s->t_old);
    if (s->dense_dop853) {
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
static inline int attempt_size(solver_t *s, double t, double min_step, double *h_abs, double *h,
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

#endif
