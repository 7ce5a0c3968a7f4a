/* See _driver.h: the segment loop, the one driver of ballc.simulate (docs/driver.md).
 * Each handler is named after the row of ballc.automaton.TRANSITIONS it applies.
 * Compiled with the rest of the extension: -std=c99, so no FP contraction (never
 * -ffast-math). */
#define _POSIX_C_SOURCE 199309L   /* clock_gettime under -std=c99 */
#include <time.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "_driver.h"
#include "_integrator.h"
#include "_system.h"
#include "_rolling.h"

#define N BALLC_MAX_STATES   /* room for a state; the run's are r->ns (params' planes) */
#define NL BALLC_MAX_LATCH   /* room for a latch; the run's is r->nl */
#define NLP BALLC_N_LATCH_PER_PLANE
#define MAXP BALLC_MAX_PLANES
#define EVENTS_PER_PLANE 12  /* the driver's own events of a segment per plane, at most
                              * (6, and the rolling part's: 3 per part) */
#define SLIP_D BALLC_LATCH_SLIP_DIRECTION_X   /* within a plane's latch block */
#define KIN_PER_PLANE BALLC_CONTACT_KINEMATICS_PER_PLANE

#define CLEAR_FACTOR BALLC_CLEAR_FACTOR
#define PASS_FACTOR BALLC_PASS_FACTOR
#define STOP_FACTOR BALLC_STOP_FACTOR
#define APPROACH_FRACTION BALLC_APPROACH_FRACTION
#define MAX_RELATCH BALLC_MAX_RELATCH
#define MAX_TRANSITIONS BALLC_MAX_TRANSITIONS
#define MAX_STALLED BALLC_MAX_STALLED
#define MIN_IMPACT_RATE BALLC_MIN_IMPACT_RATE
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* |v| of 3 values, the unit in the last place of |x| */
static double norm3(const double *v) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }
static double ulp(double x) { x = fabs(x); return nextafter(x, INFINITY) - x; }

/* max(a, b) / min(a, b): the first unless the second is larger/smaller */
static double py_max(double a, double b) { return b > a ? b : a; }
static double py_min(double a, double b) { return b < a ? b : a; }

/* ---- growable output (ballc_grow, _dense.c) ---- */

#define grow ballc_grow

void ballc_drive_free(ballc_drive_output *o)
{
    free(o->t); free(o->y); free(o->block_count); free(o->block_flags);
    free(o->block_latch); free(o->contacts); free(o->phases);
    free(o->pieces); free(o->dense_t); free(o->dense_c); free(o->dense_kind);
    ballc_dense_free(&o->orbit_base);
    free(o->trials);
    o->trials = NULL;
    free(o->switch_t); free(o->switch_to);
    o->switch_t = NULL; o->switch_to = NULL;
    free(o->log);
    o->log = NULL;
    free(o->user_hit_event); free(o->user_hit_t); free(o->user_hit_y);
    o->user_hit_event = NULL; o->user_hit_t = o->user_hit_y = NULL;
    o->pieces = NULL; o->dense_t = o->dense_c = NULL; o->dense_kind = NULL;
    o->t = o->y = o->block_latch = NULL;
    o->block_count = NULL; o->block_flags = NULL; o->contacts = NULL; o->phases = NULL;
}

/* ---- the run: contacts, modes and latches between segments ---- */

/* A plane's penetration as the driver's events take it: rho = coef . (x, y, z) + offset
 * with coef = -n, offset = r + n . p (n the unit normal, p the plane's point); with
 * ``axis`` >= 0 the normal is along that coordinate axis and rho = scale * y[axis] +
 * offset (the event of one state: the seed's floor and ceiling, and exact flight's
 * quadratic in one coordinate).  ``position``: the centre's coordinate where it touches
 * an axis-aligned plane (compliantmodes.plane_position), whose ulps set the thresholds;
 * a tilted plane's are set per segment from the state (plane_position below). */
typedef struct {
    double coef[3], offset, scale, position;
    int axis;
} plane_geometry;

typedef struct {
    const ballc_drive_config *c;
    ballc_drive_output *o;
    ballc_parameters_t prepared;
    int np, ns, nl;             /* the run's planes, states and latched values */
    plane_geometry geometry[MAXP];
    double gravity[3];          /* params' gravity vector (m/s^2) */
    double t, y[N], latch[NL];
    int in_contact[MAXP], coulomb[MAXP];
    double approach[MAXP];
    int has_approach[MAXP];
    long relatches[MAXP], transitions[MAXP], stalled;
    double last_transition;
    int has_last_transition;
    double dissipated_at_start[MAXP][2];
    double rest_check[MAXP];
    int status, stop_code, stop_plane;
    int failed_kernel;          /* a C kernel failed: the run is aborted */
    const char *why;            /* why the run was aborted (BALLC_DRIVE_ABORTED) */
    /* this segment's re-arms: (t, latch before) */
    long n_rearmed, cap_rearmed;
    double *rearmed_t, *rearmed_latch;
    /* the segment's events: room for DRIVER_EVENTS + n_user (alloc_events) */
    int n_ev;
    double *ev_coef, *ev_offset;
    int *ev_terminal, *ev_direction, *ev_nonlinear;
    int *ev_plane_code, *ev_rearm;
    int *ev_kind, *ev_plane;
    int *ev_index;                   /* linear in one state: it (exact flight), else -1 */
    double *ev_scale;                /*   and its coefficient */
    double *flight_s;                /* exact flight's hits (s, event), 2 per event, */
    int *flight_e, *flight_seen;     /*   and their counts */
    ballc_flags seg_flags;
    /* the user's events: occurrences so far, a callback's error */
    long *user_seen;
    int user_failed;
    /* the compliant law's modes: per plane */
    int compliant[MAXP], armed[MAXP], capacity_row[MAXP];   /* COMPLIANT_*, bool, -1 or 4/5 */
    int has_step[MAXP];
    double step_bound[MAXP], step_until[MAXP];              /* contact_step: (bound, until) */
    int fired_row;
    /* the bridge's _ball_event cache: the last compliant margins computed */
    double margins_y[N], margins_out[6];
    int margins_plane, margins_solved;
    /* ballc.orbit: the trial under way (its plane, span, period guess
     * and segments; broken by an event), and whether the last one was just refused */
    int trial_on, trial_plane, trial_broken, trial_failed;
    double trial_from, trial_to, trial_guess;
    ballc_dense trial;
    /* the last poll (wall time, s), whether one stopped the run, and the
     * segment integrator's own interpolant (-1: its dense steps are in the result) */
    double polled;
    int interrupted;
    long seg_interpolant;
    ballc_segment_rec seg;      /* the segment under way's log record */
    ballc_rolling_run rolling_run[MAXP];   /* rolling resistance's exact modes, per plane */
} run_t;

enum { COMPLIANT_NONE = 0, COMPLIANT_ELASTIC, COMPLIANT_SLIDING };
/* A compliant guard's event code: MARGIN_CODE + row * MAXP + plane (its margins' row);
 * the capacity guards are rows 4 and 5.  Codes 0 .. MAXP - 1: a plane's stick release;
 * <= -2: the user's callable -2 - k. */
#define MARGIN_CODE MAXP
#define CAPACITY_FIRST (MARGIN_CODE + 4 * MAXP)
#define CAPACITY_SECOND (MARGIN_CODE + 5 * MAXP)

enum { K_ENTER, K_LEAVE, K_THROUGH, K_DEEPEST, K_APPROACH, K_STOP, K_CLEAR, K_RELEASE,
       K_ARM, K_YIELD, K_RESTICK, K_CAPACITY,
       K_ROLL_FIRST,   /* rolling resistance's events (_rolling.h BALLC_ROLLING_*) */
       K_USER = K_ROLL_FIRST + BALLC_ROLLING_EVENTS };   /* from K_APPROACH on: CARRY_STEP */

/* ---- the segment log (_driver.h: ballc_segment_rec) ---- */

/* the event kinds are the first segment ends, in the same order */
typedef char k_codes_are_segment_ends[((int)K_ENTER == (int)BALLC_SEG_ENTER
                                       && (int)K_DEEPEST == (int)BALLC_SEG_DEEPEST
                                       && (int)K_CAPACITY == (int)BALLC_SEG_CAPACITY
                                       && (int)K_ROLL_FIRST == (int)BALLC_SEG_ROLL_APPROACH
                                       && (int)K_USER == (int)BALLC_SEG_TWIST_RESTICK + 1
                                       && (int)K_USER == (int)BALLC_SEG_USER) ? 1 : -1];

typedef char integrator_prof_fits[RADAU5_PROF_N == 7 ? 1 : -1];

const char *const ballc_plane_mode_names[BALLC_N_PLANE_MODES] = {
    "flight", "contact", "slip", "slip_fixed", "stick", "elastic", "sliding", "resting",
    "rolling", "free_sliding", "passed_through"};

const char *const ballc_segment_end_names[BALLC_N_SEGMENT_ENDS] = {
    "enter", "leave", "through", "deepest", "approach", "stop", "clear", "release", "arm",
    "yield", "restick", "capacity", "roll_approach", "roll_stop", "roll_clear",
    "roll_release", "twist_stop", "twist_release", "roll_yield", "roll_restick",
    "twist_yield", "twist_restick", "user", "t_end", "rest check", "uniform check",
    "orbit check", "step bound", "failed"};

/* plane p's mode now (BALLC_PLANE_*, ballc.automaton.MODES) */
static int plane_mode(const run_t *r, int p)
{
    if (!r->in_contact[p])
        return r->stop_code == BALLC_DRIVE_THROUGH && r->stop_plane == p
            ? BALLC_PLANE_PASSED_THROUGH : BALLC_PLANE_FLIGHT;
    if (r->o->end_kind != BALLC_END_NONE && r->o->end_plane == p)
        return r->o->end_kind == BALLC_END_REST ? BALLC_PLANE_RESTING
            : r->o->end_kind == BALLC_END_ROLLING
              || r->o->end_kind == BALLC_END_ACCELERATING ? BALLC_PLANE_ROLLING
            : BALLC_PLANE_FREE_SLIDING;
    switch (r->coulomb[p]) {
    case BALLC_MODE_SLIP: return BALLC_PLANE_SLIP;
    case BALLC_MODE_SLIP_FIXED: return BALLC_PLANE_SLIP_FIXED;
    case BALLC_MODE_STICK: return BALLC_PLANE_STICK;
    default: break;
    }
    if (r->compliant[p] == COMPLIANT_ELASTIC) return BALLC_PLANE_ELASTIC;
    if (r->compliant[p] == COMPLIANT_SLIDING) return BALLC_PLANE_SLIDING;
    return BALLC_PLANE_CONTACT;
}

/* Each plane's mode, rolling part's and twisting part's mode now, for the log (-1 for
 * the slots beyond the scene's planes). */
static void log_modes(const run_t *r, signed char *mode, signed char *rolling,
                      signed char *twisting)
{
    for (int p = 0; p < MAXP; p++) {
        int here = p < r->np;
        mode[p] = here ? (signed char)plane_mode(r, p) : (signed char)-1;
        rolling[p] = here ? (signed char)ballc_rolling_mode(r->latch + p * NLP, 0)
                          : (signed char)-1;
        twisting[p] = here ? (signed char)ballc_rolling_mode(r->latch + p * NLP, 1)
                           : (signed char)-1;
    }
}

/* A segment starts at r->t in the present modes. */
static void log_open(run_t *r)
{
    ballc_segment_rec *g = &r->seg;
    memset(g, 0, sizeof *g);
    g->t_start = r->t;
    g->plane = -1;
    g->rearm_kind = g->rearm_plane = g->rearm_before = g->rearm_after = -1;
    log_modes(r, g->before, g->rolling_before, g->twisting_before);
}

/* An event of plane p re-armed inside the segment, leaving it in mode ``before``. */
static void log_rearm(run_t *r, int kind, int p, int before)
{
    ballc_segment_rec *g = &r->seg;
    g->rearms++;
    g->rearm_kind = (signed char)kind;
    g->rearm_plane = (signed char)p;
    g->rearm_before = (signed char)before;
    g->rearm_after = (signed char)plane_mode(r, p);
}

/* The segment ended at t_end, by ``end`` (BALLC_SEG_*) of ``plane``, and its end has
 * been handled: append its record.  -1: out of memory. */
static int log_close(run_t *r, int end, int plane, double t_end)
{
    ballc_drive_output *o = r->o;
    if (grow((void **)&o->log, &o->cap_log, o->n_log + 1, sizeof(ballc_segment_rec)))
        return -1;
    ballc_segment_rec *g = &r->seg;
    g->end = end;
    g->plane = plane;
    g->t_end = t_end;
    log_modes(r, g->after, g->rolling_after, g->twisting_after);
    o->log[o->n_log++] = *g;
    return 0;
}

/* the segment's right-hand-side flags: the observer's kernels (when it has mass), each
 * contact's laws and, ``with_coulomb``, its exact Coulomb mode or compliant mode */
static ballc_flags run_flags(const run_t *r, int with_coulomb)
{
    const ballc_drive_config *c = r->c;
    ballc_flags flags = c->observer_bits;
    for (int p = 0; p < r->np; p++) {
        if (!r->in_contact[p]) continue;
        if (c->compliant_modes) {   /* the law's mode: sliding, elastic once armed */
            if (r->compliant[p] == COMPLIANT_SLIDING)
                flags |= ballc_flag(BALLC_KIND_COMPLIANT_SLIDING, p);
            else if (r->compliant[p] == COMPLIANT_ELASTIC && r->armed[p])
                flags |= ballc_flag(BALLC_KIND_COMPLIANT_ELASTIC, p);
            else flags |= ballc_flag(BALLC_KIND_COMPLIANT, p);
            continue;
        }
        flags |= c->contact_bits[p];
        if (with_coulomb) {
            if (r->coulomb[p] == BALLC_MODE_SLIP) flags |= ballc_flag(BALLC_KIND_SLIP, p);
            else if (r->coulomb[p] == BALLC_MODE_SLIP_FIXED)
                flags |= ballc_flag(BALLC_KIND_SLIP_FIXED, p);
            else if (r->coulomb[p] == BALLC_MODE_STICK) flags |= ballc_flag(BALLC_KIND_STICK, p);
        }
    }
    return flags;
}

/* Whether any plane has the flag of ``kind`` (the integrator's Jacobian options) */
static int any_plane(const run_t *r, ballc_flags flags, int kind)
{
    for (int p = 0; p < r->np; p++)
        if (flags & ballc_flag(kind, p)) return 1;
    return 0;
}

/* the plane's penetration rho (m), as its events take it (plane_geometry) */
static double rho_of(const run_t *r, int p, const double *y)
{
    const plane_geometry *g = &r->geometry[p];
    if (g->axis >= 0) return g->scale * y[g->axis] + g->offset;
    return g->coef[0] * y[BALLC_STATE_X] + g->coef[1] * y[BALLC_STATE_Y]
           + g->coef[2] * y[BALLC_STATE_Z] + g->offset;
}

/* the penetration rate rho' = -n . v */
static double rho_rate(const run_t *r, int p, const double *y)
{
    const plane_geometry *g = &r->geometry[p];
    if (g->axis >= 0) return g->scale * y[g->axis + 6];
    return g->coef[0] * y[BALLC_STATE_VX] + g->coef[1] * y[BALLC_STATE_VY]
           + g->coef[2] * y[BALLC_STATE_VZ];
}

/* The magnitude of the centre's coordinate along the plane where it touches it
 * (compliantmodes.plane_position), whose ulps set the contact thresholds and the
 * compliant guards' rounding: an axis-aligned plane's constant; a tilted plane's, the
 * terms rho sums at state y (its rounding grows with them). */
static double plane_position(const run_t *r, int p, const double *y)
{
    const plane_geometry *g = &r->geometry[p];
    if (g->axis >= 0) return g->position;
    return fabs(g->coef[0] * y[BALLC_STATE_X]) + fabs(g->coef[1] * y[BALLC_STATE_Y])
           + fabs(g->coef[2] * y[BALLC_STATE_Z]) + fabs(g->offset);
}

/* compliantmodes.arm_penetration at state y; 0 when contacts begin at rho = 0 */
static double arm_depth(const run_t *r, int p, const double *y)
{
    if (!r->c->starts_armed) return 0.0;
    return py_max(BALLC_ARM_ULPS * ulp(plane_position(r, p, y)), r->c->arm_force_depth);
}

/* The run's plane geometry (plane_geometry) and gravity vector, from the prepared
 * parameters: once per run. */
static void plane_setup(run_t *r)
{
    const double radius = r->c->radius;
    for (int p = 0; p < r->np; p++) {
        const ballc_plane_t *pl = &r->prepared.planes[p];
        const double *n = pl->frame[2], *point = pl->point;
        plane_geometry *g = &r->geometry[p];
        g->axis = -1;
        int zeros = 0, along = -1;
        for (int i = 0; i < 3; i++) {
            g->coef[i] = -n[i];
            if (n[i] == 0.0) zeros++;
            else along = i;
        }
        if (zeros == 2) {   /* along a coordinate axis: the event of one state */
            g->axis = BALLC_STATE_X + along;
            g->scale = -n[along];
            g->offset = radius + n[along] * point[along];
            /* the centre's coordinate where it touches: p + r along n */
            g->position = fabs(point[along] + n[along] * radius);
        } else {
            g->scale = 0.0;
            g->offset = radius + (n[0] * point[0] + n[1] * point[1] + n[2] * point[2]);
            g->position = 0.0;
        }
    }
    for (int i = 0; i < 3; i++) r->gravity[i] = r->c->params[BALLC_PARAMETER_GRAVITY_X + i];
}

/* keep a contact's deepest penetration and where it happened */
static void record_depth(ballc_contact_rec *k, double depth, const double *y)
{
    if (depth >= k->max_penetration) {
        k->max_penetration = depth;
        k->contact_point[0] = y[BALLC_STATE_X];
        k->contact_point[1] = y[BALLC_STATE_Y];
        k->contact_point[2] = y[BALLC_STATE_Z];
    }
}

/* |v| + r |omega| (m/s): the scale slip speeds are compared with */
static double speed_scale(const run_t *r, const double *y)
{
    double s = norm3(y + BALLC_STATE_VX) + r->c->radius * norm3(y + BALLC_STATE_OMEGA_X);
    return s + 1e-300;
}

/* the slip velocity's integration error scale: rtol (|v| + r |omega|) + atol */
static double error_speed(const run_t *r, const double *y)
{
    return r->c->rtol * speed_scale(r, y) + r->c->atol;
}

/* u = du/dy . y, plane p's slip velocity (u is linear in the state: slip_map's rows) */
static void slip_velocity(const run_t *r, int p, const double *y, double u[2])
{
    for (int row = 0; row < 2; row++) {
        const double *m = r->prepared.slip_map[p] + row * r->ns;
        double s = 0.0;
        for (int j = 0; j < r->ns; j++)
            if (m[j] != 0.0) s += m[j] * y[j];
        u[row] = s;
    }
}

/* plane p's slip: u, |u|, its error scale and the clear speed */
static void slip(const run_t *r, int p, const double *y, double u[2], double *speed,
                 double *error, double *clear)
{
    slip_velocity(r, p, y, u);
    *speed = hypot(u[0], u[1]);
    *error = error_speed(r, y);
    *clear = CLEAR_FACTOR * *error;
}

/* at an approach: whether the slip is clear of zero, or passes by it -- its part
 * across the latched direction beyond PASS_FACTOR times the error -- and stays free */
static int slips_on_freely(const run_t *r, int p, const double u[2], double speed,
                           double error, double clear)
{
    if (speed > 2 * clear) return 1;
    const double *d = r->latch + p * NLP + SLIP_D;
    double along = u[0] * d[0] + u[1] * d[1];
    double across = sqrt(py_max(u[0] * u[0] + u[1] * u[1] - along * along, 0.0));
    return across > PASS_FACTOR * error;
}

static int record_phase(run_t *r, int p, int phase)
{
    ballc_drive_output *o = r->o;
    long k = o->open[p];
    long last = -1;
    for (long i = o->n_phases - 1; i >= 0; i--)
        if (o->phases[i].contact == k) { last = i; break; }
    if (last >= 0 && o->phases[last].phase == phase) return 0;
    if (grow((void **)&o->phases, &o->cap_phases, o->n_phases + 1, sizeof(ballc_phase_rec)))
        return -2;
    o->phases[o->n_phases].contact = k;
    o->phases[o->n_phases].t = r->t;
    o->phases[o->n_phases].phase = phase;
    o->n_phases++;
    return 0;
}

/* enter Coulomb ``mode`` on plane p now (direction may be NULL: kept) */
static int set_mode(run_t *r, int p, int mode, const double *direction,
                    int has_approach, double approach)
{
    r->coulomb[p] = mode;
    r->has_approach[p] = has_approach;
    r->approach[p] = approach;
    r->transitions[p] += 1;
    if (direction) {
        r->latch[p * NLP + SLIP_D] = direction[0];
        r->latch[p * NLP + SLIP_D + 1] = direction[1];
    }
    return record_phase(r, p, mode == BALLC_MODE_STICK ? 1 : 0);
}

/* a force at rounding level of the stick force: 64 eps (weight + |load|) */
static double force_scale(const run_t *r, double load)
{
    return (64 * DBL_EPSILON) * (r->c->weight + fabs(load));
}

/* Whether a plane in contact holds its rolling or twisting velocity (rolling
 * resistance's exact holding mode). */
static int rolling_holds(const run_t *r)
{
    for (int p = 0; p < r->np; p++)
        if (r->in_contact[p] && ballc_rolling_held_mask(r->latch, p, 0)) return 1;
    return 0;
}

/* The slip of plane p removed by an impulse (stickslip.remove_slip), the other planes'
 * sticking slips held; while rolling resistance holds a velocity, that one is held too
 * (and plane p's own held ones removed with its slip: _rolling.h). */
static int remove_slip(run_t *r, int p, ballc_flags flags, double *y_out)
{
    if (rolling_holds(r))
        return ballc_remove_velocities(r->y, &r->prepared, r->latch, flags, p,
                                       ballc_rolling_held_mask(r->latch, p, 0) | BALLC_HOLD_SLIP,
                                       y_out);
    return ballc_remove_slip(r->y, r->c->params, flags, p, y_out);
}

/* at zero slip: the slip projected to exactly zero, then stick when the constraint
 * force lies in the friction cone, else slip from rest along -lambda */
static int settle(run_t *r, int p)
{
    /* the other planes keep their modes (a second one sticking keeps its slip) */
    ballc_flags base = run_flags(r, 1) & ~(ballc_flag(BALLC_KIND_SLIP, p)
                                           | ballc_flag(BALLC_KIND_SLIP_FIXED, p)
                                           | ballc_flag(BALLC_KIND_STICK, p));
    double y0[N], out[4];
    if (remove_slip(r, p, base, y0) != BALLC_OK) {
        r->failed_kernel = 1;
        return -1;
    }
    ballc_flags stick_flags = base | ballc_flag(BALLC_KIND_STICK, p);
    if (ballc_stick_state(y0, r->c->params, r->latch, stick_flags, p, out) != BALLC_OK) {
        r->failed_kernel = 1;
        return -1;
    }
    double size = hypot(out[0], out[1]);
    memcpy(r->y, y0, r->ns * sizeof(double));
    if (out[3] >= -force_scale(r, out[2]) || size == 0)
        return set_mode(r, p, BALLC_MODE_STICK, NULL, 0, 0.0);
    double d[2] = {-out[0] / size, -out[1] / size};
    return set_mode(r, p, BALLC_MODE_SLIP_FIXED, d, 0, 0.0);
}

/* a contact's first Coulomb mode: free slip clear of zero, a held direction below
 * that, settle at zero slip */
static int start_coulomb(run_t *r, int p)
{
    double u[2], speed, error, clear;
    slip(r, p, r->y, u, &speed, &error, &clear);
    if (speed > 2 * clear || speed > 0) {
        double d[2] = {u[0] / speed, u[1] / speed};
        return set_mode(r, p, speed > 2 * clear ? BALLC_MODE_SLIP : BALLC_MODE_SLIP_FIXED,
                        d, 0, 0.0);
    }
    return settle(r, p);
}

/* ---- the compliant law's modes (ballc.compliantmodes) ---- */

static int deflection_x(int p)
{
    return ballc_plane_state(p);
}

/* the law's margins (ballc_compliant_margins, with every other plane in contact); -1
 * when the kernel failed */
static int margins_of(run_t *r, int p, const double *y, double *m)
{
    int i, ok = 1;
    for (i = 0; i < r->ns; i++) ok &= isfinite(y[i]) != 0;
    for (i = 0; i < r->nl; i++) ok &= isfinite(r->latch[i]) != 0;
    if (!ok || ballc_compliant_margins_prepared(y, &r->prepared, r->latch, run_flags(r, 1),
                                                p, -1, m) != BALLC_OK) {
        for (i = 0; i < BALLC_COMPLIANT_MARGINS; i++) m[i] = NAN;
        r->failed_kernel = 1;
        return -1;
    }
    return 0;
}

/* out = y with |s| = s_cap, the spring energy released booked as tangential work
 * (only_down: a spring below the cap is left as it is) */
static int at_cap(run_t *r, int p, const double *y, int only_down, double *out)
{
    int sx = deflection_x(p);
    memcpy(out, y, r->ns * sizeof(double));
    double s[2] = {out[sx], out[sx + 1]};
    double size = hypot(s[0], s[1]);
    if (!(size > 0)) return 0;
    double m[BALLC_COMPLIANT_MARGINS];
    if (margins_of(r, p, out, m)) return -1;
    double s_cap = m[2], k_t = m[3];
    if (only_down && size <= s_cap) return 0;
    double f = s_cap / size;
    out[sx] = s[0] * f;
    out[sx + 1] = s[1] * f;
    out[BALLC_STATE_DISSIPATED_TANGENTIAL] += 0.5 * k_t * (size * size - s_cap * s_cap);
    return 0;
}

/* the deflection at the cap along the slip velocity: 1 and along (2), 0 without
 * slip, -1 on failure */
static int along_slip(run_t *r, int p, const double *y, double *along)
{
    double u[2];
    slip_velocity(r, p, y, u);
    double speed = hypot(u[0], u[1]);
    if (!(speed > 0)) return 0;
    double m[BALLC_COMPLIANT_MARGINS];
    if (margins_of(r, p, y, m)) return -1;
    double length = m[2] > 0 ? m[2] : 1e-100;   /* START_DEFLECTION */
    along[0] = length * u[0] / speed;
    along[1] = length * u[1] / speed;
    return 1;
}

/* where the elastic spring meets the cap (a yield; arming = 1: a contact's start or
 * its arming): *mode (sliding when the re-stick margin there is >= 0) and the state */
static int decide(run_t *r, int p, const double *y, int arming, int *mode, double *out)
{
    int sx = deflection_x(p);
    double trial[N];
    if (at_cap(r, p, y, 0, trial)) return -1;
    double s[2] = {y[sx], y[sx + 1]};
    int relaxed = arming || !(hypot(s[0], s[1]) > 0);
    if (relaxed) {
        double along[2];
        int got = along_slip(r, p, y, along);
        if (got < 0) return -1;
        if (!got) {
            *mode = COMPLIANT_ELASTIC;
            memcpy(out, y, r->ns * sizeof(double));
            return 0;
        }
        trial[sx] = along[0];
        trial[sx + 1] = along[1];
    }
    double m[BALLC_COMPLIANT_MARGINS];
    if (margins_of(r, p, trial, m)) return -1;
    if (m[1] >= 0) {
        *mode = COMPLIANT_SLIDING;
        memcpy(out, relaxed ? trial : y, r->ns * sizeof(double));
        return 0;
    }
    *mode = COMPLIANT_ELASTIC;
    return at_cap(r, p, y, 1, out);
}

/* enter the compliant ``mode`` on plane p now */
static int set_compliant(run_t *r, int p, int mode)
{
    r->compliant[p] = mode;
    r->capacity_row[p] = -1;
    r->transitions[p] += 1;
    return record_phase(r, p, mode == COMPLIANT_SLIDING ? 0 : 1);
}

/* a compliant contact's start (after the latch): armed or not, its first mode, and
 * its step bound (t_c / BALLC_STEPS_PER_CONTACT for BALLC_IMPACT_SPAN t_c) */
static int start_compliant(run_t *r, int p, double rate)
{
    const ballc_drive_config *c = r->c;
    r->armed[p] = rho_of(r, p, r->y) >= 0.5 * arm_depth(r, p, r->y);
    int mode;
    double y[N];
    if (decide(r, p, r->y, 1, &mode, y)) return -1;
    memcpy(r->y, y, r->ns * sizeof(double));
    if (set_compliant(r, p, mode)) return -1;
    double t_c = c->contact_time_base * pow(rate, -0.2);   /* Hertz's contact time */
    r->has_step[p] = 1;
    r->step_bound[p] = t_c / BALLC_STEPS_PER_CONTACT;
    r->step_until[p] = r->t + BALLC_IMPACT_SPAN * t_c;
    return 0;
}

/* the next segment's largest step: the user's, and a compliant impact's bound */
static double run_max_step(const run_t *r)
{
    double step = r->c->max_step;
    for (int p = 0; p < r->np; p++)
        if (r->has_step[p] && r->step_until[p] > r->t) step = py_min(step, r->step_bound[p]);
    return step;
}

/* when the next compliant step bound ends (inf: none) */
static double step_bound_end(const run_t *r)
{
    double end = INFINITY;
    int found = 0;
    for (int p = 0; p < r->np; p++)
        if (r->has_step[p] && r->step_until[p] > r->t) {
            end = found ? py_min(end, r->step_until[p]) : r->step_until[p];
            found = 1;
        }
    return end;
}

/* Whether plane p is an incline where rolling down may end in closed form: not the
 * resting plane, gravity pressing the ball into it, and the rotation exact (massless
 * observer, isotropic inertia: flight.scene_allows) */
static int is_incline(const run_t *r, int p)
{
    const double *n = r->prepared.planes[p].frame[2], *g = r->gravity;
    return r->c->rolls_allowed && p != r->c->resting_plane
           && n[0] * g[0] + n[1] * g[1] + n[2] * g[2] < 0;
}

/* The plane whose rest checks apply in the segment starting now: the one plane in
 * contact, when it is the resting plane or an incline; -1 when none */
static int checked_plane(const run_t *r)
{
    int found = -1;
    for (int p = 0; p < r->np; p++) {
        if (!r->in_contact[p]) continue;
        if (found >= 0) return -1;   /* two planes at once */
        found = p;
    }
    if (found < 0 || !(found == r->c->resting_plane || is_incline(r, found))) return -1;
    return found;
}

static int start_rolling(run_t *r, int p);
static int recheck_modes(run_t *r, int p);

/* the automaton's "enter": latch rhodot^- and the dig-in direction (ballc.modes), relax
 * the tangential spring, open the contact's record, pick its first mode */
static int begin_contact(run_t *r, int p)
{
    const ballc_drive_config *c = r->c;
    ballc_drive_output *o = r->o;
    double *y = r->y;
    double kin[BALLC_MAX_CONTACT_KINEMATICS_NOUT];
    ballc_contact_kinematics(y, &r->prepared, kin);
    int k = p * KIN_PER_PLANE;
    double rho = kin[k], rate = kin[k + 1];
    const double *v = kin + k + 2;
    int kernel_rate = 1;
    if (rho > 0) {
        double stored = 0.8 * c->hertz_k * pow(rho, 2.5) / c->total_mass;
        rate = sqrt(rate * rate + stored);
        kernel_rate = 0;
    }
    double speed = norm3(v), direction[3];
    if (speed > 0) {
        for (int i = 0; i < 3; i++) direction[i] = v[i] / speed;
    } else {   /* into the plane, -n */
        for (int i = 0; i < 3; i++) direction[i] = 0.0 - r->prepared.planes[p].frame[2][i];
    }
    if (MIN_IMPACT_RATE > rate) { rate = MIN_IMPACT_RATE; kernel_rate = 0; }
    int l = p * NLP;
    r->latch[l] = rate;
    for (int i = 0; i < 3; i++) r->latch[l + 1 + i] = direction[i];
    y[ballc_plane_state(p)] = 0.0;
    y[ballc_plane_state(p) + 1] = 0.0;
    r->in_contact[p] = 1;
    if (grow((void **)&o->contacts, &o->cap_contacts, o->n_contacts + 1,
             sizeof(ballc_contact_rec)))
        return -2;
    ballc_contact_rec *rec = &o->contacts[o->n_contacts];
    memset(rec, 0, sizeof *rec);
    rec->plane = p;
    rec->t_start = r->t;
    memcpy(rec->v_before, y + BALLC_STATE_VX, 3 * sizeof(double));
    memcpy(rec->w_before, y + BALLC_STATE_OMEGA_X, 3 * sizeof(double));
    rec->rate = rate;
    rec->rate_is_kernel_value = kernel_rate;
    memcpy(rec->digin, direction, sizeof direction);
    rec->max_penetration = 0.0;
    rec->contact_point[0] = rec->contact_point[1] = rec->contact_point[2] = NAN;
    rec->t_end = NAN;
    record_depth(rec, rho_of(r, p, y), y);
    o->open[p] = (int)o->n_contacts;
    o->n_contacts++;
    r->dissipated_at_start[p][0] = y[BALLC_STATE_DISSIPATED_NORMAL];
    r->dissipated_at_start[p][1] = y[BALLC_STATE_DISSIPATED_TANGENTIAL];
    r->relatches[p] = r->transitions[p] = 0;
    r->rest_check[p] = p == c->resting_plane || is_incline(r, p) ? r->t + c->rest_period
                                                                  : INFINITY;
    if (c->exact && start_coulomb(r, p)) return -1;
    if (c->compliant_modes && start_compliant(r, p, rate)) return -1;
    return start_rolling(r, p);
}

/* the automaton's "leave": close the contact's record */
static void end_contact(run_t *r, int p)
{
    ballc_drive_output *o = r->o;
    if (r->c->rolling || r->c->twisting)   /* the rolling part rests with the contact */
        ballc_rolling_end(&r->prepared, p, r->y, r->latch);
    r->rest_check[p] = INFINITY;
    r->in_contact[p] = 0;
    r->coulomb[p] = BALLC_MODE_NONE;
    r->has_approach[p] = 0;
    r->has_step[p] = 0;
    r->compliant[p] = COMPLIANT_NONE;
    r->capacity_row[p] = -1;
    ballc_contact_rec *rec = &o->contacts[o->open[p]];
    o->open[p] = -1;
    rec->ended = 1;
    rec->t_end = r->t;
    memcpy(rec->v_after, r->y + BALLC_STATE_VX, 3 * sizeof(double));
    memcpy(rec->w_after, r->y + BALLC_STATE_OMEGA_X, 3 * sizeof(double));
    rec->lost[0] = r->y[BALLC_STATE_DISSIPATED_NORMAL] - r->dissipated_at_start[p][0];
    rec->lost[1] = r->y[BALLC_STATE_DISSIPATED_TANGENTIAL] - r->dissipated_at_start[p][1];
}

/* the automaton's "through": the ball passed through plane p (rho reached r), the run
 * stops with status 1; the contact's record is left open, its depth the radius */
static void pass_through(run_t *r, int p)
{
    ballc_drive_output *o = r->o;
    ballc_contact_rec *rec = &o->contacts[o->open[p]];
    o->open[p] = -1;
    rec->passed_through = 1;
    rec->max_penetration = r->c->radius;
    r->in_contact[p] = 0;
    r->status = 1;
    r->stop_code = BALLC_DRIVE_THROUGH;
    r->stop_plane = p;
}

/* mode changes in a row at one time, and the limits on them */
static long stalled_at(const run_t *r, double t)
{
    return (r->has_last_transition && t == r->last_transition) ? r->stalled + 1 : 0;
}

static int unsettled(const run_t *r, int p, long stalled)
{
    return r->transitions[p] >= MAX_TRANSITIONS || stalled >= MAX_STALLED;
}

/* count a mode change of plane p now; 0 (and the run stopped, status -1)
 * when its transitions have reached a limit, else 1. */
static int settles(run_t *r, int p)
{
    r->stalled = stalled_at(r, r->t);
    r->last_transition = r->t;
    r->has_last_transition = 1;
    if (!unsettled(r, p, r->stalled)) return 1;
    r->status = -1;
    r->stop_code = BALLC_DRIVE_UNSETTLED;
    r->stop_plane = p;
    return 0;
}

/* A stick's release: slip from rest along -lambda (the slip removed). */
static int coulomb_release(run_t *r, int p)
{
    double out[4], y1[N], dir[2];
    if (ballc_stick_state(r->y, r->c->params, r->latch, run_flags(r, 1), p, out)
            != BALLC_OK) {
        r->failed_kernel = 1;
        return -1;
    }
    double size = hypot(out[0], out[1]);
    const double *d = NULL;
    if (size > 0) {
        dir[0] = -out[0] / size;
        dir[1] = -out[1] / size;
        d = dir;
    }
    if (remove_slip(r, p, run_flags(r, 1), y1) != BALLC_OK) {
        r->failed_kernel = 1;
        return -1;
    }
    memcpy(r->y, y1, r->ns * sizeof(double));
    return set_mode(r, p, BALLC_MODE_SLIP_FIXED, d, 0, 0.0);
}

/* the automaton's approach, stop, clear and release: the next exact-Coulomb mode */
static int coulomb_event(run_t *r, int kind, int p)
{
    if (!settles(r, p)) return 0;
    double u[2], speed, error, clear, dir[2];
    slip(r, p, r->y, u, &speed, &error, &clear);
    const double *direction = NULL;
    if (speed > 0) {
        dir[0] = u[0] / speed;
        dir[1] = u[1] / speed;
        direction = dir;
    }
    switch (kind) {
    case K_APPROACH:
        r->relatches[p] += 1;
        if (r->relatches[p] <= MAX_RELATCH && slips_on_freely(r, p, u, speed, error, clear))
            return set_mode(r, p, BALLC_MODE_SLIP, direction, 1,
                            py_min(clear, APPROACH_FRACTION * speed));
        return set_mode(r, p, BALLC_MODE_SLIP_FIXED, direction, 0, 0.0);
    case K_STOP:
        if (speed <= STOP_FACTOR * error) return settle(r, p);
        return set_mode(r, p, BALLC_MODE_SLIP, direction, 1,
                        py_min(clear, APPROACH_FRACTION * speed));
    case K_CLEAR:
        return set_mode(r, p, BALLC_MODE_SLIP, direction, 0, 0.0);
    default:   /* release */
        return coulomb_release(r, p);
    }
}

/* ---- rolling resistance's exact and sds modes (_rolling.h) ---- */

/* The scales of the rolling part's guards and resets at y (_rolling.h). */
static ballc_rolling_scales rolling_scales(const run_t *r, int p, const double *y)
{
    double error = error_speed(r, y), speed = speed_scale(r, y);
    /* the compliant guards' rounding, with rho at least the arming depth: below it the
     * margins, of a cap ~ rho^(3/2), are not resolved (compliantmodes.arm_penetration) */
    double position = plane_position(r, p, y);
    double arm = py_max(BALLC_ARM_ULPS * ulp(position), r->c->arm_force_depth);
    double rounding = py_max(64 * DBL_EPSILON,
                             8 * ulp(position) / py_max(rho_of(r, p, y), arm));
    ballc_rolling_scales s = {error, CLEAR_FACTOR * error, 4 * ulp(speed),
                              r->c->weight, rounding, speed};
    return s;
}

/* Whether a plane's sds slider acts: its segments take a Jacobian at every step, as the
 * compliant law's sliding mode (its turn's stiffness (e . w) / |xi| follows |xi|). */
static int rolling_slides(const run_t *r)
{
    for (int p = 0; p < r->np; p++)
        for (int part = 0; part < 2; part++)
            if (r->in_contact[p]
                    && ballc_rolling_mode(r->latch + p * NLP, part) == BALLC_ROLLING_MODE_SLIDER)
                return 1;
    return 0;
}

/* A contact starts: the rolling and twisting parts' first modes. */
static int start_rolling(run_t *r, int p)
{
    const ballc_drive_config *c = r->c;
    if (!c->rolling && !c->twisting) return 0;
    ballc_rolling_scales scales = rolling_scales(r, p, r->y);
    if (ballc_rolling_start(&r->prepared, p, c->rolling, c->twisting, r->y,
                            r->latch, run_flags(r, 1), r->coulomb[p] == BALLC_MODE_STICK,
                            &r->rolling_run[p], &scales)) {
        r->failed_kernel = 1;
        return -1;
    }
    return recheck_modes(r, p);
}

/* After a reset of plane p that moved the state or changed what holds (a settle, a
 * release), every exact mode must still be on its guard's side (_rolling.h,
 * ballc_rolling_recheck): a Coulomb slip with u . d above its approach speed (free) or
 * above -margin (fixed), a stick with its margin mu N - |lambda| above -scale (a hold
 * that starts next to it shares the load: a ball held from rolling on an incline needs
 * all of m g sin(theta) from friction), and so the rolling and twisting parts; one that
 * is not starts afresh, or is released, which may move the state again (a few passes).
 * Only with rolling resistance: without it, Coulomb's resets keep their own invariants. */
static int recheck_modes(run_t *r, int p)
{
    const ballc_drive_config *c = r->c;
    if (!c->rolling && !c->twisting) return 0;
    for (int pass = 0; pass < 8; pass++) {
        int restarted = 0;
        int mode = r->coulomb[p];
        if (c->exact && (mode == BALLC_MODE_SLIP || mode == BALLC_MODE_SLIP_FIXED)) {
            double u[2], speed, error, clear;
            slip(r, p, r->y, u, &speed, &error, &clear);
            const double *d = r->latch + p * NLP + SLIP_D;
            double along = u[0] * d[0] + u[1] * d[1];
            double guard = mode == BALLC_MODE_SLIP
                           ? (r->has_approach[p] ? r->approach[p] : clear)
                           : -4 * ulp(speed_scale(r, r->y));
            if (!(along > guard)) {
                if (start_coulomb(r, p)) return -1;
                restarted++;
            }
        } else if (c->exact && mode == BALLC_MODE_STICK) {
            double out[4];
            if (ballc_stick_state(r->y, c->params, r->latch, run_flags(r, 1), p, out)
                    != BALLC_OK) {
                r->failed_kernel = 1;
                return -1;
            }
            if (out[3] < -force_scale(r, out[2])) {
                if (coulomb_release(r, p)) return -1;
                restarted++;
            }
        }
        ballc_rolling_scales scales = rolling_scales(r, p, r->y);
        int n = ballc_rolling_recheck(&r->prepared, p, r->y, r->latch, run_flags(r, 1),
                                      r->coulomb[p] == BALLC_MODE_STICK,
                                      &r->rolling_run[p], &scales);
        if (n < 0) {
            r->failed_kernel = 1;
            return -1;
        }
        if (!restarted && !n) return 0;
    }
    return 0;
}

/* An event of the rolling part: its reset (_rolling.c), counted as a mode change. */
static int rolling_event(run_t *r, int kind, int p)
{
    if (!settles(r, p)) return 0;
    ballc_rolling_scales scales = rolling_scales(r, p, r->y);
    r->transitions[p] += 1;
    if (ballc_rolling_transition(&r->prepared, p, kind - K_ROLL_FIRST, r->y, r->latch,
                                 run_flags(r, 1), r->coulomb[p] == BALLC_MODE_STICK,
                                 &r->rolling_run[p], &scales)) {
        r->failed_kernel = 1;
        return -1;
    }
    return recheck_modes(r, p);
}

/* the automaton's arm, yield, capacity and restick: the compliant law's next mode */
static int compliant_event(run_t *r, int kind, int p)
{
    if (!settles(r, p)) {
        r->o->unsettled_compliant = 1;
        return 0;
    }
    if (kind == K_CAPACITY) {   /* no change: the next segment watches the way back */
        r->capacity_row[p] = r->fired_row == 4 ? 5 : 4;
        return 0;
    }
    double y[N];
    if (kind == K_ARM) r->armed[p] = 1;
    else if (kind == K_YIELD) {   /* the load vanished, the spring far below the cap */
        double m[BALLC_COMPLIANT_MARGINS];
        if (margins_of(r, p, r->y, m)) return -1;
        if (!(m[2] > 0) || m[0] > 0.5) {
            r->armed[p] = 0;
            return set_compliant(r, p, COMPLIANT_ELASTIC);
        }
    }
    if (kind == K_ARM || kind == K_YIELD) {
        int mode;
        if (decide(r, p, r->y, kind == K_ARM, &mode, y)) return -1;
        memcpy(r->y, y, r->ns * sizeof(double));
        return set_compliant(r, p, mode);
    }
    if (at_cap(r, p, r->y, 1, y)) return -1;   /* restick */
    memcpy(r->y, y, r->ns * sizeof(double));
    return set_compliant(r, p, COMPLIANT_ELASTIC);
}

/* the row c of u . d = c . y (u is linear in the state) */
static void stop_coefficients(const run_t *r, int p, const double *d, double *row)
{
    const double *a = r->prepared.slip_map[p], *b = a + r->ns;
    for (int j = 0; j < r->ns; j++) row[j] = d[0] * a[j] + d[1] * b[j];
}

/* ---- the integrator's callbacks ---- */

static int drv_fun(void *ctx, double t, const double *y, double *f)
{
    run_t *r = (run_t *)ctx;
    (void)t;
    return ballc_rhs_checked_inputs(y, &r->prepared, r->latch, r->seg_flags, f);
}

static int drv_jac(void *ctx, double t, const double *y, double *jac)
{
    run_t *r = (run_t *)ctx;
    (void)t;
    return ballc_jacobian_checked_inputs(y, &r->prepared, r->latch, r->seg_flags, jac);
}

static int drv_event(void *ctx, int e, double t, const double *y, double *g)
{
    run_t *r = (run_t *)ctx;
    double out[6];
    (void)t;
    int code = r->ev_plane_code[e];
    if (r->ev_kind[e] >= K_ROLL_FIRST && r->ev_kind[e] < K_USER)   /* the rolling part's */
        return ballc_rolling_guard_value(&r->prepared, r->ev_plane[e],
                                         r->ev_kind[e] - K_ROLL_FIRST, y, r->latch,
                                         r->seg_flags, g);
    if (code <= -2) {   /* the user's callable (the bridge's _user_event) */
        int st = r->c->user_fun(r->c->user_ctx, -2 - code, t, y, g);
        if (st) r->user_failed = 1;
        return st;
    }
    if (code >= MARGIN_CODE) {   /* a compliant guard: the bridge's _ball_event, cached */
        int row = (code - MARGIN_CODE) / MAXP, plane = (code - MARGIN_CODE) % MAXP;
        if (r->margins_plane == plane && (row != 1 || r->margins_solved)
                && memcmp(r->margins_y, y, r->ns * sizeof(double)) == 0) {
            g[0] = r->margins_out[row];
            return BALLC_OK;
        }
        int st = ballc_compliant_margins_prepared(y, &r->prepared, r->latch, r->seg_flags,
                                                  plane, row, r->margins_out);
        r->margins_plane = st == BALLC_OK ? plane : -1;
        r->margins_solved = row == 1;
        memcpy(r->margins_y, y, r->ns * sizeof(double));
        g[0] = r->margins_out[row];
        return st;
    }
    int status = ballc_stick_state_prepared(y, &r->prepared, r->latch, r->seg_flags, code,
                                            out);
    g[0] = out[3];
    return status;
}

/* A re-arm at t: (t, the latch before) for the samples' blocks (add_later_rows);
 * -1 out of memory */
static int note_rearm(run_t *r, double t)
{
    if (grow((void **)&r->rearmed_t, &r->cap_rearmed, r->n_rearmed + 1, sizeof(double)))
        return -1;
    double *lat = realloc(r->rearmed_latch, (size_t)r->cap_rearmed * r->nl * sizeof(double));
    if (!lat) return -1;
    r->rearmed_latch = lat;
    r->rearmed_t[r->n_rearmed] = t;
    memcpy(r->rearmed_latch + r->n_rearmed * r->nl, r->latch, r->nl * sizeof(double));
    r->n_rearmed++;
    return 0;
}

/* A user's LinearEvent with ``rearm`` (ballc.events): called back; accepted, the event
 * goes on as its new row and offset for the rest of the segment, and the run with the
 * latch returned (the samples from t on carry it) */
static int user_rearm(run_t *r, int e, double t, const double *y)
{
    const ballc_drive_config *c = r->c;
    double coef[N], offset, latch[NL];
    int got = c->rearm_fun(c->user_ctx, r->ev_plane[e], t, y, coef, &offset, latch);
    if (got < 0) r->user_failed = 1;   /* the loop stops: the bridge raises it */
    if (got != 1 || note_rearm(r, t)) return 0;
    memcpy(r->ev_coef + (size_t)e * r->ns, coef, r->ns * sizeof(double));
    r->ev_offset[e] = offset;
    r->ev_index[e] = -1;
    memcpy(r->latch, latch, r->nl * sizeof(double));
    r->margins_plane = -1;   /* the margins read the latch */
    return 1;
}

/* a terminal event's re-arm inside the segment: the capacity guard turns; a free
 * slip's approach that passes by zero re-latches its direction (the right-hand side is
 * the same on both sides) and goes on; a user's LinearEvent asks its ``rearm`` */
static int drv_rearm(void *ctx, int e, double t, const double *y)
{
    run_t *r = (run_t *)ctx;
    int code = r->ev_plane_code[e];
    int p = r->ev_plane[e];
    if (code >= CAPACITY_FIRST) {   /* the bridge's _ball_rearm: a capacity guard toggles */
        r->ev_plane_code[e] = code < CAPACITY_SECOND ? code + MAXP : code - MAXP;
        log_rearm(r, K_CAPACITY, p, plane_mode(r, p));
        return 1;
    }
    if (r->ev_kind[e] == K_USER) return user_rearm(r, e, t, y);
    long stalled = stalled_at(r, t);
    if (unsettled(r, p, stalled) || r->relatches[p] + 1 > MAX_RELATCH) return 0;
    double u[2], speed, error, clear;
    slip(r, p, y, u, &speed, &error, &clear);
    if (!slips_on_freely(r, p, u, speed, error, clear)) return 0;
    if (note_rearm(r, t)) return 0;
    r->stalled = stalled;
    r->last_transition = t;
    r->has_last_transition = 1;
    r->relatches[p] += 1;
    double d[2] = {u[0] / speed, u[1] / speed};
    double approach = py_min(clear, APPROACH_FRACTION * speed);
    int before = plane_mode(r, p);
    if (set_mode(r, p, BALLC_MODE_SLIP, d, 1, approach)) return 0;
    log_rearm(r, K_APPROACH, p, before);
    stop_coefficients(r, p, d, r->ev_coef + (size_t)e * r->ns);
    r->ev_offset[e] = -approach;
    r->margins_plane = -1;   /* the margins read the latch */
    return 1;
}

/* ---- one segment's events (the automaton's guards, then the user's) ---- */

static int add_event(run_t *r, int kind, int p, const double *coef, int state, double scale,
                     double offset, int terminal, int direction)
{
    int k = r->n_ev++;
    double *row = r->ev_coef + (size_t)k * r->ns;
    if (coef) memcpy(row, coef, r->ns * sizeof(double));
    else {
        memset(row, 0, r->ns * sizeof(double));
        if (state >= 0) row[state] = scale;
    }
    r->ev_offset[k] = offset;
    r->ev_terminal[k] = terminal;
    r->ev_direction[k] = direction;
    r->ev_nonlinear[k] = 0;
    r->ev_plane_code[k] = -1;
    r->ev_rearm[k] = 0;
    r->ev_kind[k] = kind;
    r->ev_plane[k] = p;
    r->ev_index[k] = coef ? -1 : state;
    r->ev_scale[k] = scale;
    return k;
}

/* An event of plane p's penetration, rho + shift (rate: of its rate rho' + shift):
 * one state's when the plane is axis-aligned, else a row on x, y, z (v) */
static int add_plane_event(run_t *r, int kind, int p, int rate, double shift, int terminal,
                           int direction)
{
    const plane_geometry *g = &r->geometry[p];
    double offset = rate ? shift : g->offset + shift;
    if (g->axis >= 0)
        return add_event(r, kind, p, NULL, g->axis + (rate ? 6 : 0), g->scale, offset,
                         terminal, direction);
    double row[N];
    memset(row, 0, r->ns * sizeof(double));
    for (int i = 0; i < 3; i++) row[(rate ? BALLC_STATE_VX : BALLC_STATE_X) + i] = g->coef[i];
    return add_event(r, kind, p, row, -1, 0, offset, terminal, direction);
}

static int segment_events(run_t *r, ballc_flags flags)
{
    const ballc_drive_config *c = r->c;
    const double *y0 = r->y;
    int have_clear = 0;
    double clear = 0.0;
    r->n_ev = 0;
    for (int p = 0; p < r->np; p++) {
        double rho0 = rho_of(r, p, y0);
        double position = plane_position(r, p, y0);
        double base = 4 * ulp(position);   /* events.threshold_base */
        if (r->in_contact[p]) {
            double threshold = py_max(base, -rho0 + base);
            add_plane_event(r, K_LEAVE, p, 0, threshold, 1, -1);
            add_plane_event(r, K_THROUGH, p, 0, -c->radius, 1, 1);
            add_plane_event(r, K_DEEPEST, p, 1, 0.0, 0, -1);
        } else {
            double threshold = py_max(base, rho0 + base);
            double arm = arm_depth(r, p, y0);
            if (arm > 0) threshold = py_max(threshold, arm);
            add_plane_event(r, K_ENTER, p, 0, -threshold, 1, 1);
        }
        int mode = r->coulomb[p];
        if (mode == BALLC_MODE_SLIP || mode == BALLC_MODE_SLIP_FIXED) {
            if (!have_clear) {
                clear = CLEAR_FACTOR * error_speed(r, y0);
                have_clear = 1;
            }
            double along[N];
            stop_coefficients(r, p, r->latch + p * NLP + SLIP_D, along);
            if (mode == BALLC_MODE_SLIP) {
                double speed = r->has_approach[p] ? r->approach[p] : clear;
                int k = add_event(r, K_APPROACH, p, along, -1, 0, -speed, 1, -1);
                r->ev_rearm[k] = 1;
            } else {
                double margin = 4 * ulp(speed_scale(r, y0));
                add_event(r, K_STOP, p, along, -1, 0, margin, 1, -1);
                add_event(r, K_CLEAR, p, along, -1, 0, -2 * clear, 1, 1);
            }
        } else if (mode == BALLC_MODE_STICK) {
            double out[4];
            if (ballc_stick_state(y0, c->params, r->latch, flags, p, out) != BALLC_OK) {
                r->failed_kernel = 1;
                return -1;
            }
            int k = add_event(r, K_RELEASE, p, NULL, -1, 0, force_scale(r, out[2]), 1, -1);
            r->ev_nonlinear[k] = 1;
            r->ev_plane_code[k] = p;
        }
        if (r->in_contact[p] && ballc_rolling_on(r->latch + p * NLP)) {   /* _rolling.h */
            ballc_rolling_guard guards[4];
            ballc_rolling_scales scales = rolling_scales(r, p, y0);
            int n = ballc_rolling_guards(&r->prepared, p, y0, r->latch, flags,
                                         &r->rolling_run[p], &scales, guards);
            if (n < 0) {
                r->failed_kernel = 1;
                return -1;
            }
            for (int i = 0; i < n; i++) {
                const ballc_rolling_guard *g = &guards[i];
                int k = add_event(r, K_ROLL_FIRST + g->event, p, g->linear ? g->row : NULL,
                                  -1, 0, g->offset, 1, g->direction);
                r->ev_nonlinear[k] = !g->linear;
            }
        }
        if (r->compliant[p] != COMPLIANT_NONE) {   /* the mode's guard */
            if (!r->armed[p]) {   /* the penetration rising through the arming depth */
                add_plane_event(r, K_ARM, p, 0, -arm_depth(r, p, y0), 1, 1);
                continue;
            }
            double ulp8 = 8 * ulp(position);
            double rounding = py_max(64 * DBL_EPSILON, ulp8 / py_max(rho0, 1e-300));
            int elastic = r->compliant[p] == COMPLIANT_ELASTIC;
            double offset = elastic ? rounding
                                    : rounding * speed_scale(r, y0) * c->restick_factor;
            int k = add_event(r, elastic ? K_YIELD : K_RESTICK, p, NULL, -1, 0, offset, 1, -1);
            r->ev_nonlinear[k] = 1;
            r->ev_plane_code[k] = MARGIN_CODE + (elastic ? 0 : 1) * MAXP + p;
            if (elastic && c->damping_positive) {   /* the viscous capacity's kink */
                double m[BALLC_COMPLIANT_MARGINS];
                if (margins_of(r, p, y0, m)) return -1;
                int row = r->capacity_row[p] >= 0 ? r->capacity_row[p] : (m[4] >= 0 ? 4 : 5);
                double cap = m[2] * m[3];
                k = add_event(r, K_CAPACITY, p, NULL, -1, 0, rounding * py_max(cap, 1e-12),
                              1, -1);
                r->ev_nonlinear[k] = 1;
                r->ev_plane_code[k] = MARGIN_CODE + row * MAXP + p;
                r->ev_rearm[k] = 1;
            }
        }
    }
    /* the user's: terminal = the occurrences left */
    for (int u = 0; u < c->n_user; u++) {
        int left = c->user_count[u] ? (int)(c->user_count[u] - r->user_seen[u]) : 0;
        double offset = c->user_offset[u];
        if (c->user_linear[u] && left != c->user_count[u]) offset = offset + 0.0;  /* shifted */
        int k = add_event(r, K_USER, u, c->user_linear[u] ? c->user_coef + (size_t)u * r->ns : NULL,
                          -1, 0, offset, left, c->user_direction[u]);
        r->ev_index[k] = c->user_linear[u] ? c->user_index[u] : -1;
        r->ev_scale[k] = c->user_linear[u] ? c->user_scale[u] : 0.0;
        r->ev_rearm[k] = c->user_rearm && c->user_linear[u] && c->user_rearm[u];
        if (!c->user_linear[u]) {   /* a callable: called back through the bridge */
            r->ev_nonlinear[k] = 1;
            r->ev_plane_code[k] = -2 - u;
        }
    }
    return 0;
}

/* ---- samples: per block of a segment, its flags and latch ---- */

static int add_block(run_t *r, const double *t, const double *y, long count,
                     ballc_flags flags, const double *latch)
{
    ballc_drive_output *o = r->o;
    const int ns = r->ns, nl = r->nl;
    long cap = o->cap;
    if (grow((void **)&o->t, &o->cap, o->n + count, sizeof(double))) return -1;
    if (o->cap != cap || !o->y) {
        double *yy = realloc(o->y, (size_t)(o->cap ? o->cap : 1) * ns * sizeof(double));
        if (!yy) return -1;
        o->y = yy;
    }
    long cb = o->cap_blocks;
    if (grow((void **)&o->block_count, &cb, o->n_blocks + 1, sizeof(long))) return -1;
    if (cb != o->cap_blocks) {
        ballc_flags *f = realloc(o->block_flags, (size_t)cb * sizeof(ballc_flags));
        if (!f) return -1;
        o->block_flags = f;
        double *l = realloc(o->block_latch, (size_t)cb * nl * sizeof(double));
        if (!l) return -1;
        o->block_latch = l;
        o->cap_blocks = cb;
    }
    if (count) {
        memcpy(o->t + o->n, t, (size_t)count * sizeof(double));
        memcpy(o->y + (size_t)o->n * ns, y, (size_t)count * ns * sizeof(double));
    }
    o->n += count;
    o->block_count[o->n_blocks] = count;
    o->block_flags[o->n_blocks] = flags;
    memcpy(o->block_latch + (size_t)o->n_blocks * nl, latch, nl * sizeof(double));
    o->n_blocks++;
    return 0;
}

/* a segment's samples later than ``after`` (without t_eval its first sample is its start,
 * stored already), in blocks split where a re-arm changed the latch */
static int add_later_rows(run_t *r, long n, const double *t, const double *y_out,
                          double after, ballc_flags flags)
{
    long first = r->c->t_eval ? 0 : 1;   /* simulate: skip */
    while (first < n && t[first] <= after) first++;
    for (long k = 0; k < r->n_rearmed; k++) {
        double when = r->rearmed_t[k];
        long cut = 0;   /* searchsorted(t, when, 'right') */
        while (cut < n && t[cut] <= when) cut++;
        if (cut < first) cut = first;
        if (add_block(r, t + first, y_out + (size_t)first * r->ns, cut - first, flags,
                      r->rearmed_latch + (size_t)k * r->nl))
            return -1;
        first = cut;
    }
    return add_block(r, t + first, y_out + (size_t)first * r->ns, n - first, flags,
                     r->latch);
}

static int add_later(run_t *r, const radau5_result *res, double after, ballc_flags flags)
{
    return add_later_rows(r, res->n_out, res->t_out, res->y_out, after, flags);
}

/* ---- exact free flight (ballc.flight) ---- */

/* The exact solution's coefficients (ballc.flight's docstring): omega, the dissipated
 * work and the deflections constant, the centre a parabola under the gravity vector
 * (3 values), the quaternion turning at omega, q(s) = cos(|omega| s / 2) q0
 * + sin(|omega| s / 2) [0, n] (x) q0; n states */
void ballc_flight_init(ballc_flight *f, double t0, const double *y0, const double *gravity,
                       int n)
{
    f->n = n;
    f->t0 = t0;
    double wx = y0[BALLC_STATE_OMEGA_X], wy = y0[BALLC_STATE_OMEGA_Y], wz = y0[BALLC_STATE_OMEGA_Z];
    f->rate = sqrt(wx * wx + wy * wy + wz * wz);
    double nx = 0.0, ny = 0.0, nz = 0.0;
    if (f->rate > 0) { nx = wx / f->rate; ny = wy / f->rate; nz = wz / f->rate; }
    double qw = y0[BALLC_STATE_QW], qx = y0[BALLC_STATE_QX], qy = y0[BALLC_STATE_QY],
           qz = y0[BALLC_STATE_QZ];
    double turned[4] = {-(nx * qx + ny * qy + nz * qz), nx * qw + ny * qz - nz * qy,
                        ny * qw + nz * qx - nx * qz, nz * qw + nx * qy - ny * qx};
    memset(f->c, 0, sizeof f->c);
    memcpy(f->c[0], y0, n * sizeof(double));
    for (int i = 0; i < 4; i++) {
        f->c[0][BALLC_STATE_QW + i] = 0.0;
        f->c[3][BALLC_STATE_QW + i] = y0[BALLC_STATE_QW + i];
        f->c[4][BALLC_STATE_QW + i] = turned[i];
    }
    for (int i = 0; i < 3; i++) f->c[1][BALLC_STATE_X + i] = y0[BALLC_STATE_VX + i];
    for (int i = 0; i < 3; i++) {   /* v0 + g s, c0 + v0 s + g s^2 / 2 */
        f->c[1][BALLC_STATE_VX + i] = gravity[i];
        f->c[2][BALLC_STATE_X + i] = 0.5 * gravity[i];
    }
}

/* y(t): the 5 products of coefficients and basis (1, s, s^2, cos, sin), summed in order */
void ballc_flight_at(const ballc_flight *f, double t, double *y)
{
    double s = t - f->t0;
    double half = 0.5 * f->rate * s;
    double basis[5] = {1.0, s, s * s, cos(half), sin(half)};
    for (int n = 0; n < f->n; n++) {
        double acc = 0.0;
        for (int k = 0; k < 5; k++) acc += f->c[k][n] * basis[k];
        y[n] = acc;
    }
}

/* ---- rolling down an unbounded incline (the end state BALLC_END_ACCELERATING) ---- */

void ballc_rolling_init(ballc_rolling *f, double t0, const double *y0,
                        const double *acceleration, double radius, const double *normal,
                        int n)
{
    f->n = n;
    f->t0 = t0;
    memcpy(f->y0, y0, n * sizeof(double));
    const double *a = acceleration, *m = normal;
    double e[3] = {m[1] * a[2] - m[2] * a[1], m[2] * a[0] - m[0] * a[2],
                   m[0] * a[1] - m[1] * a[0]};   /* n x a */
    double size = norm3(e), w0 = 0.0;
    for (int i = 0; i < 3; i++) {
        f->a[i] = a[i];
        f->axis[i] = size > 0 ? e[i] / size : 0.0;
        w0 += y0[BALLC_STATE_OMEGA_X + i] * f->axis[i];
    }
    f->w0 = w0;
    f->spin_rate = norm3(a) / radius;   /* rad/s^2 */
}

double ballc_rolling_angle(const ballc_rolling *f, double t)
{
    double s = t - f->t0;
    return f->w0 * s + 0.5 * f->spin_rate * s * s;
}

void ballc_rolling_at(const ballc_rolling *f, double t, double *y)
{
    double s = t - f->t0;
    memcpy(y, f->y0, f->n * sizeof(double));
    for (int i = 0; i < 3; i++) {
        y[BALLC_STATE_X + i] += f->y0[BALLC_STATE_VX + i] * s + 0.5 * f->a[i] * s * s;
        y[BALLC_STATE_VX + i] += f->a[i] * s;
        y[BALLC_STATE_OMEGA_X + i] = f->axis[i] * (f->w0 + f->spin_rate * s);
    }
    /* q(s) = cos(theta / 2) q0 + sin(theta / 2) [0, e] (x) q0 */
    double half = 0.5 * ballc_rolling_angle(f, t), c = cos(half), sn = sin(half);
    const double *q = f->y0 + BALLC_STATE_QW, *e = f->axis;
    double turned[4] = {-(e[0] * q[1] + e[1] * q[2] + e[2] * q[3]),
                        e[0] * q[0] + e[1] * q[3] - e[2] * q[2],
                        e[1] * q[0] + e[2] * q[1] - e[0] * q[3],
                        e[2] * q[0] + e[0] * q[2] - e[1] * q[1]};
    for (int i = 0; i < 4; i++) y[BALLC_STATE_QW + i] = c * q[i] + sn * turned[i];
}

/* the roots of c0 + c1 s + c2 s^2 in [0, s_max] where it changes sign in ``direction``
 * (cancellation-free), in
 * increasing order (at most 2) */
int ballc_flight_crossings(double c0, double c1, double c2, int direction, double s_max,
                           double *out)
{
    double roots[2];
    int rising[2], m, n = 0;
    if (c2 == 0) {
        if (c1 == 0) return 0;
        roots[0] = -c0 / c1;
        rising[0] = c1 > 0;
        m = 1;
    } else {
        double disc = c1 * c1 - 4.0 * c2 * c0;
        if (!(disc > 0)) return 0;
        double q = -0.5 * (c1 + copysign(sqrt(disc), c1));
        double a = q / c2, b = c0 / q;
        if (b < a) { roots[0] = b; roots[1] = a; }   /* sorted((a, b)) */
        else { roots[0] = a; roots[1] = b; }
        rising[0] = c2 < 0;
        rising[1] = c2 > 0;
        m = 2;
    }
    for (int i = 0; i < m; i++)
        if (0 <= roots[i] && roots[i] <= s_max
                && (direction == 0 || (direction > 0) == rising[i]))
            out[n++] = roots[i];
    return n;
}


/* the exact free flight of a segment from (r->t, r->y) to t1 whose events are all linear in
 * one state that is not the quaternion (the contact starts, the user's LinearEvents):
 * its samples (t_eval's points from ev, n_eval of them, or the even grid) and its hits,
 * in ``res`` as the integrator would give them (freed by radau5_free).  Returns 0,
 * -1 (aborted: r->why) or -2 (memory). */
static int flight_segment(run_t *r, double t1, const double *ev, long n_eval,
                          radau5_result *res)
{
    const ballc_drive_config *c = r->c;
    double t0 = r->t;
    const double *g = r->gravity;
    ballc_flight f;
    ballc_flight_init(&f, t0, r->y, g, r->ns);
    memset(res, 0, sizeof *res);
    res->stiff_at = NAN;
    res->method_end = -1;
    double span = t1 - t0;
    /* the hits (s, event), at most 2 per event, sorted by s, then event */
    double *hs = r->flight_s;
    int *he = r->flight_e, nh = 0;
    for (int e = 0; e < r->n_ev; e++) {   /* FreeFlight.event_polynomial, crossings */
        int k = r->ev_index[e];
        if (r->ev_nonlinear[e]) {
            r->why = "an exact flight met an event that is not linear";
            return -1;
        }
        double c0, c1, c2;
        if (k >= 0) {
            double scale = r->ev_scale[e], y0k = r->y[k];
            int position = k >= BALLC_STATE_X && k <= BALLC_STATE_Z;
            int velocity = k >= BALLC_STATE_VX && k <= BALLC_STATE_VZ;
            c0 = scale * y0k + r->ev_offset[e];
            c1 = scale * (position ? r->y[k + 6] : velocity ? g[k - BALLC_STATE_VX] : 0.0);
            c2 = position ? 0.5 * scale * g[k - BALLC_STATE_X] : 0.0;
        } else {   /* several states (none of the quaternion's): plain C dots */
            const double *row = r->ev_coef + (size_t)e * r->ns;
            c0 = 0.0;
            for (int i = 0; i < r->ns; i++) c0 += row[i] * r->y[i];
            c0 += r->ev_offset[e];
            c1 = 0.0;
            for (int i = 0; i < 3; i++) c1 += row[BALLC_STATE_X + i] * r->y[BALLC_STATE_VX + i];
            c2 = 0.0;
            for (int i = 0; i < 3; i++) {   /* gravity's share (its zero components none) */
                if (g[i] == 0.0) continue;
                c1 += row[BALLC_STATE_VX + i] * g[i];
                c2 += 0.5 * row[BALLC_STATE_X + i] * g[i];
            }
        }
        double roots[2];
        int n = ballc_flight_crossings(c0, c1, c2, r->ev_direction[e], span, roots);
        if (r->ev_terminal[e] > 0 && n > r->ev_terminal[e]) n = r->ev_terminal[e];
        for (int i = 0; i < n; i++) {
            int at = nh++;   /* insertion by (s, event) */
            while (at > 0 && (hs[at - 1] > roots[i]
                              || (hs[at - 1] == roots[i] && he[at - 1] > e))) {
                hs[at] = hs[at - 1];
                he[at] = he[at - 1];
                at--;
            }
            hs[at] = roots[i];
            he[at] = e;
        }
    }
    int *seen = r->flight_seen, stop = -1;
    memset(seen, 0, (size_t)r->n_ev * sizeof(int));
    for (int h = 0; h < nh; h++) {
        int e = he[h];
        seen[e]++;
        if (r->ev_terminal[e] && seen[e] >= r->ev_terminal[e]) { stop = h; break; }
    }
    double t_end = t1;
    int kept = nh;   /* every hit; with a stop, those up to it */
    if (stop >= 0) {
        kept = 0;
        for (int h = 0; h < nh; h++)   /* hits <= stop (tuples) */
            if (hs[h] < hs[stop] || (hs[h] == hs[stop] && he[h] <= he[stop])) kept++;
        t_end = py_min(t0 + hs[stop], t1);
        res->status = RADAU5_EVENT;
    } else {
        res->status = RADAU5_REACHED;
    }
    long n;
    double *times;
    if (c->t_eval) {   /* t[(t >= t0) & (t <= t_stop)] of the segment's points */
        n = 0;
        while (n < n_eval && ev[n] <= t_end) n++;
        long lo = 0;
        while (lo < n && !(ev[lo] >= t0)) lo++;
        ev += lo;
        n -= lo;
        times = malloc((size_t)(n ? n : 1) * sizeof(double));
        if (!times) return -2;
        if (n) memcpy(times, ev, (size_t)n * sizeof(double));
    } else {
        double max_step = run_max_step(r);
        double turn = f.rate * (t_end - t0) / BALLC_FLIGHT_MAX_TURN;
        double longest = max_step < INFINITY ? (t_end - t0) / max_step : 0.0;
        if (!(fabs(turn) < BALLC_FLIGHT_MAX_SAMPLES)
                || !(fabs(longest) < BALLC_FLIGHT_MAX_SAMPLES)) {
            r->why = "an exact flight would store more than 1e8 samples (give t_eval, or "
                     "exact_flight=False)";
            return -1;
        }
        double m = py_max(py_max((double)BALLC_FLIGHT_MIN_INTERVALS, ceil(turn)), ceil(longest));
        long intervals = (long)m;
        n = intervals + 1;
        times = malloc((size_t)n * sizeof(double));
        if (!times) return -2;
        double dt = t_end - t0;
        for (long i = 0; i <= intervals; i++)
            times[i] = t0 + dt * ((double)i / (double)intervals);
        times[intervals] = t_end;
    }
    res->t_out = times;
    res->n_out = n;
    res->y_out = malloc((size_t)(n ? n : 1) * r->ns * sizeof(double));
    res->hit_event = malloc((size_t)(kept ? kept : 1) * sizeof(int));
    res->hit_t = malloc((size_t)(kept ? kept : 1) * sizeof(double));
    res->hit_y = malloc((size_t)(kept ? kept : 1) * r->ns * sizeof(double));
    if (!res->y_out || !res->hit_event || !res->hit_t || !res->hit_y) return -2;
    for (long i = 0; i < n; i++) ballc_flight_at(&f, times[i], res->y_out + (size_t)i * r->ns);
    for (int h = 0, m = 0; h < nh && m < kept; h++) {
        if (stop >= 0 && !(hs[h] < hs[stop] || (hs[h] == hs[stop] && he[h] <= he[stop])))
            continue;
        double when = h == stop ? t_end : py_min(t0 + hs[h], t1);
        res->hit_event[m] = he[h];
        res->hit_t[m] = when;
        ballc_flight_at(&f, when, res->hit_y + (size_t)m * r->ns);
        m++;
    }
    res->n_hits = kept;
    return 0;
}

/* ---- the rest checks (ballc.resting) ---- */

/* _core.energies of one state row */
static void energy_of(const run_t *r, const double *y, double *e)
{
    ballc_energy(y, &r->prepared, e);
}

/* the energy y has above ``new`` added to new's dissipated_normal */
static void booked(const run_t *r, const double *y, double *new_y)
{
    double a[BALLC_MAX_ENERGY_NOUT], b[BALLC_MAX_ENERGY_NOUT];
    energy_of(r, y, a);
    energy_of(r, new_y, b);
    double before = a[0], after = b[0];
    for (int i = 1; i < BALLC_ENERGY_NOUT(r->np); i++) {
        before += a[i];
        after += b[i];
    }
    new_y[BALLC_STATE_DISSIPATED_NORMAL] += before - after;
}

/* the Hertz spring plus gravity above rho_eq, x = (rho - rho_eq) / rho_eq > -1 */
static double normal_above(const ballc_drive_config *c, double x)
{
    return c->rest_weight * c->rho_eq * (0.4 * expm1(2.5 * log1p(x)) - x);
}

/* the compliant law's tangential springs' energy, every plane's (J) */
static double tangential_springs(const run_t *r, const double *e)
{
    double spring = e[2 + r->np];
    for (int q = 1; q < r->np; q++) spring += e[2 + r->np + q];
    return spring;
}

/* the rolling part's sds springs' energy, every plane's (J; 0 without them) */
static double rolling_springs(const run_t *r, const double *e)
{
    double spring = 0.0;
    for (int q = 0; q < r->np; q++) spring += e[2 + 2 * r->np + q];
    return spring;
}

/* Whether plane p holds its rolling (rolling resistance's exact holding mode) and sticks:
 * the ball can then only spin about the normal, uniformly (the constraints keep omega
 * along n and the centre still; no force has a moment about n), whatever its inertia
 * and observer -- a uniform motion in closed form. */
static int held_still(const run_t *r, int p)
{
    return p >= 0 && r->in_contact[p]
           && ballc_rolling_mode(r->latch + p * NLP, 0) == BALLC_ROLLING_MODE_HOLDING
           && r->coulomb[p] == BALLC_MODE_STICK;
}

/* The resting plane p's state: y with the centre at the static equilibrium's height
 * above the plane (r - rho_eq along its normal, which is opposite gravity) and no
 * velocity along the normal, every deflection 0 */
static void at_equilibrium(const run_t *r, int p, double *y)
{
    const plane_geometry *g = &r->geometry[p];
    const ballc_plane_t *pl = &r->prepared.planes[p];
    if (g->axis >= 0) {   /* along a coordinate axis: set that coordinate */
        int k = g->axis - BALLC_STATE_X;
        y[g->axis] = pl->point[k] + pl->frame[2][k] * r->c->z_eq;
        y[g->axis + 6] = 0.0;
    } else {
        const double *n = pl->frame[2];
        double height = 0.0, along = 0.0;
        for (int i = 0; i < 3; i++) {
            height += n[i] * (y[BALLC_STATE_X + i] - pl->point[i]);
            along += n[i] * y[BALLC_STATE_VX + i];
        }
        for (int i = 0; i < 3; i++) {
            y[BALLC_STATE_X + i] += (r->c->z_eq - height) * n[i];
            y[BALLC_STATE_VX + i] -= along * n[i];
        }
    }
    for (int q = 0; q < r->np; q++)
        y[ballc_plane_state(q)] = y[ballc_plane_state(q) + 1] = 0.0;
}

/* whether the contact with plane p is at rest (ballc.resting's criteria 2-4) */
static int at_rest(const run_t *r, int p, const double *y, double t_start, double t)
{
    const ballc_drive_config *c = r->c;
    if (t - t_start < c->rest_period) return 0;
    double across = 0.0, up = 0.0;
    /* a ball whose rolling is held (the exact model's holding, or the sds spring below
     * its cap) rests wherever its observer is: it cannot roll the observer lower */
    int roll_mode = ballc_rolling_mode(r->latch + p * NLP, 0);
    int held = roll_mode == BALLC_ROLLING_MODE_HOLDING || roll_mode == BALLC_ROLLING_MODE_SPRING;
    if (c->observer_massive && !held) {   /* the observer's offset from the centre, plane's frame */
        double where[BALLC_OBSERVER_POSITION_NOUT], d[3], local[3];
        ballc_observer_position(y, c->params, r->prepared.constants, NULL, where);
        for (int i = 0; i < 3; i++) d[i] = where[i] - y[BALLC_STATE_X + i];
        ballc_plane_to_local(&r->prepared.planes[p], d, local);
        across = hypot(local[0], local[1]);
        up = local[2];
        if (up >= 0) return 0;
    }
    double e[BALLC_MAX_ENERGY_NOUT];
    energy_of(r, y, e);
    double kinetic = e[0], spring = tangential_springs(r, e);
    double rho = rho_of(r, p, y);
    double x = (rho - c->rho_eq) / c->rho_eq;
    double normal = INFINITY;
    if (x > -1) normal = normal_above(c, x);   /* deep: inf, not at rest */
    double observer = 0.0;
    if (c->observer_massive && !held) {
        double reach = hypot(across, up);
        observer = reach > 0 ? c->observer_weight * across * across / (reach + fabs(up)) : 0.0;
    }
    double above = kinetic + py_max(normal, 0.0) + spring + observer;
    return above <= c->rest_threshold;
}

/* the largest |v| of n values: NaN when one is NaN */
static double max_abs(const double *v, int n)
{
    double m = fabs(v[0]);
    for (int i = 0; i < n; i++) {
        if (isnan(v[i])) return NAN;
        if (fabs(v[i]) > m) m = fabs(v[i]);
    }
    return m;
}

/* rolls() of a ball held and sticking on plane p (held_still): roll = y with no velocity
 * along the normal and the centre at the contact's own equilibrium along it (Newton's
 * method on the normal acceleration: with the seed's dig-in law and a direction latched
 * off the normal, the weight is not carried by the Hertz force alone), the rolling
 * springs and deflections as they are; the end state when the small normal oscillation
 * about it holds less than the rest threshold's energy and the state is steady there
 * (its spin about the normal then goes on uniformly). */
static int held_spin(const run_t *r, int p, const double *y, double slip_speed, double *roll)
{
    const ballc_drive_config *c = r->c;
    const ballc_plane_t *pl = &r->prepared.planes[p];
    const double *n = pl->frame[2];
    ballc_flags flags = run_flags(r, 1);
    double rate[N], moved[N], slope = 0.0;
    memcpy(roll, y, r->ns * sizeof(double));
    double height = 0.0, vn = 0.0;
    for (int i = 0; i < 3; i++) {
        height += n[i] * (y[BALLC_STATE_X + i] - pl->point[i]);
        vn += n[i] * y[BALLC_STATE_VX + i];
    }
    for (int i = 0; i < 3; i++) {
        roll[BALLC_STATE_X + i] += (c->z_eq - height) * n[i];
        roll[BALLC_STATE_VX + i] -= vn * n[i];
    }
    double moved_by = c->z_eq - height;   /* roll's height - y's */
    for (int it = 0; it < 40; it++) {
        if (ballc_rhs(roll, c->params, r->latch, flags, rate) != BALLC_OK) return -1;
        double h = 1e-6 * c->rho_eq, a = 0.0, b = 0.0;
        for (int i = 0; i < 3; i++) a += n[i] * rate[BALLC_STATE_VX + i];
        memcpy(moved, roll, r->ns * sizeof(double));
        for (int i = 0; i < 3; i++) moved[BALLC_STATE_X + i] += h * n[i];
        if (ballc_rhs(moved, c->params, r->latch, flags, rate) != BALLC_OK) return -1;
        for (int i = 0; i < 3; i++) b += n[i] * rate[BALLC_STATE_VX + i];
        slope = (b - a) / h;
        if (!(slope < 0)) return 0;   /* no restoring force: not in contact */
        double dz = -a / slope;
        for (int i = 0; i < 3; i++) roll[BALLC_STATE_X + i] += dz * n[i];
        moved_by += dz;
        if (fabs(dz) <= 4 * DBL_EPSILON * fabs(c->z_eq)) break;
    }
    double above = c->half_mass * (vn * vn - slope * moved_by * moved_by);
    if (!(above <= c->rest_threshold)) return 0;
    booked(r, y, roll);
    if (ballc_rhs(roll, c->params, r->latch, flags, rate) != BALLC_OK) return -1;
    double level = c->rolls_level;
    if (max_abs(rate + BALLC_STATE_VX, 3) > level
            || c->radius * max_abs(rate + BALLC_STATE_OMEGA_X, 3) > level)
        return 0;
    return slip_speed <= c->rolls_dv ? BALLC_END_ROLLING : BALLC_END_SLIDING;
}

/* uniform rolling or sliding on plane p (ballc.resting): BALLC_END_ROLLING / SLIDING
 * with ``roll`` the uniform state, 0 none, -1 when a kernel failed */
static int rolls(run_t *r, int p, const double *y, double t_start, double t,
                 double slip_speed, double *roll)
{
    const ballc_drive_config *c = r->c;
    int held = held_still(r, p);
    if (t - t_start < c->rest_period || !(c->rolls_allowed || held)) return 0;
    if (held) return held_spin(r, p, y, slip_speed, roll);
    double e[BALLC_MAX_ENERGY_NOUT];
    energy_of(r, y, e);
    double x = (rho_of(r, p, y) - c->rho_eq) / c->rho_eq;
    if (!(x > -1)) return 0;
    double normal = normal_above(c, x);
    double rate_n = rho_rate(r, p, y);
    double above = c->half_mass * (rate_n * rate_n) + tangential_springs(r, e)
                   + py_max(normal, 0.0);
    if (c->rolling || c->twisting) above += rolling_springs(r, e);
    if (!(above <= c->rest_threshold)) return 0;
    memcpy(roll, y, r->ns * sizeof(double));   /* the uniform state, energy booked */
    at_equilibrium(r, p, roll);
    booked(r, y, roll);
    double rate[N];
    if (ballc_rhs(roll, c->params, r->latch, run_flags(r, 1), rate) != BALLC_OK) {
        r->failed_kernel = 1;
        return -1;
    }
    double level = c->rolls_level;
    if (max_abs(rate + BALLC_STATE_VX, 3) > level
            || c->radius * max_abs(rate + BALLC_STATE_OMEGA_X, 3) > level)
        return 0;
    for (int q = 0; q < r->np; q++)
        if (max_abs(rate + ballc_plane_state(q), 2) > level) return 0;
    return slip_speed <= c->rolls_dv ? BALLC_END_ROLLING : BALLC_END_SLIDING;
}

/* ---- the periodic end state (ballc.orbit; _orbit.c) ---- */

/* the trial's log: (t_from, t_to, accepted) */
static int log_trial(run_t *r)
{
    ballc_drive_output *o = r->o;
    if (grow((void **)&o->trials, &o->cap_trials, 3 * (o->n_trials + 1), sizeof(double)))
        return -2;
    double *k = o->trials + 3 * o->n_trials++;
    k[0] = r->trial_from;
    k[1] = r->trial_to;
    k[2] = 0.0;
    return 0;
}

/* at a rest check that found no end state, with no trial under
 * way, start one (criteria 1-2) when it ends before t_end; the next rest check is then
 * at the latest at its end.  Not at once after a refused trial.  0, or -2 (memory) */
static int plan_orbit_trial(run_t *r, int p)
{
    const ballc_drive_config *c = r->c;
    if (r->trial_on) return 0;
    if (r->trial_failed) {   /* not at once again: at the next scheduled rest check */
        r->trial_failed = 0;
        return 0;
    }
    double rate = norm3(r->y + BALLC_STATE_OMEGA_X);
    if (!(rate > 0)) return 0;
    double guess = 2 * M_PI / rate;
    double t_to = r->t + BALLC_ORBIT_TRIAL_PERIODS * guess;
    if (!(t_to < c->t_end)
            || !ballc_orbit_equivariant(c->params, r->latch, run_flags(r, 1), r->y,
                                        c->orbit_axis))
        return 0;
    r->trial_on = 1;
    r->trial_plane = p;
    r->trial_broken = 0;
    r->trial_from = r->t;
    r->trial_to = t_to;
    r->trial_guess = guess;
    ballc_dense_clear(&r->trial);
    r->rest_check[p] = py_min(r->rest_check[p], t_to);
    return log_trial(r);
}

/* the segment [t0, t1] of the trial under way, or (an event ended it,
 * or it was flown) the trial broken.  0, or -2 (memory) */
static int trial_add(run_t *r, const radau5_result *res, double t0, double t1, int reached,
                     int flown)
{
    ballc_dense *d = &r->trial;
    double end = d->n_pieces ? d->t1[d->n_pieces - 1] : r->trial_from;
    if (r->trial_broken) return 0;
    if (!reached || flown || t0 != end) {
        r->trial_broken = 1;
        return 0;
    }
    if (!res->n_dense) return 0;   /* nothing integrated */
    return ballc_dense_add(d, t0, t1, res->n_dense, res->dense_t, res->dense_c,
                           res->dense_kind, res->dense_terms, r->ns) ? -2 : 0;
}

/* when this check ends the trial under way, the relative periodic
 * orbit if criteria 3-5 hold (BALLC_END_ROLLING or SLIDING, o->orbit and its base),
 * else 0 (and the trial is over); before the trial's end, 0 and the next check at the
 * latest at its end.  -1 when the trial's solution failed, -2 out of memory. */
static int check_orbit(run_t *r, int p)
{
    const ballc_drive_config *c = r->c;
    ballc_drive_output *o = r->o;
    if (!r->trial_on || r->trial_plane != p) return 0;
    if (r->t < r->trial_to) {
        r->rest_check[p] = py_min(r->rest_check[p], r->trial_to);
        return 0;
    }
    r->trial_on = 0;
    r->trial_failed = 1;
    r->seg.end = BALLC_SEG_ORBIT_CHECK;   /* the log: the trial ended at this check */
    ballc_dense *d = &r->trial;
    if (r->trial_broken || !d->n_pieces || d->t1[d->n_pieces - 1] != r->t) return 0;
    const ballc_piecewise *solution = ballc_dense_view(d);
    if (!solution) return -2;
    double atol[N];
    for (int i = 0; i < r->ns; i++) atol[i] = c->atol_states ? c->atol_states[i] : c->atol;
    ballc_orbit_tolerances tol = {c->rtol, atol, c->rest_factor, c->rest_threshold,
                                  c->params};
    ballc_orbit orbit;
    int found = ballc_orbit_measure(ballc_piecewise_states, (void *)solution, r->trial_from,
                                    r->t, c->orbit_axis, r->trial_guess, &tol, &orbit);
    if (found < 0) return found == -2 ? -2 : -1;
    if (!found) return 0;
    r->trial_failed = 0;
    o->trials[3 * (o->n_trials - 1) + 2] = 1.0;
    /* sticking (Coulomb's stick, the compliant law's elastic mode) is rolling */
    double u[2], speed, error, clear;
    slip(r, p, r->y, u, &speed, &error, &clear);
    int sticking = r->coulomb[p] == BALLC_MODE_STICK
                   || (r->coulomb[p] == BALLC_MODE_NONE && r->compliant[p] == COMPLIANT_ELASTIC);
    o->end_orbit = 1;
    o->orbit = orbit;
    if (ballc_dense_span(d, orbit.c0, orbit.c0 + orbit.period, &o->orbit_base)) return -2;
    return sticking || speed <= c->rest_factor * error ? BALLC_END_ROLLING : BALLC_END_SLIDING;
}

/* At a rest check on an incline p: BALLC_END_ACCELERATING (r->y the rolling state,
 * r->o->end_acceleration its acceleration) when the ball rolls down it uniformly
 * accelerated and nothing else is reached before t_end, else 0 (the next check
 * scheduled).  The closed form is exact for a massless observer and isotropic inertia
 * (checked before: is_incline) once the normal oscillation has settled (its energy about
 * the static equilibrium under the load M g_n below the rest threshold), the contact
 * point does not slip, the centre moves along gravity's component in the plane g_t and
 * the ball does not spin about the normal: then a = g_t / (1 + I / (M r^2)) and the spin
 * turns about the fixed axis n x a / |a| at |a| / r per second (the lever arm r). */
static int incline_state(run_t *r, int p)
{
    const ballc_drive_config *c = r->c;
    const ballc_contact_rec *k = &r->o->contacts[r->o->open[p]];
    r->seg.end = BALLC_SEG_UNIFORM_CHECK;   /* the log */
    r->rest_check[p] = r->t + py_max(c->rest_period, BALLC_CHECK_GROWTH * (r->t - k->t_start));
    if (r->t - k->t_start < c->rest_period) return 0;
    const double *y = r->y, *n = r->prepared.planes[p].frame[2], *g = r->gravity;
    const double M = c->total_mass, radius = c->radius;
    double gn = -(n[0] * g[0] + n[1] * g[1] + n[2] * g[2]);   /* the load per mass */
    double gt[3], size = 0.0;
    for (int i = 0; i < 3; i++) {
        gt[i] = g[i] + gn * n[i];
        size += gt[i] * gt[i];
    }
    size = sqrt(size);
    if (!(gn > 0) || !(size > 0)) return 0;
    /* the normal motion settled at the static equilibrium under M g_n */
    double rho_eq = pow(M * gn / c->hertz_k, 2.0 / 3.0);
    double x = (rho_of(r, p, y) - rho_eq) / rho_eq;
    if (!(x > -1)) return 0;
    double normal = M * gn * rho_eq * (0.4 * expm1(2.5 * (x == 0.0 ? x : log1p(x))) - x);
    double e[BALLC_MAX_ENERGY_NOUT];
    energy_of(r, y, e);
    double above = 0.5 * M * pow(rho_rate(r, p, y), 2.0) + tangential_springs(r, e)
                   + py_max(normal, 0.0);
    if (c->rolling || c->twisting) {
        /* rolling resistance: a ball held from rolling and sticking rests on the incline
         * (tan theta <= mu_r and mu); one rolling down does so against the rolling
         * torque, which the closed form below has not: it goes on integrating */
        if (!held_still(r, p)) return 0;
        if (!(above + e[0] + rolling_springs(r, e) <= c->rest_threshold)) return 0;
        double rest[N], height = 0.0;
        const ballc_plane_t *pl = &r->prepared.planes[p];
        memcpy(rest, y, r->ns * sizeof(double));
        for (int i = 0; i < 3; i++) height += n[i] * (y[BALLC_STATE_X + i] - pl->point[i]);
        for (int i = 0; i < 3; i++) {
            rest[BALLC_STATE_X + i] += (radius - rho_eq - height) * n[i];
            rest[BALLC_STATE_VX + i] = rest[BALLC_STATE_OMEGA_X + i] = 0.0;
        }
        booked(r, y, rest);
        memcpy(r->y, rest, r->ns * sizeof(double));
        r->seg.end = BALLC_SEG_REST_CHECK;
        return BALLC_END_REST;
    }
    if (!(above <= c->rest_threshold)) return 0;
    /* rolling along g_t, no spin about n */
    double u[2], speed, error, clear;
    slip(r, p, y, u, &speed, &error, &clear);
    if (!(speed <= c->rolls_dv)) return 0;
    const double *v = y + BALLC_STATE_VX, *w = y + BALLC_STATE_OMEGA_X;
    double vn = n[0] * v[0] + n[1] * v[1] + n[2] * v[2];
    double along = 0.0, across = 0.0, spin = n[0] * w[0] + n[1] * w[1] + n[2] * w[2];
    for (int i = 0; i < 3; i++) along += (v[i] - vn * n[i]) * gt[i] / size;
    for (int i = 0; i < 3; i++) {
        double d = v[i] - vn * n[i] - along * gt[i] / size;
        across += d * d;
    }
    if (!(sqrt(across) <= c->rolls_dv) || !(radius * fabs(spin) <= c->rolls_dv)) return 0;
    double factor = 1.0 / (1.0 + c->params[BALLC_PARAMETER_INERTIA_XX] / (M * radius * radius));
    double a[3];
    for (int i = 0; i < 3; i++) a[i] = factor * gt[i];
    /* unbounded: no other plane reached on the way before t_end */
    for (int q = 0; q < r->np; q++) {
        if (q == p) continue;
        const plane_geometry *h = &r->geometry[q];
        double c1 = 0.0, c2 = 0.0, roots[2];
        for (int i = 0; i < 3; i++) {
            c1 += h->coef[i] * along * gt[i] / size;
            c2 += 0.5 * h->coef[i] * a[i];
        }
        if (ballc_flight_crossings(rho_of(r, q, y), c1, c2, 1, c->t_end - r->t, roots)) return 0;
    }
    /* the rolling state: at the equilibrium height, moving along g_t, rolling exactly */
    double roll[N];
    memcpy(roll, y, r->ns * sizeof(double));
    const ballc_plane_t *pl = &r->prepared.planes[p];
    double height = 0.0;
    for (int i = 0; i < 3; i++) height += n[i] * (y[BALLC_STATE_X + i] - pl->point[i]);
    for (int i = 0; i < 3; i++) {
        roll[BALLC_STATE_X + i] += (radius - rho_eq - height) * n[i];
        roll[BALLC_STATE_VX + i] = along * gt[i] / size;
    }
    const double *rv = roll + BALLC_STATE_VX;   /* omega = n x v / r */
    roll[BALLC_STATE_OMEGA_X] = (n[1] * rv[2] - n[2] * rv[1]) / radius;
    roll[BALLC_STATE_OMEGA_Y] = (n[2] * rv[0] - n[0] * rv[2]) / radius;
    roll[BALLC_STATE_OMEGA_Z] = (n[0] * rv[1] - n[1] * rv[0]) / radius;
    for (int q = 0; q < r->np; q++)
        roll[ballc_plane_state(q)] = roll[ballc_plane_state(q) + 1] = 0.0;
    booked(r, y, roll);
    memcpy(r->y, roll, r->ns * sizeof(double));
    memcpy(r->o->end_acceleration, a, sizeof a);
    return BALLC_END_ACCELERATING;
}

/* a rest check on plane p at (r->t, r->y): BALLC_END_* when the run
 * finishes in closed form from here (r->y the new state, or the state of the orbit's
 * start), 0 to go on (the next check scheduled), -1 when a kernel failed, -2 out of
 * memory.  Its checks are the automaton's "rest check" (at_rest), "uniform check"
 * (rolls) and "orbit check" (check_orbit), each when the one before found nothing */
static int end_state(run_t *r, int p)
{
    const ballc_drive_config *c = r->c;
    const ballc_contact_rec *k = &r->o->contacts[r->o->open[p]];
    if (p != c->resting_plane) return incline_state(r, p);
    int rest = at_rest(r, p, r->y, k->t_start, r->t);
    if (rest < 0) return -1;
    r->seg.end = rest ? BALLC_SEG_REST_CHECK : BALLC_SEG_UNIFORM_CHECK;   /* the log */
    if (rest) {   /* the rest state: static equilibrium, energy booked */
        double new_y[N];
        memcpy(new_y, r->y, r->ns * sizeof(double));
        for (int i = 0; i < 3; i++) new_y[BALLC_STATE_VX + i] = new_y[BALLC_STATE_OMEGA_X + i] = 0.0;
        at_equilibrium(r, p, new_y);
        booked(r, r->y, new_y);
        memcpy(r->y, new_y, r->ns * sizeof(double));
        return BALLC_END_REST;
    }
    /* the next check */
    r->rest_check[p] = r->t + py_max(c->rest_period, BALLC_CHECK_GROWTH * (r->t - k->t_start));
    double u[2], speed, error, clear, roll[N];
    slip(r, p, r->y, u, &speed, &error, &clear);
    int kind = rolls(r, p, r->y, k->t_start, r->t, speed, roll);
    if (kind < 0) return -1;
    if (kind) {
        memcpy(r->y, roll, r->ns * sizeof(double));
        return kind;
    }
    if (!c->orbit_applies) return 0;
    kind = check_orbit(r, p);
    if (kind) return kind;
    return plan_orbit_trial(r, p);
}

/* The closed-form end state ``kind`` found at (r->t, r->y) on plane p, to t_end: its
 * samples (rest: t_end alone; uniform motion: the free flight without gravity, the turn
 * at most BALLC_FLIGHT_MAX_TURN per interval; rolling down an incline: ballc_rolling,
 * likewise; an orbit: 32 per period; at least 32
 * intervals and at most BALLC_MAX_ROLL_SAMPLES samples, evenly spaced after r->t) in a
 * block with the last one's flags and latch, and the contact's record of its end.
 * 0, -1 (the orbit's base could not be evaluated), -2 out of memory. */
static int end_samples(run_t *r, int kind, int p)
{
    const ballc_drive_config *c = r->c;
    ballc_drive_output *o = r->o;
    double t0 = r->t, t1 = c->t_end, span = t1 - t0;
    long n = 1;
    ballc_rolling rolling;
    if (kind == BALLC_END_ACCELERATING)
        ballc_rolling_init(&rolling, t0, r->y, o->end_acceleration, c->radius,
                           r->prepared.planes[p].frame[2], r->ns);
    if (kind != BALLC_END_REST) {
        double wanted = o->end_orbit
            ? ceil(32 * span / o->orbit.period)
            : kind == BALLC_END_ACCELERATING
            ? ceil(fabs(ballc_rolling_angle(&rolling, t1)) / BALLC_FLIGHT_MAX_TURN)
            : ceil(norm3(r->y + BALLC_STATE_OMEGA_X) * span / BALLC_FLIGHT_MAX_TURN);
        wanted = py_max((double)BALLC_FLIGHT_MIN_INTERVALS, wanted);
        n = (long)py_min((double)BALLC_MAX_ROLL_SAMPLES, wanted);
    }
    double *t = malloc((size_t)n * sizeof(double));
    double *y = malloc((size_t)n * r->ns * sizeof(double));
    int rc = t && y ? 0 : -2;
    if (!rc) {
        for (long k = 1; k <= n; k++) t[k - 1] = t0 + span * (double)k / (double)n;
        t[n - 1] = t1;
        if (kind == BALLC_END_REST) {
            memcpy(y, r->y, r->ns * sizeof(double));
        } else if (o->end_orbit) {
            const ballc_piecewise *base = ballc_dense_view(&o->orbit_base);
            rc = !base ? -2 : ballc_orbit_states(&o->orbit, ballc_piecewise_states,
                                                 (void *)base, n, t, y);
            if (rc == -1) r->why = "the orbit's base solution could not be evaluated";
        } else if (kind == BALLC_END_ACCELERATING) {
            for (long k = 0; k < n; k++) ballc_rolling_at(&rolling, t[k], y + (size_t)k * r->ns);
        } else {
            const double none[3] = {0.0, 0.0, 0.0};
            ballc_flight f;
            ballc_flight_init(&f, t0, r->y, none, r->ns);
            for (long k = 0; k < n; k++) ballc_flight_at(&f, t[k], y + (size_t)k * r->ns);
        }
    }
    if (!rc) {
        long last = o->n_blocks - 1;
        rc = add_block(r, t, y, n, o->block_flags[last], o->block_latch + (size_t)last * r->nl)
             ? -2 : 0;
    }
    free(t);
    free(y);
    if (!rc) {   /* the contact's record: its end state from t0 on */
        if (grow((void **)&o->phases, &o->cap_phases, o->n_phases + 1,
                 sizeof(ballc_phase_rec)))
            return -2;
        ballc_phase_rec *k = &o->phases[o->n_phases++];
        k->contact = o->open[p];
        k->t = t0;
        k->phase = kind == BALLC_END_ACCELERATING ? BALLC_PHASE_ROLLING
                   : 1 + kind;   /* BALLC_PHASE_REST, _ROLLING, _FREE_SLIDING */
    }
    return rc;
}

/* the segment's dense output: its steps kept, the integrator's own interpolant (its
 * id), or an exact flight's (t0, r->y) */
static int add_piece(run_t *r, const radau5_result *res, double t0, double t1, int flown)
{
    ballc_drive_output *o = r->o;
    if (flown || r->seg_interpolant >= 0) {   /* no steps of ours: a piece that names it */
        if (grow((void **)&o->pieces, &o->cap_pieces, o->n_pieces + 1,
                 sizeof(ballc_piece_rec)))
            return -1;
        ballc_piece_rec *k = &o->pieces[o->n_pieces++];
        memset(k, 0, sizeof *k);
        k->t0 = t0;
        k->t1 = t1;
        if (flown) {   /* exact flight: FreeFlight(t0, y0, ...) */
            k->flight = 1;
            memcpy(k->y0, r->y, r->ns * sizeof(double));
        } else {       /* kept by the integrator (scipy's) */
            k->own = 1;
            k->interpolant = r->seg_interpolant;
        }
        return 0;
    }
    long m = res->n_dense, width = (long)(1 + res->dense_terms) * r->ns;
    if (grow((void **)&o->pieces, &o->cap_pieces, o->n_pieces + 1, sizeof(ballc_piece_rec)))
        return -1;
    long cs = o->cap_steps;
    if (grow((void **)&o->dense_kind, &cs, o->n_steps + m, sizeof(int))) return -1;
    if (cs != o->cap_steps) {
        double *dt = realloc(o->dense_t, (size_t)cs * 2 * sizeof(double));
        if (!dt) return -1;
        o->dense_t = dt;
        o->cap_steps = cs;
    }
    if (grow((void **)&o->dense_c, &o->cap_coef, o->n_coef + m * width, sizeof(double)))
        return -1;
    ballc_piece_rec *k = &o->pieces[o->n_pieces++];
    k->t0 = t0;
    k->t1 = t1;
    k->flight = 0;
    k->own = 0;
    k->step0 = o->n_steps;
    k->n_steps = m;
    k->coef0 = o->n_coef;
    k->terms = res->dense_terms;
    if (m) {
        memcpy(o->dense_t + 2 * o->n_steps, res->dense_t, (size_t)m * 2 * sizeof(double));
        memcpy(o->dense_kind + o->n_steps, res->dense_kind, (size_t)m * sizeof(int));
        memcpy(o->dense_c + o->n_coef, res->dense_c, (size_t)(m * width) * sizeof(double));
    }
    o->n_steps += m;
    o->n_coef += m * width;
    return 0;
}

/* ---- the integrator interface (_driver.h) ---- */

int ballc_compiled_integrator(void *ctx, const radau5_problem *problem,
                              ballc_segment *segment, radau5_result *result)
{
    (void)ctx;
    segment->interpolant = -1;
    return radau5_solve(problem, result);
}

/* ---- polling: the progress report and Ctrl-C, throttled in wall time ---- */

static double wall_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Between segments and every RADAU5_POLL_STEPS tries of a compiled step (radau5_problem
 * .poll): once poll_interval s of wall time have passed since the last, report the time
 * reached and ask for a pending signal (both the bridge's, with the GIL).  Nonzero: stop
 * (the bridge raises what it kept: KeyboardInterrupt). */
static int drv_poll(void *ctx, double t)
{
    run_t *r = (run_t *)ctx;
    const ballc_drive_config *c = r->c;
    double now = wall_seconds();
    if (now - r->polled < (c->poll_interval > 0 ? c->poll_interval : 0.1)) return 0;
    r->polled = now;
    if ((c->progress && c->progress(c->user_ctx, t))
            || (c->interrupted && c->interrupted(c->user_ctx)))
        r->interrupted = 1;
    return r->interrupted;
}

/* ---- the loop ---- */

/* The segment's event arrays, for the driver's events and n_user of the user's; -1 out
 * of memory (free_events frees what was allocated) */
static int alloc_events(run_t *r, int n_user)
{
    size_t cap = EVENTS_PER_PLANE * MAXP + (size_t)(n_user > 0 ? n_user : 0);
    double *d = malloc(cap * (N + 4) * sizeof(double));
    int *k = malloc(cap * 11 * sizeof(int));
    r->user_seen = calloc(n_user > 0 ? (size_t)n_user : 1, sizeof(long));
    r->ev_coef = d;
    r->ev_terminal = k;
    if (!d || !k || !r->user_seen) return -1;
    r->ev_offset = d + cap * N;
    r->ev_scale = r->ev_offset + cap;
    r->flight_s = r->ev_scale + cap;   /* 2 cap */
    r->ev_direction = k + cap;
    r->ev_nonlinear = k + 2 * cap;
    r->ev_plane_code = k + 3 * cap;
    r->ev_rearm = k + 4 * cap;
    r->ev_kind = k + 5 * cap;
    r->ev_plane = k + 6 * cap;
    r->ev_index = k + 7 * cap;
    r->flight_seen = k + 8 * cap;
    r->flight_e = k + 9 * cap;        /* 2 cap */
    return 0;
}

static void free_events(run_t *r)
{
    free(r->ev_coef);
    free(r->ev_terminal);
    free(r->user_seen);
}

#ifdef RADAU5_PROFILE
static double thread_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return ts.tv_sec * 1e9 + ts.tv_nsec;
}
#endif

int ballc_drive(const ballc_drive_config *c, const double *y0, ballc_drive_output *o)
{
    memset(o, 0, sizeof *o);
#ifdef RADAU5_PROFILE
    double started = thread_ns();
    o->profiled = 1;
#endif
    run_t *r = calloc(1, sizeof(run_t));
    if (!r) return BALLC_DRIVE_NO_MEMORY;
    if (alloc_events(r, c->n_user)) {
        free_events(r);
        free(r);
        return BALLC_DRIVE_NO_MEMORY;
    }
    for (int p = 0; p < MAXP; p++) {
        o->open[p] = -1;
        r->rest_check[p] = INFINITY;
        r->capacity_row[p] = -1;
    }
    o->stiff_at = NAN;
    r->c = c;
    r->o = o;
    if (ballc_parameters_init(&r->prepared, c->params) != BALLC_OK) {   /* Python checks */
        free_events(r);
        free(r);
        o->status = -1;
        snprintf(o->message, sizeof o->message, "%s",
                 "the parameters' plane table is not valid (1 to 6 planes, unit normals)");
        return o->stop_code = BALLC_DRIVE_ABORTED;
    }
    r->np = o->n_planes = r->prepared.n_planes;
    r->ns = o->n_states = r->prepared.n_states;
    r->nl = o->n_latch = r->prepared.n_latch;
    memcpy(r->y, y0, r->ns * sizeof(double));
    r->margins_plane = -1;
    r->polled = wall_seconds();
    r->seg_interpolant = -1;
    int rc = 0;
    for (int i = 0; i < r->prepared.n_parameters; i++)
        if (!isfinite(c->params[i])) { rc = -1; r->why = "a parameter is not finite"; }
    if (!rc) plane_setup(r);
    for (int p = 0; p < r->np && !rc; p++)
        if (rho_of(r, p, r->y) > 0) rc = begin_contact(r, p);
    double t0 = 0.0;
    if (!rc && !c->t_eval) rc = add_block(r, &t0, r->y, 1, run_flags(r, 1), r->latch);
    long eval_at = 0;   /* t_eval: the first point after run.t */
    if (!rc && c->t_eval) {   /* the points at 0 (t_eval == 0.0), each the initial state */
        long keep = 0;
        for (long i = 0; i < c->n_eval; i++) keep += c->t_eval[i] == 0.0;
        double *rows = malloc((size_t)(keep ? keep : 1) * r->ns * sizeof(double));
        double *times = malloc((size_t)(keep ? keep : 1) * sizeof(double));
        if (!rows || !times) rc = -2;
        else {
            long j = 0;
            for (long i = 0; i < c->n_eval; i++)
                if (c->t_eval[i] == 0.0) {
                    times[j] = c->t_eval[i];
                    memcpy(rows + j * r->ns, r->y, r->ns * sizeof(double));
                    j++;
                }
            rc = add_block(r, times, rows, keep, run_flags(r, 1), r->latch) ? -2 : 0;
        }
        free(rows);
        free(times);
    }
    double atol[N];
    for (int i = 0; i < r->ns; i++) atol[i] = c->atol_states ? c->atol_states[i] : c->atol;
    double first = c->first_step;
    int has_first = c->has_first_step;
    int implicit = 0;   /* method "auto": the segment starts with radau5 */
    long nfev = 0, njev = 0, nlu = 0;
    int stiff_found = 0;

    while (!rc && r->t < c->t_end && r->status == 0) {
        if (drv_poll(r, r->t)) {   /* raised by the bridge */
            r->stop_code = BALLC_DRIVE_USER_ERROR;
            break;
        }
        ballc_flags flags = run_flags(r, 1);
        int trial = r->trial_on;   /* an orbit's trial needs dense output */
        r->seg_flags = flags;
        if (segment_events(r, flags)) { rc = -1; break; }
        r->n_rearmed = 0;
        double t_check = INFINITY;
        int checked = c->checks_rest ? checked_plane(r) : -1;   /* its rest checks */
        if (checked >= 0) t_check = r->rest_check[checked];
        /* a rest check, or the end of a compliant contact's step bound, ends it */
        double t_stop = py_min(py_min(t_check, c->t_end), step_bound_end(r));
        double max_step = run_max_step(r);
        for (int i = 0; i < r->ns; i++)
            if (!isfinite(r->y[i])) rc = -1;
        for (int i = 0; i < r->nl; i++)
            if (!isfinite(r->latch[i])) rc = -1;
        if (rc) r->why = "the state or the latched values are not finite";
        if (rc) break;
        log_open(r);
        radau5_result res;
        int solved = RADAU5_DONE, flown = 0;
        if (c->exact_flight && flags == 0 && c->user_flight) {   /* exact flight applies */
            long n_eval = 0;
            const double *ev = NULL;
            if (c->t_eval) {
                while (eval_at < c->n_eval && !(c->t_eval[eval_at] > r->t)) eval_at++;
                long hi = eval_at;
                while (hi < c->n_eval && c->t_eval[hi] <= t_stop) hi++;
                ev = c->t_eval + eval_at;
                n_eval = hi - eval_at;
            }
            int got = flight_segment(r, t_stop, ev, n_eval, &res);
            if (got) { radau5_free(&res); rc = got; break; }
            flown = 1;
            r->seg_interpolant = -1;
        } else {
        radau5_problem pr;
        memset(&pr, 0, sizeof pr);
        pr.n = r->ns;
        pr.fun = drv_fun;
        pr.jac = drv_jac;
        pr.ctx = r;
        pr.t0 = r->t;
        pr.t_bound = t_stop;
        pr.y0 = r->y;
        pr.rtol = c->rtol;
        pr.atol = atol;
        pr.max_step = max_step;
        pr.first_step = 0.0;
        if (has_first) {   /* a carried step fits what is left */
            double f = py_min(first, t_stop - r->t);
            if (!(isfinite(f) && 0 < f && f <= fabs(t_stop - r->t))) {
                r->why = "first_step does not fit the segment";
                rc = -1;
                break;
            }
            pr.first_step = f;
        }
        pr.max_nfev = c->max_nfev ? (c->max_nfev - nfev > 1 ? c->max_nfev - nfev : 1) : 0;
        pr.t_eval = NULL;
        pr.n_eval = 0;
        if (c->t_eval) {   /* t_eval[(t_eval > run.t) & (t_eval <= t_stop)] (sorted) */
            while (eval_at < c->n_eval && !(c->t_eval[eval_at] > r->t)) eval_at++;
            long hi = eval_at;
            while (hi < c->n_eval && c->t_eval[hi] <= t_stop) hi++;
            pr.t_eval = hi > eval_at ? c->t_eval + eval_at : r->y;   /* non-NULL: none */
            pr.n_eval = hi - eval_at;
        }
        pr.n_events = r->n_ev;
        pr.ev_coef = r->ev_coef;
        pr.ev_offset = r->ev_offset;
        pr.ev_nonlinear = r->ev_nonlinear;
        pr.ev_fun = drv_event;
        pr.ev_terminal = r->ev_terminal;
        pr.ev_direction = r->ev_direction;
        pr.dense_output = c->dense_output || trial;
        pr.controller = c->controller;
        pr.outputs_checked = 1;
        pr.refine_events = 1;
        pr.ev_rearm = r->ev_rearm;
        pr.rearm = drv_rearm;
        pr.method = c->method;
        pr.jacobian_ahead = any_plane(r, flags, BALLC_KIND_COMPLIANT);
        pr.jacobian_every_step = any_plane(r, flags, BALLC_KIND_COMPLIANT_SLIDING)
                                 || rolling_slides(r);
        r->margins_plane = -1;   /* a fresh bridge context per segment */
        pr.auto_implicit = c->method == RADAU5_METHOD_AUTO && implicit;
        pr.poll = drv_poll;
        ballc_segment seg = {flags, r->latch, c->params, -1, r->nl};   /* the integrator interface */
        memset(&res, 0, sizeof res);
        solved = (c->integrate ? c->integrate : ballc_compiled_integrator)(
            c->integrate_ctx, &pr, &seg, &res);
        r->seg_interpolant = seg.interpolant;
        }
        o->segments++;
        r->seg.method = flown ? -1 : c->method != RADAU5_METHOD_AUTO ? c->method
                        : implicit ? RADAU5_METHOD_RADAU : RADAU5_METHOD_DOP853;
        has_first = 0;
        implicit = 0;
#ifdef RADAU5_PROFILE
        o->integrator_ns += res.prof[RADAU5_PROF_TOTAL_NS];
        for (int i = 0; i < RADAU5_PROF_N; i++) o->integrator_prof[i] += res.prof[i];
#endif
        if (r->user_failed || r->interrupted || solved == BALLC_INTEGRATOR_RAISED
                || res.status == RADAU5_INTERRUPTED) {   /* the bridge raises what it kept */
            radau5_free(&res);
            r->stop_code = BALLC_DRIVE_USER_ERROR;
            break;
        }
        if (solved != RADAU5_DONE) {   /* the integrator refused the segment */
            rc = solved == RADAU5_OUT_OF_MEMORY ? -2 : -1;
            memcpy(o->message, res.message, sizeof o->message);
            o->message[sizeof o->message - 1] = 0;
            r->why = o->message;
            radau5_free(&res);
            break;
        }
        nfev += res.nfev;
        njev += res.njev;
        nlu += res.nlu;
        r->seg.nfev = res.nfev;
        r->seg.njev = res.njev;
        r->seg.nlu = res.nlu;
        r->seg.nstep = res.nstep;
        r->seg.nreject = res.nreject;
        r->seg.method_end = flown ? -1 : res.method_end;
        r->seg.switches = (int)res.n_switches;
        if (!stiff_found && isfinite(res.stiff_at)) {
            o->stiff_at = res.stiff_at;
            stiff_found = 1;
        }
        if (c->method == RADAU5_METHOD_AUTO && res.n_switches) {   /* switches += ... */
            long cs = o->cap_switches;
            if (grow((void **)&o->switch_t, &cs, o->n_switches + res.n_switches,
                     sizeof(double))) { radau5_free(&res); rc = -2; break; }
            int *to = realloc(o->switch_to, (size_t)cs * sizeof(int));
            if (!to) { radau5_free(&res); rc = -2; break; }
            o->switch_to = to;
            o->cap_switches = cs;
            memcpy(o->switch_t + o->n_switches, res.switch_t,
                   (size_t)res.n_switches * sizeof(double));
            memcpy(o->switch_to + o->n_switches, res.switch_to,
                   (size_t)res.n_switches * sizeof(int));
            o->n_switches += res.n_switches;
        }
        int ended_implicit = res.method_end == RADAU5_METHOD_RADAU;
        if (add_later(r, &res, r->t, flags)) { radau5_free(&res); rc = -2; break; }
        int fired = -1;
        double t_fired = INFINITY;
        long fired_hit = -1;
        for (int e = 0; e < r->n_ev; e++) {
            long count = 0, last = -1;
            for (long h = 0; h < res.n_hits; h++)
                if (res.hit_event[h] == e) { count++; last = h; }
            if (!count) continue;
            if (r->ev_kind[e] == K_DEEPEST) {
                int p = r->ev_plane[e];
                for (long h = 0; h < res.n_hits; h++)
                    if (res.hit_event[h] == e) {
                        const double *yy = res.hit_y + (size_t)h * r->ns;
                        record_depth(&o->contacts[o->open[p]], rho_of(r, p, yy), yy);
                    }
            } else if (r->ev_terminal[e] > 0 && r->ev_terminal[e] <= count
                       && res.hit_t[last] < t_fired) {
                fired = e;
                t_fired = res.hit_t[last];
                fired_hit = last;
            }
        }
        for (long h = 0; h < res.n_hits; h++) {   /* users.count, user_t, user_y */
            int e = res.hit_event[h];
            if (r->ev_kind[e] != K_USER) continue;
            int u = r->ev_plane[e];
            r->user_seen[u]++;
            long m = o->n_user_hits, cu = o->cap_user_hits;
            if (grow((void **)&o->user_hit_t, &cu, m + 1, sizeof(double))) { rc = -2; break; }
            if (cu != o->cap_user_hits) {
                int *ue = realloc(o->user_hit_event, (size_t)cu * sizeof(int));
                if (ue) o->user_hit_event = ue;
                double *uy = realloc(o->user_hit_y, (size_t)cu * r->ns * sizeof(double));
                if (uy) o->user_hit_y = uy;
                if (!ue || !uy) { rc = -2; break; }
                o->cap_user_hits = cu;
            }
            o->user_hit_event[m] = u;
            o->user_hit_t[m] = res.hit_t[h];
            memcpy(o->user_hit_y + (size_t)m * r->ns, res.hit_y + (size_t)h * r->ns,
                   r->ns * sizeof(double));
            o->n_user_hits++;
        }
        if (rc) { radau5_free(&res); break; }
        if (res.status == RADAU5_FAILED) {
            if (c->dense_output && res.n_out
                    && add_piece(r, &res, r->t, res.t_out[res.n_out - 1], flown)) {
                radau5_free(&res); rc = -2; break;
            }
            r->status = -1;
            r->stop_code = BALLC_DRIVE_FAILED;
            memcpy(o->message, res.message, sizeof o->message);
            o->message[sizeof o->message - 1] = 0;
            o->fail_end = res.n_out ? res.t_out[res.n_out - 1] : r->t;
            radau5_free(&res);
            if (log_close(r, BALLC_SEG_FAILED, -1, o->fail_end)) rc = -2;
            break;
        }
        if (trial && trial_add(r, &res, r->t, t_stop, res.status == RADAU5_REACHED, flown)) {
            radau5_free(&res); rc = -2; break;
        }
        if (res.status == RADAU5_REACHED) {
            if (c->dense_output && add_piece(r, &res, r->t, t_stop, flown)) {
                radau5_free(&res); rc = -2; break;
            }
            r->t = t_stop;
            if (t_stop < c->t_end) {   /* a rest check (ballc.resting) or a step bound's end */
                if (!res.n_out) {
                    r->why = "a segment stopped at a rest check stored no sample";
                    radau5_free(&res);
                    rc = -1;
                    break;
                }
                memcpy(r->y, res.y_out + (size_t)(res.n_out - 1) * r->ns, r->ns * sizeof(double));
                radau5_free(&res);
                if (t_stop != t_check) {   /* only a step bound ended: a fresh step */
                    implicit = ended_implicit;
                    if (log_close(r, BALLC_SEG_STEP_BOUND, -1, r->t)) { rc = -2; break; }
                    continue;
                }
                int p = checked;
                int kind = end_state(r, p);
                if (kind < 0) { rc = kind; break; }
                if (kind) {   /* to t_end in closed form */
                    o->end_kind = kind;
                    o->end_plane = p;
                    o->end_t = r->t;
                    memcpy(o->end_y, r->y, r->ns * sizeof(double));
                    rc = end_samples(r, kind, p);
                    if (!rc && log_close(r, r->seg.end, p, r->t)) rc = -2;
                    break;
                }
                implicit = ended_implicit;   /* auto keeps the method it ended with */
                if (log_close(r, r->seg.end, p, r->t)) { rc = -2; break; }
                continue;   /* the next segment starts with its own first step */
            }
            radau5_free(&res);
            if (log_close(r, BALLC_SEG_T_END, -1, r->t)) rc = -2;
            break;
        }
        if (fired < 0) {
            r->why = "the integrator stopped on a terminal event but reported no hit";
            radau5_free(&res);
            rc = -1;
            break;
        }
        if (c->dense_output && add_piece(r, &res, r->t, t_fired, flown)) {
            radau5_free(&res); rc = -2; break;
        }
        double h_next = res.h_next;
        r->t = t_fired;
        memcpy(r->y, res.hit_y + (size_t)fired_hit * r->ns, r->ns * sizeof(double));
        radau5_free(&res);
        const double *q = r->y + BALLC_STATE_QW;
        double h = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        for (int i = 0; i < 4; i++) r->y[BALLC_STATE_QW + i] /= h;
        int kind = r->ev_kind[fired], p = r->ev_plane[fired];
        if (kind == K_USER) {   /* a terminal user event: the run stops, status 1 */
            r->status = 1;
            r->stop_code = BALLC_DRIVE_TERMINATED;
            if (log_close(r, BALLC_SEG_USER, p, r->t)) rc = -2;
            break;
        }
        if (kind == K_CAPACITY)   /* its row may have toggled inside the segment */
            r->fired_row = (r->ev_plane_code[fired] - MARGIN_CODE) / MAXP;
        int handled = 0;
        switch (kind) {
        case K_ENTER: handled = begin_contact(r, p); break;
        case K_LEAVE: end_contact(r, p); break;
        case K_THROUGH: pass_through(r, p); break;
        case K_ARM: case K_YIELD: case K_RESTICK: case K_CAPACITY:
            handled = compliant_event(r, kind, p);
            break;
        case K_ROLL_FIRST + BALLC_ROLLING_APPROACH: case K_ROLL_FIRST + BALLC_ROLLING_STOP:
        case K_ROLL_FIRST + BALLC_ROLLING_CLEAR: case K_ROLL_FIRST + BALLC_ROLLING_RELEASE:
        case K_ROLL_FIRST + BALLC_TWISTING_STOP: case K_ROLL_FIRST + BALLC_TWISTING_RELEASE:
        case K_ROLL_FIRST + BALLC_ROLLING_YIELD: case K_ROLL_FIRST + BALLC_ROLLING_RESTICK:
        case K_ROLL_FIRST + BALLC_TWISTING_YIELD: case K_ROLL_FIRST + BALLC_TWISTING_RESTICK:
            handled = rolling_event(r, kind, p);
            break;
        default:
            handled = coulomb_event(r, kind, p);
            if (!handled && r->status == 0) handled = recheck_modes(r, p);
            break;
        }
        if (handled) { rc = handled == -2 ? -2 : -1; break; }
        if (log_close(r, kind, p, r->t)) { rc = -2; break; }
        if (kind >= K_APPROACH && h_next > 0) {   /* CARRY_STEP */
            first = py_min(h_next, run_max_step(r));
            has_first = 1;
            implicit = ended_implicit;
        }
    }
    if (rc != -2 && o->n_blocks && o->block_count[o->n_blocks - 1]) {
        /* the contacts still open at the end: their depth at the last sample */
        const double *last = o->y + (size_t)(o->n - 1) * r->ns;
        for (int p = 0; p < r->np; p++)
            if (o->open[p] >= 0) record_depth(&o->contacts[o->open[p]], rho_of(r, p, last), last);
    }
    if (rc == -1) {   /* aborted where it cannot go on: status -1, and why */
        r->stop_code = BALLC_DRIVE_ABORTED;
        r->status = -1;
        if (r->failed_kernel)
            r->why = "a C kernel failed (non-finite inputs or outputs)";
        if (r->why != o->message)
            snprintf(o->message, sizeof o->message, "%s",
                     r->why ? r->why : "an internal step failed (out of memory?)");
    } else if (rc) {
        r->stop_code = BALLC_DRIVE_NO_MEMORY;
    }
    o->stop_code = r->stop_code;
    o->status = r->status;
    o->stop_plane = r->stop_plane;
    o->t_run = r->t;
    for (int p = 0; p < r->np; p++) {
        o->in_contact[p] = r->in_contact[p];
        o->transitions[p] = r->transitions[p];
    }
    o->stalled = r->stalled;
    o->nfev = nfev;
    o->njev = njev;
    o->nlu = nlu;
    free(r->rearmed_t);
    free(r->rearmed_latch);
    ballc_dense_free(&r->trial);
    free_events(r);
    free(r);
#ifdef RADAU5_PROFILE
    o->drive_ns = thread_ns() - started;
#endif
    return o->stop_code;
}
