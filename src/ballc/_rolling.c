/* See _rolling.h. */
#include <math.h>
#include <string.h>

#include "_rolling.h"
#include "_system.h"

#define MAXS BALLC_MAX_STATES
#define NC BALLC_N_CONTACT_STATES
#define NQ 7   /* coordinates: the speeds start here */
#define NU 6

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

typedef void (*kernel_fn)(const double *restrict, const double *restrict,
                          const double *restrict, const double *restrict, double *restrict);

/* The sds kernels per part (rolling, twisting): spring, slider, the slider's rho''
 * coefficients, their Jacobians, the margins. */
static const struct {
    kernel_fn spring, spring_jac, slider, slider_jac, slider_acceleration, margins;
} SDS[2] = {
    {ballc_plane_rolling_spring, ballc_plane_rolling_spring_jac, ballc_plane_rolling_slider,
     ballc_plane_rolling_slider_jac, ballc_plane_rolling_slider_acceleration,
     ballc_plane_rolling_margins},
    {ballc_plane_twisting_spring, ballc_plane_twisting_spring_jac, ballc_plane_twisting_slider,
     ballc_plane_twisting_slider_jac, ballc_plane_twisting_slider_acceleration,
     ballc_plane_twisting_margins},
};
#define SDS_NOUT BALLC_PLANE_ROLLING_SPRING_NOUT   /* 6 + 1 + 3: kernels.SDS_LAYOUT */
typedef char sds_layouts_agree[(BALLC_PLANE_ROLLING_SLIDER_NOUT == SDS_NOUT
                                && BALLC_PLANE_TWISTING_SPRING_NOUT == SDS_NOUT
                                && BALLC_PLANE_TWISTING_SLIDER_NOUT == SDS_NOUT) ? 1 : -1];

static int sds(int mode)
{
    return mode == BALLC_ROLLING_MODE_SPRING || mode == BALLC_ROLLING_MODE_SLIDER;
}

void ballc_rolling_assemble(const ballc_parameters_t *params, int plane, const double *local,
                            const double *inputs, const double *plane_latch,
                            ballc_rolling_eval *roll, double *force, double *xdot)
{
    const ballc_plane_t *pl = &params->planes[plane];
    const double *values = params->values, *constants = params->constants;
    double out[BALLC_PLANE_ROLLING_NOUT];
    for (int part = 0; part < 2; part++) roll->mode[part] = ballc_rolling_mode(plane_latch, part);
    roll->dw = params->rolling_map[plane];
    roll->G = params->rolling_force_map[plane];
    for (int i = 0; i < BALLC_ROLLING_W; i++) roll->e[i] = roll->lambda[i] = 0.0;
    for (int i = 0; i < 4; i++) roll->acceleration[i] = 0.0;
    ballc_plane_rolling(local, values, constants, inputs, out);
    for (int i = 0; i < BALLC_ROLLING_W; i++) roll->w[i] = out[i];
    roll->load = out[BALLC_ROLLING_W];
    for (int part = 0; part < 2; part++) {
        int mode = roll->mode[part];
        if (sds(mode)) {   /* the generated spring or slider, in the plane's frame */
            double k[SDS_NOUT];
            int slider = mode == BALLC_ROLLING_MODE_SLIDER;
            (slider ? SDS[part].slider : SDS[part].spring)(local, values, constants, inputs, k);
            ballc_plane_to_inertial(pl, k, 2);   /* torque and force */
            for (int i = 0; i < NU; i++) force[i] += k[i];
            if (xdot) {
                xdot[params->rolling_state] += k[NU];
                for (int i = 0; i < 3; i++) xdot[pl->rolling + i] += k[NU + 1 + i];
                if (slider) {
                    double c[4];
                    SDS[part].slider_acceleration(local, values, constants, inputs, c);
                    for (int i = 0; i < 4; i++) roll->acceleration[i] += c[i];
                }
            }
            continue;
        }
        if (!exact_sliding(mode)) continue;
        const int first = FIRST[part], count = COUNT[part];
        const double *d = plane_latch + DIRECTION[part];
        const double *w = roll->w + first;
        double *e = roll->e + first;
        double speed = count == 2 ? sqrt(w[0] * w[0] + w[1] * w[1]) : fabs(w[0]);
        if (speed > 0 && mode == BALLC_ROLLING_MODE_FREE) {
            double along = count == 2 ? w[0] * d[0] + w[1] * d[1] : w[0] * d[0];
            double sign = along < 0 ? -1.0 : 1.0;
            for (int i = 0; i < count; i++) e[i] = sign * w[i] / speed;
        } else {
            for (int i = 0; i < count; i++) e[i] = d[i];
        }
        const double cap = values[MU[part]] * roll->load;
        for (int i = 0; i < count; i++) {
            double f = -cap * e[i];
            const double *g = roll->G + first + i;   /* column first + i of 6 x 3 */
            for (int j = 0; j < NU; j++) force[j] += g[3 * j] * f;
            if (xdot) xdot[params->rolling_state] -= f * w[i];
        }
    }
}

void ballc_rolling_jacobian(const ballc_parameters_t *params, int plane, const double *local,
                            const double *inputs, const double *plane_latch,
                            const ballc_rolling_eval *roll, double *dF, double *jac)
{
    const ballc_plane_t *pl = &params->planes[plane];
    const double *values = params->values, *constants = params->constants;
    const int NS = params->n_states;
    double load_jac[BALLC_PLANE_ROLLING_JAC_NOUT], rows[BALLC_PLANE_ROLLING_JAC_NOUT / NC * MAXS];
    int have_load = 0;
    for (int part = 0; part < 2; part++) {
        int mode = roll->mode[part];
        if (sds(mode)) {
            double k[SDS_NOUT * NC], krows[SDS_NOUT * MAXS];
            (mode == BALLC_ROLLING_MODE_SLIDER ? SDS[part].slider_jac : SDS[part].spring_jac)(
                local, values, constants, inputs, k);
            ballc_plane_state_columns(pl, k, SDS_NOUT, NS, krows);
            ballc_plane_rows_to_inertial(pl, krows, NS, 0, 2);   /* torque and force rows */
            for (int i = 0; i < NU * NS; i++) dF[i] += krows[i];
            for (int j = 0; j < NS; j++) {
                jac[params->rolling_state * NS + j] += krows[NU * NS + j];
                for (int i = 0; i < 3; i++)
                    jac[(pl->rolling + i) * NS + j] += krows[(NU + 1 + i) * NS + j];
            }
            continue;
        }
        if (!exact_sliding(mode)) continue;
        if (!have_load) {   /* dF_n/dx: the last row of plane_rolling's Jacobian */
            ballc_plane_rolling_jac(local, values, constants, inputs, load_jac);
            ballc_plane_state_columns(pl, load_jac, BALLC_PLANE_ROLLING_JAC_NOUT / NC, NS, rows);
            have_load = 1;
        }
        const double *dN_dx = rows + BALLC_ROLLING_W * NS;
        const int first = FIRST[part], count = COUNT[part];
        const double mu = values[MU[part]], N = roll->load;
        const double *e = roll->e + first, *w = roll->w + first;
        const double *d = plane_latch + DIRECTION[part];
        double de[2][2] = {{0, 0}, {0, 0}};
        if (count == 2 && mode == BALLC_ROLLING_MODE_FREE) {
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
            double dN = dN_dx[j], dwj[2], df[2], de_w = 0;
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
            jac[params->rolling_state * NS + j] += mu * (ew * dN + N * de_w);
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
    const int NS = params->n_states;
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
    const int NS = params->n_states;
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
                         const double *latch, ballc_flags flags, const ballc_rolling_run *run,
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
        } else if (sds(mode)) {   /* the yield or re-stick margin, evaluated in C */
            ballc_rolling_guard *g = &out[n++];
            int slider = mode == BALLC_ROLLING_MODE_SLIDER;
            g->event = part ? (slider ? BALLC_TWISTING_RESTICK : BALLC_TWISTING_YIELD)
                            : (slider ? BALLC_ROLLING_RESTICK : BALLC_ROLLING_YIELD);
            g->linear = 0;
            g->direction = -1;
            g->offset = slider ? scales->rounding * scales->speed : scales->rounding;
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
                              const double *y, const double *latch, ballc_flags flags, double *g)
{
    if (event >= BALLC_ROLLING_YIELD) {   /* the sds margins */
        double m[BALLC_SDS_MARGINS];
        int status = ballc_rolling_margins(y, params, latch, flags, plane, m);
        int part = event >= BALLC_TWISTING_YIELD;
        int restick = event == BALLC_ROLLING_RESTICK || event == BALLC_TWISTING_RESTICK;
        *g = m[3 * part + restick];
        return status;
    }
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
                  double *latch, ballc_flags flags, int stick, const ballc_rolling_scales *scales)
{
    double *l = latch + plane * NLP, y1[MAXS], state[BALLC_ROLLING_STATE_NOUT];
    int mask = ballc_rolling_held_mask(latch, plane, stick) | HOLD[part];
    if (ballc_remove_velocities(y, params, latch, flags, plane, mask, y1) != BALLC_OK)
        return -1;
    memcpy(y, y1, params->n_states * sizeof(double));
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

/* ---- the sds model's modes (spring, slider) ---- */

static const int STIFFNESS[2] = {BALLC_PARAMETER_ROLLING_STIFFNESS,
                                 BALLC_PARAMETER_TWISTING_STIFFNESS};

/* |xi| of a part's spring at y, and its unit direction (0 when |xi| is 0) */
static double spring_of(const ballc_parameters_t *params, int plane, int part, const double *y,
                        double *dir)
{
    const double *xi = y + params->planes[plane].rolling + FIRST[part];
    double size = COUNT[part] == 2 ? hypot(xi[0], xi[1]) : fabs(xi[0]);
    for (int i = 0; i < COUNT[part]; i++) dir[i] = size > 0 ? xi[i] / size : 0.0;
    return size;
}

/* The part's spring set to ``size`` along ``dir``; the energy it releases booked as
 * dissipated (1/2 k (|xi|^2 - size^2)). */
static void set_spring(const ballc_parameters_t *params, int plane, int part, double *y,
                       double size, const double *dir)
{
    double *xi = y + params->planes[plane].rolling + FIRST[part], old[2];
    double before = spring_of(params, plane, part, y, old);
    for (int i = 0; i < COUNT[part]; i++) xi[i] = size * dir[i];
    y[params->rolling_state] +=
        0.5 * params->values[STIFFNESS[part]] * (before * before - size * size);
}

/* compliantmodes.decide for an sds part at its cap (a yield): the slider when its
 * re-stick margin with the spring at the cap is >= 0 (the elastic law would stretch it
 * past the cap), else the spring (it only touched the cap), brought back to the cap
 * when beyond it.  Without load (the cap 0: a contact's last instants) the spring is
 * relaxed. */
static int sds_decide(const ballc_parameters_t *params, int plane, int part, double *y,
                      double *latch, ballc_flags flags)
{
    double *l = latch + plane * NLP, m[BALLC_SDS_MARGINS], dir[2], w[BALLC_ROLLING_W];
    if (ballc_rolling_margins(y, params, latch, flags, plane, m) != BALLC_OK) return -1;
    double cap = m[3 * part + 2];
    double size = spring_of(params, plane, part, y, dir);
    if (!(cap > 0)) {
        set_spring(params, plane, part, y, 0.0, dir);
        set_part(l, part, BALLC_ROLLING_MODE_SPRING, NULL);
        return 0;
    }
    if (!(size > 0)) {   /* along the velocity, or the spring it is */
        velocities(params, plane, y, w);
        if (!(part_velocity(w, part, dir) > 0)) {
            set_part(l, part, BALLC_ROLLING_MODE_SPRING, NULL);
            return 0;
        }
    }
    double trial[MAXS];
    memcpy(trial, y, params->n_states * sizeof(double));
    set_spring(params, plane, part, trial, cap, dir);
    set_part(l, part, BALLC_ROLLING_MODE_SLIDER, NULL);
    if (ballc_rolling_margins(trial, params, latch, flags, plane, m) != BALLC_OK) return -1;
    if (m[3 * part + 1] >= 0) {
        memcpy(y, trial, params->n_states * sizeof(double));
        return 0;
    }
    set_part(l, part, BALLC_ROLLING_MODE_SPRING, NULL);
    if (size > cap) set_spring(params, plane, part, y, cap, dir);
    return 0;
}

/* A slider re-sticks: the spring, brought back to the cap when beyond it. */
static int sds_restick(const ballc_parameters_t *params, int plane, int part, double *y,
                       double *latch, ballc_flags flags)
{
    double m[BALLC_SDS_MARGINS], dir[2];
    if (ballc_rolling_margins(y, params, latch, flags, plane, m) != BALLC_OK) return -1;
    double size = spring_of(params, plane, part, y, dir);
    set_part(latch + plane * NLP, part, BALLC_ROLLING_MODE_SPRING, NULL);
    if (size > m[3 * part + 2]) set_spring(params, plane, part, y, fmax(m[3 * part + 2], 0.0), dir);
    return 0;
}

/* _Run.start_coulomb for a part: FREE when clear of 0 (rolling only), FIXED when moving,
 * else settled. */
static int start_part(const ballc_parameters_t *params, int plane, int part, double *y,
                      double *latch, ballc_flags flags, int stick, ballc_rolling_run *run,
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
                        int twisting, double *y, double *latch, ballc_flags flags, int stick,
                        ballc_rolling_run *run, const ballc_rolling_scales *scales)
{
    const int model[2] = {rolling, twisting};
    run->relatches = 0;
    run->has_approach = 0;
    for (int part = 0; part < 2; part++) {
        if (model[part] == 1) {   /* exact */
            if (start_part(params, plane, part, y, latch, flags, stick, run, scales)) return -1;
        } else if (model[part] == 2) {   /* sds: the spring from rest (its yield follows) */
            double *xi = y + params->planes[plane].rolling + FIRST[part];
            for (int i = 0; i < COUNT[part]; i++) xi[i] = 0.0;
            set_part(latch + plane * NLP, part, BALLC_ROLLING_MODE_SPRING, NULL);
        }
    }
    return 0;
}

int ballc_rolling_transition(const ballc_parameters_t *params, int plane, int event,
                             double *y, double *latch, ballc_flags flags, int stick,
                             ballc_rolling_run *run, const ballc_rolling_scales *scales)
{
    double *l = latch + plane * NLP, w[BALLC_ROLLING_W], dir[2];
    if (event >= BALLC_ROLLING_YIELD) {   /* the sds model */
        int sds_part = event >= BALLC_TWISTING_YIELD;
        if (event == BALLC_ROLLING_YIELD || event == BALLC_TWISTING_YIELD)
            return sds_decide(params, plane, sds_part, y, latch, flags);
        return sds_restick(params, plane, sds_part, y, latch, flags);
    }
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
        double state[BALLC_ROLLING_STATE_NOUT], y1[MAXS];
        if (ballc_rolling_state(y, params, latch, flags, plane, state) != BALLC_OK) return -1;
        const double *lambda = state + FIRST[part];
        double size = COUNT[part] == 2 ? hypot(lambda[0], lambda[1]) : fabs(lambda[0]);
        int mask = ballc_rolling_held_mask(latch, plane, stick);
        if (ballc_remove_velocities(y, params, latch, flags, plane, mask, y1) != BALLC_OK)
            return -1;
        memcpy(y, y1, params->n_states * sizeof(double));
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
                          double *latch, ballc_flags flags, int stick, ballc_rolling_run *run,
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
        if (sds(mode)) {   /* the spring within its cap, the slider stretched */
            double m[BALLC_SDS_MARGINS];
            if (ballc_rolling_margins(y, params, latch, flags, plane, m) != BALLC_OK) return -1;
            int slider = mode == BALLC_ROLLING_MODE_SLIDER;
            double margin = m[3 * part + slider];
            double guard = slider ? scales->rounding * scales->speed : scales->rounding;
            if (margin >= -guard || !(m[3 * part + 2] > 0)) continue;   /* or no load */
            if ((slider ? sds_restick : sds_decide)(params, plane, part, y, latch, flags))
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

void ballc_rolling_end(const ballc_parameters_t *params, int plane, double *y, double *latch)
{
    double *l = latch + plane * NLP, dir[2];
    for (int part = 0; part < 2; part++) {
        if (spring_of(params, plane, part, y, dir) > 0) set_spring(params, plane, part, y, 0.0, dir);
        l[MODE[part]] = BALLC_ROLLING_MODE_NONE;
        for (int i = 0; i < COUNT[part]; i++) l[DIRECTION[part] + i] = 0.0;
    }
}
