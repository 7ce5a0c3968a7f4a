/* The segment loop of ballc.simulate: the one driver (docs/driver.md).
 *
 * ballc_drive runs a whole simulation -- the hybrid automaton of ballc.automaton: contacts
 * and their latches, exact Coulomb friction's slip/stick modes (ballc.stickslip), the
 * compliant law's elastic/sliding modes (ballc.compliantmodes), the rest checks and the
 * closed-form end states (ballc.resting, ballc.orbit in _orbit.c), exact free flight
 * (ballc.flight), user events (callables called back through the bridge), every method
 * through the integrator interface (below), the progress report and Ctrl-C polled from
 * C, and the segment log.  Python validates the inputs, computes the per-scene constants
 * (ballc_drive_config) and builds the Result from ballc_drive_output; it holds no copy of
 * this logic.  Plain C99 numerics (hypot, sqrt, nextafter, sums in index order); compiled
 * as the rest of the extension: -std=c99 (no FP contraction), never -ffast-math.
 */
#ifndef BALLC_DRIVER_H
#define BALLC_DRIVER_H

#include "ballc_kernels.h"
#include "_orbit.h"
#include "_integrator.h"
#include "_system.h"

/* The automaton's constants (ballc.stickslip, ballc.compliantmodes, ballc.resting,
 * ballc.flight and ballc.modes document them; Python reads them from ballc._core) */
#define BALLC_CLEAR_FACTOR 100.0      /* clear speed: 100 x the slip's error scale */
#define BALLC_PASS_FACTOR 3.0         /* a miss beyond 3 x the error passes by zero */
#define BALLC_STOP_FACTOR 10.0        /* a stop's leftover slip removed up to 10 x */
#define BALLC_APPROACH_FRACTION 0.5   /* a re-latched slip's next approach: |u| / 2 */
#define BALLC_MAX_RELATCH 1000        /* re-latches per contact before a stop is forced */
#define BALLC_MAX_TRANSITIONS 100000  /* mode changes per contact: more do not settle */
#define BALLC_MAX_STALLED 100         /* mode changes in a row without time moving on */
#define BALLC_MIN_IMPACT_RATE 1e-9    /* the smallest latched penetration rate (m/s) */
#define BALLC_STEPS_PER_CONTACT 16    /* compliant impact: steps of at most t_c / 16 */
#define BALLC_IMPACT_SPAN 4           /* ... for its first 4 t_c */
#define BALLC_CHECK_GROWTH 0.25       /* rest checks: the next at age a + max(20 T0, a / 4) */
#define BALLC_FLIGHT_MIN_INTERVALS 32 /* closed-form samples: at least 32 intervals, */
#define BALLC_FLIGHT_MAX_TURN (3.14159265358979323846 / 16)  /* a turn of pi/16 at most */
#define BALLC_MAX_ROLL_SAMPLES 4096   /* at most 4096 samples of a closed-form end state */
#define BALLC_ARM_ULPS 1048576.0      /* a compliant contact is armed at 2^20 ulp of the
                                       * plane's position (and ARM_FORCE's depth) */
#define BALLC_FLIGHT_MAX_SAMPLES 100000000L   /* an exact flight's samples, at most */

/* The exact free-flight solution from (t0, y0) (n states) under ``gravity`` (the
 * acceleration vector, 3 values; ballc.flight): y(t) = c0 + c1 s + c2 s^2
 * + c3 cos(|omega| s / 2) + c4 sin(|omega| s / 2), s = t - t0 */
typedef struct { double t0, rate, c[5][BALLC_MAX_STATES]; int n; } ballc_flight;
void ballc_flight_init(ballc_flight *f, double t0, const double *y0, const double *gravity,
                       int n);
void ballc_flight_at(const ballc_flight *f, double t, double *y);
/* Rolling down an unbounded incline, uniformly accelerated (ballc.resting.AcceleratedRolling):
 * from (t0, y0) (n states), rolling without slip with no spin about the plane's unit
 * normal ``normal``, the centre's acceleration ``acceleration`` (3): the centre
 * c0 + v0 s + a s^2 / 2, the velocity v0 + a s, the angular velocity (w0 + |a| s / r) e
 * about the fixed axis e = n x a / |a| (w0 = omega0 . e), the quaternion turned about e
 * by w0 s + |a| s^2 / (2 r), the rest constant; s = t - t0 */
typedef struct {
    double t0, w0, spin_rate, axis[3], a[3], y0[BALLC_MAX_STATES];
    int n;
} ballc_rolling;
void ballc_rolling_init(ballc_rolling *f, double t0, const double *y0,
                        const double *acceleration, double radius, const double *normal,
                        int n);
void ballc_rolling_at(const ballc_rolling *f, double t, double *y);
/* its turn about e by t (rad) */
double ballc_rolling_angle(const ballc_rolling *f, double t);
/* the roots of c0 + c1 s + c2 s^2 in [0, s_max] where it changes sign in ``direction``
 * (> 0 rising, < 0 falling, 0 either; a tangency is none), increasing, cancellation-
 * free: at most 2 into out, their number returned */
int ballc_flight_crossings(double c0, double c1, double c2, int direction, double s_max,
                           double *out);

/* ballc_drive_config.method of a run with one of scipy's methods (its integrator is the
 * bridge's callback), and the segment log's method of its segments */
enum { BALLC_METHOD_SCIPY = -2 };

/* stop codes */
enum {
    BALLC_DRIVE_OK = 0,          /* reached t_end (status 0) */
    BALLC_DRIVE_FAILED = 1,      /* integrator failure (status -1); message, fail_end */
    BALLC_DRIVE_UNSETTLED = 2,   /* stick-slip did not settle (status -1); stop_plane */
    BALLC_DRIVE_THROUGH = 3,     /* passed through stop_plane (status 1) */
    BALLC_DRIVE_ABORTED = 4,     /* stopped where it cannot go on (status -1): message
                                  * (a kernel failed, a non-finite state, ...) */
    BALLC_DRIVE_NO_MEMORY = 5,
    BALLC_DRIVE_TERMINATED = 6,  /* a terminal user event (status 1) */
    BALLC_DRIVE_USER_ERROR = 7   /* a user event raised, an integrator raised, or Ctrl-C:
                                  * the bridge raises the exception it kept */
};

/* ---- the integrator interface (issue 29) ----
 *
 * The loop integrates every segment through one function: ballc_integrator, from the
 * config (NULL: ballc_compiled_integrator).  ``problem`` is the segment as radau5_solve
 * takes it -- t0 towards t_bound from y0, the right-hand side (fun, jac and ctx: the
 * segment's flags and latch), the events (linear rows, or ev_fun for the system's own
 * and the user's callables; terminal counts, directions, ev_rearm/rearm), rtol, atol
 * (N values), max_step, first_step, max_nfev, t_eval, dense_output, method,
 * jacobian_ahead, auto_implicit and poll -- and ``segment`` what an integrator that
 * does not call back into the problem's fun needs to build its own right-hand side:
 * the flags and the latch.  The integrator fills ``result`` as radau5_solve does
 * (samples, event hits, status and message, nfev/njev/nlu, h_next, dense steps; an
 * integrator without some of them leaves them 0, h_next 0 carries no step, stiff_at
 * NaN, method_end -1) and may keep its interpolant itself: then segment->interpolant is
 * its id (>= 0), else -1 and the dense steps are in the result.  It returns
 * RADAU5_DONE, RADAU5_OUT_OF_MEMORY, RADAU5_BAD_PROBLEM, or BALLC_INTEGRATOR_RAISED
 * when it failed with an exception it keeps for the bridge to raise (scipy's methods:
 * the bridge's _scipy_integrate, which evaluates the events with radau5_event_value). */
typedef struct {
    ballc_flags flags;         /* the segment's ballc_rhs flags */
    const double *latch;       /* the latched values (the run's latch) at its start */
    const double *params;      /* the parameter vector */
    long interpolant;          /* out: the integrator's own interpolant's id, or -1 */
    int n_latch;               /* the latch's length */
} ballc_segment;

typedef int (*ballc_integrator)(void *ctx, const radau5_problem *problem,
                                ballc_segment *segment, radau5_result *result);

enum { BALLC_INTEGRATOR_RAISED = -100 };

/* An integrator's own interpolant ``id`` (segment->interpolant) at n times t into y (n
 * rows of the run's states), with the integrator's ctx: 0, or nonzero when it cannot (an
 * exception kept for the bridge).  For C code that evaluates a segment's dense output
 * (ballc.orbit's trial) when the integrator keeps it itself; the compiled integrators'
 * dense steps are in their result instead. */
typedef int (*ballc_interpolant_fn)(void *ctx, long id, long n, const double *t, double *y);

/* radau5, dop853 and auto: radau5_solve (ctx unused) */
int ballc_compiled_integrator(void *ctx, const radau5_problem *problem,
                              ballc_segment *segment, radau5_result *result);


enum { BALLC_MODE_NONE = 0, BALLC_MODE_SLIP, BALLC_MODE_SLIP_FIXED, BALLC_MODE_STICK };

typedef struct {                       /* constants of one run, filled by the bridge */
    const double *params;              /* the parameter vector, its plane table included:
                                        * the run's planes, states and latch follow from it */
    double rtol, atol;                 /* one atol for all states */
    double t_end, max_step, first_step;
    int has_first_step;
    long max_nfev;                     /* 0: none */
    int method, controller;
    ballc_flags observer_bits;         /* the observer's flag when it has mass */
    ballc_flags contact_bits[BALLC_MAX_PLANES];   /* friction | digin of a plane in contact */
    int exact;                         /* stickslip.uses_exact_coulomb */
    double radius, weight, hertz_k, total_mass, rest_period;   /* rest: 20 T0 */
    int resting_plane, checks_rest;    /* -1: none */
    /* t_eval (sorted, within [0, t_end]; NULL: none) and dense output */
    const double *t_eval;
    long n_eval;
    int dense_output;
    /* exact flight (options.exact_flight and flight.scene_allows) */
    int exact_flight;
    /* the user's events, in order: LinearEvents (a row, offset;
     * index and scale when one state) or callables (called back through user_fun,
     * the bridge's, with user_ctx: it keeps an exception for the bridge to raise) */
    int n_user;
    const double *user_coef;           /* n_user x the run's states */
    const double *user_offset, *user_scale;
    const int *user_linear, *user_index, *user_count, *user_direction;
    int user_flight;                   /* every one lets exact flight apply */
    int (*user_fun)(void *ctx, int k, double t, const double *y, double *g);
    void *user_ctx;
    /* asked before each segment (may be NULL): nonzero when the run is to stop now (the
     * bridge's: a pending Ctrl-C, kept with user_ctx's exceptions for it to raise) */
    int (*interrupted)(void *ctx);
    /* the compliant law's exact modes (ballc.compliantmodes) */
    int compliant_modes;               /* compliantmodes.uses_modes */
    int starts_armed;                  /* compliantmodes.starts_armed: contacts begin at the
                                        * arming depth (else at rho = 0) */
    double arm_force_depth;            /* (ARM_FORCE / k0)^(2/3): arm_penetration's floor */
    double restick_factor;             /* max(1, mu / max(tangential_stiffness_ratio, 1e-300)) */
    int damping_positive;              /* tangential_damping_ratio > 0: capacity guards */
    double contact_time_base;          /* 3.2145 (m_total / k0)^0.4: contact_time */
    /* the rest checks (ballc.resting): the scene's constants */
    int observer_massive;              /* observer_mass > 0 */
    int rolls_allowed;                 /* flight.scene_allows: uniform motion possible */
    int orbit_applies;                 /* orbit.applies: a check finding nothing tries an orbit */
    double rest_threshold;             /* resting.energy_threshold */
    double rho_eq, z_eq;               /* equilibrium_penetration, radius - rho_eq */
    double rest_weight;                /* total_mass * |gravity| */
    double observer_weight;            /* observer_mass * |gravity| */
    double rolls_dv, rolls_level, half_mass;   /* resting.rolls: dv, 1e3 eps g, 0.5 M */
    /* ballc.orbit, run at the rest checks when orbit_applies (_orbit.c) */
    double orbit_axis[3];              /* orbit.body_axis */
    double rest_factor;                /* resting.REST_FACTOR */
    /* the integrator, per-state atol, progress, polling, the user's rearm */
    ballc_integrator integrate;        /* NULL: ballc_compiled_integrator */
    void *integrate_ctx;
    ballc_interpolant_fn interpolant;  /* its own interpolants (NULL: none) */
    const double *atol_states;         /* one per state (NULL: atol for each); atol is then
                                        * their largest (stickslip.error_speed's) */
    /* may be NULL: the simulated time reached, reported at most every poll_interval s of
     * wall time (the bridge's: the progress bar), with user_ctx */
    int (*progress)(void *ctx, double t);   /* nonzero: it raised (kept): stop */
    double poll_interval;              /* s of wall time between polls: progress and
                                        * interrupted, between segments and inside the
                                        * compiled integrators' step loops (<= 0: 0.1) */
    /* the user's LinearEvents' ``rearm`` (user_rearm[k] nonzero: it has one), called
     * through rearm_fun with user_ctx: 1 and the event's new row, offset and the latch
     * the run goes on with written, 0 declined, -1 raised (the exception kept) */
    const int *user_rearm;
    int (*rearm_fun)(void *ctx, int k, double t, const double *y, double *coef,
                     double *offset, double *latch);
    /* issue 31: rolling resistance (_rolling.h): the rolling and twisting parts' models
     * (0 off, 1 exact, 2 sds; both 0: the run has no rolling states) */
    int rolling, twisting;
} ballc_drive_config;

/* how a run ended at a rest check (ballc.resting): the state from end_t on is end_y */
enum { BALLC_END_NONE = 0, BALLC_END_REST, BALLC_END_ROLLING, BALLC_END_SLIDING,
       BALLC_END_ACCELERATING };   /* rolling down an unbounded incline: end_acceleration */

typedef struct {
    int plane, ended, passed_through, rate_is_kernel_value;
    double t_start, t_end, v_before[3], w_before[3], v_after[3], w_after[3];
    double rate, digin[3], max_penetration, contact_point[3], lost[2];   /* the centre at
                                                                         * max. penetration */
} ballc_contact_rec;

/* a contact's phases: when each starts (slip, stick) and its closed-form end state */
enum { BALLC_PHASE_SLIP = 0, BALLC_PHASE_STICK, BALLC_PHASE_REST, BALLC_PHASE_ROLLING,
       BALLC_PHASE_FREE_SLIDING };   /* an end state's: 1 + BALLC_END_* (ACCELERATING: ROLLING) */
typedef struct { long contact; double t; int phase; } ballc_phase_rec;

/* dense output: one piece (t0, t1) per segment, its steps [step0, step0 + n_steps) of
 * dense_t / dense_kind and their coefficients from dense_c[coef0], (1 + terms) N each */
typedef struct {
    double t0, t1;
    long step0, n_steps, coef0;
    int terms;
    int flight;                /* exact flight: FreeFlight(t0, y0, gravity, t_max = t1) */
    double y0[BALLC_MAX_STATES];
    int own;                   /* nonzero: the integrator's own interpolant, by its id */
    long interpolant;
} ballc_piece_rec;

/* The segment log (result.segments): one record per segment integrated (or flown), in
 * order, appended where the segment ends -- after the handler of the event that ended
 * it, or the check or bound that did.  Always kept: a few stores per segment. */

/* A plane's mode (ballc.automaton.MODES, in its order: ballc_plane_mode_names) */
enum {
    BALLC_PLANE_FLIGHT = 0, BALLC_PLANE_CONTACT, BALLC_PLANE_SLIP, BALLC_PLANE_SLIP_FIXED,
    BALLC_PLANE_STICK, BALLC_PLANE_ELASTIC, BALLC_PLANE_SLIDING, BALLC_PLANE_RESTING,
    BALLC_PLANE_ROLLING, BALLC_PLANE_FREE_SLIDING, BALLC_PLANE_PASSED_THROUGH,
    BALLC_N_PLANE_MODES
};

/* Why a segment ended (ballc_segment_end_names): first the event kinds of the automaton
 * (its terminal events: enter .. capacity, and a terminal user event), then the ends
 * that are no event.  A scheduled rest check runs its checks in turn -- rest, uniform
 * motion, an orbit's trial ending now -- each when the one before found nothing: the
 * end names the last that ran (so "uniform check" says the rest check found no rest). */
enum {
    BALLC_SEG_ENTER = 0, BALLC_SEG_LEAVE, BALLC_SEG_THROUGH, BALLC_SEG_DEEPEST,
    BALLC_SEG_APPROACH, BALLC_SEG_STOP, BALLC_SEG_CLEAR, BALLC_SEG_RELEASE, BALLC_SEG_ARM,
    BALLC_SEG_YIELD, BALLC_SEG_RESTICK, BALLC_SEG_CAPACITY,
    /* rolling resistance's exact modes (_rolling.h, BALLC_ROLLING_* in its order) */
    BALLC_SEG_ROLL_APPROACH, BALLC_SEG_ROLL_STOP, BALLC_SEG_ROLL_CLEAR, BALLC_SEG_ROLL_RELEASE,
    BALLC_SEG_TWIST_STOP, BALLC_SEG_TWIST_RELEASE, BALLC_SEG_ROLL_YIELD,
    BALLC_SEG_ROLL_RESTICK, BALLC_SEG_TWIST_YIELD, BALLC_SEG_TWIST_RESTICK,
    BALLC_SEG_USER,
    BALLC_SEG_T_END,            /* reached t_end */
    BALLC_SEG_REST_CHECK,       /* a rest check that found rest */
    BALLC_SEG_UNIFORM_CHECK,    /* ... no rest; uniform rolling / sliding, or nothing */
    BALLC_SEG_ORBIT_CHECK,      /* ... neither; an orbit's trial ended here */
    BALLC_SEG_STEP_BOUND,       /* a compliant contact's step bound ended */
    BALLC_SEG_FAILED,           /* the integrator failed (status -1) */
    BALLC_N_SEGMENT_ENDS
};

extern const char *const ballc_plane_mode_names[BALLC_N_PLANE_MODES];
extern const char *const ballc_segment_end_names[BALLC_N_SEGMENT_ENDS];

typedef struct {
    double t_start, t_end;      /* s; a failure: the last time reached */
    long nfev, njev, nlu;       /* of this segment (0 for an exact flight) */
    long nstep, nreject;        /* its accepted and rejected steps */
    int method, method_end;     /* the integrator it started / ended with: RADAU5_METHOD_*
                                 * (auto: radau5 or dop853), -1 an exact flight */
    int switches;               /* method "auto": switches inside the segment */
    int end;                    /* BALLC_SEG_* */
    int plane;                  /* the event's plane (its index in the plane table), a
                                 * user event's index, or -1 (no event) */
    int rearms;                 /* events re-armed inside the segment (a free slip's
                                 * approach re-latched, the capacity guard toggled) */
    signed char before[BALLC_MAX_PLANES], after[BALLC_MAX_PLANES];
                                /* BALLC_PLANE_* of each plane during the segment and
                                 * after its end was handled (-1: no such plane) */
    signed char rearm_kind, rearm_plane;    /* the last re-arm: BALLC_SEG_APPROACH or
                                             * _CAPACITY and its plane; -1 none */
    signed char rearm_before, rearm_after;  /* the plane's mode before / after it */
    /* each plane's rolling and twisting modes (BALLC_ROLLING_MODE_*: the latch's codes)
     * during the segment and after its end was handled */
    signed char rolling_before[BALLC_MAX_PLANES], rolling_after[BALLC_MAX_PLANES];
    signed char twisting_before[BALLC_MAX_PLANES], twisting_after[BALLC_MAX_PLANES];
} ballc_segment_rec;

typedef struct {
    int n_planes, n_states, n_latch;    /* the run's (its parameters' plane table) */
    long n, cap;                        /* samples: t (n), y (n x n_states) */
    double *t, *y;
    long n_blocks, cap_blocks;          /* blocks: count, flags, latch (n_latch) */
    long *block_count;
    ballc_flags *block_flags;
    double *block_latch;
    long n_contacts, cap_contacts;
    ballc_contact_rec *contacts;
    long n_phases, cap_phases;
    ballc_phase_rec *phases;
    int open[BALLC_MAX_PLANES];         /* open contact per plane, -1 none */
    long n_user_hits, cap_user_hits;    /* the user's events' hits, in order */
    int *user_hit_event;
    double *user_hit_t, *user_hit_y;
    long n_switches, cap_switches;      /* method "auto": (t, method switched to) */
    double *switch_t;
    int *switch_to;
    long n_pieces, cap_pieces;          /* dense output */
    ballc_piece_rec *pieces;
    long n_steps, cap_steps, n_coef, cap_coef;
    double *dense_t, *dense_c;
    int *dense_kind;
    /* the end */
    int stop_code, status, stop_plane;
    double t_run;                       /* run.t at the end */
    double fail_end;                    /* FAILED: t[-1] of the segment, or run.t */
    int in_contact[BALLC_MAX_PLANES];
    long transitions[BALLC_MAX_PLANES], stalled;
    int unsettled_compliant;            /* UNSETTLED: the compliant law's modes */
    long nfev, njev, nlu;
    double stiff_at;                    /* NaN: none */
    char message[240];                  /* FAILED: the integrator's message; ABORTED:
                                         * why the run could not go on */
    long segments;
    int end_kind, end_plane;            /* BALLC_END_*: rest / uniform motion found;
                                         * its closed-form samples are the last block */
    double end_t, end_y[BALLC_MAX_STATES];
    double end_acceleration[3];         /* ACCELERATING: the centre's (m/s^2) */
    /* a -DRADAU5_PROFILE build: thread CPU time (ns) inside radau5_solve, summed over
     * the segments, and in the whole of ballc_drive; zeros otherwise */
    int profiled;
    double integrator_ns, drive_ns;
    /* ballc.orbit: with end_orbit, the end state (end_kind rolling or sliding) is the
     * relative periodic orbit ``orbit``, y(t) from orbit_base (its trial's solution over
     * [c0, c0 + T]); every trial (t_from, t_to, accepted), 3 numbers each in trials */
    int end_orbit;
    ballc_orbit orbit;
    ballc_dense orbit_base;
    long n_trials, cap_trials;
    double *trials;
    long n_log, cap_log;                /* the segment log (result.segments) */
    ballc_segment_rec *log;
    /* a -DRADAU5_PROFILE build: radau5_result's prof (RADAU5_PROF_N = 7: ticks inside the
     * RHS, Jacobian, factorisations, solves, events, in all, and ns in all) summed over
     * the segments; zeros otherwise */
    double integrator_prof[7];
} ballc_drive_output;

int ballc_drive(const ballc_drive_config *config, const double *y0,
                ballc_drive_output *out);
void ballc_drive_free(ballc_drive_output *out);

#endif
