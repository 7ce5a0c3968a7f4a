/* integrator: the integration loop of ballc's compiled integrators (_integrator.c,
 * radau5_solve) and its public API; the steps are the methods' own files:
 *   - Radau IIA of order 5 (_radau_iia.c, problem.method = RADAU5_METHOD_RADAU, the
 *     default): scipy.integrate.Radau's method and error control
 *     (scipy/integrate/_ivp/radau.py): the same constants, simplified Newton iteration
 *     on the transformed collocation system (one real and one complex linear system per
 *     iteration), third-order embedded error estimate (with the extra solve after a
 *     rejection), predictive (Gustafsson) step-size controller, Jacobian / LU reuse
 *     strategy and collocation-polynomial dense output;
 *   - DOP853 (_dop853.c, problem.method = RADAU5_METHOD_DOP853): Dormand & Prince's
 *     explicit pair of order 8 as scipy.integrate.DOP853 (its coefficients, error
 *     estimate, step-size control and 7th-order dense output; no Jacobian, which may then
 *     be NULL): for scenes that are not stiff, where its order 8 takes far fewer steps at
 *     tight tolerances.  The dense output's 3 extra stages are computed only for the steps
 *     that need them (an event's sign change, a t_eval point, dense_output), where scipy
 *     computes them on every step when there are events: nfev is smaller than scipy's by
 *     that much.
 * The loop (the same code for both methods): solve_ivp's event logic (find_active_events,
 * handle_events, brentq with xtol = rtol = 4 eps), for events that are linear
 * functionals of the state, g(y) = c . y + d (on one step g(t) is then a polynomial in
 * t), and for events the system evaluates itself (a callback, evaluated on the dense
 * output); their refinement and re-arming, t_eval, dense output and the call budget.
 * Events are evaluated exactly as solve_ivp evaluates them (the driver keeps segments
 * from starting on an event's zero; see simulate.py).  One difference, on by default
 * (radau5_problem.refine_events): the state at a terminal event is not the crossing
 * step's dense output (Radau's: a cubic, order 3, without error control) but the end
 * point of the step taken again from that step's start to the event's time.  The loop
 * and the steps share the solver's state through _integrator_private.h.
 *
 * Generic in the system: the right-hand side and Jacobian are C callbacks, the
 * dimension is a run-time value.  Radau's Newton systems are solved by ballc's own
 * small LU with partial pivoting (_lu.h: fixed loop order, no BLAS, no threads),
 * so results do not depend on the machine's LAPACK or its threading.  Only the
 * coupled states are factored: states whose column of the Jacobian is zero (pure
 * outputs, e.g. positions nothing depends on, accumulated work) make mu/h I - J
 * lower block-triangular, so they follow from the coupled block's solution by
 * substitution; they stay in the error norm and in the Newton convergence test.
 *
 * The public names keep the radau5_ prefix (radau5_solve, radau5_problem, ...) for
 * both methods.
 */
#ifndef BALLC_INTEGRATOR_H
#define BALLC_INTEGRATOR_H

#include <complex.h>

/* f (n) = rhs(t, y); jac (n x n, row-major) = d rhs / d y.  Return 0 on success,
 * anything else when the function cannot be evaluated at (t, y). */
typedef int (*radau5_fun)(void *ctx, double t, const double *y, double *f);
typedef int (*radau5_jac)(void *ctx, double t, const double *y, double *jac);
/* *g = value of the system-defined (non-linear) event ``e`` at (t, y), before its offset.
 * Return 0 on success. */
typedef int (*radau5_event_fun)(void *ctx, int e, double t, const double *y, double *g);
/* Re-arm terminal event ``e`` at its hit (t, y), or decline.  Returns 1 when it has
 * written the event's new coefficients and offset into the arrays behind ev_coef and
 * ev_offset (and updated whatever else of ctx the right-hand side reads, which must
 * then be unchanged at and just past (t, y)): the integration goes on from (t, y) with
 * its step size, Jacobian and history, and the hit is not stored.  Returns 0 to stop
 * there as any terminal event. */
typedef int (*radau5_rearm_fun)(void *ctx, int e, double t, const double *y);

typedef struct {
    int n;                    /* number of states */
    radau5_fun fun;
    radau5_jac jac;
    void *ctx;                /* passed to fun and jac */
    double t0, t_bound;       /* t_bound may be < t0 (integration backwards) */
    const double *y0;         /* n */
    double rtol;              /* > 0 (the caller applies scipy's 100 eps floor) */
    const double *atol;       /* n values, >= 0 */
    double max_step;          /* > 0, may be INFINITY */
    double first_step;        /* 0: chosen as scipy's select_initial_step (order 3) */
    long max_nfev;            /* > 0: give up (status RADAU5_FAILED) once nfev reaches it */
    const double *t_eval;     /* NULL: store every step; else n_eval times, sorted in */
    long n_eval;              /*   the direction of integration, within the interval */
    int n_events;             /* events g_k(y) = coef[k*n:(k+1)*n] . y + offset[k], or, */
    const double *ev_coef;    /*   where ev_nonlinear[k] is nonzero, */
    const double *ev_offset;  /*   g_k(t, y) = ev_fun(ctx, k, t, y) + offset[k] */
    const int *ev_nonlinear;  /* may be NULL: all linear */
    radau5_event_fun ev_fun;  /* may be NULL when no event is non-linear */
    const int *ev_terminal;   /* k > 0: stop at the k-th occurrence in this call;
                               * 0: not terminal */
    const int *ev_direction;  /* +1 rising only, -1 falling only, 0 both */
    int dense_output;         /* nonzero: keep every step's interpolant (dense_t, dense_c) */
    int controller;           /* RADAU5_CTRL_* bits (internal; 0: scipy's step control) */
    int outputs_checked;      /* nonzero: fun and jac return nonzero whenever an output is
                               * not finite, so the solver does not check them again */
    int refine_events;        /* nonzero: the state at a terminal event is a step's end
                               * point (the crossing step is taken again from its start
                               * to the event's time), not the dense output's value */
    const int *ev_rearm;      /* may be NULL; nonzero: the terminal event may be re-armed */
    radau5_rearm_fun rearm;   /*   by rearm (only where refine_events stepped to its time) */
    int method;               /* RADAU5_METHOD_RADAU (0), RADAU5_METHOD_DOP853 (1) or
                               * RADAU5_METHOD_AUTO (2, see below) */
    int jacobian_ahead;       /* nonzero: a segment's first step whose Newton fails with the
                               * start's Jacobian retries once with the Jacobian at the
                               * step's explicit Euler end (the compliant law's contacts) */
    int auto_implicit;        /* RADAU5_METHOD_AUTO only: nonzero starts with Radau IIA
                               * instead of DOP853 (a segment continuing a stiff one) */
    /* may be NULL; called with ctx and the time reached every RADAU5_POLL_STEPS tries of a
     * step (the caller keeps it cheap: a clock test, and now and then a progress report or
     * a check for Ctrl-C); nonzero stops the integration there with status
     * RADAU5_INTERRUPTED, keeping what was computed */
    int (*poll)(void *ctx, double t);
    int jacobian_every_step;  /* nonzero: Radau IIA takes the Jacobian at every accepted
                               * step's end, not only when Newton converged slowly (the
                               * compliant law's sliding mode: its stiffness (e . v_t) / |s|
                               * follows |s| step by step; a Jacobian kept from an earlier
                               * step overestimates it and Newton settles on a wrong
                               * deflection direction, issue 28) */
    int norm_states;          /* the error norms' divisor: the RMS norms (error estimates,
                               * Radau's Newton increments, the initial step's) divide
                               * their sums by it instead of n (0: n).  ballc's rolling
                               * resistance states are last and constant without it: a
                               * run without it gives them no weight, and its results
                               * are those of the state without them, bit for bit */
} radau5_problem;

#define RADAU5_POLL_STEPS 16

/* RADAU5_METHOD_AUTO: LSODA's idea with the two steps.  The call starts with DOP853
 * (unless problem.auto_implicit) and switches to Radau IIA, before the next step, once
 * Hairer's stiffness test has seen AUTO_STIFF_STEPS accepted steps in a row with
 * |h lambda| > AUTO_STABILITY_BOUND (the same test that sets stiff_at), or once a probe
 * finds the steps stiff: every AUTO_PROBE_STEPS accepted DOP853 steps the Jacobian is
 * taken at the state in hand and the steps count as stiff when their mean size times
 * rho(J) is above AUTO_CALM_BOUND and Hairer's count holds at least AUTO_PROBE_EVIDENCE
 * steps beyond its bound (without it the probe also fired where an exact Coulomb slip
 * nears zero, its force's derivative mu N / |u| unbounded, on the seed's rubber ball: 18
 * needless switches in 5 s at rtol 1e-10) (Hairer's test alone missed a steel ball's contact at
 * rtol 1e-3 and 1e-11, where DOP853's steps hovered about its bound, and a stick/slip
 * chatter at 1e-4 that both DOP853 and auto gave up on: docs/auto_method.md).  It switches back
 * once AUTO_NONSTIFF_STEPS accepted Radau steps in a row had h rho(J) < AUTO_CALM_BOUND:
 * steps that DOP853 could take stably, with a margin for its higher cost per step;
 * rho(J) is the spectral radius of the Radau step's Jacobian, estimated by
 * AUTO_POWER_ITERATIONS power iterations (once per Jacobian).  The new method starts
 * from the state, right-hand side and step size in hand (Radau with a Jacobian taken
 * there, no predictor and no step-size history).  Each step keeps its own method's
 * interpolant (dense output, events, t_eval); result->dense_kind says which, per stored
 * step.  Steps taken again to a terminal event's time (refine_events) use the method in
 * use and do not switch. */
enum { RADAU5_METHOD_RADAU = 0, RADAU5_METHOD_DOP853 = 1, RADAU5_METHOD_AUTO = 2 };
#define AUTO_STABILITY_BOUND 6.1
#define AUTO_STIFF_STEPS 15
#define AUTO_NONSTIFF_STEPS 15
/* h rho(J) below which a Radau step counts as calm: half dop853's stability bound, since a
 * DOP853 step costs 12 right-hand sides to Radau's 4-8 (measured, steel compliant scene at
 * rtol 1e-4: 6.1 -> 73,723 calls, 3.0 -> 49,244, 1.0 -> 878,598; the other stiff scenes
 * never switch back and are the same at all three: docs/auto_method.md) */
#ifndef AUTO_CALM_BOUND
#define AUTO_CALM_BOUND 3.0
#endif
#define AUTO_POWER_ITERATIONS 8
#define AUTO_PROBE_STEPS 15
#define AUTO_PROBE_EVIDENCE 1

/* Step control: scipy's Radau (0) or elements of Hairer & Wanner's RADAU5 (radau5.f,
 * RADCOR/ESTRAD), each a bit, for benchmarks/controllers.py.
 *   NIT7    at most 7 Newton iterations (scipy: 6), safety 0.9 (1 + 2 nit)/(newt + 2 nit)
 *   LIMITS  h_new/h in [0.2, 8] (scipy: [0.2, 10]); no growth right after a rejection
 *   PRED    Gustafsson's predictive factor after accepted steps only, min with the
 *           standard one, plain safety 0.9, previous error floored at 0.01; a rejected
 *           step uses the standard factor alone (scipy: the predictive one on both)
 *   HOLD    keep h (and the LU) when h_new/h is in [1, 1.2] (scipy: whenever < 1.2)
 *   JAC     a new Jacobian after an accepted step only when the Newton contraction
 *           theta > 0.001 (scipy: also more than 2 iterations); theta = 0 after 1
 *   TOL     the tolerances transformed, rtol' = 0.1 rtol^(2/3), atol' = rtol' atol/rtol
 *           (error norm, Newton scale and stopping tolerance all use them)
 *   SCALE   the error scale from |y| at the step's start (scipy: max(|y|, |y_new|)) */
enum {
    RADAU5_CTRL_NIT7 = 1, RADAU5_CTRL_LIMITS = 2, RADAU5_CTRL_PRED = 4,
    RADAU5_CTRL_HOLD = 8, RADAU5_CTRL_JAC = 16, RADAU5_CTRL_TOL = 32,
    RADAU5_CTRL_SCALE = 64,
    RADAU5_CTRL_SCIPY = 0, RADAU5_CTRL_HAIRER = 127
};

enum { RADAU5_REACHED = 0, RADAU5_EVENT = 1, RADAU5_FAILED = -1,
       RADAU5_INTERRUPTED = -2 /* problem.poll asked to stop */ };
/* What radau5_solve returns (result->status says how the integration ended). */
enum { RADAU5_DONE = 0, RADAU5_OUT_OF_MEMORY = -1, RADAU5_BAD_PROBLEM = -2 };

/* result->prof (only in a build with -DRADAU5_PROFILE; zeros otherwise): CPU
 * time-stamp-counter ticks spent in each part and in the whole radau5_solve, and the
 * latter in nanoseconds of thread CPU time: the parts are shares of the ticks (a
 * preemption falls on a part in proportion to its length), scaled to the CPU time. */
enum { RADAU5_PROF_FUN = 0, RADAU5_PROF_JAC, RADAU5_PROF_FACTOR, RADAU5_PROF_SOLVE,
       RADAU5_PROF_EVENTS, RADAU5_PROF_TOTAL, RADAU5_PROF_TOTAL_NS, RADAU5_PROF_N };

typedef struct {
    int status;               /* RADAU5_REACHED, RADAU5_EVENT, RADAU5_FAILED or
                               * RADAU5_INTERRUPTED */
    char message[240];
    long nfev, njev, nlu, nstep, nreject;
    double h_next;            /* the step size the controller chose for the next step */
    long n_out;               /* stored points: t_out (n_out), y_out (n_out x n) */
    double *t_out;
    double *y_out;
    long n_hits;              /* event occurrences, in the order found (not the re-armed) */
    long n_rearmed;           /* terminal events re-armed (see radau5_rearm_fun) */
    int *hit_event;
    double *hit_t;
    double *hit_y;            /* n_hits x n */
    long n_dense;             /* with dense_output: accepted steps, each (t_old, t) in */
    double *dense_t;          /*   dense_t (n_dense x 2) and y_old then dense_terms rows */
    double *dense_c;          /*   of n coefficients in dense_c (n_dense x (1 + terms) n),
                               *   x = (t - t_old) / (t_new - t_old).  Radau (3 terms):
                               *   y(t) = y_old + sum_j Q_j x^(j+1), Q_j the j-th row.
                               *   DOP853 (7): rows F0..F6 of dop853_eval. */
    int dense_terms;          /* 3 (Radau) or 7 (DOP853, and AUTO: the widest) */
    int *dense_kind;          /* n_dense: each stored step's own number of terms, 3 or 7
                               * (AUTO: a Radau step's rows 3..6 are zeros) */
    double stiff_at;          /* DOP853: the start of the step at which Hairer's stiffness
                               * test (15 steps in a row with |h lambda| > 6.1) first
                               * fired; NaN when it did not (and always for Radau) */
    long n_switches;          /* AUTO: method switches, each at switch_t (the state in hand
                               * there, before the step), to switch_to (a method code) */
    double *switch_t;
    int *switch_to;
    int method_end;           /* the method of the last step (AUTO: the one in use) */
    long nstep_implicit;      /* accepted Radau IIA steps (of nstep) */
    int profiled;             /* 1 in a -DRADAU5_PROFILE build */
    double prof[RADAU5_PROF_N];
} radau5_result;

/* Integrate; returns RADAU5_DONE, RADAU5_OUT_OF_MEMORY or RADAU5_BAD_PROBLEM (a bad
 * dimension; result->message says which).
 * The result always holds what was computed; release it with radau5_free. */
int radau5_solve(const radau5_problem *problem, radau5_result *result);
void radau5_free(radau5_result *result);

/* Event e of the problem at (t, y), as the loop evaluates it: its row dotted with y plus
 * its offset, or ev_fun plus the offset (NaN, and *status nonzero, when that fails);
 * for integrators that locate the problem's events themselves (scipy's, through the
 * C loop's integrator interface). */
double radau5_event_value(const radau5_problem *problem, int e, double t, const double *y,
                          int *status);

/* radau5_constants (the Radau IIA method's constants, tests only): _radau_iia.h. */

#endif
