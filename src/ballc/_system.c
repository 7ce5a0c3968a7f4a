/* See _system.h.  Hand-written glue: calls generated kernels (the contact laws in each
 * plane's frame, _plane.h), solves M udot = F. */
#include <float.h>
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "_system.h"
#include "_rolling.h"

#define MAXS BALLC_MAX_STATES
#define NB BALLC_N_BALL_STATES   /* the ball's states: the generated dynamics' columns */
#define NQ 7  /* coordinates: quaternion (4) and centre (3) */
#define NU 6  /* speeds: angular velocity (3) and centre velocity (3) */
#define NC BALLC_N_CONTACT_STATES
#define MAXP BALLC_MAX_PLANES

#if defined(__GNUC__)
#define BALLC_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define BALLC_ALWAYS_INLINE inline
#endif

typedef void (*kernel_fn)(const double *restrict, const double *restrict,
                          const double *restrict, const double *restrict, double *restrict);

/* A kernel's parameter arguments: the parameters and their constants. */
#define PARAMS(p) (p)->values, (p)->constants

int ballc_plane_count(const double *params)
{
    double count = params[BALLC_PARAMETER_PLANE_COUNT];
    if (!(count >= 1 && count <= MAXP) || count != (double)(int)count) return -1;
    return (int)count;
}

int ballc_parameters_init(ballc_parameters_t *prepared, const double *params)
{
    prepared->values = params;
    int n = ballc_plane_count(params);
    if (n < 0) {
        prepared->n_planes = 0;
        return BALLC_BAD_PLANES;
    }
    prepared->n_planes = n;
    /* rolling resistance: its states, after every plane's (none without it) */
    prepared->rolling = params[BALLC_PARAMETER_ROLLING_RESISTANCE] != 0
                        || params[BALLC_PARAMETER_TWISTING_RESISTANCE] != 0;
    prepared->rolling_state = prepared->rolling ? NB + BALLC_N_PLANE_STATES * n : -1;
    prepared->n_states = NB + BALLC_N_PLANE_STATES * n
                         + (prepared->rolling ? BALLC_N_ROLLING_BALL_STATES
                                                + BALLC_N_ROLLING_PLANE_STATES * n : 0);
    prepared->n_latch = BALLC_N_LATCH_PER_PLANE * n;
    prepared->n_parameters = BALLC_PARAMETER_PLANES + BALLC_N_PLANE_FIELDS * n;
    ballc_parameter_constants(params, prepared->constants);
    const double anywhere[NC] = {0};   /* the slip maps are constants (codegen checks) */
    double maps[BALLC_PLANE_SLIP_MAP_NOUT];
    ballc_plane_slip_map(anywhere, PARAMS(prepared), NULL, maps);
    for (int p = 0; p < n; p++) {
        const double *entry = params + BALLC_PARAMETER_PLANES + p * BALLC_N_PLANE_FIELDS;
        ballc_plane_t *pl = &prepared->planes[p];
        int rolling = prepared->rolling ? prepared->rolling_state + BALLC_N_ROLLING_BALL_STATES
                                          + BALLC_N_ROLLING_PLANE_STATES * p : -1;
        ballc_plane_init(pl, entry + BALLC_PLANE_POINT_X, entry + BALLC_PLANE_NORMAL_X,
                         params + BALLC_PARAMETER_GRAVITY_X, ballc_plane_state(p), rolling);
        /* the plane's slip map by the ball's state, its force map in inertial components */
        ballc_plane_state_columns(pl, maps, 2, prepared->n_states, prepared->slip_map[p]);
        memcpy(prepared->slip_force_map[p], maps + 2 * NC, sizeof prepared->slip_force_map[p]);
        ballc_plane_rows_to_inertial(pl, prepared->slip_force_map[p], 2, 0, 2);
        if (!prepared->rolling) continue;
        /* the same for its rolling and twisting velocities (_rolling.h) */
        double roll[BALLC_PLANE_ROLLING_MAP_NOUT];
        ballc_plane_rolling_map(anywhere, PARAMS(prepared), NULL, roll);
        ballc_plane_state_columns(pl, roll, 3, prepared->n_states, prepared->rolling_map[p]);
        memcpy(prepared->rolling_force_map[p], roll + 3 * NC,
               sizeof prepared->rolling_force_map[p]);
        ballc_plane_rows_to_inertial(pl, prepared->rolling_force_map[p], 3, 0, 2);
    }
    return BALLC_OK;
}

/* Contact laws: which flag switches them on, per plane, their kernels (in a plane's own
 * frame), (friction only) the kernels of the law's normal share (mu = 0), used under
 * exact Coulomb friction, and (the compliant sliding mode only) the kernel of its rates'
 * coefficients of the exact penetration acceleration rho'' (codegen:
 * contact.ACCELERATION_LAWS). */
static const struct {
    int kind; kernel_fn value, jac, normal, normal_jac, acceleration;
} CONTACT_LAWS[] = {
    {BALLC_KIND_FRICTION, ballc_plane_friction, ballc_plane_friction_jac,
     ballc_plane_friction_normal, ballc_plane_friction_normal_jac, NULL},
    {BALLC_KIND_DIGIN, ballc_plane_digin, ballc_plane_digin_jac, NULL, NULL, NULL},
    {BALLC_KIND_COMPLIANT, ballc_plane_compliant, ballc_plane_compliant_jac, NULL, NULL, NULL},
    {BALLC_KIND_COMPLIANT_SLIDING, ballc_plane_compliant_sliding,
     ballc_plane_compliant_sliding_jac, NULL, NULL, ballc_plane_compliant_sliding_acceleration},
    {BALLC_KIND_COMPLIANT_ELASTIC, ballc_plane_compliant_elastic,
     ballc_plane_compliant_elastic_jac, NULL, NULL, NULL},
};
#define N_CONTACT_LAWS (sizeof CONTACT_LAWS / sizeof CONTACT_LAWS[0])
#define LAW_NOUT BALLC_CONTACT_LAW_NOUT

/* Whether law k acts on ``plane`` under ``flags``. */
static int law_acts(ballc_flags flags, size_t k, int plane)
{
    return (flags & ballc_flag(CONTACT_LAWS[k].kind, plane)) != 0;
}

/* Whether any law of ``plane`` acts under ``flags``: the plane is in contact. */
static int in_contact(ballc_flags flags, int plane)
{
    ballc_flags any = 0;
    for (size_t k = 0; k < N_CONTACT_LAWS; k++) any |= ballc_flag(CONTACT_LAWS[k].kind, plane);
    return (flags & any) != 0;
}

/* Where a law's auxiliary outputs (dissipation normal, tangential, deflection rate x, y)
 * go in the state derivative. */
static void auxiliary_targets(const ballc_plane_t *plane, int target[4])
{
    target[0] = BALLC_STATE_DISSIPATED_NORMAL;
    target[1] = BALLC_STATE_DISSIPATED_TANGENTIAL;
    target[2] = plane->deflection;
    target[3] = target[2] + 1;
}

/* A plane's contact state and kernel inputs (its frame), for its law kernels. */
typedef struct {
    double state[NC];
    double inputs[BALLC_N_PLANE_INPUTS];
} plane_contact_t;

static void plane_contact(const ballc_parameters_t *params, int plane, const double *state,
                          const double *latch, plane_contact_t *contact)
{
    const ballc_plane_t *pl = &params->planes[plane];
    ballc_plane_contact_state(pl, state, contact->state);
    ballc_plane_inputs(pl, latch + plane * BALLC_N_LATCH_PER_PLANE, contact->inputs);
}

static const double *law_latch(const double *latch, int plane)
{
    return latch + plane * BALLC_N_LATCH_PER_PLANE;
}

typedef struct {
    double L[6];   /* Cholesky factor of S, packed lower: L00 L10 L11 L20 L21 L22, */
    double Linv[3];   /* and the reciprocals of its diagonal (the solves multiply) */
    double B[9];
    double D, inverse_D;
} schur_t;

/* Branch-free: x - x is 0 for a finite x and NaN for an infinite or NaN one.  Two
 * pairs of sums (one chain of additions would wait on each; this runs twice per
 * right-hand side and on every Jacobian), with a pointer-sized index: under Python's
 * -fwrapv an int index keeps the compiler from pairing them into vector adds. */
static int all_finite(const double *v, int n)
{
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
    ptrdiff_t i = 0;
    for (; i + 4 <= n; i += 4) {
        s0 += v[i] - v[i];
        s1 += v[i + 1] - v[i + 1];
        s2 += v[i + 2] - v[i + 2];
        s3 += v[i + 3] - v[i + 3];
    }
    for (; i < n; i++) s0 += v[i] - v[i];
    return (s0 + s1) + (s2 + s3) == 0.0;
}

/* The number of parameters of ``params`` (its plane table's count), or -1. */
static int parameter_count(const double *params)
{
    int n = ballc_plane_count(params);
    return n < 0 ? -1 : BALLC_PARAMETER_PLANES + BALLC_N_PLANE_FIELDS * n;
}

/* Exact Coulomb mode of ``plane`` under ``flags``. */
enum { MODE_NONE = 0, MODE_SLIP = 1, MODE_SLIP_FIXED = 2, MODE_STICK = 3 };
static int exact_mode(ballc_flags flags, int plane)
{
    if (!(flags & ballc_flag(BALLC_KIND_FRICTION, plane))) return MODE_NONE;
    if (flags & ballc_flag(BALLC_KIND_STICK, plane)) return MODE_STICK;
    if (flags & ballc_flag(BALLC_KIND_SLIP_FIXED, plane)) return MODE_SLIP_FIXED;
    if (flags & ballc_flag(BALLC_KIND_SLIP, plane)) return MODE_SLIP;
    return MODE_NONE;
}

static int is_sliding(int mode)
{
    return mode == MODE_SLIP || mode == MODE_SLIP_FIXED;
}

/* A plane's slip: the velocity u (along t1, t2), its map du/dx (2 x n_states, row-major) and the
 * generalized-force map G_t (6 x 2) of a unit tangential force along t1, t2. */
typedef struct {
    double u[2];
    const double *du, *G;
} slip_t;

/* The slip of ``plane`` at the contact state ``local`` (its frame). */
static void slip_of(const ballc_parameters_t *params, int plane, const double *local,
                    slip_t *slip)
{
    ballc_plane_slip(local, PARAMS(params), NULL, slip->u);
    slip->du = params->slip_map[plane];
    slip->G = params->slip_force_map[plane];
}

void ballc_slip_state(const double *state, const ballc_parameters_t *params, int plane,
                      double *out)
{
    double local[NC];
    slip_t slip;
    ballc_plane_contact_state(&params->planes[plane], state, local);
    slip_of(params, plane, local, &slip);
    int ns = params->n_states;
    out[0] = slip.u[0];
    out[1] = slip.u[1];
    memcpy(out + 2, slip.du, 2 * ns * sizeof(double));
    memcpy(out + 2 + 2 * ns, slip.G, 12 * sizeof(double));
}

/* What one evaluation of the equations yields besides the state derivative. */
typedef struct {
    double mass[BALLC_MASS_SIZE];
    double contact_force[3 * MAXP];   /* on the ball, per plane: its frame */
    int mode[MAXP];                   /* exact Coulomb mode per plane */
    double load[MAXP];                /* N: the friction share's normal force */
    slip_t slip[MAXP];
    double e[MAXP][2];                /* sliding: the force direction is -e */
    double lambda[MAXP][2];           /* sticking: the constraint force */
    /* the coefficients of rho'' in the auxiliary rates, per plane (0 without) */
    double acceleration[MAXP][4];
    ballc_rolling_eval rolling[MAXP];   /* rolling resistance (_rolling.h) */
} evaluation_t;

/* The exact penetration acceleration rho'' of ``plane`` from the solved udot: rho = r -
 * n . (c - p), so rho'' = -n . a. */
static double penetration_acceleration(const ballc_parameters_t *params, int plane,
                                       const double *udot)
{
    const double *n = params->planes[plane].frame[2], *a = udot + (BALLC_STATE_VX - NQ);
    return -(n[0] * a[0] + n[1] * a[1] + n[2] * a[2]);
}

/* Mass blocks and forcing of everything that acts under ``flags``; the rates of the
 * auxiliary states go to ``xdot`` (indexed by state, may be NULL).  A plane in exact
 * Coulomb mode gets its friction law's normal share (the mu = 0 kernel) and, when sliding,
 * the Coulomb force -mu N e; a sticking plane's constraint force is added later
 * (it needs M). */
static void assemble(const double *state, const ballc_parameters_t *params, const double *latch,
                     ballc_flags flags, evaluation_t *ev, double *force, double *xdot)
{
    double buf[BALLC_BALL_NOUT];
    double out[LAW_NOUT];
    const int np = params->n_planes;
    ballc_ball(state, PARAMS(params), NULL, buf);
    memcpy(ev->mass, buf, BALLC_MASS_SIZE * sizeof(double));
    memcpy(force, buf + BALLC_MASS_SIZE, NU * sizeof(double));
    if (flags & BALLC_WITH_OBSERVER) {
        ballc_observer(state, PARAMS(params), NULL, buf);
        for (int i = 0; i < BALLC_MASS_SIZE; i++) ev->mass[i] += buf[i];
        for (int i = 0; i < NU; i++) force[i] += buf[BALLC_MASS_SIZE + i];
    }
    if (xdot)
        for (int i = BALLC_N_MECHANICAL_STATES; i < params->n_states; i++) xdot[i] = 0.0;
    for (int i = 0; i < 3 * np; i++) ev->contact_force[i] = 0.0;
    for (int plane = 0; plane < np; plane++) {
        ev->mode[plane] = exact_mode(flags, plane);
        ev->load[plane] = 0.0;
        for (int i = 0; i < 4; i++) ev->acceleration[plane][i] = 0.0;
        ev->rolling[plane].mode[0] = ev->rolling[plane].mode[1] = BALLC_ROLLING_MODE_NONE;
        for (int i = 0; i < 4; i++) ev->rolling[plane].acceleration[i] = 0.0;
    }
    const double mu = params->values[BALLC_PARAMETER_FRICTION_COEFFICIENT];
    for (int plane = 0; plane < np; plane++) {
        if (!in_contact(flags, plane)) continue;   /* a plane far away costs nothing */
        const ballc_plane_t *pl = &params->planes[plane];
        plane_contact_t contact;
        double sum[LAW_NOUT] = {0};
        plane_contact(params, plane, state, latch, &contact);
        for (size_t k = 0; k < N_CONTACT_LAWS; k++) {
            if (!law_acts(flags, k, plane)) continue;
            int exact = ev->mode[plane] != MODE_NONE && CONTACT_LAWS[k].normal;
            (exact ? CONTACT_LAWS[k].normal : CONTACT_LAWS[k].value)(
                contact.state, PARAMS(params), contact.inputs, out);
            for (int i = 0; i < LAW_NOUT; i++) sum[i] += out[i];
            if (exact) ev->load[plane] = out[BALLC_LAW_FORCE + 2];   /* along n */
            if (xdot && CONTACT_LAWS[k].acceleration) {
                /* its rho'' share is added after the solve */
                double coefficients[4];
                CONTACT_LAWS[k].acceleration(contact.state, PARAMS(params), contact.inputs,
                                             coefficients);
                for (int i = 0; i < 4; i++) ev->acceleration[plane][i] += coefficients[i];
            }
        }
        /* the laws' torque and force, turned back from the plane's frame */
        ballc_plane_to_inertial(pl, sum + BALLC_LAW_GENERALIZED_FORCE, 2);
        for (int i = 0; i < NU; i++) force[i] += sum[BALLC_LAW_GENERALIZED_FORCE + i];
        double *contact_force = ev->contact_force + 3 * plane;
        for (int i = 0; i < 3; i++) contact_force[i] = sum[BALLC_LAW_FORCE + i];
        if (xdot) {
            int target[4];
            auxiliary_targets(pl, target);
            for (int i = 0; i < 4; i++) xdot[target[i]] += sum[BALLC_LAW_DISSIPATION + i];
        }
        if (params->rolling && ballc_rolling_on(law_latch(latch, plane)))   /* the 4th part */
            ballc_rolling_assemble(params, plane, contact.state, contact.inputs,
                                   law_latch(latch, plane), &ev->rolling[plane], force, xdot);
        if (ev->mode[plane] == MODE_NONE) continue;
        slip_t *slip = &ev->slip[plane];
        slip_of(params, plane, contact.state, slip);
        if (!is_sliding(ev->mode[plane])) continue;
        const double *d = law_latch(latch, plane) + BALLC_LATCH_SLIP_DIRECTION_X;
        double ux = slip->u[0], uy = slip->u[1], speed = sqrt(ux * ux + uy * uy);
        double *e = ev->e[plane];
        if (speed > 0 && ev->mode[plane] == MODE_SLIP) {
            double sign = ux * d[0] + uy * d[1] < 0 ? -1.0 : 1.0;
            e[0] = sign * ux / speed;
            e[1] = sign * uy / speed;
        } else {
            e[0] = d[0];
            e[1] = d[1];
        }
        double f[2] = {-mu * ev->load[plane] * e[0], -mu * ev->load[plane] * e[1]};
        const double *G = slip->G;
        for (int i = 0; i < NU; i++) force[i] += G[2 * i] * f[0] + G[2 * i + 1] * f[1];
        contact_force[0] += f[0];
        contact_force[1] += f[1];
        if (xdot) xdot[BALLC_STATE_DISSIPATED_TANGENTIAL] -= f[0] * ux + f[1] * uy;
    }
}

/* Factor S = J - B B^T / D. */
static int schur_factor(const double *mass, schur_t *f)
{
    const double *J = mass;          /* J00 J01 J02 J11 J12 J22 */
    memcpy(f->B, mass + 6, 9 * sizeof(double));
    f->D = mass[15];
    if (!(f->D > 0)) return BALLC_NOT_POSITIVE_DEFINITE;
    f->inverse_D = 1.0 / f->D;
    const double *B = f->B;
    double S[3][3];
    const int jrow[3][3] = {{0, 1, 2}, {1, 3, 4}, {2, 4, 5}};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            S[i][j] = J[jrow[i][j]] - (B[3*i]*B[3*j] + B[3*i+1]*B[3*j+1]
                                       + B[3*i+2]*B[3*j+2]) * f->inverse_D;
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
    f->Linv[0] = 1.0 / l00; f->Linv[1] = 1.0 / l11; f->Linv[2] = 1.0 / l22;
    return BALLC_OK;
}

/* Solve M z = b in place (b: 6 = [b_omega; b_v]).  Inlined where its columns come in a
 * batch (hold_solve): the columns' operations interleave. */
static BALLC_ALWAYS_INLINE void schur_solve_inline(const schur_t *f, double *b)
{
    const double *B = f->B, *L = f->L, *Li = f->Linv;
    double *bw = b, *bv = b + 3;
    double r[3];
    for (int i = 0; i < 3; i++)
        r[i] = bw[i] - (B[3*i]*bv[0] + B[3*i+1]*bv[1] + B[3*i+2]*bv[2]) * f->inverse_D;
    /* forward: L y = r */
    double y0 = r[0] * Li[0];
    double y1 = (r[1] - L[1]*y0) * Li[1];
    double y2 = (r[2] - L[3]*y0 - L[4]*y1) * Li[2];
    /* backward: L^T w = y */
    double w2 = y2 * Li[2];
    double w1 = (y1 - L[4]*w2) * Li[1];
    double w0 = (y0 - L[1]*w1 - L[3]*w2) * Li[0];
    bw[0] = w0; bw[1] = w1; bw[2] = w2;
    for (int j = 0; j < 3; j++)
        bv[j] = (bv[j] - (B[j]*w0 + B[3+j]*w1 + B[6+j]*w2)) * f->inverse_D;
}

static void schur_solve(const schur_t *f, double *b)
{
    schur_solve_inline(f, b);
}

/* Responses of a sticking plane: z_k = M^-1 G_t e_k (6 x 2, column k at z[k]) and the
 * Delassus block W = (du/d speeds) z (2 x 2) of the plane itself, inverted into Winv
 * (Winv may be NULL: then W is not inverted).  Returns BALLC_SINGULAR when W is not
 * invertible. */
static int stick_response(const schur_t *factor, const slip_t *slip, int ns,
                          double z[2][NU], double Winv[2][2])
{
    const double *G = slip->G, *du = slip->du;
    double W[2][2];
    for (int k = 0; k < 2; k++) {
        for (int i = 0; i < NU; i++) z[k][i] = G[2 * i + k];
        schur_solve(factor, z[k]);
        for (int r = 0; r < 2; r++) {
            double s = 0;
            for (int i = 0; i < NU; i++) s += du[r * ns + NQ + i] * z[k][i];
            W[r][k] = s;
        }
    }
    if (!Winv) return BALLC_OK;
    double det = W[0][0] * W[1][1] - W[0][1] * W[1][0];
    if (!(fabs(det) > 0) || !isfinite(det)) return BALLC_SINGULAR;
    Winv[0][0] = W[1][1] / det; Winv[0][1] = -W[0][1] / det;
    Winv[1][0] = -W[1][0] / det; Winv[1][1] = W[0][0] / det;
    return BALLC_OK;
}

/* The two eliminations below (dense_solve, held_dense_solve) differ in their pivoting;
 * these are their common steps.  Swap rows c and p of A (m x m, row-major) and of b. */
static inline void swap_rows(int m, double *A, double *b, int c, int p)
{
    for (int j = 0; j < m; j++) {
        double t = A[c * m + j]; A[c * m + j] = A[p * m + j]; A[p * m + j] = t;
    }
    double t = b[c]; b[c] = b[p]; b[p] = t;
}

/* Eliminate column c below the pivot A(c, c): rows c + 1 .. m - 1 of A and b. */
static inline void eliminate_below(int m, double *A, double *b, int c)
{
    for (int r = c + 1; r < m; r++) {
        double f = A[r * m + c] / A[c * m + c];
        for (int j = c; j < m; j++) A[r * m + j] -= f * A[c * m + j];
        b[r] -= f * b[c];
    }
}

/* Solve the dense m x m system A x = b (A row-major, m <= MAX_HELD) in place by Gaussian
 * elimination with partial pivoting: b becomes x.  BALLC_SINGULAR when a pivot is 0. */
static int dense_solve(int m, double *A, double *b)
{
    for (int c = 0; c < m; c++) {
        int pivot = c;
        for (int r = c + 1; r < m; r++)
            if (fabs(A[r * m + c]) > fabs(A[pivot * m + c])) pivot = r;
        if (!(fabs(A[pivot * m + c]) > 0) || !isfinite(A[pivot * m + c])) return BALLC_SINGULAR;
        if (pivot != c) swap_rows(m, A, b, c, pivot);
        eliminate_below(m, A, b, c);
    }
    for (int c = m - 1; c >= 0; c--) {
        double s = b[c];
        for (int j = c + 1; j < m; j++) s -= A[c * m + j] * b[j];
        b[c] = s / A[c * m + c];
    }
    return BALLC_OK;
}

/* The impulses (or forces) of several planes' tangential constraints at once: the planes
 * ``which`` (k of them), their slips, and the right-hand side ``target`` (2 k: the change
 * of each plane's slip velocity wanted, along its t1, t2) give lambda (2 k) with
 * sum_b W_ab lambda_b = target_a, W_ab = (du_a/d speeds) M^-1 G_b, and the change of the
 * speeds M^-1 sum_b G_b lambda_b added to ``speeds`` (6). */
static int joint_constraint(const schur_t *factor, const slip_t *const *slips, int k, int ns,
                            const double *target, double *lambda, double *speeds)
{
    double z[2 * MAXP][NU], W[4 * MAXP * MAXP];
    int m = 2 * k;
    for (int b = 0; b < k; b++) stick_response(factor, slips[b], ns, &z[2 * b], NULL);
    for (int a = 0; a < k; a++)
        for (int r = 0; r < 2; r++)
            for (int c = 0; c < m; c++) {
                double s = 0;
                for (int i = 0; i < NU; i++) s += slips[a]->du[r * ns + NQ + i] * z[c][i];
                W[(2 * a + r) * m + c] = s;
            }
    for (int c = 0; c < m; c++) lambda[c] = target[c];
    int status = dense_solve(m, W, lambda);
    if (status != BALLC_OK) return status;
    for (int c = 0; c < m; c++)
        for (int i = 0; i < NU; i++) speeds[i] += z[c][i] * lambda[c];
    return BALLC_OK;
}

/* The velocities held by constraint forces, of every plane at once (_rolling.h): a
 * sticking plane's slip (2), a holding rolling part's (2) and twisting part's (1).  Each
 * row: its map (a row of n_states, dv/dx: the speeds' columns are used), the generalized
 * force of its unit constraint force (6, inertial), the velocity now and where its
 * multiplier goes. */
#define MAX_HELD (5 * MAXP)
typedef struct {
    int k;
    const double *row[MAX_HELD];
    double G[MAX_HELD][NU];
    double v[MAX_HELD];
    double *lambda[MAX_HELD];
} held_t;

/* Add a plane's slip (its rows and force map) to ``h``. */
static void hold_slip(held_t *h, const slip_t *slip, int ns, double *lambda)
{
    for (int r = 0; r < 2; r++, h->k++) {
        h->row[h->k] = slip->du + r * ns;
        for (int i = 0; i < NU; i++) h->G[h->k][i] = slip->G[2 * i + r];
        h->v[h->k] = slip->u[r];
        h->lambda[h->k] = lambda ? lambda + r : NULL;
    }
}

/* Add a plane's rolling (part 0: 2 rows) or twisting (part 1: 1 row) velocity to ``h``. */
static void hold_rolling(held_t *h, ballc_rolling_eval *roll, int part, int ns)
{
    for (int r = part ? 2 : 0; r < (part ? 3 : 2); r++, h->k++) {
        h->row[h->k] = roll->dw + r * ns;
        for (int i = 0; i < NU; i++) h->G[h->k][i] = roll->G[3 * i + r];
        h->v[h->k] = roll->w[r];
        h->lambda[h->k] = roll->lambda + r;
    }
}

/* Solve A x = b (m x m, row-major) in place (b becomes x) for a set of held velocities
 * that may be redundant: Gaussian elimination with complete pivoting, and where every
 * pivot left is below 1e-12 of the largest entry the remaining unknowns are 0 (a held
 * velocity the others already hold -- a ball sticking on two planes at once, both
 * holding its rolling: their forces are then statically indeterminate, and this takes
 * one split of them).  BALLC_SINGULAR when A is not finite or is 0. */
static BALLC_ALWAYS_INLINE int held_dense_solve(int m, double *A, double *b)
{
    int column[MAX_HELD], rank = m;
    double largest = 0.0;
    for (int i = 0; i < m * m; i++) {
        double a = fabs(A[i]);
        if (!(a <= DBL_MAX)) return BALLC_SINGULAR;   /* not finite */
        if (a > largest) largest = a;
    }
    if (!(largest > 0)) return BALLC_SINGULAR;
    for (int c = 0; c < m; c++) column[c] = c;
    for (int c = 0; c < m; c++) {
        int pr = c, pc = c;
        double best = fabs(A[c * m + c]);
        for (int r = c; r < m; r++)
            for (int j = c; j < m; j++) {
                double a = fabs(A[r * m + j]);
                if (a > best) { best = a; pr = r; pc = j; }
            }
        if (!(best > 1e-12 * largest)) { rank = c; break; }
        if (pr != c) swap_rows(m, A, b, c, pr);
        if (pc != c) {
            for (int r = 0; r < m; r++) {
                double t = A[r * m + c]; A[r * m + c] = A[r * m + pc]; A[r * m + pc] = t;
            }
            int t = column[c]; column[c] = column[pc]; column[pc] = t;
        }
        eliminate_below(m, A, b, c);
    }
    double x[MAX_HELD];
    for (int c = m - 1; c >= 0; c--) {
        if (c >= rank) { x[c] = 0.0; continue; }
        double s = b[c];
        for (int j = c + 1; j < m; j++) s -= A[c * m + j] * x[j];
        x[c] = s / A[c * m + c];
    }
    for (int c = 0; c < m; c++) b[column[c]] = x[c];
    return BALLC_OK;
}

/* hold_solve's body for k held velocities (inlined with k a constant below: the loops of
 * the common sizes unrolled, the same operations in the same order). */
static BALLC_ALWAYS_INLINE int hold_solve_k(const schur_t *factor, const held_t *h,
                                            const double *target, int store, double *speeds,
                                            const int k)
{
    double z[MAX_HELD][NU], W[MAX_HELD * MAX_HELD], lambda[MAX_HELD];
    for (int c = 0; c < k; c++) {
        for (int i = 0; i < NU; i++) z[c][i] = h->G[c][i];
        schur_solve_inline(factor, z[c]);
    }
    for (int a = 0; a < k; a++)
        for (int c = 0; c < k; c++) {
            double s = 0;
            for (int i = 0; i < NU; i++) s += h->row[a][NQ + i] * z[c][i];
            W[a * k + c] = s;
        }
    for (int c = 0; c < k; c++) lambda[c] = target[c];
    int status = held_dense_solve(k, W, lambda);
    if (status != BALLC_OK) return status;
    for (int c = 0; c < k; c++) {
        for (int i = 0; i < NU; i++) speeds[i] += z[c][i] * lambda[c];
        if (store && h->lambda[c]) *h->lambda[c] = lambda[c];
    }
    return BALLC_OK;
}

/* The constraint forces (or impulses) of the held velocities ``h``: lambda solves
 * W lambda = target (W_ab = (dv_a/d speeds) M^-1 G_b, the Delassus matrix of all of
 * them), and M^-1 G lambda is added to ``speeds`` (6); each multiplier stored where its
 * row says (when ``store``). */
static int hold_solve(const schur_t *factor, const held_t *h, const double *target,
                      int store, double *speeds)
{
    switch (h->k) {   /* a sticking plane holding its rolling: 4 (and its twisting: 5) */
    case 2: return hold_solve_k(factor, h, target, store, speeds, 2);
    case 3: return hold_solve_k(factor, h, target, store, speeds, 3);
    case 4: return hold_solve_k(factor, h, target, store, speeds, 4);
    case 5: return hold_solve_k(factor, h, target, store, speeds, 5);
    default: return hold_solve_k(factor, h, target, store, speeds, h->k);
    }
}

/* udot (6) and the auxiliary rates.  A sticking plane's constraint force lambda makes
 * du/dt = 0: lambda = -W^-1 (du/d speeds) udot_0, udot = udot_0 + z lambda; several
 * sticking planes at once (a ball resting in a wedge's corner) are solved jointly, with
 * the Delassus matrix of all of them (one plane: the 2 x 2 solve of its own). */
static int accelerations(const double *state, const ballc_parameters_t *params, const double *latch,
                         ballc_flags flags, schur_t *factor, evaluation_t *ev, double *udot,
                         double *xdot)
{
    const int np = params->n_planes, ns = params->n_states;
    assemble(state, params, latch, flags, ev, udot, xdot);
    int status = schur_factor(ev->mass, factor);
    if (status != BALLC_OK) return status;
    schur_solve(factor, udot);
    int sticking[MAXP], k = 0, held = 0;
    for (int plane = 0; plane < np; plane++) {
        if (ev->mode[plane] == MODE_STICK) sticking[k++] = plane;
        held |= ballc_rolling_held(&ev->rolling[plane]);
    }
    if (held) {   /* rolling resistance holds: every held velocity of every plane at once */
        held_t h;   /* rows 0 .. h.k - 1 written as they are added: ~2 KB not zeroed */
        double target[MAX_HELD];
        h.k = 0;
        for (int plane = 0; plane < np; plane++) {
            if (ev->mode[plane] == MODE_STICK)
                hold_slip(&h, &ev->slip[plane], ns, ev->lambda[plane]);
            ballc_rolling_eval *roll = &ev->rolling[plane];
            int mask = ballc_rolling_held(roll);
            if (mask & BALLC_HOLD_ROLLING) hold_rolling(&h, roll, 0, ns);
            if (mask & BALLC_HOLD_TWISTING) hold_rolling(&h, roll, 1, ns);
        }
        for (int a = 0; a < h.k; a++) {   /* -(dv/d speeds) udot_0 */
            double s = 0;
            for (int i = 0; i < NU; i++) s += h.row[a][NQ + i] * udot[i];
            target[a] = -s;
        }
        status = hold_solve(factor, &h, target, 1, udot);
        if (status != BALLC_OK) return status;
        if (xdot)
            for (int plane = 0; plane < np; plane++) {
                const ballc_rolling_eval *roll = &ev->rolling[plane];
                if (!ballc_rolling_held(roll)) continue;
                for (int i = 0; i < BALLC_ROLLING_W; i++)
                    xdot[params->rolling_state] -= roll->lambda[i] * roll->w[i];
            }
    } else if (k == 1) {
        int plane = sticking[0];
        const slip_t *slip = &ev->slip[plane];
        const double *du = slip->du;
        double z[2][NU], Winv[2][2], a0[2];
        status = stick_response(factor, slip, ns, z, Winv);
        if (status != BALLC_OK) return status;
        for (int r = 0; r < 2; r++) {
            a0[r] = 0;
            for (int i = 0; i < NU; i++) a0[r] += du[r * ns + NQ + i] * udot[i];
        }
        double *lambda = ev->lambda[plane];
        lambda[0] = -(Winv[0][0] * a0[0] + Winv[0][1] * a0[1]);
        lambda[1] = -(Winv[1][0] * a0[0] + Winv[1][1] * a0[1]);
        for (int i = 0; i < NU; i++) udot[i] += z[0][i] * lambda[0] + z[1][i] * lambda[1];
    } else if (k > 1) {
        const slip_t *slips[MAXP];
        double target[2 * MAXP], lambda[2 * MAXP];
        for (int a = 0; a < k; a++) {
            slips[a] = &ev->slip[sticking[a]];
            for (int r = 0; r < 2; r++) {
                double s = 0;
                for (int i = 0; i < NU; i++) s += slips[a]->du[r * ns + NQ + i] * udot[i];
                target[2 * a + r] = -s;
            }
        }
        status = joint_constraint(factor, slips, k, ns, target, lambda, udot);
        if (status != BALLC_OK) return status;
        for (int a = 0; a < k; a++) {
            ev->lambda[sticking[a]][0] = lambda[2 * a];
            ev->lambda[sticking[a]][1] = lambda[2 * a + 1];
        }
    }
    for (int a = 0; a < k; a++) {
        int plane = sticking[a];
        const double *lambda = ev->lambda[plane];
        ev->contact_force[3 * plane] += lambda[0];       /* along t1, t2 */
        ev->contact_force[3 * plane + 1] += lambda[1];
        if (xdot)
            xdot[BALLC_STATE_DISSIPATED_TANGENTIAL] -=
                lambda[0] * ev->slip[plane].u[0] + lambda[1] * ev->slip[plane].u[1];
    }
    if (xdot)
        for (int plane = 0; plane < np; plane++) {
            const double *coefficients = ev->acceleration[plane];
            if (!coefficients[0] && !coefficients[1] && !coefficients[2] && !coefficients[3])
                continue;
            int target[4];
            auxiliary_targets(&params->planes[plane], target);
            double rho_dd = penetration_acceleration(params, plane, udot);
            for (int i = 0; i < 4; i++) xdot[target[i]] += coefficients[i] * rho_dd;
        }
    if (xdot && params->rolling)   /* the rolling part's sds sliders: their rho'' shares */
        for (int plane = 0; plane < np; plane++) {
            const double *c = ev->rolling[plane].acceleration;
            if (!c[0] && !c[1] && !c[2] && !c[3]) continue;
            double rho_dd = penetration_acceleration(params, plane, udot);
            xdot[params->rolling_state] += c[0] * rho_dd;
            for (int i = 0; i < 3; i++) xdot[params->planes[plane].rolling + i] += c[1 + i] * rho_dd;
        }
    return all_finite(udot, NU) ? BALLC_OK : BALLC_NOT_FINITE;
}

static int any_stick(ballc_flags flags, int n_planes)
{
    for (int plane = 0; plane < n_planes; plane++)
        if (exact_mode(flags, plane) == MODE_STICK) return 1;
    return 0;
}

/* Whether a plane in contact holds its rolling or twisting velocity (its latch). */
static int any_held(const ballc_parameters_t *params, ballc_flags flags, const double *latch)
{
    if (!params->rolling) return 0;
    for (int plane = 0; plane < params->n_planes; plane++) {
        if (!in_contact(flags, plane)) continue;
        const double *l = law_latch(latch, plane);
        for (int part = 0; part < 2; part++)
            if (ballc_rolling_mode(l, part) == BALLC_ROLLING_MODE_HOLDING) return 1;
    }
    return 0;
}

/* The public entry points' part of the checks: a valid plane count, finite parameters
 * and latch (latch may be NULL: not read), and the parameters prepared from them; 0 when
 * they are not. */
static int prepare(const double *params, const double *latch, ballc_parameters_t *prepared)
{
    int n = parameter_count(params);
    if (n < 0 || !all_finite(params, n)) return 0;
    ballc_parameters_init(prepared, params);
    return !latch || all_finite(latch, prepared->n_latch);
}

/* The number of states of a parameter vector (0 when its plane count is not valid). */
static int state_count(const double *params)
{
    int n = ballc_plane_count(params);
    if (n < 0) return 0;
    int rolling = params[BALLC_PARAMETER_ROLLING_RESISTANCE] != 0
                  || params[BALLC_PARAMETER_TWISTING_RESISTANCE] != 0;
    return NB + BALLC_N_PLANE_STATES * n
           + (rolling ? BALLC_N_ROLLING_BALL_STATES + BALLC_N_ROLLING_PLANE_STATES * n : 0);
}

int ballc_rhs(const double *state, const double *params, const double *latch,
              ballc_flags flags, double *xdot)
{
    ballc_parameters_t prepared;
    if (!prepare(params, latch, &prepared)) {
        for (int i = 0, n = state_count(params); i < n; i++) xdot[i] = NAN;
        return BALLC_NOT_FINITE;
    }
    return ballc_rhs_checked_inputs(state, &prepared, latch, flags, xdot);
}

int ballc_rhs_checked_inputs(const double *state, const ballc_parameters_t *params,
                             const double *latch, ballc_flags flags, double *xdot)
{
    schur_t factor;
    evaluation_t ev;
    const int ns = params->n_states;
    if (!all_finite(state, ns)) {
        for (int i = 0; i < ns; i++) xdot[i] = NAN;
        return BALLC_NOT_FINITE;
    }
    ballc_kinematics(state, PARAMS(params), NULL, xdot);
    int status = accelerations(state, params, latch, flags, &factor, &ev, xdot + NQ, xdot);
    if (status == BALLC_OK && !all_finite(xdot, ns)) status = BALLC_NOT_FINITE;
    return status;
}

int ballc_contact_forces(const double *state, const double *params, const double *latch,
                         ballc_flags flags, double *forces)
{
    ballc_parameters_t prepared;
    if (!prepare(params, latch, &prepared)) {
        int n = ballc_plane_count(params);
        for (int i = 0; i < 3 * n; i++) forces[i] = 0.0;
        return BALLC_NOT_FINITE;
    }
    return ballc_contact_forces_prepared(state, &prepared, latch, flags, forces);
}

int ballc_contact_forces_prepared(const double *state, const ballc_parameters_t *params,
                                  const double *latch, ballc_flags flags, double *forces)
{
    schur_t factor;
    evaluation_t ev;
    double udot[NU];
    const int np = params->n_planes;
    for (int i = 0; i < 3 * np; i++) forces[i] = 0.0;
    if (!all_finite(state, params->n_states) || !all_finite(latch, params->n_latch))
        return BALLC_NOT_FINITE;
    int status = accelerations(state, params, latch, flags, &factor, &ev, udot, NULL);
    if (status != BALLC_OK) return status;
    memcpy(forces, ev.contact_force, 3 * np * sizeof(double));
    for (int p = 0; p < np; p++)   /* from each plane's frame */
        ballc_plane_to_inertial(&params->planes[p], forces + 3 * p, 1);
    return all_finite(forces, 3 * np) ? BALLC_OK : BALLC_NOT_FINITE;
}

int ballc_stick_state(const double *state, const double *params, const double *latch,
                      ballc_flags flags, int plane, double *out)
{
    for (int i = 0; i < 4; i++) out[i] = NAN;
    ballc_parameters_t prepared;
    if (!prepare(params, latch, &prepared)) return BALLC_NOT_FINITE;
    return ballc_stick_state_prepared(state, &prepared, latch, flags, plane, out);
}

int ballc_stick_state_prepared(const double *state, const ballc_parameters_t *params,
                               const double *latch, ballc_flags flags, int plane, double *out)
{
    schur_t factor;
    evaluation_t ev;
    double udot[NU];
    for (int i = 0; i < 4; i++) out[i] = NAN;
    if (plane < 0 || plane >= params->n_planes || exact_mode(flags, plane) != MODE_STICK)
        return BALLC_SINGULAR;
    if (!all_finite(state, params->n_states) || !all_finite(latch, params->n_latch))
        return BALLC_NOT_FINITE;
    int status = accelerations(state, params, latch, flags, &factor, &ev, udot, NULL);
    if (status != BALLC_OK) return status;
    out[0] = ev.lambda[plane][0];
    out[1] = ev.lambda[plane][1];
    out[2] = ev.load[plane];
    out[3] = params->values[BALLC_PARAMETER_FRICTION_COEFFICIENT] * ev.load[plane]
             - hypot(out[0], out[1]);
    return all_finite(out, 4) ? BALLC_OK : BALLC_NOT_FINITE;
}

/* The margins kernel's outputs: the BALLC_COMPLIANT_MARGINS margins (the re-stick margin
 * at rho'' = 0), then the re-stick margin's coefficient of rho''. */
#define MARGINS_RESTICK_ACCELERATION BALLC_COMPLIANT_MARGINS

int ballc_compliant_margins_prepared(const double *state, const ballc_parameters_t *params,
                                     const double *latch, ballc_flags flags, int plane,
                                     int row, double *out)
{
    double m[BALLC_PLANE_COMPLIANT_MARGINS_NOUT];
    plane_contact_t contact;
    plane_contact(params, plane, state, latch, &contact);
    ballc_plane_compliant_margins(contact.state, PARAMS(params), contact.inputs, m);
    for (int i = 0; i < BALLC_COMPLIANT_MARGINS; i++) out[i] = m[i];
    if ((row < 0 || row == 1) && m[MARGINS_RESTICK_ACCELERATION] != 0) {
        /* the exact rho'' of the contact sliding at the cap (the elastic law at the cap
         * applies the same force, so it is the rho'' of either mode there), with every
         * other plane's contribution of the segment */
        ballc_flags own = ballc_plane_flags(plane);
        ballc_flags sliding = (flags & ~own & ~BALLC_WITH_OBSERVER)
                              | ballc_flag(BALLC_KIND_COMPLIANT_SLIDING, plane);
        if (params->values[BALLC_PARAMETER_OBSERVER_MASS] != 0) sliding |= BALLC_WITH_OBSERVER;
        schur_t factor;
        evaluation_t ev;
        double udot[NU];
        int status = accelerations(state, params, latch, sliding, &factor, &ev, udot, NULL);
        if (status != BALLC_OK) return status;
        out[1] += m[MARGINS_RESTICK_ACCELERATION]
                  * penetration_acceleration(params, plane, udot);
    }
    return (row < 0 ? all_finite(out, BALLC_COMPLIANT_MARGINS) : isfinite(out[row]))
           ? BALLC_OK : BALLC_NOT_FINITE;
}

int ballc_compliant_margins(const double *state, const double *params, const double *latch,
                            int plane, double *out)
{
    for (int i = 0; i < BALLC_COMPLIANT_MARGINS; i++) out[i] = NAN;
    ballc_parameters_t prepared;
    if (!prepare(params, latch, &prepared)) return BALLC_NOT_FINITE;
    if (plane < 0 || plane >= prepared.n_planes) return BALLC_SINGULAR;
    if (!all_finite(state, prepared.n_states)) return BALLC_NOT_FINITE;
    return ballc_compliant_margins_prepared(state, &prepared, latch, 0, plane, -1, out);
}

int ballc_remove_slip(const double *state, const double *params, ballc_flags flags, int plane,
                      double *state_out)
{
    schur_t factor;
    double mass[BALLC_MASS_SIZE], buf[BALLC_BALL_NOUT];
    double local[NC], z[2][NU], Winv[2][2];
    slip_t slip;
    ballc_parameters_t prepared;
    int ns = state_count(params);
    for (int i = 0; i < ns; i++) state_out[i] = state[i];
    if (!prepare(params, NULL, &prepared)) return BALLC_NOT_FINITE;
    if (plane < 0 || plane >= prepared.n_planes) return BALLC_SINGULAR;
    if (!all_finite(state, ns)) return BALLC_NOT_FINITE;
    ballc_ball(state, PARAMS(&prepared), NULL, buf);
    memcpy(mass, buf, sizeof mass);
    if (flags & BALLC_WITH_OBSERVER) {
        ballc_observer(state, PARAMS(&prepared), NULL, buf);
        for (int i = 0; i < BALLC_MASS_SIZE; i++) mass[i] += buf[i];
    }
    int status = schur_factor(mass, &factor);
    if (status != BALLC_OK) return status;
    ballc_plane_contact_state(&prepared.planes[plane], state, local);
    slip_of(&prepared, plane, local, &slip);
    /* the other planes that stick keep their slip velocity */
    slip_t others[MAXP];
    const slip_t *slips[MAXP] = {&slip};
    int k = 1;
    for (int p = 0; p < prepared.n_planes; p++) {
        if (p == plane || exact_mode(flags, p) != MODE_STICK) continue;
        ballc_plane_contact_state(&prepared.planes[p], state, local);
        slip_of(&prepared, p, local, &others[k]);
        slips[k] = &others[k];
        k++;
    }
    const double *u = slip.u;
    if (k == 1) {
        status = stick_response(&factor, &slip, ns, z, Winv);
        if (status != BALLC_OK) return status;
        double impulse[2] = {-(Winv[0][0] * u[0] + Winv[0][1] * u[1]),
                             -(Winv[1][0] * u[0] + Winv[1][1] * u[1])};
        for (int i = 0; i < NU; i++)
            state_out[NQ + i] += z[0][i] * impulse[0] + z[1][i] * impulse[1];
    } else {
        double target[2 * MAXP] = {-u[0], -u[1]}, impulse[2 * MAXP], speeds[NU] = {0};
        status = joint_constraint(&factor, slips, k, ns, target, impulse, speeds);
        if (status != BALLC_OK) return status;
        for (int i = 0; i < NU; i++) state_out[NQ + i] += speeds[i];
    }
    return all_finite(state_out, ns) ? BALLC_OK : BALLC_NOT_FINITE;
}

/* Add dF/dx (6 x n_states: the ball's columns) and d(M a)/dq (6 x 4) of one dynamics
 * kernel family (its Jacobian is by the ball's states, NB columns). */
static void add_dynamics_jac(kernel_fn kernel, const double *state,
                             const ballc_parameters_t *params, const double *udot,
                             double *dF, double *dMa)
{
    double buf[BALLC_BALL_JAC_NOUT];   /* ball and observer kernels have equal sizes */
    const int ns = params->n_states;
    kernel(state, PARAMS(params), udot, buf);
    for (int i = 0; i < NU; i++)
        for (int j = 0; j < NB; j++) dF[i * ns + j] += buf[i * NB + j];
    for (int i = 0; i < NU * 4; i++) dMa[i] += buf[NU * NB + i];
}

/* Forward-difference Jacobian of the whole right-hand side, for sticking planes
 * (lambda depends on the state through M, the forcing and the Delassus matrix).
 * Jacobians are rare (the integrator reuses them), so this costs little. */
static int difference_jacobian(const double *state, const ballc_parameters_t *params, const double *latch,
                               ballc_flags flags, double *jac)
{
    const int ns = params->n_states;
    double f0[MAXS], f1[MAXS], y[MAXS];
    int status = ballc_rhs_checked_inputs(state, params, latch, flags, f0);
    if (status != BALLC_OK) return status;
    memcpy(y, state, ns * sizeof(double));
    for (int j = 0; j < ns; j++) {
        y[j] = state[j] + 1.4901161193847656e-08 * fmax(1.0, fabs(state[j]));
        double h = y[j] - state[j];
        status = ballc_rhs_checked_inputs(y, params, latch, flags, f1);
        y[j] = state[j];
        if (status != BALLC_OK) return status;
        for (int i = 0; i < ns; i++) jac[i * ns + j] = (f1[i] - f0[i]) / h;
    }
    return all_finite(jac, ns * ns) ? BALLC_OK : BALLC_NOT_FINITE;
}

/* Add the sliding Coulomb force's derivatives: F_t = -mu N e(u), with
 * de/du = sign (I - e e^T) / |u| (sign: e's orientation along the latched direction;
 * 0 with a fixed direction), and those of the tangential dissipation rate mu N (e . u).
 * ``law_jac``: the normal share's Jacobian by the state, its rows in the plane's frame
 * (the row of the force along n: dN/dx). */
static void add_slip_jac(const evaluation_t *ev, int plane, double mu, const double *latch,
                         const double *law_jac, int ns, double *dF, double *jac)
{
    const slip_t *slip = &ev->slip[plane];
    const double *du = slip->du, *G = slip->G;
    const double *e = ev->e[plane], *d = law_latch(latch, plane) + BALLC_LATCH_SLIP_DIRECTION_X;
    double ux = slip->u[0], uy = slip->u[1], speed = hypot(ux, uy);
    double N = ev->load[plane];
    double de[2][2] = {{0, 0}, {0, 0}};
    if (speed > 0 && ev->mode[plane] == MODE_SLIP) {
        double sign = ux * d[0] + uy * d[1] < 0 ? -1.0 : 1.0;
        for (int a = 0; a < 2; a++)
            for (int b = 0; b < 2; b++)
                de[a][b] = sign * ((a == b) - e[a] * e[b]) / speed;
    }
    double eu = e[0] * ux + e[1] * uy;
    for (int j = 0; j < ns; j++) {
        double dN = law_jac[(BALLC_LAW_FORCE + 2) * ns + j];
        double du0 = du[j], du1 = du[ns + j];
        double df[2];
        for (int a = 0; a < 2; a++)
            df[a] = -mu * (e[a] * dN + N * (de[a][0] * du0 + de[a][1] * du1));
        for (int i = 0; i < NU; i++) dF[i * ns + j] += G[2 * i] * df[0] + G[2 * i + 1] * df[1];
        jac[BALLC_STATE_DISSIPATED_TANGENTIAL * ns + j] +=
            mu * (eu * dN + N * (e[0] * du0 + e[1] * du1));
    }
}

int ballc_jacobian(const double *state, const double *params, const double *latch,
                   ballc_flags flags, double *jac)
{
    ballc_parameters_t prepared;
    if (!prepare(params, latch, &prepared)) return BALLC_NOT_FINITE;
    return ballc_jacobian_checked_inputs(state, &prepared, latch, flags, jac);
}

int ballc_jacobian_checked_inputs(const double *state, const ballc_parameters_t *params,
                                  const double *latch, ballc_flags flags, double *jac)
{
    schur_t factor;
    evaluation_t ev;
    double udot[NU];
    const int ns = params->n_states, np = params->n_planes;
    if (!all_finite(state, ns)) return BALLC_NOT_FINITE;
    if (any_stick(flags, np) || any_held(params, flags, latch))
        return difference_jacobian(state, params, latch, flags, jac);
    int status = accelerations(state, params, latch, flags, &factor, &ev, udot, NULL);
    if (status != BALLC_OK) return status;

    for (int i = 0; i < ns * ns; i++) jac[i] = 0.0;
    {   /* rows 0..6: the kinematics, by the ball's states */
        double kin[BALLC_KINEMATICS_JAC_NOUT];
        ballc_kinematics_jac(state, PARAMS(params), NULL, kin);
        for (int i = 0; i < NQ; i++)
            for (int j = 0; j < NB; j++) jac[i * ns + j] = kin[i * NB + j];
    }

    const double mu = params->values[BALLC_PARAMETER_FRICTION_COEFFICIENT];
    const double radius = params->values[BALLC_PARAMETER_RADIUS];
    double dF[NU * MAXS] = {0}, dMa[NU * 4] = {0}, buf[LAW_NOUT * MAXS], local[LAW_NOUT * NC];
    add_dynamics_jac(ballc_ball_jac, state, params, udot, dF, dMa);
    if (flags & BALLC_WITH_OBSERVER)
        add_dynamics_jac(ballc_observer_jac, state, params, udot, dF, dMa);
    for (int plane = 0; plane < np; plane++) {
        if (!in_contact(flags, plane)) continue;
        const ballc_plane_t *pl = &params->planes[plane];
        plane_contact_t contact;
        int target[4];
        auxiliary_targets(pl, target);
        plane_contact(params, plane, state, latch, &contact);
        /* At rho <= 0 no law carries a load (no adhesion): each law's force and rates are
         * 0 there, and so is their derivative on that side -- the side of a contact at
         * rho = 0, which (armed at rho > 0) is leaving.  The kernels' derivatives at
         * rho = 0 exactly are half the loaded side's (d max(rho, 0)/drho = 1/2 there),
         * which for the compliant law run through its floors of rho and sqrt(rho)
         * (1e-30 m): ~1e28 W/m in the tangential dissipation with the deflection a
         * contact leaves, and radau5's Newton failed on a step that ended on rho = 0
         * (docs/contact_laws.md, "The Jacobian at rho <= 0"). */
        if (radius - contact.state[BALLC_CONTACT_STATE_Z] <= 0) continue;
        for (size_t k = 0; k < N_CONTACT_LAWS; k++) {
            if (!law_acts(flags, k, plane)) continue;
            int exact = is_sliding(ev.mode[plane]) && CONTACT_LAWS[k].normal_jac;
            (exact ? CONTACT_LAWS[k].normal_jac : CONTACT_LAWS[k].jac)(
                contact.state, PARAMS(params), contact.inputs, local);
            ballc_plane_state_columns(pl, local, LAW_NOUT, ns, buf);
            if (exact) add_slip_jac(&ev, plane, mu, latch, buf, ns, dF, jac);
            /* the torque's and the force's rows back from the plane's frame */
            ballc_plane_rows_to_inertial(pl, buf, ns, BALLC_LAW_GENERALIZED_FORCE, 2);
            for (int i = 0; i < NU * ns; i++) dF[i] += buf[BALLC_LAW_GENERALIZED_FORCE * ns + i];
            for (int i = 0; i < 4; i++)
                for (int j = 0; j < ns; j++)
                    jac[target[i] * ns + j] += buf[(BALLC_LAW_DISSIPATION + i) * ns + j];
        }
        if (params->rolling && ballc_rolling_on(law_latch(latch, plane)))   /* the 4th part */
            ballc_rolling_jacobian(params, plane, contact.state, contact.inputs,
                                   law_latch(latch, plane), &ev.rolling[plane], dF, jac);
    }
    /* d udot / dx_j = M^-1 (dF/dx_j - d(M udot)/dx_j); M depends on q only. */
    for (int j = 0; j < ns; j++) {
        double col[NU];
        for (int i = 0; i < NU; i++)
            col[i] = dF[i * ns + j] - (j < 4 ? dMa[i * 4 + j] : 0.0);
        schur_solve(&factor, col);
        for (int i = 0; i < NU; i++) jac[(NQ + i) * ns + j] = col[i];
    }
    return all_finite(jac, ns * ns) ? BALLC_OK : BALLC_NOT_FINITE;
}

void ballc_energy(const double *state, const ballc_parameters_t *params, double *out)
{
    double local[NC], e[BALLC_PLANE_ENERGY_NOUT];
    const int np = params->n_planes;
    ballc_mechanical_energy(state, PARAMS(params), NULL, out);
    for (int p = 0; p < np; p++) {
        ballc_plane_contact_state(&params->planes[p], state, local);
        ballc_plane_energy(local, PARAMS(params), NULL, e);
        out[2 + p] = e[0];
        out[2 + np + p] = e[1];
        out[2 + 2 * np + p] = 0.0;   /* no rolling springs without rolling resistance */
        if (params->rolling)
            ballc_plane_rolling_energy(local, PARAMS(params), NULL, out + 2 + 2 * np + p);
    }
}

int ballc_rolling_state(const double *state, const ballc_parameters_t *params,
                        const double *latch, ballc_flags flags, int plane, double *out)
{
    schur_t factor;
    evaluation_t ev;
    double udot[NU];
    for (int i = 0; i < BALLC_ROLLING_STATE_NOUT; i++) out[i] = NAN;
    if (plane < 0 || plane >= params->n_planes || !in_contact(flags, plane)) return BALLC_SINGULAR;
    if (!all_finite(state, params->n_states) || !all_finite(latch, params->n_latch))
        return BALLC_NOT_FINITE;
    int status = accelerations(state, params, latch, flags, &factor, &ev, udot, NULL);
    if (status != BALLC_OK) return status;
    const ballc_rolling_eval *roll = &ev.rolling[plane];
    if (roll->mode[0] == BALLC_ROLLING_MODE_NONE && roll->mode[1] == BALLC_ROLLING_MODE_NONE) {
        /* rolling resistance off: its velocities and load all the same */
        plane_contact_t contact;
        double w[BALLC_PLANE_ROLLING_NOUT];
        plane_contact(params, plane, state, latch, &contact);
        ballc_plane_rolling(contact.state, PARAMS(params), contact.inputs, w);
        for (int i = 0; i < 3; i++) out[i] = 0.0;
        out[3] = w[3];
        out[4] = params->values[BALLC_PARAMETER_ROLLING_RESISTANCE] * w[3];
        out[5] = params->values[BALLC_PARAMETER_TWISTING_RESISTANCE] * w[3];
        for (int i = 0; i < 3; i++) out[6 + i] = w[i];
        return all_finite(out, BALLC_ROLLING_STATE_NOUT) ? BALLC_OK : BALLC_NOT_FINITE;
    }
    for (int i = 0; i < 3; i++) out[i] = roll->lambda[i];
    out[3] = roll->load;
    out[4] = params->values[BALLC_PARAMETER_ROLLING_RESISTANCE] * roll->load
             - hypot(roll->lambda[0], roll->lambda[1]);
    out[5] = params->values[BALLC_PARAMETER_TWISTING_RESISTANCE] * roll->load
             - fabs(roll->lambda[2]);
    for (int i = 0; i < 3; i++) out[6 + i] = roll->w[i];
    return all_finite(out, BALLC_ROLLING_STATE_NOUT) ? BALLC_OK : BALLC_NOT_FINITE;
}

int ballc_rolling_margins(const double *state, const ballc_parameters_t *params,
                          const double *latch, ballc_flags flags, int plane, double *out)
{
    static void (*const MARGINS[2])(const double *restrict, const double *restrict,
                                    const double *restrict, const double *restrict,
                                    double *restrict) = {ballc_plane_rolling_margins,
                                                         ballc_plane_twisting_margins};
    for (int i = 0; i < BALLC_SDS_MARGINS; i++) out[i] = NAN;
    if (plane < 0 || plane >= params->n_planes) return BALLC_SINGULAR;
    if (!all_finite(state, params->n_states) || !all_finite(latch, params->n_latch))
        return BALLC_NOT_FINITE;
    schur_t factor;
    evaluation_t ev;
    double udot[NU], m[BALLC_PLANE_ROLLING_MARGINS_NOUT];
    int status = accelerations(state, params, latch, flags, &factor, &ev, udot, NULL);
    if (status != BALLC_OK) return status;
    double rho_dd = penetration_acceleration(params, plane, udot);
    plane_contact_t contact;
    plane_contact(params, plane, state, latch, &contact);
    for (int part = 0; part < 2; part++) {
        MARGINS[part](contact.state, PARAMS(params), contact.inputs, m);
        out[3 * part] = m[0];
        out[3 * part + 1] = m[1] + m[3] * rho_dd;
        out[3 * part + 2] = m[2];
    }
    return all_finite(out, BALLC_SDS_MARGINS) ? BALLC_OK : BALLC_NOT_FINITE;
}

int ballc_remove_velocities(const double *state, const ballc_parameters_t *params,
                            const double *latch, ballc_flags flags, int plane, int mask,
                            double *state_out)
{
    schur_t factor;
    evaluation_t ev;
    double force[NU], scratch[NU];
    const int ns = params->n_states, np = params->n_planes;
    memcpy(state_out, state, ns * sizeof(double));
    if (plane < 0 || plane >= np || !params->rolling) return BALLC_SINGULAR;
    if (!all_finite(state, ns) || !all_finite(latch, params->n_latch)) return BALLC_NOT_FINITE;
    /* the mass matrix, the slips and the rolling parts' velocities and maps at the state */
    assemble(state, params, latch, flags, &ev, force, NULL);
    int status = schur_factor(ev.mass, &factor);
    if (status != BALLC_OK) return status;
    /* the velocities of ``mask`` on ``plane`` go to 0, every other held one stays */
    held_t h = {0};
    double target[MAX_HELD];
    slip_t slips[MAXP];
    for (int p = 0; p < np; p++) {
        if (!in_contact(flags, p)) continue;
        plane_contact_t contact;
        plane_contact(params, p, state, latch, &contact);
        int own = p == plane ? mask : 0;
        int first = h.k;
        if ((own & BALLC_HOLD_SLIP) || exact_mode(flags, p) == MODE_STICK) {
            slip_of(params, p, contact.state, &slips[p]);
            hold_slip(&h, &slips[p], ns, NULL);
            for (int c = first; c < h.k; c++) target[c] = own & BALLC_HOLD_SLIP ? -h.v[c] : 0.0;
        }
        ballc_rolling_eval *roll = &ev.rolling[p];
        if (own & (BALLC_HOLD_ROLLING | BALLC_HOLD_TWISTING))   /* its velocities and maps */
            ballc_rolling_assemble(params, p, contact.state, contact.inputs, law_latch(latch, p),
                                   roll, scratch, NULL);
        int held = ballc_rolling_held(roll);
        for (int part = 0; part < 2; part++) {
            int bit = part ? BALLC_HOLD_TWISTING : BALLC_HOLD_ROLLING;
            if (!((own | held) & bit)) continue;
            first = h.k;
            hold_rolling(&h, roll, part, ns);
            for (int c = first; c < h.k; c++) target[c] = own & bit ? -h.v[c] : 0.0;
        }
    }
    if (!h.k) return BALLC_OK;
    status = hold_solve(&factor, &h, target, 0, state_out + NQ);
    if (status != BALLC_OK) return status;
    return all_finite(state_out, ns) ? BALLC_OK : BALLC_NOT_FINITE;
}

void ballc_contact_kinematics(const double *state, const ballc_parameters_t *params,
                              double *out)
{
    double local[NC];
    for (int p = 0; p < params->n_planes; p++, out += BALLC_CONTACT_KINEMATICS_PER_PLANE) {
        ballc_plane_contact_state(&params->planes[p], state, local);
        ballc_plane_kinematics(local, PARAMS(params), NULL, out);
        ballc_plane_to_inertial(&params->planes[p], out + 2, 1);   /* the velocity */
    }
}
