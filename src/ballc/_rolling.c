/* See _rolling.h. */
#include <math.h>
#include <string.h>

#include "_rolling.h"
#include "_lu.h"
#include "_system.h"

#define NS BALLC_N_STATES
#define NQ 7   /* coordinates: the speeds start here */
#define NU 6
#define MAX_HELD 5

/* the parts: their first velocity component and their number */
static const int FIRST[2] = {0, 2}, COUNT[2] = {2, 1};
static const int MU[2] = {BALLC_PARAMETER_ROLLING_RESISTANCE,
                          BALLC_PARAMETER_TWISTING_RESISTANCE};
static const int DIRECTION[2] = {BALLC_LATCH_ROLLING_DIRECTION_X,
                                 BALLC_LATCH_TWISTING_DIRECTION};

int ballc_rolling_held(const ballc_rolling_eval *roll)
{
    return (roll->mode[0] == BALLC_ROLLING_MODE_HOLDING ? BALLC_HOLD_ROLLING : 0)
         | (roll->mode[1] == BALLC_ROLLING_MODE_HOLDING ? BALLC_HOLD_TWISTING : 0);
}

static int exact_sliding(int mode)
{
    return mode == BALLC_ROLLING_MODE_FREE || mode == BALLC_ROLLING_MODE_FIXED;
}

void ballc_rolling_assemble(const double *local, const double *params, const double *constants,
                            const double *inputs, const double *plane_latch,
                            const double *dw, const double *G, ballc_rolling_eval *roll,
                            double *force, double *xdot)
{
    double out[BALLC_PLANE_ROLLING_NOUT];
    for (int part = 0; part < 2; part++) roll->mode[part] = ballc_rolling_mode(plane_latch, part);
    roll->dw = dw;
    roll->G = G;
    for (int i = 0; i < BALLC_ROLLING_W; i++) roll->e[i] = roll->lambda[i] = 0.0;
    ballc_plane_rolling(local, params, constants, inputs, out);
    for (int i = 0; i < BALLC_ROLLING_W; i++) roll->w[i] = out[i];
    roll->load = out[BALLC_ROLLING_W];
    for (int part = 0; part < 2; part++) {
        if (!exact_sliding(roll->mode[part])) continue;
        const int first = FIRST[part], count = COUNT[part];
        const double *d = plane_latch + DIRECTION[part];
        const double *w = roll->w + first;
        double *e = roll->e + first;
        double speed = count == 2 ? sqrt(w[0] * w[0] + w[1] * w[1]) : fabs(w[0]);
        if (speed > 0 && roll->mode[part] == BALLC_ROLLING_MODE_FREE) {
            double along = count == 2 ? w[0] * d[0] + w[1] * d[1] : w[0] * d[0];
            double sign = along < 0 ? -1.0 : 1.0;
            for (int i = 0; i < count; i++) e[i] = sign * w[i] / speed;
        } else {
            for (int i = 0; i < count; i++) e[i] = d[i];
        }
        const double cap = params[MU[part]] * roll->load;
        for (int i = 0; i < count; i++) {
            double f = -cap * e[i];
            const double *g = G + first + i;   /* column first + i of 6 x 3 */
            for (int k = 0; k < NU; k++) force[k] += g[3 * k] * f;
            if (xdot) xdot[BALLC_STATE_DISSIPATED_ROLLING] -= f * w[i];
        }
    }
}

/* The held velocities of ``mask``: their current values v, their rows dv/dx (k x NS,
 * pointers) and the generalized forces of their unit constraint forces (6 x k). */
static int gather(int mask, const double *slip_u, const double *slip_du, const double *slip_G,
                  const ballc_rolling_eval *roll, double *v, const double **rows,
                  double G[NU][MAX_HELD])
{
    int k = 0;
    if (mask & BALLC_HOLD_SLIP)
        for (int r = 0; r < 2; r++, k++) {
            v[k] = slip_u ? slip_u[r] : 0.0;
            rows[k] = slip_du + r * NS;
            for (int i = 0; i < NU; i++) G[i][k] = slip_G[2 * i + r];
        }
    for (int part = 0; part < 2; part++) {
        if (!(mask & (part ? BALLC_HOLD_TWISTING : BALLC_HOLD_ROLLING))) continue;
        for (int r = FIRST[part]; r < FIRST[part] + COUNT[part]; r++, k++) {
            v[k] = roll->w[r];
            rows[k] = roll->dw + r * NS;
            for (int i = 0; i < NU; i++) G[i][k] = roll->G[3 * i + r];
        }
    }
    return k;
}

/* z_j = M^-1 G_j (k columns of 6) and the Delassus matrix W = (dv/d speeds) z, factored. */
static int response(int k, const double **rows, double G[NU][MAX_HELD], ballc_mass_solve solve,
                    const void *factor, double z[MAX_HELD][NU], double *W, int *piv)
{
    for (int j = 0; j < k; j++) {
        for (int i = 0; i < NU; i++) z[j][i] = G[i][j];
        solve(factor, z[j]);
        for (int r = 0; r < k; r++) {
            double s = 0;
            for (int i = 0; i < NU; i++) s += rows[r][NQ + i] * z[j][i];
            W[r * k + j] = s;
        }
    }
    for (int i = 0; i < k * k; i++)
        if (!isfinite(W[i])) return BALLC_SINGULAR;
    return ballc_lu_factor(k, W, piv) == BALLC_LU_OK ? BALLC_OK : BALLC_SINGULAR;
}

int ballc_rolling_hold(int mask, const double *slip_du, const double *slip_G,
                       ballc_rolling_eval *roll, ballc_mass_solve solve, const void *factor,
                       double *udot, double *slip_lambda)
{
    double v[MAX_HELD], G[NU][MAX_HELD], z[MAX_HELD][NU], W[MAX_HELD * MAX_HELD];
    double lambda[MAX_HELD];
    const double *rows[MAX_HELD];
    int piv[MAX_HELD];
    int k = gather(mask, NULL, slip_du, slip_G, roll, v, rows, G);
    int status = response(k, rows, G, solve, factor, z, W, piv);
    if (status != BALLC_OK) return status;
    for (int r = 0; r < k; r++) {   /* -(dv/d speeds) udot_0 */
        double s = 0;
        for (int i = 0; i < NU; i++) s += rows[r][NQ + i] * udot[i];
        lambda[r] = -s;
    }
    ballc_lu_solve(k, W, piv, lambda);
    for (int j = 0; j < k; j++)
        for (int i = 0; i < NU; i++) udot[i] += z[j][i] * lambda[j];
    int j = 0;
    if (mask & BALLC_HOLD_SLIP) {
        slip_lambda[0] = lambda[j++];
        slip_lambda[1] = lambda[j++];
    }
    for (int part = 0; part < 2; part++)
        if (mask & (part ? BALLC_HOLD_TWISTING : BALLC_HOLD_ROLLING))
            for (int r = FIRST[part]; r < FIRST[part] + COUNT[part]; r++)
                roll->lambda[r] = lambda[j++];
    return BALLC_OK;
}

int ballc_rolling_impulse(int mask, const double *slip_u, const double *slip_du,
                          const double *slip_G, const ballc_rolling_eval *roll,
                          ballc_mass_solve solve, const void *factor, double *speeds)
{
    double v[MAX_HELD], G[NU][MAX_HELD], z[MAX_HELD][NU], W[MAX_HELD * MAX_HELD];
    const double *rows[MAX_HELD];
    int piv[MAX_HELD];
    int k = gather(mask, slip_u, slip_du, slip_G, roll, v, rows, G);
    if (!k) return BALLC_OK;
    int status = response(k, rows, G, solve, factor, z, W, piv);
    if (status != BALLC_OK) return status;
    for (int r = 0; r < k; r++) v[r] = -v[r];
    ballc_lu_solve(k, W, piv, v);
    for (int j = 0; j < k; j++)
        for (int i = 0; i < NU; i++) speeds[i] += z[j][i] * v[j];
    return BALLC_OK;
}

void ballc_rolling_jacobian(const ballc_rolling_eval *roll, const double *params,
                            const double *plane_latch, const double *load_jac, double *dF,
                            double *jac)
{
    for (int part = 0; part < 2; part++) {
        if (!exact_sliding(roll->mode[part])) continue;
        const int first = FIRST[part], count = COUNT[part];
        const double mu = params[MU[part]], N = roll->load;
        const double *e = roll->e + first, *w = roll->w + first;
        const double *d = plane_latch + DIRECTION[part];
        double de[2][2] = {{0, 0}, {0, 0}};
        if (count == 2 && roll->mode[part] == BALLC_ROLLING_MODE_FREE) {
            double speed = hypot(w[0], w[1]);
            if (speed > 0) {
                double sign = w[0] * d[0] + w[1] * d[1] < 0 ? -1.0 : 1.0;
                for (int a = 0; a < 2; a++)
                    for (int b = 0; b < 2; b++)
                        de[a][b] = sign * ((a == b) - e[a] * e[b]) / speed;
            }
        }
        double ew = 0;
        for (int i = 0; i < count; i++) ew += e[i] * w[i];
        for (int j = 0; j < NS; j++) {
            double dN = load_jac[j], dwj[2], df[2], de_w = 0;
            for (int i = 0; i < count; i++) dwj[i] = roll->dw[(first + i) * NS + j];
            for (int a = 0; a < count; a++) {
                double turn = 0;
                for (int b = 0; b < count; b++) turn += de[a][b] * dwj[b];
                df[a] = -mu * (e[a] * dN + N * turn);
                de_w += e[a] * dwj[a];
            }
            for (int a = 0; a < count; a++) {
                const double *g = roll->G + first + a;
                for (int i = 0; i < NU; i++) dF[i * NS + j] += g[3 * i] * df[a];
            }
            jac[BALLC_STATE_DISSIPATED_ROLLING * NS + j] += mu * (ew * dN + N * de_w);
        }
    }
}

/* ---- the segment loop's part: the exact modes' guards and resets ---- */

#define NLP BALLC_N_LATCH_PER_PLANE
/* stickslip.py's constants, the same for rolling and twisting */
#define PASS_FACTOR 3.0
#define STOP_FACTOR 10.0
#define APPROACH_FRACTION 0.5
#define MAX_RELATCH 1000
static const int MODE[2] = {BALLC_LATCH_ROLLING_MODE, BALLC_LATCH_TWISTING_MODE};
static const int HOLD[2] = {BALLC_HOLD_ROLLING, BALLC_HOLD_TWISTING};

int ballc_rolling_held_mask(const double *latch, int plane, int stick)
{
    const double *l = latch + plane * NLP;
    int mask = stick ? BALLC_HOLD_SLIP : 0;
    for (int part = 0; part < 2; part++)
        if (ballc_rolling_mode(l, part) == BALLC_ROLLING_MODE_HOLDING) mask |= HOLD[part];
    return mask;
}

/* The rolling and twisting velocities at y: the map's rows dotted with y (they are
 * linear in the state, as the guards' rows). */
static void velocities(const ballc_parameters_t *params, int plane, const double *y,
                       double *w)
{
    const double *dw = params->rolling_map[plane];
    for (int i = 0; i < BALLC_ROLLING_W; i++) {
        double s = 0;
        for (int j = 0; j < NS; j++) s += dw[i * NS + j] * y[j];
        w[i] = s;
    }
}

/* the row d . dw/dx of a part's velocity along its latched direction */
static void along_row(const ballc_parameters_t *params, int plane, int part,
                      const double *plane_latch, double *row)
{
    const double *dw = params->rolling_map[plane] + FIRST[part] * NS;
    const double *d = plane_latch + DIRECTION[part];
    for (int j = 0; j < NS; j++) {
        row[j] = d[0] * dw[j];
        if (COUNT[part] == 2) row[j] += d[1] * dw[NS + j];
    }
}

static double force_scale(const ballc_rolling_scales *scales, double load)
{
    return (64 * 2.220446049250313e-16) * (scales->weight + fabs(load));
}

int ballc_rolling_guards(const ballc_parameters_t *params, int plane, const double *y0,
                         const double *latch, int flags, const ballc_rolling_run *run,
                         const ballc_rolling_scales *scales, ballc_rolling_guard *out)
{
    const double *l = latch + plane * NLP;
    int n = 0;
    double state[BALLC_ROLLING_STATE_NOUT];
    int have_state = 0;
    for (int part = 0; part < 2; part++) {
        int mode = ballc_rolling_mode(l, part);
        if (mode == BALLC_ROLLING_MODE_FREE || mode == BALLC_ROLLING_MODE_FIXED) {
            ballc_rolling_guard *g = &out[n++];
            along_row(params, plane, part, l, g->row);
            g->linear = 1;
            g->direction = -1;
            if (mode == BALLC_ROLLING_MODE_FREE) {   /* twisting is never FREE */
                g->event = BALLC_ROLLING_APPROACH;
                g->offset = -(run->has_approach ? run->approach : scales->clear);
                continue;
            }
            g->event = part ? BALLC_TWISTING_STOP : BALLC_ROLLING_STOP;
            g->offset = scales->margin;
            if (part) continue;
            ballc_rolling_guard *c = &out[n++];
            memcpy(c->row, g->row, sizeof c->row);
            c->linear = 1;
            c->direction = 1;
            c->event = BALLC_ROLLING_CLEAR;
            c->offset = -2 * scales->clear;
        } else if (mode == BALLC_ROLLING_MODE_HOLDING) {
            if (!have_state
                    && ballc_rolling_state(y0, params, latch, flags, plane, state) != BALLC_OK)
                return -1;
            have_state = 1;
            ballc_rolling_guard *g = &out[n++];
            g->event = part ? BALLC_TWISTING_RELEASE : BALLC_ROLLING_RELEASE;
            g->linear = 0;
            g->direction = -1;
            g->offset = force_scale(scales, state[3]);
        }
    }
    return n;
}

int ballc_rolling_guard_value(const ballc_parameters_t *params, int plane, int event,
                              const double *y, const double *latch, int flags, double *g)
{
    double state[BALLC_ROLLING_STATE_NOUT];
    int status = ballc_rolling_state(y, params, latch, flags, plane, state);
    *g = state[event == BALLC_TWISTING_RELEASE ? 5 : 4];
    return status;
}

/* Set a part's mode and (when given) direction in the plane's latch block. */
static void set_part(double *plane_latch, int part, int mode, const double *direction)
{
    plane_latch[MODE[part]] = mode;
    if (direction)
        for (int i = 0; i < COUNT[part]; i++) plane_latch[DIRECTION[part] + i] = direction[i];
}

/* The part's velocity (count values), its size, and its unit direction (dir; 0 when it
 * is 0). */
static double part_velocity(const double *w, int part, double *dir)
{
    const double *v = w + FIRST[part];
    double speed = COUNT[part] == 2 ? hypot(v[0], v[1]) : fabs(v[0]);
    for (int i = 0; i < COUNT[part]; i++) dir[i] = speed > 0 ? v[i] / speed : 0.0;
    return speed;
}

/* stickslip.settle for a rolling or twisting part: what is left of its velocity is
 * removed by an impulse that holds the plane's other held velocities too; the part then
 * holds when the constraint force that holds it is within its cap, else it starts
 * FIXED from rest along -lambda. */
static int settle(const ballc_parameters_t *params, int plane, int part, double *y,
                  double *latch, int flags, int stick, const ballc_rolling_scales *scales)
{
    double *l = latch + plane * NLP, y1[NS], state[BALLC_ROLLING_STATE_NOUT];
    int mask = ballc_rolling_held_mask(latch, plane, stick) | HOLD[part];
    if (ballc_remove_velocities(y, params, latch, flags, plane, mask, y1) != BALLC_OK)
        return -1;
    memcpy(y, y1, sizeof y1);
    int before = ballc_rolling_mode(l, part);
    set_part(l, part, BALLC_ROLLING_MODE_HOLDING, NULL);
    if (ballc_rolling_state(y, params, latch, flags, plane, state) != BALLC_OK) {
        set_part(l, part, before, NULL);
        return -1;
    }
    const double *lambda = state + FIRST[part];
    double size = COUNT[part] == 2 ? hypot(lambda[0], lambda[1]) : fabs(lambda[0]);
    if (state[4 + part] >= -force_scale(scales, state[3]) || size == 0) return 0;
    double d[2] = {-lambda[0] / size, COUNT[part] == 2 ? -lambda[1] / size : 0.0};
    set_part(l, part, BALLC_ROLLING_MODE_FIXED, d);
    return 0;
}

/* _Run.start_coulomb for a part: FREE when clear of 0 (rolling only), FIXED when moving,
 * else settled. */
static int start_part(const ballc_parameters_t *params, int plane, int part, double *y,
                      double *latch, int flags, int stick, ballc_rolling_run *run,
                      const ballc_rolling_scales *scales)
{
    double w[BALLC_ROLLING_W], dir[2];
    velocities(params, plane, y, w);
    double speed = part_velocity(w, part, dir);
    double *l = latch + plane * NLP;
    if (part == 0) run->has_approach = 0;
    if (speed > 0) {
        int free = part == 0 && speed > 2 * scales->clear;
        set_part(l, part, free ? BALLC_ROLLING_MODE_FREE : BALLC_ROLLING_MODE_FIXED, dir);
        return 0;
    }
    set_part(l, part, BALLC_ROLLING_MODE_FIXED, NULL);
    return settle(params, plane, part, y, latch, flags, stick, scales);
}

int ballc_rolling_start(const ballc_parameters_t *params, int plane, int rolling,
                        int twisting, double *y, double *latch, int flags, int stick,
                        ballc_rolling_run *run, const ballc_rolling_scales *scales)
{
    run->relatches = 0;
    run->has_approach = 0;
    if (rolling && start_part(params, plane, 0, y, latch, flags, stick, run, scales)) return -1;
    if (twisting && start_part(params, plane, 1, y, latch, flags, stick, run, scales)) return -1;
    return 0;
}

int ballc_rolling_transition(const ballc_parameters_t *params, int plane, int event,
                             double *y, double *latch, int flags, int stick,
                             ballc_rolling_run *run, const ballc_rolling_scales *scales)
{
    double *l = latch + plane * NLP, w[BALLC_ROLLING_W], dir[2];
    int part = event == BALLC_TWISTING_STOP || event == BALLC_TWISTING_RELEASE;
    velocities(params, plane, y, w);
    double speed = part_velocity(w, part, dir);
    const double *direction = speed > 0 ? dir : NULL;
    switch (event) {
    case BALLC_ROLLING_APPROACH: {
        run->relatches += 1;
        const double *d = l + DIRECTION[0];
        double along = w[0] * d[0] + w[1] * d[1];
        double across = sqrt(fmax(w[0] * w[0] + w[1] * w[1] - along * along, 0.0));
        int freely = speed > 2 * scales->clear || across > PASS_FACTOR * scales->error;
        if (run->relatches <= MAX_RELATCH && freely) {   /* passing by 0: re-latched */
            run->has_approach = 1;
            run->approach = fmin(scales->clear, APPROACH_FRACTION * speed);
            set_part(l, 0, BALLC_ROLLING_MODE_FREE, direction);
        } else {
            run->has_approach = 0;
            set_part(l, 0, BALLC_ROLLING_MODE_FIXED, direction);
        }
        return 0;
    }
    case BALLC_ROLLING_STOP: case BALLC_TWISTING_STOP:
        if (speed <= STOP_FACTOR * scales->error)
            return settle(params, plane, part, y, latch, flags, stick, scales);
        if (part) {   /* twisting on through 0: the other way */
            set_part(l, 1, BALLC_ROLLING_MODE_FIXED, direction);
            return 0;
        }
        run->has_approach = 1;
        run->approach = fmin(scales->clear, APPROACH_FRACTION * speed);
        set_part(l, 0, BALLC_ROLLING_MODE_FREE, direction);
        return 0;
    case BALLC_ROLLING_CLEAR:
        run->has_approach = 0;
        set_part(l, 0, BALLC_ROLLING_MODE_FREE, direction);
        return 0;
    default: {   /* a release: on from rest along -lambda */
        double state[BALLC_ROLLING_STATE_NOUT], y1[NS];
        if (ballc_rolling_state(y, params, latch, flags, plane, state) != BALLC_OK) return -1;
        const double *lambda = state + FIRST[part];
        double size = COUNT[part] == 2 ? hypot(lambda[0], lambda[1]) : fabs(lambda[0]);
        int mask = ballc_rolling_held_mask(latch, plane, stick);
        if (ballc_remove_velocities(y, params, latch, flags, plane, mask, y1) != BALLC_OK)
            return -1;
        memcpy(y, y1, sizeof y1);
        double d[2] = {0, 0};
        if (size > 0) {
            d[0] = -lambda[0] / size;
            if (COUNT[part] == 2) d[1] = -lambda[1] / size;
        }
        run->has_approach = 0;
        set_part(l, part, BALLC_ROLLING_MODE_FIXED, size > 0 ? d : NULL);
        return 0;
    }
    }
}

int ballc_rolling_recheck(const ballc_parameters_t *params, int plane, double *y,
                          double *latch, int flags, int stick, ballc_rolling_run *run,
                          const ballc_rolling_scales *scales)
{
    double *l = latch + plane * NLP, w[BALLC_ROLLING_W];
    int restarted = 0;
    for (int part = 0; part < 2; part++) {
        int mode = ballc_rolling_mode(l, part);
        if (mode == BALLC_ROLLING_MODE_HOLDING) {   /* within its cap, or released */
            double state[BALLC_ROLLING_STATE_NOUT];
            if (ballc_rolling_state(y, params, latch, flags, plane, state) != BALLC_OK)
                return -1;
            if (state[4 + part] >= -force_scale(scales, state[3])) continue;
            int event = part ? BALLC_TWISTING_RELEASE : BALLC_ROLLING_RELEASE;
            if (ballc_rolling_transition(params, plane, event, y, latch, flags, stick, run,
                                         scales))
                return -1;
            restarted++;
            continue;
        }
        if (!exact_sliding(mode)) continue;
        velocities(params, plane, y, w);
        const double *d = l + DIRECTION[part], *v = w + FIRST[part];
        double along = COUNT[part] == 2 ? v[0] * d[0] + v[1] * d[1] : v[0] * d[0];
        double guard = mode == BALLC_ROLLING_MODE_FREE
                       ? (run->has_approach ? run->approach : scales->clear) : -scales->margin;
        if (along > guard) continue;
        if (start_part(params, plane, part, y, latch, flags, stick, run, scales)) return -1;
        restarted++;
    }
    return restarted;
}
