/* The segment loop of ballc.simulate in C (docs/c_loop_plan.md, stages 0, 1, 2a -- the
 * rest checks of ballc.resting; an orbit's trial, ballc.orbit, falls back --, 2b: t_eval
 * and dense output, 2c: method "auto" and exact flight, ballc.flight, 3: the compliant
 * law's exact modes, ballc.compliantmodes, and 4: user events).
 *
 * ballc_drive runs a whole simulation of the subset -- exact Coulomb friction, the
 * compliant law or no friction, user events (callables called back through the
 * bridge), no progress bar, method radau5, dop853 or auto -- and reproduces the Python driver (simulate.py with
 * events.py, stickslip.py, modes.py, samples.py) bit for bit: the same floating-point
 * operations in the same order.  What it does not port ends the run with
 * BALLC_DRIVE_FALLBACK, and simulate() then runs the Python driver from the start.
 *
 * Numerics that must match CPython / numpy exactly (see docs/c_loop_plan.md, 1.5):
 *   ballc_py_hypot: CPython 3.11's math.hypot (vector_norm), verbatim;
 *   ballc_py_ulp:   CPython's math.ulp;
 *   ballc_dot3_fma: numpy's float64 dot of length 3 (OpenBLAS ddot on this machine:
 *                   fma(c, c, fma(b, b, a * a)), checked by tests/test_c_driver.py).
 * This file must be compiled as the rest of the extension: -std=c99 (no FP contraction),
 * never -ffast-math or -march=native.
 */
#ifndef BALLC_DRIVER_H
#define BALLC_DRIVER_H

#include "ballc_kernels.h"

double ballc_py_hypot(int n, const double *values);
double ballc_py_ulp(double x);
double ballc_dot3_fma(const double *v);

/* stop codes */
enum {
    BALLC_DRIVE_OK = 0,          /* reached t_end (status 0) */
    BALLC_DRIVE_FAILED = 1,      /* integrator failure (status -1); message, fail_end */
    BALLC_DRIVE_UNSETTLED = 2,   /* stick-slip did not settle (status -1); stop_plane */
    BALLC_DRIVE_THROUGH = 3,     /* passed through stop_plane (status 1) */
    BALLC_DRIVE_FALLBACK = 4,    /* not ported here: run the Python driver */
    BALLC_DRIVE_NO_MEMORY = 5,
    BALLC_DRIVE_TERMINATED = 6,  /* a terminal user event (status 1) */
    BALLC_DRIVE_USER_ERROR = 7   /* a user event raised: the bridge raises it */
};

enum { BALLC_MODE_NONE = 0, BALLC_MODE_SLIP, BALLC_MODE_SLIP_FIXED, BALLC_MODE_STICK };

typedef struct {                       /* constants of one run, filled by the bridge */
    const double *params;              /* BALLC_N_PARAMETERS */
    double rtol, atol;                 /* one atol for all states */
    double t_end, max_step, first_step;
    int has_first_step;
    long max_nfev;                     /* 0: none */
    int method, controller;
    int observer_bits;                 /* the observer's flag when it has mass */
    int contact_bits[2];               /* friction | digin of a plane in contact */
    int slip_bits[2], slip_fixed_bits[2], stick_bits[2];
    int exact;                         /* stickslip.uses_exact_coulomb */
    double radius, weight, hertz_k, total_mass, rest_period;   /* rest: 20 T0 */
    int resting_plane, checks_rest;    /* -1: none */
    double rho_scale[2], rho_offset[2], through_offset[2], threshold_base[2];
    int n_terms[2][2];                 /* slip_terms: plane, row -> at most 2 terms */
    int term_index[2][2][2];
    double term_coef[2][2][2];
    double slip_map[2][2][BALLC_N_STATES];
    /* stage 2b: t_eval (sorted, within [0, t_end]; NULL: none) and dense output */
    const double *t_eval;
    long n_eval;
    int dense_output;
    /* stage 2c: exact flight (options.exact_flight and flight.scene_allows) */
    int exact_flight;
    double gravity;                    /* params[gravity] */
    /* stage 4: the user's events (UserEvents), in order: LinearEvents (a row, offset;
     * index and scale when one state) or callables (called back through user_fun,
     * the bridge's, with user_ctx: it keeps an exception for the bridge to raise) */
    int n_user;
    const double *user_coef;           /* n_user x N */
    const double *user_offset, *user_scale;
    const int *user_linear, *user_index, *user_count, *user_direction;
    int user_flight;                   /* every one lets exact flight apply */
    int (*user_fun)(void *ctx, int k, double t, const double *y, double *g);
    void *user_ctx;
    /* asked before each segment (may be NULL): nonzero when the run is to stop now (the
     * bridge's: a pending Ctrl-C, kept with user_ctx's exceptions for it to raise) */
    int (*interrupted)(void *ctx);
    /* stage 3: the compliant law's exact modes (ballc.compliantmodes) */
    int compliant_modes;               /* compliantmodes.uses_modes */
    int compliant_bits[2], elastic_bits[2], sliding_bits[2];   /* mode_flags per plane */
    int compliant_any;                 /* FLOOR_COMPLIANT | CEILING_COMPLIANT */
    int compliant_sliding_any;         /* FLOOR_COMPLIANT_SLIDING | CEILING_COMPLIANT_SLIDING */
    double arm_depth[2];               /* arm_penetration; 0: contacts begin at rho = 0 (compliantmodes.starts_armed) */
    double ulp8[2];                    /* 8 ulp(plane_position): _rounding */
    double restick_factor;             /* max(1, mu / max(tangential_stiffness_ratio, 1e-300)) */
    int damping_positive;              /* tangential_damping_ratio > 0: capacity guards */
    double contact_time_base;          /* 3.2145 (m_total / k0)^0.4: contact_time */
    /* the rest checks (ballc.resting; stage 2a), constants computed by Python */
    int observer_massive;              /* observer_mass > 0 */
    int rolls_allowed;                 /* flight.scene_allows: uniform motion possible */
    int orbit_applies;                 /* orbit.applies: a check finding nothing falls back */
    double rest_threshold;             /* resting.energy_threshold */
    double rho_eq, z_eq;               /* equilibrium_penetration, radius - rho_eq */
    double rest_weight;                /* total_mass * gravity */
    double observer_weight;            /* observer_mass * gravity */
    double rolls_dv, rolls_level, half_mass;   /* resting.rolls: dv, 1e3 eps g, 0.5 M */
} ballc_drive_config;

/* how a run ended at a rest check (ballc.resting): the state from end_t on is end_y */
enum { BALLC_END_NONE = 0, BALLC_END_REST, BALLC_END_ROLLING, BALLC_END_SLIDING };

typedef struct {
    int plane, ended, passed_through, rate_is_kernel_value;
    double t_start, t_end, v_before[3], w_before[3], v_after[3], w_after[3];
    double rate, digin[3], max_penetration, contact_point[2], lost[2];
} ballc_contact_rec;

typedef struct { long contact; double t; int phase; } ballc_phase_rec;  /* 0 slip, 1 stick */

/* dense output: one piece (t0, t1) per segment, its steps [step0, step0 + n_steps) of
 * dense_t / dense_kind and their coefficients from dense_c[coef0], (1 + terms) N each */
typedef struct {
    double t0, t1;
    long step0, n_steps, coef0;
    int terms;
    int flight;                /* exact flight: FreeFlight(t0, y0, gravity, t_max = t1) */
    double y0[BALLC_N_STATES];
} ballc_piece_rec;

typedef struct {
    long n, cap;                        /* samples: t (n), y (n x N_STATES) */
    double *t, *y;
    long n_blocks, cap_blocks;          /* blocks: count, flags, latch (N_LATCH) */
    long *block_count;
    int *block_flags;
    double *block_latch;
    long n_contacts, cap_contacts;
    ballc_contact_rec *contacts;
    long n_phases, cap_phases;
    ballc_phase_rec *phases;
    int open[2];                        /* open contact per plane, -1 none */
    long n_user_hits, cap_user_hits;    /* the user's events' hits, in order */
    int *user_hit_event;
    double *user_hit_t, *user_hit_y;
    long n_switches, cap_switches;      /* method "auto": (t, method switched to) */
    double *switch_t;
    int *switch_to;
    long n_pieces, cap_pieces;          /* dense output (stage 2b) */
    ballc_piece_rec *pieces;
    long n_steps, cap_steps, n_coef, cap_coef;
    double *dense_t, *dense_c;
    int *dense_kind;
    /* the end */
    int stop_code, status, stop_plane;
    double t_run;                       /* run.t at the end */
    double fail_end;                    /* FAILED: t[-1] of the segment, or run.t */
    int in_contact[2];
    long transitions[2], stalled;
    int unsettled_compliant;            /* UNSETTLED: the compliant law's modes */
    long nfev, njev, nlu;
    double stiff_at;                    /* NaN: none */
    char message[240];                  /* FAILED: the integrator's message */
    long segments;
    int end_kind, end_plane;            /* BALLC_END_*: rest / uniform motion found */
    double end_t, end_y[BALLC_N_STATES];
    /* a -DRADAU5_PROFILE build: thread CPU time (ns) inside radau5_solve, summed over
     * the segments, and in the whole of ballc_drive; zeros otherwise */
    int profiled;
    double integrator_ns, drive_ns;
} ballc_drive_output;

int ballc_drive(const ballc_drive_config *config, const double *y0,
                ballc_drive_output *out);
void ballc_drive_free(ballc_drive_output *out);

#endif
