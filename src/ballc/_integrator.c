/* See _integrator.h.  A port of solve_ivp's loop, event and output logic
 * (scipy/integrate/_ivp/ivp.py, scipy 1.17) around the methods' steps (Radau IIA:
 * _radau_iia.c; DOP853: _dop853.c), for linear events and events the system evaluates.
 * Comments name the scipy function each part mirrors. */
#ifdef RADAU5_PROFILE
#define _POSIX_C_SOURCE 199309L   /* clock_gettime under -std=c99 */
#endif
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef RADAU5_PROFILE
#include <time.h>
#endif

#include "_integrator_private.h"

#ifdef RADAU5_PROFILE
__thread double *ballc_prof_acc;   /* see _integrator_private.h */
#endif

/* One accepted step of the method in use. */
static int step(solver_t *s)
{
    return s->dop853 ? dop853_step(s) : radau_iia_step(s);
}

/* The last step's dense output made ready for dense(): DOP853 computes its extra stages
 * then (dop853_prepare_dense), once per step and only for the steps whose dense output
 * is used (Radau's is part of the step).  Returns 0, or -1 (message set) when they
 * cannot be evaluated. */
static int prepare_dense(solver_t *s)
{
    return s->dense_dop853 ? dop853_prepare_dense(s) : 0;
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
    d0 = sqrt(d0 / s->n_norm);
    d1 = sqrt(d1 / s->n_norm);
    double h0 = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
    h0 = fmin(h0, interval);
    for (int c = 0; c < n; c++) s->tmp[c] = s->y[c] + h0 * s->direction * s->f[c];
    if (call_fun(s, p->t0 + h0 * s->direction, s->tmp, s->f_new) == 0) {
        for (int c = 0; c < n; c++) {
            double v = (s->f_new[c] - s->f[c]) / s->scale[c];
            d2 += v * v;
        }
        d2 = sqrt(d2 / s->n_norm) / h0;
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
    void **buffers[] = {(void **)&r->dense_t, (void **)&r->dense_c, (void **)&r->dense_kind};
    const int terms = r->dense_terms, own = dense_terms_count(s);
    const size_t sizes[] = {2 * sizeof(double), (1 + terms) * (size_t)n * sizeof(double),
                            sizeof(int)};
    if (reserve(&s->cap_dense, r->n_dense, 256, 3, buffers, sizes) != 0) return -1;
    r->dense_t[2 * r->n_dense] = s->t_old;
    r->dense_t[2 * r->n_dense + 1] = s->t;
    double *c = r->dense_c + (size_t)r->n_dense * (1 + terms) * n;
    memcpy(c, s->y_old, n * sizeof(double));
    memcpy(c + n, dense_terms(s), (size_t)own * n * sizeof(double));
    if (own < terms)   /* AUTO: a Radau step in rows as wide as DOP853's */
        memset(c + (size_t)(1 + own) * n, 0, (size_t)(terms - own) * n * sizeof(double));
    r->dense_kind[r->n_dense] = own;
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

double radau5_event_value(const radau5_problem *p, int e, double t, const double *y,
                          int *status)
{
    double g = p->ev_offset[e];
    *status = 0;
    if (p->ev_nonlinear != NULL && p->ev_nonlinear[e]) {
        double v;
        *status = p->ev_fun == NULL ? -1 : p->ev_fun(p->ctx, e, t, y, &v);
        return *status ? NAN : g + v;
    }
    const double *c = p->ev_coef + (size_t)e * p->n;
    for (int i = 0; i < p->n; i++) g += c[i] * y[i];
    return g;
}

static double event_value(const solver_t *s, int e, double t, const double *y)
{
    int status;
    return radau5_event_value(s->p, e, t, y, &status);
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
    poly_t q = {s->p->ev_offset[e], {0}, s->t_old, s->t - s->t_old, s->dense_dop853};
    for (int i = 0; i < n; i++) q.a0 += c[i] * s->y_old[i];
    const double *rows = dense_terms(s);
    const int terms = dense_terms_count(s);
    for (int j = 0; j < terms; j++)
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
        ok = radau_iia_jacobian(s, s->t, s->y) == 0;
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
        memmove(r->dense_kind + (n_dense - 1), r->dense_kind + n_dense,
                (size_t)(r->n_dense - n_dense) * sizeof(int));
        r->n_dense--;
    }
    return 1;
}

/* ---- RADAU5_METHOD_AUTO: the switch between the two steps (see _integrator.h) ---- */

/* The spectral radius of s->J, estimated by AUTO_POWER_ITERATIONS power iterations from
 * a fixed start vector: the geometric mean of the last two growth factors |J v| / |v|
 * (for a complex pair of dominant eigenvalues, as the contact spring's, the factor
 * alternates about the modulus; over two iterations it is the modulus squared). */
static double spectral_radius(solver_t *s)
{
    const int n = s->n;
    double *v = s->pw, *w = s->pw + n;
    double norm = 0, last = 0, before = 0;
    for (int c = 0; c < n; c++) {
        v[c] = 1.0 + 0.01 * c;
        norm += v[c] * v[c];
    }
    norm = sqrt(norm);
    for (int it = 0; it < AUTO_POWER_ITERATIONS; it++) {
        double wn = 0;
        for (int i = 0; i < n; i++) {
            double sum = 0;
            const double *row = s->J + (size_t)i * n;
            for (int c = 0; c < n; c++) sum += row[c] * v[c];
            w[i] = sum;
            wn += sum * sum;
        }
        wn = sqrt(wn);
        if (!isfinite(wn)) return INFINITY;
        if (wn == 0) return 0.0;   /* nilpotent on the start vector: no stiffness seen */
        before = last;
        last = wn / norm;
        for (int c = 0; c < n; c++) v[c] = w[c] / wn;
        norm = 1.0;
    }
    return sqrt(last * before);
}

/* After an accepted step with AUTO.  DOP853: the Jacobian probe (see _integrator.h).
 * Radau: count the step as calm when DOP853 could have taken it stably, and as cheaply,
 * h rho(J) < AUTO_CALM_BOUND (rho estimated once per Jacobian). */
static void auto_observe(solver_t *s)
{
    if (s->dop853) {
        /* every AUTO_PROBE_STEPS DOP853 steps: the Jacobian at the state in hand, and
         * stiff when those steps' mean size times rho(J) is above AUTO_CALM_BOUND (the
         * mirror of the test back: Radau would take such steps at most as cheaply) and
         * Hairer's own estimate saw at least AUTO_PROBE_EVIDENCE of them beyond 6.1 */
        if (s->probe_steps++ == 0) s->probe_t = s->t_old;
        if (s->probe_steps < AUTO_PROBE_STEPS) return;
        s->probe_steps = 0;
        if (radau_iia_jacobian(s, s->t, s->y) != 0) return;   /* no verdict: go on */
        s->rho = spectral_radius(s);
        s->rho_njev = s->r->njev;
        if (fabs(s->t - s->probe_t) / AUTO_PROBE_STEPS * s->rho > AUTO_CALM_BOUND
            && s->stiff_steps >= AUTO_PROBE_EVIDENCE)
            s->stiff_probe = 1;
        return;
    }
    if (s->rho_njev != s->r->njev) {
        s->rho = spectral_radius(s);
        s->rho_njev = s->r->njev;
    }
    if (fabs(s->t - s->t_old) * s->rho < AUTO_CALM_BOUND)
        s->calm_steps++;
    else
        s->calm_steps = 0;
}

static int record_switch(solver_t *s, int to)
{
    radau5_result *r = s->r;
    void **buffers[] = {(void **)&r->switch_t, (void **)&r->switch_to};
    const size_t sizes[] = {sizeof(double), sizeof(int)};
    if (reserve(&s->cap_switch, r->n_switches, 8, 2, buffers, sizes) != 0) return -1;
    r->switch_t[r->n_switches] = s->t;
    r->switch_to[r->n_switches] = to;
    r->n_switches++;
    return 0;
}

/* Before a step with AUTO: change the method when its test says so.  DOP853 -> Radau
 * IIA: the Jacobian at the state in hand (no predictor, no step-size history: as a
 * first step, with the step size in hand); Radau IIA -> DOP853: from the state, right-
 * hand side and step size in hand.  Returns 0, -1 when out of memory, -2 when the
 * Jacobian cannot be evaluated (message set). */
static int auto_switch(solver_t *s)
{
    if (s->dop853) {
        if (s->stiff_steps < AUTO_STIFF_STEPS && !s->stiff_probe) return 0;
        s->stiff_probe = s->probe_steps = 0;
        if (radau_iia_jacobian(s, s->t, s->y) != 0) {
            snprintf(s->r->message, sizeof s->r->message,
                     "the Jacobian cannot be evaluated at t = %.17g (method auto, switching "
                     "to radau5)", s->t);
            return -2;
        }
        s->dop853 = 0;
        s->current_jac = 1;
        s->lu_valid = 0;
        s->have_sol = 0;
        s->have_h_abs_old = s->have_error_norm_old = s->have_acc = 0;
        s->calm_steps = 0;
        return record_switch(s, RADAU5_METHOD_RADAU);
    }
    if (s->calm_steps < AUTO_NONSTIFF_STEPS) return 0;
    s->dop853 = 1;
    s->probe_steps = 0;
    s->stiff_steps = s->nonstiff_steps = 0;
    return record_switch(s, RADAU5_METHOD_DOP853);
}

/* ---- driver (solve_ivp's loop) ---- */

void radau5_free(radau5_result *r)
{
    free(r->t_out); free(r->y_out);
    free(r->hit_event); free(r->hit_t); free(r->hit_y);
    free(r->dense_t); free(r->dense_c); free(r->dense_kind);
    free(r->switch_t); free(r->switch_to);
    r->t_out = r->y_out = r->hit_t = r->hit_y = r->dense_t = r->dense_c = NULL;
    r->dense_kind = r->switch_to = NULL;
    r->switch_t = NULL;
    r->n_switches = 0;
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
    if (p->method != RADAU5_METHOD_RADAU && p->method != RADAU5_METHOD_DOP853
            && p->method != RADAU5_METHOD_AUTO) {
        snprintf(r->message, sizeof r->message, "method = %d: need RADAU5_METHOD_RADAU (0), "
                 "RADAU5_METHOD_DOP853 (1) or RADAU5_METHOD_AUTO (2)", p->method);
        return RADAU5_BAD_PROBLEM;
    }
    if (p->method != RADAU5_METHOD_DOP853 && p->jac == NULL) {
        snprintf(r->message, sizeof r->message, "Radau (and auto) needs a Jacobian: jac is NULL");
        return RADAU5_BAD_PROBLEM;
    }

#ifdef RADAU5_PROFILE
    ballc_prof_acc = r->prof;
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
    s.n_norm = p->norm_states > 0 ? p->norm_states : n;
    s.auto_mode = p->method == RADAU5_METHOD_AUTO;
    s.dop853 = p->method == RADAU5_METHOD_DOP853 || (s.auto_mode && !p->auto_implicit);
    s.dense_dop853 = s.dop853;
    s.rho_njev = -1;
    r->dense_terms = (s.dop853 || s.auto_mode) ? DOP853_DENSE_TERMS : 3;
    radau_iia_init_constants(&s.k);
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
         + (size_t)n * (DOP853_STAGES_EXTENDED + DOP853_DENSE_TERMS)    /* K, F */
         + 2 * (size_t)n;                                   /* pw */
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
    s.pw = d; d += 2 * (size_t)n;
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
    if (!s.dop853 && radau_iia_jacobian(&s, s.t, s.y) != 0) {
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

    long tries = 0;
    for (;;) {
        if (p->poll != NULL && ++tries % RADAU5_POLL_STEPS == 0 && p->poll(p->ctx, s.t)) {
            r->status = RADAU5_INTERRUPTED;
            snprintf(r->message, sizeof r->message, "interrupted at t = %.9g", s.t);
            break;
        }
        if (p->max_nfev > 0 && r->nfev >= p->max_nfev) {
            r->status = RADAU5_FAILED;
            snprintf(r->message, sizeof r->message,
                     "gave up at t = %.9g after %ld right-hand-side evaluations (max_nfev)",
                     s.t, r->nfev);
            break;
        }
        if (s.auto_mode) {
            int sw = auto_switch(&s);
            if (sw == -1) goto oom;
            if (sw != 0) {
                r->status = RADAU5_FAILED;
                break;
            }
        }
        if (!step(&s)) {
            r->status = RADAU5_FAILED;
            break;
        }
        if (s.auto_mode) auto_observe(&s);
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
    r->method_end = s.dop853 ? RADAU5_METHOD_DOP853 : RADAU5_METHOD_RADAU;
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
