/* See _system.h.  Hand-written glue: calls generated kernels, solves M udot = F. */
#include <math.h>
#include <string.h>

#include "_system.h"

#define NS BALLC_N_STATES
#define NQ 7  /* coordinates: quaternion (4) and centre (3) */
#define NU 6  /* speeds: angular velocity (3) and centre velocity (3) */

typedef void (*kernel_fn)(const double *restrict, const double *restrict,
                          const double *restrict, double *restrict);

/* Contact laws: which flag switches them on, their kernels, their plane. */
static const struct { int flag; kernel_fn value, jac; int plane; } CONTACT_LAWS[] = {
    {BALLC_FLOOR_FRICTION, ballc_floor_friction, ballc_floor_friction_jac, 0},
    {BALLC_FLOOR_DIGIN, ballc_floor_digin, ballc_floor_digin_jac, 0},
    {BALLC_FLOOR_COMPLIANT, ballc_floor_compliant, ballc_floor_compliant_jac, 0},
    {BALLC_CEILING_FRICTION, ballc_ceiling_friction, ballc_ceiling_friction_jac, 1},
    {BALLC_CEILING_DIGIN, ballc_ceiling_digin, ballc_ceiling_digin_jac, 1},
    {BALLC_CEILING_COMPLIANT, ballc_ceiling_compliant, ballc_ceiling_compliant_jac, 1},
};
#define N_CONTACT_LAWS (sizeof CONTACT_LAWS / sizeof CONTACT_LAWS[0])
#define LAW_NOUT BALLC_CONTACT_LAW_NOUT

/* Where a law's auxiliary outputs (dissipation normal, tangential, deflection rate x, y)
 * go in the state derivative. */
static void auxiliary_targets(int plane, int target[4])
{
    target[0] = BALLC_STATE_DISSIPATED_NORMAL;
    target[1] = BALLC_STATE_DISSIPATED_TANGENTIAL;
    target[2] = plane == 0 ? BALLC_STATE_FLOOR_DEFLECTION_X : BALLC_STATE_CEILING_DEFLECTION_X;
    target[3] = target[2] + 1;
}

static const double *law_latch(const double *latch, int plane)
{
    return latch + plane * BALLC_N_LATCH_PER_PLANE;
}

typedef struct {
    double L[6];   /* Cholesky factor of S, packed lower: L00 L10 L11 L20 L21 L22 */
    double B[9];
    double D;
} schur_t;

static int all_finite(const double *v, int n)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(v[i])) return 0;
    return 1;
}

/* Every input the equations may read must be finite: a NaN would otherwise slip
 * through branch-free code (e.g. a NaN height reads as "no contact"). */
static int inputs_finite(const double *state, const double *params, const double *latch)
{
    return all_finite(state, NS) && all_finite(params, BALLC_N_PARAMETERS)
        && all_finite(latch, BALLC_N_LATCH);
}

/* Mass blocks (16) and forcing (6) of everything that acts under ``flags``; the rates
 * of the auxiliary states go to ``auxiliary`` (indexed by state, may be NULL). */
static void assemble(const double *state, const double *params, const double *latch,
                     int flags, double *mass, double *force, double *xdot)
{
    double buf[BALLC_BALL_NOUT];
    double out[LAW_NOUT];
    ballc_ball(state, params, NULL, buf);
    memcpy(mass, buf, BALLC_MASS_SIZE * sizeof(double));
    memcpy(force, buf + BALLC_MASS_SIZE, NU * sizeof(double));
    if (flags & BALLC_WITH_OBSERVER) {
        ballc_observer(state, params, NULL, buf);
        for (int i = 0; i < BALLC_MASS_SIZE; i++) mass[i] += buf[i];
        for (int i = 0; i < NU; i++) force[i] += buf[BALLC_MASS_SIZE + i];
    }
    if (xdot)
        for (int i = BALLC_N_MECHANICAL_STATES; i < NS; i++) xdot[i] = 0.0;
    for (size_t k = 0; k < N_CONTACT_LAWS; k++) {
        if (!(flags & CONTACT_LAWS[k].flag)) continue;
        int plane = CONTACT_LAWS[k].plane, target[4];
        CONTACT_LAWS[k].value(state, params, law_latch(latch, plane), out);
        for (int i = 0; i < NU; i++) force[i] += out[i];
        if (!xdot) continue;
        auxiliary_targets(plane, target);
        for (int i = 0; i < 4; i++) xdot[target[i]] += out[BALLC_LAW_DISSIPATION + i];
    }
}

int ballc_contact_forces(const double *state, const double *params, const double *latch,
                         int flags, double *forces)
{
    double out[LAW_NOUT];
    for (int i = 0; i < 3 * BALLC_N_PLANES; i++) forces[i] = 0.0;
    if (!inputs_finite(state, params, latch)) return BALLC_NOT_FINITE;
    for (size_t k = 0; k < N_CONTACT_LAWS; k++) {
        if (!(flags & CONTACT_LAWS[k].flag)) continue;
        int plane = CONTACT_LAWS[k].plane;
        CONTACT_LAWS[k].value(state, params, law_latch(latch, plane), out);
        for (int i = 0; i < 3; i++) forces[3 * plane + i] += out[BALLC_LAW_FORCE + i];
    }
    return all_finite(forces, 3 * BALLC_N_PLANES) ? BALLC_OK : BALLC_NOT_FINITE;
}

/* Factor S = J - B B^T / D. */
static int schur_factor(const double *mass, schur_t *f)
{
    const double *J = mass;          /* J00 J01 J02 J11 J12 J22 */
    memcpy(f->B, mass + 6, 9 * sizeof(double));
    f->D = mass[15];
    if (!(f->D > 0)) return BALLC_NOT_POSITIVE_DEFINITE;
    const double *B = f->B;
    double S[3][3];
    const int jrow[3][3] = {{0, 1, 2}, {1, 3, 4}, {2, 4, 5}};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            S[i][j] = J[jrow[i][j]] - (B[3*i]*B[3*j] + B[3*i+1]*B[3*j+1]
                                       + B[3*i+2]*B[3*j+2]) / f->D;
    double l00 = S[0][0];
    if (!(l00 > 0)) return BALLC_NOT_POSITIVE_DEFINITE;
    l00 = sqrt(l00);
    double l10 = S[1][0] / l00, l20 = S[2][0] / l00;
    double l11 = S[1][1] - l10*l10;
    if (!(l11 > 0)) return BALLC_NOT_POSITIVE_DEFINITE;
    l11 = sqrt(l11);
    double l21 = (S[2][1] - l20*l10) / l11;
    double l22 = S[2][2] - l20*l20 - l21*l21;
    if (!(l22 > 0)) return BALLC_NOT_POSITIVE_DEFINITE;
    l22 = sqrt(l22);
    f->L[0] = l00; f->L[1] = l10; f->L[2] = l11;
    f->L[3] = l20; f->L[4] = l21; f->L[5] = l22;
    return BALLC_OK;
}

/* Solve M z = b in place (b: 6 = [b_omega; b_v]). */
static void schur_solve(const schur_t *f, double *b)
{
    const double *B = f->B, *L = f->L;
    double *bw = b, *bv = b + 3;
    double r[3];
    for (int i = 0; i < 3; i++)
        r[i] = bw[i] - (B[3*i]*bv[0] + B[3*i+1]*bv[1] + B[3*i+2]*bv[2]) / f->D;
    /* forward: L y = r */
    double y0 = r[0] / L[0];
    double y1 = (r[1] - L[1]*y0) / L[2];
    double y2 = (r[2] - L[3]*y0 - L[4]*y1) / L[5];
    /* backward: L^T w = y */
    double w2 = y2 / L[5];
    double w1 = (y1 - L[4]*w2) / L[2];
    double w0 = (y0 - L[1]*w1 - L[3]*w2) / L[0];
    bw[0] = w0; bw[1] = w1; bw[2] = w2;
    for (int j = 0; j < 3; j++)
        bv[j] = (bv[j] - (B[j]*w0 + B[3+j]*w1 + B[6+j]*w2)) / f->D;
}

static int accelerations(const double *state, const double *params, const double *latch,
                         int flags, schur_t *factor, double *udot, double *xdot)
{
    double mass[BALLC_MASS_SIZE];
    assemble(state, params, latch, flags, mass, udot, xdot);
    int status = schur_factor(mass, factor);
    if (status != BALLC_OK) return status;
    schur_solve(factor, udot);
    return all_finite(udot, NU) ? BALLC_OK : BALLC_NOT_FINITE;
}

int ballc_rhs(const double *state, const double *params, const double *latch,
              int flags, double *xdot)
{
    schur_t factor;
    if (!inputs_finite(state, params, latch)) {
        for (int i = 0; i < NS; i++) xdot[i] = NAN;
        return BALLC_NOT_FINITE;
    }
    ballc_kinematics(state, params, NULL, xdot);
    int status = accelerations(state, params, latch, flags, &factor, xdot + NQ, xdot);
    if (status == BALLC_OK && !all_finite(xdot, NS)) status = BALLC_NOT_FINITE;
    return status;
}

/* Add dF/dx (6 x 13) and d(M a)/dq (6 x 4) of one dynamics kernel family. */
static void add_dynamics_jac(kernel_fn kernel, const double *state, const double *params, const double *udot,
                             double *dF, double *dMa)
{
    double buf[BALLC_BALL_JAC_NOUT];   /* ball and observer kernels have equal sizes */
    kernel(state, params, udot, buf);
    for (int i = 0; i < NU * NS; i++) dF[i] += buf[i];
    for (int i = 0; i < NU * 4; i++) dMa[i] += buf[NU * NS + i];
}

int ballc_jacobian(const double *state, const double *params, const double *latch,
                   int flags, double *jac)
{
    schur_t factor;
    double udot[NU];
    if (!inputs_finite(state, params, latch)) return BALLC_NOT_FINITE;
    int status = accelerations(state, params, latch, flags, &factor, udot, NULL);
    if (status != BALLC_OK) return status;

    for (int i = 0; i < NS * NS; i++) jac[i] = 0.0;
    ballc_kinematics_jac(state, params, NULL, jac);   /* rows 0..6 */

    double dF[NU * NS] = {0}, dMa[NU * 4] = {0}, buf[LAW_NOUT * NS];
    add_dynamics_jac(ballc_ball_jac, state, params, udot, dF, dMa);
    if (flags & BALLC_WITH_OBSERVER)
        add_dynamics_jac(ballc_observer_jac, state, params, udot, dF, dMa);
    for (size_t k = 0; k < N_CONTACT_LAWS; k++) {
        if (!(flags & CONTACT_LAWS[k].flag)) continue;
        int plane = CONTACT_LAWS[k].plane, target[4];
        CONTACT_LAWS[k].jac(state, params, law_latch(latch, plane), buf);
        for (int i = 0; i < NU * NS; i++) dF[i] += buf[i];
        auxiliary_targets(plane, target);
        for (int i = 0; i < 4; i++)
            for (int j = 0; j < NS; j++)
                jac[target[i] * NS + j] += buf[(BALLC_LAW_DISSIPATION + i) * NS + j];
    }
    /* d udot / dx_j = M^-1 (dF/dx_j - d(M udot)/dx_j); M depends on q only. */
    for (int j = 0; j < NS; j++) {
        double col[NU];
        for (int i = 0; i < NU; i++)
            col[i] = dF[i * NS + j] - (j < 4 ? dMa[i * 4 + j] : 0.0);
        schur_solve(&factor, col);
        for (int i = 0; i < NU; i++) jac[(NQ + i) * NS + j] = col[i];
    }
    return all_finite(jac, NS * NS) ? BALLC_OK : BALLC_NOT_FINITE;
}
