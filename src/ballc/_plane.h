/* A plane as a point and an orthonormal frame, and the change into and out of it.
 *
 * The contact laws are generated once, in a plane's own frame (codegen/model.py,
 * FRAME_PLANE: the plane z = 0 with its normal +z towards the ball).  A plane given by a
 * point p and its frame (t1, t2, n), R = [t1 t2 n], applies them to the ball as follows:
 *
 *   the contact state (BALLC_CONTACT_STATE_*): the centre's height z_l = n . (c - p), the
 *     angular velocity omega_l = R^T omega and velocity v_l = R^T v, and the plane's
 *     tangential deflection and rolling spring as they are (they live in its frame);
 *   the plane's inputs (BALLC_N_PLANE_INPUTS): its latch block with the dig-in direction
 *     (latched in inertial components) turned into the frame, and gravity into the
 *     plane, -n . g;
 *   the law's vector outputs back: the generalized forces of the speeds (omega, v) are a
 *     torque and a force, tau = R tau_l and F = R F_l, the contact force F = R F_l; its
 *     scalars (dissipation rates) and the deflection rates (the plane's frame) as they are;
 *   its Jacobian d/d(contact state) as d/d(state): the centre's columns n dz_l, those of
 *     omega and v through R^T, the deflection's and the rolling spring's to the plane's
 *     own, the rest 0 (a sphere's
 *     contact depends neither on its orientation nor on where along the plane it is).
 */
#ifndef BALLC_PLANE_H
#define BALLC_PLANE_H

#include "ballc_kernels.h"

typedef struct {
    double point[3];
    double frame[3][3];      /* rows t1, t2, n (inertial components): R^T */
    double gravity_into;     /* -n . g (m/s^2): gravity's component into the plane */
    int deflection;          /* the state index of the plane's deflection_x (y next) */
    int rolling;             /* the state index of its rolling spring (rolling_x, _y,
                              * twisting), -1 in a run without rolling resistance */
} ballc_plane_t;

/* The plane through ``point`` with the normal ``normal`` (towards the ball, any length
 * > 0: normalised here), its frame: t1 the coordinate axis the normal has least of (the
 * first such) made perpendicular to n and unit, t2 = n x t1 (the floor: x, y, z; the
 * ceiling, normal -z: x, -y, -z).  ``gravity`` (3) the gravity vector, ``deflection``
 * the state index of the plane's deflection_x, ``rolling`` that of its rolling_x (-1:
 * none, the rolling springs read as 0). */
void ballc_plane_init(ballc_plane_t *plane, const double *point, const double *normal,
                      const double *gravity, int deflection, int rolling);

/* v_l = R^T v: the components along t1, t2, n. */
static inline void ballc_plane_to_local(const ballc_plane_t *plane, const double *v,
                                        double *local)
{
    for (int i = 0; i < 3; i++)
        local[i] = plane->frame[i][0] * v[0] + plane->frame[i][1] * v[1]
                   + plane->frame[i][2] * v[2];
}

/* The ball's contact state (BALLC_N_CONTACT_STATES) in the plane's frame (inline: it and
 * the two below run in every right-hand side with a contact). */
static inline void ballc_plane_contact_state(const ballc_plane_t *plane, const double *state,
                                             double *local)
{
    const double *p = plane->point, *n = plane->frame[2];
    local[BALLC_CONTACT_STATE_Z] = n[0] * (state[BALLC_STATE_X] - p[0])
                                   + n[1] * (state[BALLC_STATE_Y] - p[1])
                                   + n[2] * (state[BALLC_STATE_Z] - p[2]);
    ballc_plane_to_local(plane, state + BALLC_STATE_OMEGA_X, local + BALLC_CONTACT_STATE_OMEGA_X);
    ballc_plane_to_local(plane, state + BALLC_STATE_VX, local + BALLC_CONTACT_STATE_VX);
    local[BALLC_CONTACT_STATE_DEFLECTION_X] = state[plane->deflection];
    local[BALLC_CONTACT_STATE_DEFLECTION_Y] = state[plane->deflection + 1];
    if (plane->rolling >= 0) {
        local[BALLC_CONTACT_STATE_ROLLING_X] = state[plane->rolling];
        local[BALLC_CONTACT_STATE_ROLLING_Y] = state[plane->rolling + 1];
        local[BALLC_CONTACT_STATE_TWISTING] = state[plane->rolling + 2];
    } else {   /* a run without rolling resistance has no rolling springs */
        local[BALLC_CONTACT_STATE_ROLLING_X] = local[BALLC_CONTACT_STATE_ROLLING_Y] = 0.0;
        local[BALLC_CONTACT_STATE_TWISTING] = 0.0;
    }
}

/* A plane kernel's extra (BALLC_N_PLANE_INPUTS) from the plane's latch block
 * (BALLC_N_LATCH_PER_PLANE). */
static inline void ballc_plane_inputs(const ballc_plane_t *plane, const double *latch,
                                      double *inputs)
{
    for (int i = 0; i < BALLC_N_LATCH_PER_PLANE; i++) inputs[i] = latch[i];
    ballc_plane_to_local(plane, latch + BALLC_LATCH_DIGIN_DIRECTION_X,
                         inputs + BALLC_LATCH_DIGIN_DIRECTION_X);
    inputs[BALLC_PLANE_INPUT_GRAVITY] = plane->gravity_into;
}

/* ``count`` consecutive 3-vectors from the plane's frame to inertial components, in
 * place: v = R v_l. */
static inline void ballc_plane_to_inertial(const ballc_plane_t *plane, double *v, int count)
{
    const double (*f)[3] = plane->frame;
    for (int k = 0; k < count; k++, v += 3) {
        double a = v[0], b = v[1], c = v[2];
        for (int i = 0; i < 3; i++) v[i] = f[0][i] * a + f[1][i] * b + f[2][i] * c;
    }
}

/* A plane kernel's Jacobian rows ``local`` (rows x BALLC_N_CONTACT_STATES, row-major) as
 * derivatives by the run's state: ``jac`` (rows x n_states, written). */
void ballc_plane_state_columns(const ballc_plane_t *plane, const double *local, int rows,
                               int n_states, double *jac);

/* Rows of ``m`` (each ``columns`` long, row-major) from the plane's frame to inertial
 * components: ``count`` consecutive triples of rows from ``first_row`` on, each turned
 * by R, column by column. */
void ballc_plane_rows_to_inertial(const ballc_plane_t *plane, double *m, int columns,
                                  int first_row, int count);

#endif
