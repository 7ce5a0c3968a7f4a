/* Rolling resistance: the contact law's fourth part (docs/contact_laws.md, "Rolling
 * resistance"), as LAMMPS GRANULAR composes a contact of normal, damping, tangential,
 * rolling and twisting sub-models.
 *
 * A plane's rolling part has two parts of its own, each with a mode in the plane's latch
 * (BALLC_LATCH_ROLLING_MODE, BALLC_LATCH_TWISTING_MODE; codes BALLC_ROLLING_MODE_*):
 *
 *   rolling:  the rolling velocity v_roll = r (omega x n) (2, along the plane's t1, t2),
 *             resisted by a rolling force F_r in the plane whose torque is r n x F_r;
 *   twisting: the twisting velocity v_twist = r omega . n (1), resisted by a twisting
 *             force F_w whose torque is r F_w n.
 *
 * Both are capped at mu F_n (mu = rolling_resistance, twisting_resistance; F_n the
 * contact's normal force, codegen contact.rolling_load), so the torques at mu r F_n.
 * Two models (codegen/contact.py derives the velocities, the load and the maps):
 *
 *   exact (Ai et al. 2011, type A, with holding), in the modes of exact Coulomb friction:
 *     FREE   F = -mu F_n e, e the unit velocity, oriented along the latched direction d
 *            (so that it continues through v . d = 0, where the stop event sits);
 *     FIXED  F = -mu F_n d (the last approach to 0 and the first departure from it;
 *            twisting is always FIXED: its direction is a sign);
 *     HOLDING the velocity held constant (at ~0) by a constraint force, solved with the
 *            equations of motion together with Coulomb's stick constraint when the
 *            plane sticks too (every plane's at once: _system.c); released where
 *            |lambda| = mu F_n.
 *   sds (LAMMPS rolling sds / twisting sds, ballc's passive form): the generated
 *     kernels of the spring (below the cap) and the slider (at it).
 *
 * Mode changes are events of the segment loop (_driver.c); this file holds the physics
 * both use: the forces and their Jacobian in the equations, the constraint solve, the
 * impulse that removes what is left of a velocity when it is held, and the guards.
 */
#ifndef BALLC_ROLLING_H
#define BALLC_ROLLING_H

#include "ballc_kernels.h"
#include "_system.h"

#define BALLC_ROLLING_W 3   /* rolling (2) and twisting (1) velocities */

/* The velocities a plane may hold with constraint forces (a mask): its slip (Coulomb's
 * stick), its rolling and its twisting velocity. */
enum { BALLC_HOLD_SLIP = 1, BALLC_HOLD_ROLLING = 2, BALLC_HOLD_TWISTING = 4 };

/* A plane's rolling part in one evaluation of the equations. */
typedef struct {
    int mode[2];            /* rolling, twisting: BALLC_ROLLING_MODE_* (from the latch) */
    double w[BALLC_ROLLING_W];        /* rolling velocity (t1, t2), twisting velocity */
    double load;            /* F_n (N) */
    double e[BALLC_ROLLING_W];        /* exact FREE / FIXED: the force is -mu F_n e */
    double lambda[BALLC_ROLLING_W];   /* HOLDING: the constraint forces */
    const double *dw;       /* dw/dx (3 x N_STATES), constants */
    const double *G;        /* generalized force of unit F_r (t1, t2), F_w (6 x 3, inertial) */
    /* sds sliders: the coefficients of rho'' in the rolling dissipation rate and the
     * rolling spring rates (x, y, twisting), added after the solve (0 without) */
    double acceleration[4];
} ballc_rolling_eval;

/* The part modes in a plane's latch block (BALLC_N_LATCH_PER_PLANE values). */
static inline int ballc_rolling_mode(const double *plane_latch, int part)
{
    return (int)plane_latch[part ? BALLC_LATCH_TWISTING_MODE : BALLC_LATCH_ROLLING_MODE];
}

/* Whether any part of a plane's rolling part acts (its latch block). */
static inline int ballc_rolling_on(const double *plane_latch)
{
    return ballc_rolling_mode(plane_latch, 0) != BALLC_ROLLING_MODE_NONE
        || ballc_rolling_mode(plane_latch, 1) != BALLC_ROLLING_MODE_NONE;
}

/* The mask of the parts held (BALLC_HOLD_ROLLING, BALLC_HOLD_TWISTING).  _system.c
 * solves the constraint forces of every plane's held velocities at once (its slip when
 * it sticks too: one Delassus solve) and removes what is left of them by one impulse
 * (ballc_remove_velocities). */
int ballc_rolling_held(const ballc_rolling_eval *roll);


/* A plane's rolling part at the contact state ``local`` (its frame) with the plane
 * kernel inputs ``inputs``: its modes from ``plane_latch``, its velocities and load, and
 * its forces added to ``force`` (6, generalized, inertial): the exact FREE and FIXED
 * parts' -mu F_n e through the plane's maps, the sds parts' generated kernels; their
 * dissipation to xdot[dissipated_rolling] and the sds springs' rates to the plane's
 * rolling spring states (xdot may be NULL; the sliders' rho'' shares are left in
 * roll->acceleration). */
void ballc_rolling_assemble(const struct ballc_parameters *params, int plane,
                            const double *local, const double *inputs,
                            const double *plane_latch, ballc_rolling_eval *roll,
                            double *force, double *xdot);

/* Add the rolling part's derivatives: the exact FREE / FIXED forces F = -mu F_n e(w)
 * (de/dw = sign (I - e e^T) / |w| for a FREE rolling part, 0 otherwise) to dF
 * (6 x N_STATES) through G, and those of their dissipation rate mu F_n (e . w) to the row
 * of dissipated_rolling of ``jac``; the sds parts' from their Jacobian kernels (the
 * sliders' with the contact's own rho''), their spring rates' rows too. */
void ballc_rolling_jacobian(const struct ballc_parameters *params, int plane,
                            const double *local, const double *inputs,
                            const double *plane_latch, const ballc_rolling_eval *roll,
                            double *dF, double *jac);

/* ---- the segment loop's part (_driver.c): the exact modes' guards and resets ---- */

/* The events of a plane's rolling part, in the order a segment lists them (the segment
 * loop's event kinds follow the Coulomb and compliant ones in this order). */
enum {
    BALLC_ROLLING_APPROACH = 0,  /* FREE: v_roll . d - approach falls through 0 */
    BALLC_ROLLING_STOP,          /* FIXED: v_roll . d + margin falls through 0 */
    BALLC_ROLLING_CLEAR,         /* FIXED: v_roll . d - 2 clear rises through 0 */
    BALLC_ROLLING_RELEASE,       /* HOLDING: mu_r F_n - |lambda_r| + scale falls through 0 */
    BALLC_TWISTING_STOP,         /* FIXED: v_twist d + margin falls through 0 */
    BALLC_TWISTING_RELEASE,      /* HOLDING: mu_t F_n - |lambda_w| + scale falls through 0 */
    /* the sds model (spring below the cap, slider at it), per part */
    BALLC_ROLLING_YIELD,         /* SPRING: 1 - k |xi| / (mu F_n) + rounding falls */
    BALLC_ROLLING_RESTICK,       /* SLIDER: (e . w) - mu F_n' / k + offset falls */
    BALLC_TWISTING_YIELD,
    BALLC_TWISTING_RESTICK,
    BALLC_ROLLING_EVENTS
};

/* What the segment loop keeps of a plane's exact rolling modes between segments. */
typedef struct {
    double approach;        /* the next approach event's speed (when has_approach) */
    int has_approach;
    long relatches;         /* approaches that re-latched the direction (at most 1000) */
} ballc_rolling_run;

/* One guard of a plane's rolling part: linear, g = row . y + offset, or not, g = the
 * margin (ballc_rolling_guard_value) + offset. */
typedef struct {
    int event;              /* BALLC_ROLLING_* */
    int linear;
    double row[BALLC_MAX_STATES];   /* the run's n_states used */
    double offset;
    int direction;
} ballc_rolling_guard;

/* The scales of a run the guards and resets use: error = rtol (|v| + r |omega|) + atol
 * at the segment's start (stickslip.error_speed), clear = 100 error, margin = 4 ulp of
 * |v| + r |omega|, weight = (m + m_o) |g| (the force scale 64 eps (weight + |F_n|)),
 * rounding = the compliant guards' (8 ulp of the plane's position over rho, >= 64 eps)
 * and speed = |v| + r |omega| (the sds guards' offsets: rounding, rounding speed). */
typedef struct { double error, clear, margin, weight, rounding, speed; } ballc_rolling_scales;

/* The guards of plane ``plane``'s rolling part in its modes (``latch``) at the segment's
 * start y0 under ``flags`` (the segment's): at most 3, written to ``out``; the count, or
 * -1 when a kernel failed. */
int ballc_rolling_guards(const struct ballc_parameters *params, int plane, const double *y0,
                         const double *latch, ballc_flags flags, const ballc_rolling_run *run,
                         const ballc_rolling_scales *scales, ballc_rolling_guard *out);

/* A non-linear guard's margin at y (without its offset): BALLC_ROLLING_RELEASE's
 * mu_r F_n - |lambda_r|, BALLC_TWISTING_RELEASE's mu_t F_n - |lambda_w|, the sds
 * yield and re-stick margins (ballc_rolling_margins). */
int ballc_rolling_guard_value(const struct ballc_parameters *params, int plane, int event,
                              const double *y, const double *latch, ballc_flags flags, double *g);

/* The reset of ``event`` on ``plane`` at (y, latch), both updated in place (``stick``:
 * the plane's Coulomb mode sticks, its slip is held with the rolling part's velocities).
 * 0, or -1 when a kernel failed. */
int ballc_rolling_transition(const struct ballc_parameters *params, int plane, int event,
                             double *y, double *latch, ballc_flags flags, int stick,
                             ballc_rolling_run *run, const ballc_rolling_scales *scales);

/* A contact starts on ``plane`` with the rolling (``rolling``) and twisting
 * (``twisting``) parts on, each 1 (exact) or 2 (sds), 0 off: their first modes (exact:
 * as Coulomb's start: free, fixed, or settled; sds: its spring relaxed, and the slider
 * when the part moves -- the cap starts at 0, the spring would stretch past it -- the
 * spring otherwise); 0 or -1. */
int ballc_rolling_start(const struct ballc_parameters *params, int plane, int rolling,
                        int twisting, double *y, double *latch, ballc_flags flags, int stick,
                        ballc_rolling_run *run, const ballc_rolling_scales *scales);

/* A contact ends on ``plane``: its rolling part rests -- the modes none, the directions
 * 0, and the sds springs relaxed, the energy they held booked as dissipated (with no
 * contact there is no spring). */
void ballc_rolling_end(const struct ballc_parameters *params, int plane, double *y,
                       double *latch);

/* After a reset of ``plane`` that moved the state (an impulse that removed a velocity
 * left over), each exact rolling and twisting part that slides must still be on its
 * guard's side: its velocity along its latched direction above the approach speed
 * (free) or above -margin (fixed) -- else its guard, starting below 0, would never fire,
 * and its force would push along the motion.  A part that is not starts afresh (as at a
 * contact's start).  Returns the number of parts restarted, or -1. */
int ballc_rolling_recheck(const struct ballc_parameters *params, int plane, double *y,
                          double *latch, ballc_flags flags, int stick, ballc_rolling_run *run,
                          const ballc_rolling_scales *scales);

/* The held velocities of ``plane`` (its latch), with its slip when ``stick``: the mask
 * an impulse that zeroes one of them must hold the others with (BALLC_HOLD_*). */
int ballc_rolling_held_mask(const double *latch, int plane, int stick);

#endif
