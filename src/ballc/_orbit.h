/* The periodic end state of a ball with an eccentric observer: a relative periodic
 * orbit (ballc.orbit's docstring states the symmetry, the criterion and what it
 * neglects).  This file computes it; the C loop (_driver.c) runs it at its rest checks
 * and Python reaches it through the bridge (_orbit_bridge.pxi).
 *
 *   G = (phi, d, psi, work): turn the scene by phi about the vertical, shift it by d,
 *   turn the ball by psi about its axis a, add ``work`` (J, normal and tangential) to
 *   the dissipated work.  y(c0 + k T + s) = G^k y(c0 + s), 0 <= s < T, for every k.
 */
#ifndef BALLC_ORBIT_H
#define BALLC_ORBIT_H

#include "_dense.h"
#include "ballc_kernels.h"

/* orbit.TRIAL_PERIODS: the periods a trial integrates (the stretch before the first
 * crossing, one to measure G, one to test it); TILT_SAMPLES: samples of the tilt per
 * period, to bracket its crossings */
#define BALLC_ORBIT_TRIAL_PERIODS 3.5
#define BALLC_ORBIT_TILT_SAMPLES 64

typedef struct {
    double phi, d[2], psi, axis[3], work[2];
    /* the scene's planes (all horizontal: the orbit needs the symmetry about the
     * vertical): how many, and how each one's deflection turns with the scene, +1 (its
     * frame's t1, t2 turn with it: normal +z) or -1 (against it: normal -z) */
    int n_planes;
    double sense[BALLC_MAX_PLANES];
} ballc_motion;

/* G's planes (n_planes, sense) from a prepared parameter vector's plane table. */
void ballc_motion_planes(ballc_motion *g, const double *params);

/* G^k (k any integer, as a double): phi and psi times k, the shift summed in closed form,
 * d (e^(i k phi) - 1) / (e^(i phi) - 1), the work times k */
void ballc_motion_power(const ballc_motion *g, double k, ballc_motion *out);
/* out = G y; with ``rate``, G_* of a time derivative (no shift, no work added) */
void ballc_motion_apply(const ballc_motion *g, const double *y, int rate, double *out);

/* the vertical component of the ball's axis a in inertial components, a_z */
double ballc_orbit_tilt(const double *y, const double *axis);

/* criterion 2: f(G y) = G_* f(y) to rounding, for a G that turns, shifts and spins:
 * 1 yes, 0 no (or the right-hand side could not be evaluated) */
int ballc_orbit_equivariant(const double *params, const double *latch, long long flags,
                            const double *y, const double *axis);

typedef struct {
    double c0, period;     /* the first upward crossing and the period T */
    ballc_motion g;        /* G, measured from c0 to c0 + T */
    double rate;           /* the mechanical energy's rate of change over the trial (W) */
} ballc_orbit;

typedef struct {           /* the tolerances the trial was integrated to */
    double rtol;
    const double *atol;    /* one per state of the run (params' plane table) */
    double rest_factor;    /* resting.REST_FACTOR */
    double energy_threshold;   /* resting.energy_threshold */
    const double *params;
} ballc_orbit_tolerances;

/* Criteria 3-5 on a trial's solution y(t) (``states``, ``ctx``) over [t0, t1]
 * (``guess``: about one period): 1 and ``out`` when it is a relative periodic orbit,
 * 0 when not, -1 when the solution could not be evaluated, -2 out of memory. */
int ballc_orbit_measure(ballc_states_fn states, void *ctx, double t0, double t1,
                        const double *axis, double guess, const ballc_orbit_tolerances *tol,
                        ballc_orbit *out);

/* y(t) = G^k base(c0 + s), t = c0 + k T + s, 0 <= s < T, at n times (rows of the run's
 * states, G's planes): base(t') over [c0, c0 + T] is the trial's integrated solution.
 * 0, -1 when base failed, -2 out of memory. */
int ballc_orbit_states(const ballc_orbit *orbit, ballc_states_fn base, void *ctx, long n,
                       const double *t, double *y);

#endif
