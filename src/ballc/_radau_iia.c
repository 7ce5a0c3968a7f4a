/* See _radau_iia.h.  A line-by-line port of scipy.integrate.Radau's step (scipy 1.17,
 * scipy/integrate/_ivp/radau.py), for dense Jacobians.  Comments name the scipy function
 * each part mirrors.  The loop around it is _integrator.c's. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "_integrator_private.h"
#include "_lu.h"

void radau_iia_init_constants(constants_t *k)
{
    const double S6 = sqrt(6.0);
    k->C[0] = (4 - S6) / 10; k->C[1] = (4 + S6) / 10; k->C[2] = 1;
    k->E[0] = (-13 - 7 * S6) / 3; k->E[1] = (-13 + 7 * S6) / 3; k->E[2] = -1.0 / 3;
    k->mu_real = 3 + pow(3, 2.0 / 3) - pow(3, 1.0 / 3);
    k->mu_complex = (3 + 0.5 * (pow(3, 1.0 / 3) - pow(3, 2.0 / 3)))
                    - 0.5 * I * (pow(3, 5.0 / 6) + pow(3, 7.0 / 6));
    const double T[3][3] = {
        {0.09443876248897524, -0.14125529502095421, 0.03002919410514742},
        {0.25021312296533332, 0.20412935229379994, -0.38294211275726192},
        {1, 1, 0}};
    const double TI[3][3] = {
        {4.17871859155190428, 0.32768282076106237, 0.52337644549944951},
        {-4.17871859155190428, -0.32768282076106237, 0.47662355450055044},
        {0.50287263494578682, -2.57192694985560522, 0.59603920482822492}};
    const double P[3][3] = {
        {13.0 / 3 + 7 * S6 / 3, -23.0 / 3 - 22 * S6 / 3, 10.0 / 3 + 5 * S6},
        {13.0 / 3 - 7 * S6 / 3, -23.0 / 3 + 22 * S6 / 3, 10.0 / 3 - 5 * S6},
        {1.0 / 3, -8.0 / 3, 10.0 / 3}};
    memcpy(k->T, T, sizeof T);
    memcpy(k->TI, TI, sizeof TI);
    memcpy(k->P, P, sizeof P);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) k->PT[i][j] = P[j][i];
    for (int j = 0; j < 3; j++) k->ti_complex[j] = TI[1][j] + I * TI[2][j];
}

/* out = M x for three stage vectors of n states each (x and out: 3 x n, row by stage):
 * out[i n + c] = M[i][0] x[c] + M[i][1] x[n + c] + M[i][2] x[2 n + c], in that order.
 * M's entries as locals: through a pointer the compiler reloads them after every store. */
static inline void stage_combination(int n, const double M[3][3], const double *restrict x,
                                     double *restrict out)
{
    const double m00 = M[0][0], m01 = M[0][1], m02 = M[0][2],
                 m10 = M[1][0], m11 = M[1][1], m12 = M[1][2],
                 m20 = M[2][0], m21 = M[2][1], m22 = M[2][2];
    for (int c = 0; c < n; c++) {
        double x0 = x[c], x1 = x[n + c], x2 = x[2 * n + c];
        out[c] = m00 * x0 + m01 * x1 + m02 * x2;
        out[n + c] = m10 * x0 + m11 * x1 + m12 * x2;
        out[2 * n + c] = m20 * x0 + m21 * x1 + m22 * x2;
    }
}

/* Split the states into coupled ones (a nonzero entry in their column of J) and
 * outputs (a zero column), and gather J_oc.  The split is exact for this J: the
 * Newton matrix built from it is block-triangular, whatever made the column zero. */
static void partition(solver_t *s)
{
    const int n = s->n;
    s->nc = s->no = 0;
    for (int j = 0; j < n; j++) {
        int zero = 1;
        for (int i = 0; i < n && zero; i++) zero = s->J[i * n + j] == 0.0;
        if (zero) s->oidx[s->no++] = j;
        else s->cidx[s->nc++] = j;
    }
    int k = 0;   /* J_oc is sparse (x, y: one velocity each; idle deflections: none) */
    for (int a = 0; a < s->no; a++) {
        s->joc_start[a] = k;
        for (int b = 0; b < s->nc; b++) {
            double v = s->J[s->oidx[a] * n + s->cidx[b]];
            if (v != 0.0) {
                s->Joc[k] = v;
                s->joc_col[k++] = b;
            }
        }
    }
    s->joc_start[s->no] = k;
}

int radau_iia_jacobian(solver_t *s, double t, const double *y)
{
    PROF_START;
    s->r->njev++;
    s->jac_t = t;
    int rc = s->p->jac(s->p->ctx, t, y, s->J);
    for (int i = 0; i < s->n * s->n && rc == 0 && !s->p->outputs_checked; i++)
        if (!isfinite(s->J[i])) rc = -1;
    if (rc == 0) partition(s);
    PROF_STOP(RADAU5_PROF_JAC);
    return rc == 0 ? 0 : -1;
}

/* LU of the coupled block of MU_REAL / h I - J and MU_COMPLEX / h I - J (row-major,
 * as J; see _lu.h and partition). */
static int factor(solver_t *s, double h)
{
    PROF_START;
    const int n = s->n, nc = s->nc;
    double mr = s->k.mu_real / h;
    cplx mc = s->k.mu_complex / h;
    for (int a = 0; a < nc; a++)
        for (int b = 0; b < nc; b++) {
            double v = -s->J[s->cidx[a] * n + s->cidx[b]];
            s->LU_real[a * nc + b] = v + (a == b ? mr : 0.0);
            s->LU_complex[a * nc + b] = v + (a == b ? mc : 0.0);
        }
    s->lu_mr = mr;
    s->lu_mc = mc;
    int info_r = ballc_lu_factor(nc, s->LU_real, s->piv_real);
    int info_c = ballc_lu_factor_complex(nc, s->LU_complex, s->piv_complex);
    s->r->nlu += 2;
    s->lu_valid = 1;
    PROF_STOP(RADAU5_PROF_FACTOR);
    return (info_r == BALLC_LU_OK && info_c == BALLC_LU_OK) ? 0 : -1;
}

/* (mu/h I - J) x = b, b (n) overwritten by x: the coupled block by LU, then each
 * output o from its row, mu/h x_o - J_oc x_c = b_o. */
static void solve_real(solver_t *s, double *b)
{
    PROF_START;
    const int nc = s->nc, no = s->no;
    if (no == 0) {
        ballc_lu_solve(nc, s->LU_real, s->piv_real, b);
    } else {
        double *x = s->xc;
        for (int a = 0; a < nc; a++) x[a] = b[s->cidx[a]];
        ballc_lu_solve(nc, s->LU_real, s->piv_real, x);
        for (int a = 0; a < nc; a++) b[s->cidx[a]] = x[a];
        for (int o = 0; o < no; o++) {
            double v = b[s->oidx[o]];
            for (int q = s->joc_start[o]; q < s->joc_start[o + 1]; q++)
                v += s->Joc[q] * x[s->joc_col[q]];
            b[s->oidx[o]] = v / s->lu_mr;
        }
    }
    PROF_STOP(RADAU5_PROF_SOLVE);
}

static void solve_complex(solver_t *s, cplx *b)
{
    PROF_START;
    const int nc = s->nc, no = s->no;
    if (no == 0) {
        ballc_lu_solve_complex(nc, s->LU_complex, s->piv_complex, b);
    } else {
        cplx *x = s->xcc;
        for (int a = 0; a < nc; a++) x[a] = b[s->cidx[a]];
        ballc_lu_solve_complex(nc, s->LU_complex, s->piv_complex, x);
        for (int a = 0; a < nc; a++) b[s->cidx[a]] = x[a];
        cplx inverse = 1.0 / s->lu_mc;
        for (int o = 0; o < no; o++) {
            cplx v = b[s->oidx[o]];
            for (int q = s->joc_start[o]; q < s->joc_start[o + 1]; q++)
                v += s->Joc[q] * x[s->joc_col[q]];
            b[s->oidx[o]] = v * inverse;
        }
    }
    PROF_STOP(RADAU5_PROF_SOLVE);
}

/* radau.solve_collocation_system: Z (3 x n) starts as Z0 and ends as the solution. */
static int solve_collocation(solver_t *s, double t, double h, double *restrict Z,
                             int *n_iter, double *rate_out, int *have_rate_out,
                             double *theta_out)
{
    const int maxiter = s->newton_maxiter;
    const constants_t *k = &s->k;
    const int n = s->n;
    double M_real = k->mu_real / h;
    cplx M_complex = k->mu_complex / h;
    /* distinct buffers: restrict lets the compiler vectorise the stage loops */
    double *restrict W = s->W, *restrict F = s->F, *restrict dW = s->dW, *restrict yi = s->tmp;
    const double *restrict inv_scale = s->inv_scale;
    cplx *restrict fc = s->ctmp;
    /* TI's first row as locals: the stage loop below keeps them in registers (through k
     * the compiler reloads them for every element) */
    const double Ti00 = k->TI[0][0], Ti01 = k->TI[0][1], Ti02 = k->TI[0][2];
    stage_combination(n, k->TI, Z, W);
    const cplx tc0 = k->ti_complex[0], tc1 = k->ti_complex[1], tc2 = k->ti_complex[2];
    double dW_norm_old = 0, rate = 0, theta = 0, rate_prev = 0;
    int have_old = 0, have_rate = 0, converged = 0, it;
    for (it = 0; it < maxiter; it++) {
        int finite = 1;
        for (int i = 0; i < 3 && finite; i++) {
            for (int c = 0; c < n; c++) yi[c] = s->y[c] + Z[i * n + c];
            if (call_fun(s, t + h * k->C[i], yi, F + i * n) != 0) finite = 0;
        }
        if (!finite) break;
        for (int c = 0; c < n; c++) {
            double f0 = F[c], f1 = F[n + c], f2 = F[2 * n + c];
            dW[c] = f0 * Ti00 + f1 * Ti01 + f2 * Ti02 - M_real * W[c];
            fc[c] = f0 * tc0 + f1 * tc1 + f2 * tc2 - M_complex * (W[n + c] + I * W[2 * n + c]);
        }
        solve_real(s, dW);
        solve_complex(s, fc);
        double sum0 = 0, sum1 = 0, sum2 = 0;   /* one partial sum per stage: three short
                                                * chains of dependent additions, not one */
        for (int c = 0; c < n; c++) {
            double v0 = dW[c] * inv_scale[c], v1 = creal(fc[c]), v2 = cimag(fc[c]);
            dW[n + c] = v1;
            dW[2 * n + c] = v2;
            v1 *= inv_scale[c];
            v2 *= inv_scale[c];
            sum0 += v0 * v0;
            sum1 += v1 * v1;
            sum2 += v2 * v2;
        }
        double dW_norm = sqrt((sum0 + sum1 + sum2) / (3 * n));
        if (!isfinite(dW_norm)) break;
        if (have_old) {
            rate = dW_norm / dW_norm_old;
            /* RADAU5's theta: the first ratio, then the geometric mean of the last two */
            theta = have_rate ? sqrt(rate * rate_prev) : rate;
            rate_prev = rate;
            have_rate = 1;
        }
        if (have_rate && (rate >= 1 ||
                          pow(rate, maxiter - it) / (1 - rate) * dW_norm > s->newton_tol))
            break;
        for (int i = 0; i < 3 * n; i++) W[i] += dW[i];
        stage_combination(n, k->T, W, Z);
        if (dW_norm == 0 || (have_rate && rate / (1 - rate) * dW_norm < s->newton_tol)) {
            converged = 1;
            break;
        }
        dW_norm_old = dW_norm;
        have_old = 1;
    }
    *n_iter = (it < maxiter ? it : maxiter - 1) + 1;
    *rate_out = rate;
    *have_rate_out = have_rate;
    *theta_out = theta;
    return converged;
}

/* radau.predict_factor */
static double predict_factor(double h_abs, double h_abs_old, int have_h_abs_old,
                             double error_norm, double error_norm_old, int have_error_norm_old)
{
    double multiplier;
    if (!have_error_norm_old || !have_h_abs_old || error_norm == 0)
        multiplier = 1;
    else
        multiplier = h_abs / h_abs_old * pow(error_norm_old / error_norm, 0.25);
    return fmin(1, multiplier) * pow(error_norm, -0.25);   /* inf when error_norm == 0 */
}

/* Radau._step_impl.  Returns 1 on success, 0 on failure (message set). */
int radau_iia_step(solver_t *s)
{
    const radau5_problem *p = s->p;
    const constants_t *k = &s->k;
    const int n = s->n;
    const double t = s->t;
    double *y = s->y;

    double min_step = 10 * fabs(nextafter(t, s->direction * INFINITY) - t);
    double h_abs, h_abs_old = 0, error_norm_old = 0;
    int have_h_abs_old = 0, have_error_norm_old = 0;
    if (s->h_abs > p->max_step) {
        h_abs = p->max_step;
    } else if (s->h_abs < min_step) {
        h_abs = min_step;
    } else {
        h_abs = s->h_abs;
        h_abs_old = s->h_abs_old; have_h_abs_old = s->have_h_abs_old;
        error_norm_old = s->error_norm_old; have_error_norm_old = s->have_error_norm_old;
    }

    const int ctrl = s->ctrl;
    int rejected = 0, converged = 0, n_iter = 0, have_rate = 0;
    double rate = 0, theta = 0, h = 0, t_new = t, error_norm = 0, safety = 0;
    double *Z = s->Znew, *y_new = s->y_new, *err = s->err, *ZE = s->ZE;
    for (;;) {   /* while not step_accepted */
        if (!attempt_size(s, t, min_step, &h_abs, &h, &t_new)) return 0;

        if (!s->have_sol) {
            memset(s->Z0, 0, 3 * n * sizeof(double));
        } else {
            for (int i = 0; i < 3; i++) {
                dense(s, t + h * k->C[i], s->Z0 + i * n);
                for (int c = 0; c < n; c++) s->Z0[i * n + c] -= y[c];
            }
        }
        for (int c = 0; c < n; c++) {
            s->scale[c] = s->atol[c] + fabs(y[c]) * s->rtol;
            s->inv_scale[c] = 1.0 / s->scale[c];
        }

        converged = 0;
        int tried_ahead = 0;
        while (!converged) {
            int lu_ok = 1;
            if (!s->lu_valid) lu_ok = factor(s, h) == 0;
            memcpy(Z, s->Z0, 3 * n * sizeof(double));
            converged = lu_ok && solve_collocation(s, t, h, Z, &n_iter, &rate, &have_rate,
                                                  &theta);
            if (!lu_ok) n_iter = 0;
            if (!converged) {
                /* The first step of a segment whose Newton fails with the Jacobian of its
                 * start: try once more with the Jacobian at the explicit Euler prediction
                 * of the step's end.  A contact law can be singular where a segment starts
                 * (the compliant law's yield: stiffness ~ n/t from contact start), where
                 * the start's Jacobian holds none of the stiffness every later point has;
                 * halving h then never helps.  Only where the caller asks (problem
                 * jacobian_ahead: segments with a compliant contact). */
                if (s->p->jacobian_ahead && s->current_jac && !s->have_sol && !tried_ahead
                    && h != 0) {
                    tried_ahead = 1;
                    for (int c = 0; c < n; c++) err[c] = y[c] + h * s->f[c];
                    if (radau_iia_jacobian(s, t + h, err) == 0) {
                        s->lu_valid = 0;
                        continue;
                    }
                    if (radau_iia_jacobian(s, t, y) != 0) {
                        snprintf(s->r->message, sizeof s->r->message,
                                 "the Jacobian cannot be evaluated at t = %.17g", t);
                        return 0;
                    }
                    s->lu_valid = 0;
                }
                if (s->current_jac) break;
                if (radau_iia_jacobian(s, t, y) != 0) {
                    snprintf(s->r->message, sizeof s->r->message,
                             "the Jacobian cannot be evaluated at t = %.17g", t);
                    return 0;
                }
                s->current_jac = 1;
                s->lu_valid = 0;
            }
        }
        if (!converged) {
            h_abs *= 0.5;
            s->lu_valid = 0;
            continue;
        }

        const double E0 = k->E[0] / h, E1 = k->E[1] / h, E2 = k->E[2] / h;
        for (int c = 0; c < n; c++) {
            y_new[c] = y[c] + Z[2 * n + c];
            ZE[c] = Z[c] * E0 + Z[n + c] * E1 + Z[2 * n + c] * E2;
            err[c] = s->f[c] + ZE[c];
        }
        solve_real(s, err);
        for (int c = 0; c < n; c++) {
            if (!(ctrl & RADAU5_CTRL_SCALE))
                s->scale[c] = s->atol[c] + fmax(fabs(y[c]), fabs(y_new[c])) * s->rtol;
            s->tmp[c] = err[c] / s->scale[c];
        }
        error_norm = rms(s->tmp, n);
        safety = 0.9 * (2 * s->newton_maxiter + 1) / (2 * s->newton_maxiter + n_iter);

        if (rejected && error_norm > 1) {
            for (int c = 0; c < n; c++) s->tmp[c] = y[c] + err[c];
            if (call_fun(s, t, s->tmp, err) != 0) {
                error_norm = INFINITY;   /* scipy would go on with NaN; reject instead */
            } else {
                for (int c = 0; c < n; c++) err[c] += ZE[c];
                solve_real(s, err);
                for (int c = 0; c < n; c++) s->tmp[c] = err[c] / s->scale[c];
                error_norm = rms(s->tmp, n);
            }
        }
        if (!(error_norm <= 1)) {
            double fac = (ctrl & RADAU5_CTRL_PRED)   /* RADAU5: the standard factor alone */
                         ? pow(error_norm, -0.25)
                         : predict_factor(h_abs, h_abs_old, have_h_abs_old, error_norm,
                                          error_norm_old, have_error_norm_old);
            h_abs *= fmax(MIN_FACTOR, safety * fac);
            s->lu_valid = 0;
            rejected = 1;
            s->r->nreject++;
            continue;
        }
        /* f at the new point: needed for the next step's error estimate. */
        if (call_fun(s, t_new, y_new, s->f_new) != 0) {
            h_abs *= 0.5;   /* not in scipy (it would carry NaN): treat as a failed step */
            s->lu_valid = 0;
            rejected = 1;
            s->r->nreject++;
            continue;
        }
        break;   /* step_accepted */
    }

    int recompute_jac = p->jacobian_every_step
                        || ((ctrl & RADAU5_CTRL_JAC) ? (have_rate && theta > 1e-3)
                                                     : (n_iter > 2 && have_rate && rate > 1e-3));
    const double max_factor = (ctrl & RADAU5_CTRL_LIMITS) ? 8.0 : MAX_FACTOR;
    double fac;
    if (ctrl & RADAU5_CTRL_PRED) {
        /* RADCOR: standard factor, and Gustafsson's from the last accepted step (plain
         * safety), each within the limits; the smaller one */
        double e = fmax(error_norm, 1e-10);
        fac = fmin(max_factor, fmax(MIN_FACTOR, safety * pow(e, -0.25)));
        if (s->have_acc) {
            double gus = 0.9 * h_abs / s->h_acc * pow(s->err_acc / (e * e), 0.25);
            fac = fmin(fac, fmin(max_factor, fmax(MIN_FACTOR, gus)));
        }
        s->h_acc = h_abs;
        s->err_acc = fmax(0.01, e);
        s->have_acc = 1;
    } else {
        fac = predict_factor(h_abs, h_abs_old, have_h_abs_old, error_norm,
                             error_norm_old, have_error_norm_old);
        fac = fmin(max_factor, safety * fac);
    }
    if ((ctrl & RADAU5_CTRL_LIMITS) && rejected && fac > 1)
        fac = 1;   /* RADCOR: no growth right after a rejection */
    int hold = (ctrl & RADAU5_CTRL_HOLD) ? (fac >= 1 && fac <= 1.2) : (fac < 1.2);
    if (!recompute_jac && hold)
        fac = 1;
    else
        s->lu_valid = 0;

    if (recompute_jac && t_new == s->t_bound)
        recompute_jac = 0;   /* the last step: nothing would use it (a new run starts anew) */
    if (recompute_jac) {
        if (radau_iia_jacobian(s, t_new, y_new) != 0) {
            snprintf(s->r->message, sizeof s->r->message,
                     "the Jacobian cannot be evaluated at t = %.17g", t_new);
            return 0;
        }
        s->current_jac = 1;
    } else {
        s->current_jac = 0;
    }
    s->h_abs_old = s->h_abs;
    s->have_h_abs_old = 1;
    s->error_norm_old = error_norm;
    s->have_error_norm_old = 1;
    s->h_abs = h_abs * fac;

    memcpy(s->y_old, y, n * sizeof(double));
    memcpy(y, y_new, n * sizeof(double));
    memcpy(s->f, s->f_new, n * sizeof(double));
    memcpy(s->Z, Z, 3 * n * sizeof(double));
    s->t_old = t;
    s->t = t_new;
    s->dense_end = t_new;
    /* _compute_dense_output: Q = Z^T P (n x 3), stored transposed: row j holds the x^(j+1)
     * coefficients of the n states (the layout of the stored dense output) */
    stage_combination(n, k->PT, Z, s->Q);
    s->have_sol = 1;
    s->dense_dop853 = 0;
    s->r->nstep++;
    s->r->nstep_implicit++;
    return 1;
}

/* The method's constants as the solver uses them, for tests/test_radau5_constants.py
 * (compared with scipy.integrate._ivp.radau).  out[RADAU5_N_CONSTANTS], see the header
 * for the layout. */
void radau5_constants(double *out)
{
    constants_t k;
    radau_iia_init_constants(&k);
    double *o = out;
    for (int i = 0; i < 3; i++) *o++ = k.C[i];
    for (int i = 0; i < 3; i++) *o++ = k.E[i];
    for (int i = 0; i < 3; i++) for (int j = 0; j < 3; j++) *o++ = k.T[i][j];
    for (int i = 0; i < 3; i++) for (int j = 0; j < 3; j++) *o++ = k.TI[i][j];
    for (int i = 0; i < 3; i++) for (int j = 0; j < 3; j++) *o++ = k.P[i][j];
    *o++ = k.mu_real;
    *o++ = creal(k.mu_complex);
    *o++ = cimag(k.mu_complex);
    for (int j = 0; j < 3; j++) *o++ = creal(k.ti_complex[j]);
    for (int j = 0; j < 3; j++) *o++ = cimag(k.ti_complex[j]);
    *o++ = NEWTON_MAXITER;
    *o++ = MIN_FACTOR;
    *o++ = MAX_FACTOR;
}
