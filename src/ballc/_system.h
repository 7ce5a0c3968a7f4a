/* ballc's right-hand side and Jacobian, assembled from the generated kernels.
 *
 * The state derivative is [kinematics (7); udot (6)] where M(q) udot = F(x) and
 * M = [[J, B], [B^T, D I3]] (see codegen/kernels.py).  udot comes from a Schur
 * complement: S = J - B B^T / D (symmetric positive definite) is factored by
 * Cholesky, so no 6x6 (or 13x13) dense solve is needed.
 *
 * The contact laws are generated once, in a plane's own frame; each plane of the plane
 * table (a point and a normal per plane, in the parameters) applies them in its frame
 * (_plane.h).  A plane's slip velocity, slip direction latch, stick constraint force and
 * tangential deflection are in its frame (components along its tangents t1, t2); forces,
 * the dig-in direction latch and contact-point velocities in inertial components.
 */
#ifndef BALLC_SYSTEM_H
#define BALLC_SYSTEM_H

#include "ballc_kernels.h"
#include "_plane.h"

/* Which contributions act in the current segment: bit flags, a 64-bit integer.  Bit 0
 * the observer's kernels; then one bit per kind of contribution (BALLC_KIND_*) and
 * plane, kind after kind: ballc_flag(kind, plane) = 1 << (1 + kind BALLC_MAX_PLANES +
 * plane).  A new kind takes the next BALLC_MAX_PLANES bits. */
typedef long long ballc_flags;
#define BALLC_WITH_OBSERVER ((ballc_flags)1)
enum {
    BALLC_KIND_FRICTION = 0,       /* the friction law (weighted by 1 - mixture) */
    BALLC_KIND_DIGIN,              /* the dig-in law (weighted by the mixture) */
    BALLC_KIND_COMPLIANT,          /* the compliant law (its smooth yield) */
    /* Exact (event-driven) Coulomb friction, with the plane's FRICTION flag: the friction
     * kernel then contributes its normal share only, and the tangential force is
     * SLIP: -mu N e, e the unit slip velocity (oriented along the latched slip direction
     *       d, so that it continues smoothly through u . d = 0, where the driver's
     *       slip-to-stick event sits; e = d at zero slip), N the friction share's
     *       normal force;
     * STICK: the constraint force lambda that holds the slip velocity u constant
     *       (du/dt = 0), from the equations of motion (jointly with every other
     *       sticking plane);
     * SLIP_FIXED: sliding with the force direction held at the latched d (e = d): the
     *       last approach to zero slip and the first departure from it, where u/|u| is
     *       singular (the driver switches to SLIP once |u| is clear of zero). */
    BALLC_KIND_SLIP,
    BALLC_KIND_STICK,
    BALLC_KIND_SLIP_FIXED,
    /* The compliant law's sliding mode (instead of COMPLIANT, which is then its elastic
     * mode): the stored tangential force at the Coulomb cap, -mu F_n s/|s|
     * (codegen/contact.py, compliant_sliding_force). */
    BALLC_KIND_COMPLIANT_SLIDING,
    /* Its elastic mode once the guards are armed: the law without its smooth yield. */
    BALLC_KIND_COMPLIANT_ELASTIC,
    BALLC_N_FLAG_KINDS
};
typedef char ballc_flags_fit[1 + BALLC_N_FLAG_KINDS * BALLC_MAX_PLANES <= 63 ? 1 : -1];

/* The flag of ``kind`` on ``plane`` (0 .. BALLC_MAX_PLANES - 1). */
static inline ballc_flags ballc_flag(int kind, int plane)
{
    return (ballc_flags)1 << (1 + kind * BALLC_MAX_PLANES + plane);
}

/* Every flag of ``plane``: any of them set, the plane is in contact. */
static inline ballc_flags ballc_plane_flags(int plane)
{
    ballc_flags all = 0;
    for (int kind = 0; kind < BALLC_N_FLAG_KINDS; kind++) all |= ballc_flag(kind, plane);
    return all;
}

/* A plane's first state (its deflection_x; deflection_y next). */
static inline int ballc_plane_state(int plane)
{
    return BALLC_STATE_PLANES + BALLC_N_PLANE_STATES * plane;
}

/* The number of planes of a parameter vector (its plane table's count), or -1 when it is
 * not a whole number from 1 to BALLC_MAX_PLANES. */
int ballc_plane_count(const double *params);

/* Sum of the contact forces on the ball, per plane (x y z of each plane in turn:
 * inertial components). */
int ballc_contact_forces(const double *state, const double *params, const double *latch,
                         ballc_flags flags, double *forces);

/* Return codes.  BALLC_BAD_PLANES: the parameters' plane count is not 1 .. MAX_PLANES. */
enum { BALLC_OK = 0, BALLC_NOT_POSITIVE_DEFINITE = 1, BALLC_NOT_FINITE = 2, BALLC_SINGULAR = 3,
       BALLC_BAD_PLANES = 4 };

/* xdot (n_states: BALLC_N_BALL_STATES + BALLC_N_PLANE_STATES per plane of the
 * parameters' plane table) = f(state); latch holds BALLC_N_LATCH_PER_PLANE values per
 * plane.  The auxiliary states (dissipated work, tangential deflections) get the rates
 * of the active contact laws; a plane's deflection is constant while it is not in
 * contact. */
int ballc_rhs(const double *state, const double *params, const double *latch,
              ballc_flags flags, double *xdot);

/* jac (n_states^2, row-major) = d f / d state. */
int ballc_jacobian(const double *state, const double *params, const double *latch,
                   ballc_flags flags, double *jac);

/* A parameter vector, its parameter constants (the parameter-only subexpressions of
 * the kernels, see codegen/emit.py), its sizes and its plane table (each plane's point
 * and frame, from the parameters' point and normal), computed from it by
 * ballc_parameters_init: once per segment by the integrator's adapter, once per call by
 * the entry points that take a plain parameter vector.  The constants and planes are
 * never taken from a caller, so they cannot belong to other parameters. */
typedef struct ballc_parameters {
    const double *values;                               /* n_parameters, borrowed */
    int n_planes;                                       /* 1 .. BALLC_MAX_PLANES */
    int n_states, n_latch, n_parameters;                /* the run's sizes */
    /* rolling resistance (rolling or twisting resistance > 0): the run's rolling block,
     * dissipated_rolling at rolling_state (each plane's rolling spring: its
     * planes[p].rolling); 0 and -1 without (no such states) */
    int rolling, rolling_state;
    double constants[BALLC_N_PARAMETER_CONSTANTS];
    ballc_plane_t planes[BALLC_MAX_PLANES];
    /* each plane's slip map du/dx (2 x n_states, row-major) and the generalized-force
     * map of a unit tangential force along its t1, t2 (6 x 2, inertial): constants */
    double slip_map[BALLC_MAX_PLANES][2 * BALLC_MAX_STATES];
    double slip_force_map[BALLC_MAX_PLANES][12];
    /* each plane's rolling and twisting velocities' map dw/dx (3 x n_states) and the
     * generalized-force map of a unit rolling force along t1, t2 and a unit twisting
     * force (6 x 3, inertial): constants (_rolling.h) */
    double rolling_map[BALLC_MAX_PLANES][3 * BALLC_MAX_STATES];
    double rolling_force_map[BALLC_MAX_PLANES][18];
} ballc_parameters_t;

/* BALLC_OK, or BALLC_BAD_PLANES (the plane count is not 1 .. BALLC_MAX_PLANES: then
 * nothing else is set but n_planes = 0). */
int ballc_parameters_init(ballc_parameters_t *prepared, const double *params);

/* Energies (J): kinetic, potential, then per plane the Hertz spring's, per plane the
 * compliant law's tangential spring's and per plane the rolling part's sds springs' (0
 * without rolling resistance): 2 + 3 n_planes. */
#define BALLC_ENERGY_NOUT(n_planes) (2 + 3 * (n_planes))
#define BALLC_MAX_ENERGY_NOUT BALLC_ENERGY_NOUT(BALLC_MAX_PLANES)
void ballc_energy(const double *state, const ballc_parameters_t *params, double *out);

/* Per plane: rho, rhodot and the contact point's velocity (inertial x, y, z). */
#define BALLC_CONTACT_KINEMATICS_PER_PLANE 5
#define BALLC_MAX_CONTACT_KINEMATICS_NOUT (BALLC_CONTACT_KINEMATICS_PER_PLANE * BALLC_MAX_PLANES)
void ballc_contact_kinematics(const double *state, const ballc_parameters_t *params,
                              double *out);

/* What exact Coulomb friction needs on ``plane``: the slip velocity u (2, along the
 * plane's t1, t2), du/dx (2 x n_states, row-major; u is linear in the state) and the
 * generalized-force map of a unit tangential force along t1, t2 at the contact point
 * (6 x 2, row-major, inertial components): 2 + 2 n_states + 12 numbers. */
#define BALLC_MAX_SLIP_NOUT (2 + 2 * BALLC_MAX_STATES + 12)
void ballc_slip_state(const double *state, const ballc_parameters_t *params, int plane,
                      double *out);

/* The compliant law's mode guards on ``plane``, BALLC_COMPLIANT_MARGINS numbers: out[0]
 * the yield margin 1 - k_t |s| / (mu F_n) (1), out[1] the re-stick margin (m/s, with the
 * exact penetration acceleration of the contact sliding at the cap: one solve of the
 * dynamics, the observer's share included when it has mass; no other plane in contact),
 * out[2] s_cap =
 * mu F_n / k_t (m), out[3] k_t (N/m), out[4] the elastic mode's capacity margin
 * (mu F_n - |F_el|) - |V| (N) and out[5] its negative; see contact.compliant_margins. */
#define BALLC_COMPLIANT_MARGINS 6
int ballc_compliant_margins(const double *state, const double *params, const double *latch,
                            int plane, double *out);
/* The same with the parameters prepared (the integrator's adapter: inputs checked) and
 * the other planes' flags (``flags``: the segment's; the re-stick margin's solve takes
 * the observer's and every other plane's contributions from it, and this plane's sliding
 * mode); with ``row`` >= 0 only out[row] is needed (the re-stick margin's solve is made
 * for row 1 only; the others are then the kernel's values), with -1 all of them. */
int ballc_compliant_margins_prepared(const double *state, const ballc_parameters_t *params,
                                     const double *latch, ballc_flags flags, int plane,
                                     int row, double *out);

/* ballc_rhs and ballc_jacobian for callers that have checked once that params and latch
 * are finite and prepared the parameters (the integrator's adapters, per segment): only
 * the state is checked, per call. */
int ballc_rhs_checked_inputs(const double *state, const ballc_parameters_t *params,
                             const double *latch, ballc_flags flags, double *xdot);
int ballc_jacobian_checked_inputs(const double *state, const ballc_parameters_t *params,
                                  const double *latch, ballc_flags flags, double *jac);

/* ballc_contact_forces for callers that have checked once that params are finite and
 * prepared them (a run's samples, one call): the state and latch are checked per call. */
int ballc_contact_forces_prepared(const double *state, const ballc_parameters_t *params,
                                  const double *latch, ballc_flags flags, double *forces);

/* Stick state of ``plane`` under ``flags`` (which must hold that plane's FRICTION and
 * STICK flags): out = [lambda_x, lambda_y, N, mu N - |lambda|], the constraint force
 * that keeps the slip velocity constant (solved jointly with every other sticking
 * plane's), the friction share's normal force and the margin to the Coulomb cone (the
 * stick-to-slip event); lambda along the plane's tangents t1, t2. */
int ballc_stick_state(const double *state, const double *params, const double *latch,
                      ballc_flags flags, int plane, double *out);
/* The same with the parameters prepared (the segment loop's stick-to-slip guard, at every
 * step: the parameters are not prepared again per call); state and latch are checked. */
int ballc_stick_state_prepared(const double *state, const ballc_parameters_t *params,
                               const double *latch, ballc_flags flags, int plane, double *out);

/* Rolling resistance (_rolling.h) of ``plane`` under ``flags`` and ``latch`` (its modes):
 * out = [lambda (3: the rolling force along t1, t2 and the twisting force that hold its
 * held parts, 0 for the others), F_n, the rolling margin mu_r F_n - |lambda_r|, the
 * twisting margin mu_t F_n - |lambda_w|, the rolling velocity (2), the twisting
 * velocity].  The margins end a holding part (its release event). */
#define BALLC_ROLLING_STATE_NOUT 9
int ballc_rolling_state(const double *state, const ballc_parameters_t *params,
                        const double *latch, ballc_flags flags, int plane, double *out);

/* The sds model's mode guards of ``plane``'s rolling and twisting parts (_rolling.h,
 * codegen contact.sds_margins), 3 per part: the yield margin 1 - k |xi| / (mu F_n), the
 * re-stick margin (m/s, with the exact penetration acceleration of the dynamics under
 * ``flags`` and ``latch``: one solve) and the deflection at the cap mu F_n / k (m). */
#define BALLC_SDS_MARGINS 6
int ballc_rolling_margins(const double *state, const ballc_parameters_t *params,
                          const double *latch, ballc_flags flags, int plane, double *out);

/* state_out = state with the velocities of ``plane`` in ``mask`` (_rolling.h
 * BALLC_HOLD_*: its slip, rolling and twisting velocities) set to zero by one impulse
 * of the constraint forces that hold them (P = -W^-1 v, W their Delassus matrix); used
 * where a velocity starts being held and what is left of it is at rounding level. */
int ballc_remove_velocities(const double *state, const ballc_parameters_t *params,
                            const double *latch, ballc_flags flags, int plane, int mask,
                            double *state_out);

/* state_out = state with the slip velocity of ``plane`` set to zero by a tangential
 * impulse at the contact point (the impulse P = -W^-1 u, W the 2x2 Delassus matrix);
 * used at slip-to-stick transitions, where |u| is at rounding level.  Every other plane
 * sticking under ``flags`` keeps its slip velocity: their impulses are solved jointly
 * (W of all of them, the others' velocity changes 0). */
int ballc_remove_slip(const double *state, const double *params, ballc_flags flags, int plane,
                      double *state_out);

#endif
