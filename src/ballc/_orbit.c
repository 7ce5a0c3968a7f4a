/* See _orbit.h. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "_orbit.h"
#include "_system.h"

#define N BALLC_MAX_STATES   /* room for a row; a run has n_states of them */

/* the number of states of G's scene */
static int states_of(const ballc_motion *g)
{
    return BALLC_N_BALL_STATES + BALLC_N_PLANE_STATES * g->n_planes;
}

void ballc_motion_planes(ballc_motion *g, const double *params)
{
    ballc_parameters_t prepared;
    g->n_planes = ballc_parameters_init(&prepared, params) == BALLC_OK ? prepared.n_planes : 0;
    for (int p = 0; p < g->n_planes; p++)
        g->sense[p] = prepared.planes[p].frame[2][2] < 0 ? -1.0 : 1.0;
}

/* Hamilton product a (x) b, scalar first (orientation.quaternion_multiply) */
static void quaternion_multiply(const double *a, const double *b, double *out)
{
    double w = a[0] * b[0] - (a[1] * b[1] + a[2] * b[2] + a[3] * b[3]);
    double x = a[0] * b[1] + b[0] * a[1] + (a[2] * b[3] - a[3] * b[2]);
    double y = a[0] * b[2] + b[0] * a[2] + (a[3] * b[1] - a[1] * b[3]);
    double z = a[0] * b[3] + b[0] * a[3] + (a[1] * b[2] - a[2] * b[1]);
    out[0] = w;
    out[1] = x;
    out[2] = y;
    out[3] = z;
}

/* ---- G ---- */

void ballc_motion_power(const ballc_motion *g, double k, ballc_motion *out)
{
    double half = 0.5 * g->phi, re, im;
    double below = sin(half);
    if (fabs(below) > 1e-300) {   /* e^(i (k - 1) phi/2) sin(k phi/2) / sin(phi/2) */
        double ratio = sin(k * half) / below;
        re = cos((k - 1) * half) * ratio;
        im = sin((k - 1) * half) * ratio;
    } else {                      /* no turn: the shift adds up k times */
        re = k;
        im = 0.0;
    }
    ballc_motion p = *g;
    p.phi = k * g->phi;
    p.psi = k * g->psi;
    p.d[0] = g->d[0] * re - g->d[1] * im;
    p.d[1] = g->d[0] * im + g->d[1] * re;
    p.work[0] = g->work[0] * k;
    p.work[1] = g->work[1] * k;
    *out = p;
}

void ballc_motion_apply(const ballc_motion *g, const double *y, int rate, double *out)
{
    /* how each pair turns with the scene: inertial components with it; a plane's
     * deflection lives in its own frame (_plane.h), whose (t1, t2) turn by phi n_z: the
     * floor's (normal +z) with it, the ceiling's (normal -z: t1 = x, t2 = -y) against it */
    int planar[3 + BALLC_MAX_PLANES] = {BALLC_STATE_X, BALLC_STATE_OMEGA_X, BALLC_STATE_VX};
    double sense[3 + BALLC_MAX_PLANES] = {1.0, 1.0, 1.0};
    int pairs = 3, n = states_of(g);
    for (int p = 0; p < g->n_planes; p++, pairs++) {
        planar[pairs] = ballc_plane_state(p);
        sense[pairs] = g->sense[p];
    }
    double in[N], turned[4];
    memcpy(in, y, n * sizeof(double));
    memcpy(out, in, n * sizeof(double));
    double c = cos(g->phi), s = sin(g->phi);
    double half = 0.5 * g->phi, spin_half = 0.5 * g->psi, spin_sin = sin(spin_half);
    double vertical[4] = {cos(half), 0.0, 0.0, sin(half)};
    double spin[4] = {cos(spin_half), spin_sin * g->axis[0], spin_sin * g->axis[1],
                      spin_sin * g->axis[2]};
    /* the scene turned about the vertical, the ball about its own axis */
    quaternion_multiply(vertical, in + BALLC_STATE_QW, turned);
    quaternion_multiply(turned, spin, out + BALLC_STATE_QW);
    for (int b = 0; b < pairs; b++) {
        double x = in[planar[b]], yy = in[planar[b] + 1];
        out[planar[b]] = c * x - sense[b] * s * yy;
        out[planar[b] + 1] = sense[b] * s * x + c * yy;
    }
    if (!rate) {
        out[BALLC_STATE_X] += g->d[0];
        out[BALLC_STATE_Y] += g->d[1];
        out[BALLC_STATE_DISSIPATED_NORMAL] += g->work[0];
        out[BALLC_STATE_DISSIPATED_TANGENTIAL] += g->work[1];
    }
}

double ballc_orbit_tilt(const double *y, const double *axis)
{
    double qw = y[BALLC_STATE_QW], qx = y[BALLC_STATE_QX], qy = y[BALLC_STATE_QY],
           qz = y[BALLC_STATE_QZ];
    double norm2 = qw * qw + qx * qx + qy * qy + qz * qz;
    /* the third row of R(q) (orientation.rotation_matrix), over |q|^2 */
    double r0 = 2 * (qx * qz - qw * qy), r1 = 2 * (qy * qz + qw * qx),
           r2 = qw * qw - qx * qx - qy * qy + qz * qz;
    return (r0 * axis[0] + r1 * axis[1] + r2 * axis[2]) / norm2;
}

int ballc_orbit_equivariant(const double *params, const double *latch, long long flags,
                            const double *y, const double *axis)
{
    ballc_motion test = {1.0, {0.37, -0.21}, 0.7, {axis[0], axis[1], axis[2]}, {0.0, 0.0},
                         0, {0}};
    ballc_motion_planes(&test, params);
    if (!test.n_planes) return 0;
    const int n = states_of(&test);
    double f[N], moved[N], f_moved[N], expected[N];
    if (ballc_rhs(y, params, latch, flags, f) != BALLC_OK) return 0;
    ballc_motion_apply(&test, y, 0, moved);
    if (ballc_rhs(moved, params, latch, flags, f_moved) != BALLC_OK) return 0;
    ballc_motion_apply(&test, f, 1, expected);
    double largest = 0.0, worst = 0.0;
    for (int i = 0; i < n; i++) {
        double miss = fabs(f_moved[i] - expected[i]);
        if (isnan(f[i]) || isnan(miss)) return 0;
        if (fabs(f[i]) > largest) largest = fabs(f[i]);
        if (miss > worst) worst = miss;
    }
    double scale = largest + sqrt(params[BALLC_PARAMETER_GRAVITY_X] * params[BALLC_PARAMETER_GRAVITY_X]
                                  + params[BALLC_PARAMETER_GRAVITY_Y] * params[BALLC_PARAMETER_GRAVITY_Y]
                                  + params[BALLC_PARAMETER_GRAVITY_Z] * params[BALLC_PARAMETER_GRAVITY_Z]);
    return worst <= 1e3 * DBL_EPSILON * scale;
}

/* ---- the measurement ---- */

/* the x, y components of a = R(q) axis, q of any non-zero norm */
static void axis_in_space(const double *y, const double *axis, double *a)
{
    double qw = y[BALLC_STATE_QW], qx = y[BALLC_STATE_QX], qy = y[BALLC_STATE_QY],
           qz = y[BALLC_STATE_QZ];
    double size = sqrt(qw * qw + qx * qx + qy * qy + qz * qz);
    double w = qw / size, x = qx / size, yy = qy / size, z = qz / size;
    a[0] = (w * w + x * x - yy * yy - z * z) * axis[0] + 2 * (x * yy - w * z) * axis[1]
           + 2 * (x * z + w * yy) * axis[2];
    a[1] = 2 * (x * yy + w * z) * axis[0] + (w * w - x * x + yy * yy - z * z) * axis[1]
           + 2 * (yy * z - w * x) * axis[2];
}

/* the horizontal direction of omega, over |omega| */
static void spin_direction(const double *y, double *w)
{
    const double *o = y + BALLC_STATE_OMEGA_X;
    double size = sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
    if (size < 1e-300) size = 1e-300;
    w[0] = o[0] / size;
    w[1] = o[1] / size;
}

/* The motion G with G y0 ~ y1: phi from the horizontal turn of a and of omega, d from
 * the centre, psi from the ball's remaining turn about a. */
static void fit(const double *y0, const double *y1, const double *axis, ballc_motion *g)
{
    double a0[2], a1[2], w0[2], w1[2];
    axis_in_space(y0, axis, a0);
    axis_in_space(y1, axis, a1);
    spin_direction(y0, w0);
    spin_direction(y1, w1);
    /* z = a1 conj(a0) + w1 conj(w0): the turn both went through */
    double re = (a1[0] * a0[0] + a1[1] * a0[1]) + (w1[0] * w0[0] + w1[1] * w0[1]);
    double im = (a1[1] * a0[0] - a1[0] * a0[1]) + (w1[1] * w0[0] - w1[0] * w0[1]);
    double phi = atan2(im, re), c = cos(phi), s = sin(phi);
    double x0 = y0[BALLC_STATE_X], yy0 = y0[BALLC_STATE_Y];
    g->phi = phi;
    g->d[0] = y1[BALLC_STATE_X] - (c * x0 - s * yy0);
    g->d[1] = y1[BALLC_STATE_Y] - (s * x0 + c * yy0);
    /* the ball's turn left once the scene's is undone: conj(q0) conj(vertical) q1 */
    const double *q0 = y0 + BALLC_STATE_QW;
    double q0_conj[4] = {q0[0], -q0[1], -q0[2], -q0[3]};
    double vertical_conj[4] = {cos(0.5 * phi), -0.0, -0.0, -sin(0.5 * phi)};
    double undone[4], spin[4];
    quaternion_multiply(q0_conj, vertical_conj, undone);
    quaternion_multiply(undone, y1 + BALLC_STATE_QW, spin);
    g->psi = 2.0 * atan2(spin[1] * axis[0] + spin[2] * axis[1] + spin[3] * axis[2], spin[0]);
    memcpy(g->axis, axis, 3 * sizeof(double));
    g->work[0] = y1[BALLC_STATE_DISSIPATED_NORMAL] - y0[BALLC_STATE_DISSIPATED_NORMAL];
    g->work[1] = y1[BALLC_STATE_DISSIPATED_TANGENTIAL] - y0[BALLC_STATE_DISSIPATED_TANGENTIAL];
}

typedef struct {
    ballc_states_fn states;
    void *ctx;
    const double *axis;
    double level;
} tilt_fn;

/* tilt(y(t)) - level: 0, or -1 when y(t) failed */
static int tilt_minus_level(const tilt_fn *f, double t, double *value)
{
    double y[N];
    if (f->states(f->ctx, 1, &t, y)) return -1;
    *value = ballc_orbit_tilt(y, f->axis) - f->level;
    return 0;
}

/* Brent's method: the root of g = tilt - level in [a, b] where g(a) = fa < 0 <= g(b) =
 * fb, to (XTOL + RTOL |root|) / 2: inverse quadratic interpolation or the secant while
 * they shrink the bracket fast enough, else bisection.  1 and *root, 0 when it did not
 * converge in 100 steps, -1 when y(t) failed. */
#define ROOT_XTOL 1e-15
#define ROOT_RTOL (4 * DBL_EPSILON)
#define ROOT_STEPS 100
static int brent(const tilt_fn *g, double a, double b, double fa, double fb, double *root)
{
    double c = a, fc = fa, step = b - a, before = step;   /* c: the bracket's far end */
    for (int i = 0; i < ROOT_STEPS; i++) {
        if ((fb > 0 && fc > 0) || (fb < 0 && fc < 0)) {   /* the root is in [a, b] */
            c = a;
            fc = fa;
            step = before = b - a;
        }
        if (fabs(fc) < fabs(fb)) {   /* b the best estimate so far */
            a = b; b = c; c = a;
            fa = fb; fb = fc; fc = fa;
        }
        double tol = 0.5 * (ROOT_XTOL + ROOT_RTOL * fabs(b));
        double half = 0.5 * (c - b);
        if (fb == 0 || fabs(half) <= tol) {
            *root = b;
            return 1;
        }
        if (fabs(before) < tol || fabs(fa) <= fabs(fb)) {
            step = before = half;                 /* bisect */
        } else {
            double s = fb / fa, p, q;
            if (a == c) {                         /* secant */
                p = 2 * half * s;
                q = 1 - s;
            } else {                              /* inverse quadratic interpolation */
                double qa = fa / fc, r = fb / fc;
                p = s * (2 * half * qa * (qa - r) - (b - a) * (r - 1));
                q = (qa - 1) * (r - 1) * (s - 1);
            }
            if (p > 0) q = -q;
            else p = -p;
            double limit = 3 * half * q - fabs(tol * q), last = fabs(before * q);
            if (2 * p < (limit < last ? limit : last)) {   /* accepted */
                before = step;
                step = p / q;
            } else {
                step = before = half;
            }
        }
        a = b;
        fa = fb;
        b += fabs(step) > tol ? step : (half > 0 ? tol : -tol);
        if (tilt_minus_level(g, b, &fb)) return -1;
    }
    return 0;
}

/* times[i] = t0 + i (t1 - t0) / (n - 1), the last t1 (np.linspace) */
static void even(double t0, double t1, long n, double *times)
{
    double step = (t1 - t0) / (double)(n - 1);
    for (long i = 0; i < n; i++) times[i] = (double)i * step + t0;
    times[n - 1] = t1;
}

static double mechanical_energy(const double *y, const ballc_parameters_t *prepared,
                                double *kinetic)
{
    double e[BALLC_MAX_ENERGY_NOUT];
    ballc_energy(y, prepared, e);
    double sum = 0.0;
    for (int i = 0; i < BALLC_ENERGY_NOUT(prepared->n_planes); i++) sum += e[i];
    *kinetic = e[0];
    return sum;
}

int ballc_orbit_measure(ballc_states_fn states, void *ctx, double t0, double t1,
                        const double *axis, double guess, const ballc_orbit_tolerances *tol,
                        ballc_orbit *out)
{
    const long grid = BALLC_ORBIT_TILT_SAMPLES + 1;   /* the test's samples per period */
    double span = BALLC_ORBIT_TILT_SAMPLES * (t1 - t0) / guess;
    if (!(span >= 0 && span < 1e7)) return 0;
    ballc_parameters_t prepared;
    if (ballc_parameters_init(&prepared, tol->params) != BALLC_OK) return -1;
    const int n = prepared.n_states;   /* the solution's rows: the run's states */
    long samples = (long)span + 2;
    long rows = samples > 2 * grid ? samples : 2 * grid;
    double *times = malloc((size_t)rows * sizeof(double));
    double *ys = malloc((size_t)rows * n * sizeof(double));
    int found = 0;
    if (!times || !ys) { found = -2; goto done; }
    /* criterion 3: the tilt's upward crossings of its middle level */
    even(t0, t1, samples, times);
    if (states(ctx, samples, times, ys)) { found = -1; goto done; }
    double highest = -INFINITY, lowest = INFINITY;
    for (long i = 0; i < samples; i++) {
        double a_z = ballc_orbit_tilt(ys + (size_t)i * n, axis);
        if (isnan(a_z)) goto done;
        ys[(size_t)i * n] = a_z;   /* kept in the row's first slot */
        if (a_z > highest) highest = a_z;
        if (a_z < lowest) lowest = a_z;
    }
    if (highest - lowest < 1e-6) goto done;   /* no wobble to measure */
    tilt_fn g = {states, ctx, axis, 0.5 * (highest + lowest)};
    double ups[3];
    int n_ups = 0;
    for (long i = 0; i + 1 < samples && n_ups < 3; i++) {
        double before = ys[(size_t)i * n] - g.level, after = ys[(size_t)(i + 1) * n] - g.level;
        if (!(before < 0 && 0 <= after)) continue;
        int got = brent(&g, times[i], times[i + 1], before, after, &ups[n_ups]);
        if (got < 0) { found = -1; goto done; }
        if (!got) goto done;
        n_ups++;
    }
    if (n_ups < 3) goto done;
    double c0 = ups[0], c1 = ups[1], c2 = ups[2], period = c1 - c0;
    double y0[N], y1[N], y2[N];
    if (states(ctx, 1, &c0, y0) || states(ctx, 1, &c1, y1) || states(ctx, 1, &c2, y2)) {
        found = -1;
        goto done;
    }
    double speed = 0.0, atol_max = tol->atol[0];
    for (int i = 0; i < 3; i++)
        if (fabs(y1[BALLC_STATE_VX + i]) > speed) speed = fabs(y1[BALLC_STATE_VX + i]);
    for (int i = 1; i < n; i++)
        if (tol->atol[i] > atol_max) atol_max = tol->atol[i];
    if (fabs((c2 - c1) - period) * speed > tol->rest_factor * (atol_max + tol->rtol)) goto done;
    /* criterion 4: G from c0 to c1 moves the integrated second period onto the third */
    ballc_motion motion;
    fit(y0, y1, axis, &motion);
    ballc_motion_planes(&motion, tol->params);
    even(0.0, period, grid, times);
    for (long j = 0; j < grid; j++) {
        double s = times[j];
        times[j] = c0 + s;
        times[grid + j] = c1 + s;
    }
    if (states(ctx, 2 * grid, times, ys)) { found = -1; goto done; }
    double worst = 0.0;
    for (long j = 0; j < grid; j++) {
        double moved[N];
        const double *second = ys + (size_t)(grid + j) * n;
        ballc_motion_apply(&motion, ys + (size_t)j * n, 0, moved);
        for (int i = 0; i < n; i++) {
            if (i == BALLC_STATE_DISSIPATED_NORMAL || i == BALLC_STATE_DISSIPATED_TANGENTIAL)
                continue;   /* the work is checked as energy (criterion 5) */
            double misfit = fabs(moved[i] - second[i]) / (tol->atol[i]
                                                          + tol->rtol * fabs(second[i]));
            if (isnan(misfit)) goto done;
            if (misfit > worst) worst = misfit;
        }
    }
    if (!(worst <= tol->rest_factor)) goto done;
    /* criterion 5: the mechanical energy changed by no more than the tolerance allows */
    double kinetic, unused;
    double change = mechanical_energy(y2, &prepared, &unused)
                    - mechanical_energy(y0, &prepared, &kinetic);
    if (!(fabs(change) <= tol->rest_factor * tol->rtol * kinetic + tol->energy_threshold))
        goto done;
    out->c0 = c0;
    out->period = period;
    out->g = motion;
    out->rate = change / (c2 - c0);
    found = 1;
done:
    free(times);
    free(ys);
    return found;
}

int ballc_orbit_states(const ballc_orbit *orbit, ballc_states_fn base, void *ctx, long n,
                       const double *t, double *y)
{
    if (n <= 0) return 0;
    double *at = malloc((size_t)n * sizeof(double)), *power = malloc((size_t)n * sizeof(double));
    int status = 0;
    if (!at || !power) { status = -2; goto done; }
    double c0 = orbit->c0, period = orbit->period;
    for (long i = 0; i < n; i++) {   /* t = c0 + k T + s */
        double k = floor((t[i] - c0) / period);
        double s = t[i] - c0 - k * period;
        if (s < 0.0) s = 0.0;
        if (s > period) s = period;
        at[i] = c0 + s;
        power[i] = k;
    }
    if (base(ctx, n, at, y)) { status = -1; goto done; }
    for (long i = 0; i < n; i++) {
        ballc_motion g;
        ballc_motion_power(&orbit->g, power[i], &g);
        ballc_motion_apply(&g, y + (size_t)i * states_of(&g), 0, y + (size_t)i * states_of(&g));
    }
done:
    free(at);
    free(power);
    return status;
}
