/* dop853: Dormand & Prince's explicit Runge-Kutta pair of order 8(5,3), scipy's DOP853
 * step by step (see _dop853.h).  The coefficients are scipy's dop853_coefficients.py,
 * printed to 17 significant digits (tests/test_dop853.py compares them with scipy's). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "_dop853.h"
#include "_integrator_private.h"

static const double A[16][16] = {
    {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.05260015195876773, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.0197250569845379, 0.0591751709536137, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.02958758547680685, 0.0, 0.08876275643042054, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.2413651341592667, 0.0, -0.8845494793282861, 0.924834003261792, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.037037037037037035, 0.0, 0.0, 0.17082860872947386, 0.12546768756682242, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.037109375, 0.0, 0.0, 0.17025221101954405, 0.06021653898045596, -0.017578125, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.03709200011850479, 0.0, 0.0, 0.17038392571223998, 0.10726203044637328, -0.015319437748624402, 0.008273789163814023, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.6241109587160757, 0.0, 0.0, -3.3608926294469414, -0.868219346841726, 27.59209969944671, 20.154067550477894, -43.48988418106996, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.47766253643826434, 0.0, 0.0, -2.4881146199716677, -0.590290826836843, 21.230051448181193, 15.279233632882423, -33.28821096898486, -0.020331201708508627, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {-0.9371424300859873, 0.0, 0.0, 5.186372428844064, 1.0914373489967295, -8.149787010746927, -18.52006565999696, 22.739487099350505, 2.4936055526796523, -3.0467644718982196, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {2.273310147516538, 0.0, 0.0, -10.53449546673725, -2.0008720582248625, -17.9589318631188, 27.94888452941996, -2.8589982771350235, -8.87285693353063, 12.360567175794303, 0.6433927460157636, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.054293734116568765, 0.0, 0.0, 0.0, 0.0, 4.450312892752409, 1.8915178993145003, -5.801203960010585, 0.3111643669578199, -0.1521609496625161, 0.20136540080403034, 0.04471061572777259, 0.0, 0.0, 0.0, 0.0},
    {0.056167502283047954, 0.0, 0.0, 0.0, 0.0, 0.0, 0.25350021021662483, -0.2462390374708025, -0.12419142326381637, 0.15329179827876568, 0.00820105229563469, 0.007567897660545699, -0.008298, 0.0, 0.0, 0.0},
    {0.03183464816350214, 0.0, 0.0, 0.0, 0.0, 0.028300909672366776, 0.053541988307438566, -0.05492374857139099, 0.0, 0.0, -0.00010834732869724932, 0.0003825710908356584, -0.00034046500868740456, 0.1413124436746325, 0.0, 0.0},
    {-0.42889630158379194, 0.0, 0.0, 0.0, 0.0, -4.697621415361164, 7.683421196062599, 4.06898981839711, 0.3567271874552811, 0.0, 0.0, 0.0, -0.0013990241651590145, 2.9475147891527724, -9.15095847217987, 0.0},
};
static const double B[12] = {0.054293734116568765, 0.0, 0.0, 0.0, 0.0, 4.450312892752409, 1.8915178993145003, -5.801203960010585, 0.3111643669578199, -0.1521609496625161, 0.20136540080403034, 0.04471061572777259};
static const double C[16] = {0.0, 0.05260015195876773, 0.0789002279381516, 0.1183503419072274, 0.2816496580927726, 0.3333333333333333, 0.25, 0.3076923076923077, 0.6512820512820513, 0.6, 0.8571428571428571, 1.0, 1.0, 0.1, 0.2, 0.7777777777777778};
static const double E3[13] = {-0.18980075407240762, 0.0, 0.0, 0.0, 0.0, 4.450312892752409, 1.8915178993145003, -5.801203960010585, -0.4226823213237919, -0.1521609496625161, 0.20136540080403034, 0.02265179219836082, 0.0};
static const double E5[13] = {0.01312004499419488, 0.0, 0.0, 0.0, 0.0, -1.2251564463762044, -0.4957589496572502, 1.6643771824549864, -0.35032884874997366, 0.3341791187130175, 0.08192320648511571, -0.022355307863886294, 0.0};
static const double D_[4][16] = {
    {-8.428938276109013, 0.0, 0.0, 0.0, 0.0, 0.5667149535193777, -3.0689499459498917, 2.38466765651207, 2.117034582445028, -0.871391583777973, 2.2404374302607883, 0.6315787787694688, -0.08899033645133331, 18.148505520854727, -9.194632392478356, -4.436036387594894},
    {10.427508642579134, 0.0, 0.0, 0.0, 0.0, 242.28349177525817, 165.20045171727028, -374.5467547226902, -22.113666853125306, 7.733432668472264, -30.674084731089398, -9.332130526430229, 15.697238121770845, -31.139403219565178, -9.35292435884448, 35.81684148639408},
    {19.985053242002433, 0.0, 0.0, 0.0, 0.0, -387.0373087493518, -189.17813819516758, 527.8081592054236, -11.57390253995963, 6.8812326946963, -1.0006050966910838, 0.7777137798053443, -2.778205752353508, -60.19669523126412, 84.32040550667716, 11.99229113618279},
    {-25.69393346270375, 0.0, 0.0, 0.0, 0.0, -154.18974869023643, -231.5293791760455, 357.6391179106141, 93.40532418362432, -37.45832313645163, 104.0996495089623, 29.8402934266605, -43.53345659001114, 96.32455395918828, -39.17726167561544, -149.72683625798564},
};

/* sum[c] = sum_j w[j] K[j][c] over j < m with w[j] != 0, j ascending (a row at a time,
 * so the inner loop runs along contiguous memory; for each c the additions are those of
 * the plain per-state sum, in the same order). */
static void combine(int n, const double *w, int m, const double *restrict K,
                    double *restrict sum)
{
    for (int c = 0; c < n; c++) sum[c] = 0;
    for (int j = 0; j < m; j++) {
        const double a = w[j];
        if (a == 0) continue;
        const double *restrict k = K + (size_t)j * n;
        for (int c = 0; c < n; c++) sum[c] += a * k[c];
    }
}

/* Stages first .. last - 1 from (t, y): K[s] = f(t + C[s] h, y + h sum_j A[s][j] K[j]).
 * Returns 0, or the first nonzero return of fun. */
static int stages(dop853_fun fun, void *ctx, int n, double t, double h, const double *y,
                  double *K, int first, int last, double *ytmp)
{
    for (int s = first; s < last; s++) {
        combine(n, A[s], s, K, ytmp);
        for (int c = 0; c < n; c++) ytmp[c] = y[c] + h * ytmp[c];
        int rc = fun(ctx, t + C[s] * h, ytmp, K + s * n);
        if (rc != 0) return rc;
    }
    return 0;
}

int dop853_attempt(dop853_fun fun, void *ctx, int n, double t, double h, const double *y,
                   double *K, double *y_new, double *ytmp)
{
    int rc = stages(fun, ctx, n, t, h, y, K, 1, DOP853_STAGES, ytmp);
    if (rc != 0) return rc;
    combine(n, B, DOP853_STAGES, K, y_new);
    for (int c = 0; c < n; c++) y_new[c] = y[c] + h * y_new[c];
    return fun(ctx, t + h, y_new, K + DOP853_STAGES * n);
}

double dop853_error_norm(int n, int count, const double *K, double h, const double *scale,
                         double *e5, double *e3)
{
    combine(n, E5, DOP853_STAGES + 1, K, e5);
    combine(n, E3, DOP853_STAGES + 1, K, e3);
    double e5_2 = 0, e3_2 = 0;
    for (int c = 0; c < n; c++) {
        double a = e5[c] / scale[c], b = e3[c] / scale[c];
        e5_2 += a * a;
        e3_2 += b * b;
    }
    if (e5_2 == 0 && e3_2 == 0) return 0;
    return fabs(h) * e5_2 / sqrt((e5_2 + 0.01 * e3_2) * count);
}

int dop853_dense(dop853_fun fun, void *ctx, int n, double t_old, double h,
                 const double *y_old, const double *y, double *K, double *F, double *ytmp)
{
    int rc = stages(fun, ctx, n, t_old, h, y_old, K, DOP853_STAGES + 1,
                    DOP853_STAGES_EXTENDED, ytmp);
    if (rc != 0) return rc;
    const double *f_old = K, *f = K + DOP853_STAGES * n;
    for (int c = 0; c < n; c++) {
        double delta = y[c] - y_old[c];
        F[c] = delta;
        F[n + c] = h * f_old[c] - delta;
        F[2 * n + c] = 2 * delta - h * (f[c] + f_old[c]);
    }
    for (int i = 0; i < 4; i++) {
        double *row = F + (3 + i) * n;
        combine(n, D_[i], DOP853_STAGES_EXTENDED, K, row);
        for (int c = 0; c < n; c++) row[c] *= h;
    }
    return 0;
}

double dop853_eval_scalar(double x, double a0, const double *a)
{
    /* scipy's Dop853DenseOutput: from F6 inwards, alternately times x and times 1 - x */
    double v = 0;
    for (int i = DOP853_DENSE_TERMS - 1, k = 0; i >= 0; i--, k++) {
        v += a[i];
        v *= (k % 2 == 0) ? x : 1 - x;
    }
    return a0 + v;
}

void dop853_eval(int n, double x, const double *y_old, const double *F, double *out)
{
    double a[DOP853_DENSE_TERMS];
    for (int c = 0; c < n; c++) {
        for (int j = 0; j < DOP853_DENSE_TERMS; j++) a[j] = F[j * n + c];
        out[c] = dop853_eval_scalar(x, y_old[c], a);
    }
}

void dop853_constants(double *out)
{
    memcpy(out, A, sizeof A); out += 256;
    memcpy(out, B, sizeof B); out += 12;
    memcpy(out, C, sizeof C); out += 16;
    memcpy(out, E3, sizeof E3); out += 13;
    memcpy(out, E5, sizeof E5); out += 13;
    memcpy(out, D_, sizeof D_);
}

/* ---- the integrator's DOP853 step (see _dop853.h; the loop is _integrator.c's) ---- */

/* The function the DOP853 stages call: call_fun (counted, checked, profiled). */
static int dop853_call(void *ctx, double t, const double *y, double *f)
{
    solver_t *s = ctx;
    return call_fun(s, t, y, f);
}

/* RungeKutta._step_impl with DOP853's error norm.  Returns 1 on success, 0 on failure
 * (message set).  A step whose stages cannot be evaluated is rejected with its size
 * halved (scipy would carry the NaN on). */
int dop853_step(solver_t *s)
{
    const radau5_problem *p = s->p;
    const int n = s->n;
    const double t = s->t;
    double *y = s->y, *y_new = s->y_new, *K = s->K;
    const double exponent = -1.0 / (DOP853_ERROR_ORDER + 1);
    double min_step = 10 * fabs(nextafter(t, s->direction * INFINITY) - t);
    double h_abs = s->h_abs > p->max_step ? p->max_step
                   : (s->h_abs < min_step ? min_step : s->h_abs);
    int rejected = 0;
    double h = 0, t_new = t;
    memcpy(K, s->f, n * sizeof(double));
    s->k_stale = 1;   /* until an attempt is accepted: K no longer holds the last step's */
    for (;;) {
        if (!attempt_size(s, t, min_step, &h_abs, &h, &t_new)) return 0;
        if (dop853_attempt(dop853_call, s, n, t, h, y, K, y_new, s->tmp) != 0) {
            h_abs *= 0.5;
            rejected = 1;
            s->r->nreject++;
            continue;
        }
        for (int c = 0; c < n; c++)
            s->scale[c] = s->atol[c] + fmax(fabs(y[c]), fabs(y_new[c])) * s->rtol;
        double error_norm = dop853_error_norm(n, s->n_norm, K, h, s->scale, s->err, s->ZE);
        if (error_norm < 1) {
            double factor = error_norm == 0 ? MAX_FACTOR
                            : fmin(MAX_FACTOR, 0.9 * pow(error_norm, exponent));
            if (rejected) factor = fmin(1, factor);
            h_abs *= factor;
            break;
        }
        h_abs *= fmax(MIN_FACTOR, 0.9 * pow(error_norm, exponent));
        rejected = 1;
        s->r->nreject++;
    }
    /* Hairer's stiffness test (dop853.f, after each accepted step here): h lambda
     * estimated from the last two stages at c = 1, K[11] at the stage argument (s->tmp,
     * as dop853_attempt left it) and K[12] at y_new; 15 estimates in a row beyond the
     * stability boundary (6.1) mean the steps are bounded by stability, not accuracy */
    double num = 0, den = 0;
    for (int c = 0; c < n; c++) {
        double dk = K[DOP853_STAGES * n + c] - K[(DOP853_STAGES - 1) * n + c];
        double dy = y_new[c] - s->tmp[c];
        num += dk * dk;
        den += dy * dy;
    }
    if (den > 0 && fabs(h) * sqrt(num / den) > 6.1) {
        s->nonstiff_steps = 0;
        if (++s->stiff_steps == 15 && isnan(s->r->stiff_at)) s->r->stiff_at = t;
    } else if (++s->nonstiff_steps == 6) {
        s->stiff_steps = 0;
    }
    s->h_abs = h_abs;
    memcpy(s->y_old, y, n * sizeof(double));
    memcpy(y, y_new, n * sizeof(double));
    memcpy(s->f, K + DOP853_STAGES * n, n * sizeof(double));
    s->t_old = t;
    s->t = t_new;
    s->dense_end = t_new;
    s->dense_ready = 0;
    s->dense_dop853 = 1;
    s->k_stale = 0;
    s->have_sol = 1;
    s->r->nstep++;
    return 1;
}

int dop853_prepare_dense(solver_t *s)
{
    if (s->dense_ready) return 0;
    if (s->k_stale) {   /* a step failed after this one without its dense output made */
        snprintf(s->r->message, sizeof s->r->message,
                 "the dense output of the step from t = %.17g was lost to a failed step",
                 s->t_old);
        return -1;
    }
    if (dop853_dense(dop853_call, s, s->n, s->t_old, s->t - s->t_old, s->y_old, s->y, s->K,
                     s->Fdense, s->tmp) != 0) {
        snprintf(s->r->message, sizeof s->r->message,
                 "the right-hand side cannot be evaluated for the dense output of the step "
                 "from t = %.17g", s->t_old);
        return -1;
    }
    s->dense_ready = 1;
    return 0;
}
