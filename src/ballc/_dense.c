/* See _dense.h. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "_dense.h"

/* the first index whose value >= t (side "left"), clipped to [0, n - 1] */
static long first_at_or_after(const double *values, long stride, long n, double t)
{
    long lo = 0, hi = n;
    while (lo < hi) {
        long mid = lo + (hi - lo) / 2;
        if (values[mid * stride] < t) lo = mid + 1;
        else hi = mid;
    }
    return lo < n ? lo : n - 1;
}

void ballc_interpolant_at(const ballc_interpolant *f, double t, double *y)
{
    int w = f->width;
    if (f->n_steps <= 0) {
        for (int i = 0; i < w; i++) y[i] = NAN;
        return;
    }
    long k = first_at_or_after(f->steps + 1, 2, f->n_steps, t);
    double t_old = f->steps[2 * k], t_new = f->steps[2 * k + 1];
    double x = (t - t_old) / (t_new - t_old);
    int terms = f->kinds ? f->kinds[k] : f->terms;
    const double *c = f->coef + (size_t)k * (size_t)(1 + f->terms) * (size_t)w;
    const double *y_old = c, *q = c + w;
    if (terms == 3) {   /* Horner in x */
        for (int i = 0; i < w; i++) {
            double v = 0.0;
            for (int j = 2; j >= 0; j--) v = (v + q[j * w + i]) * x;
            y[i] = v + y_old[i];
        }
    } else {            /* alternating x and 1 - x, from the last term */
        double other = 1 - x;
        for (int i = 0; i < w; i++) {
            double v = 0.0;
            for (int j = terms - 1, m = 0; j >= 0; j--, m++)
                v = (v + q[j * w + i]) * (m % 2 == 0 ? x : other);
            y[i] = v + y_old[i];
        }
    }
}

void ballc_piecewise_at(const ballc_piecewise *s, double t, double *y)
{
    /* the first piece whose end > t (side "right"), clipped to the last */
    long lo = 0, hi = s->n_pieces;
    while (lo < hi) {
        long mid = lo + (hi - lo) / 2;
        if (s->ends[mid] <= t) lo = mid + 1;
        else hi = mid;
    }
    if (lo >= s->n_pieces) lo = s->n_pieces - 1;
    ballc_interpolant_at(&s->pieces[lo], t, y);
}

int ballc_piecewise_states(void *ctx, long n, const double *t, double *y)
{
    const ballc_piecewise *s = (const ballc_piecewise *)ctx;
    if (s->n_pieces <= 0) return -1;
    int w = s->pieces[0].width;
    for (long i = 0; i < n; i++) ballc_piecewise_at(s, t[i], y + (size_t)i * w);
    return 0;
}

/* ---- the owning buffer ---- */

#define grow ballc_grow

int ballc_grow(void **p, long *cap, long need, size_t size)
{
    if (need <= *cap) return 0;
    long c = *cap ? *cap : 16;
    while (c < need) c *= 2;
    void *q = realloc(*p, (size_t)c * size);
    if (!q) return -1;
    *p = q;
    *cap = c;
    return 0;
}

void ballc_dense_clear(ballc_dense *d)
{
    d->n_pieces = 0;
    d->total_steps = 0;
    d->total_coef = 0;
}

void ballc_dense_free(ballc_dense *d)
{
    free(d->t0); free(d->t1); free(d->step0); free(d->n_steps); free(d->terms);
    free(d->steps); free(d->coef); free(d->kinds); free(d->view);
    memset(d, 0, sizeof *d);
}

int ballc_dense_add(ballc_dense *d, double t0, double t1, long m, const double *steps,
                    const double *coef, const int *kinds, int terms, int width)
{
    long per = (long)(1 + terms) * width;
    long cp = d->cap_pieces;
    if (grow((void **)&d->t0, &cp, d->n_pieces + 1, sizeof(double))) return -1;
    if (cp != d->cap_pieces) {
        double *a = realloc(d->t1, (size_t)cp * sizeof(double));
        if (!a) return -1;
        d->t1 = a;
        long *b = realloc(d->step0, (size_t)cp * sizeof(long));
        if (!b) return -1;
        d->step0 = b;
        b = realloc(d->n_steps, (size_t)cp * sizeof(long));
        if (!b) return -1;
        d->n_steps = b;
        int *e = realloc(d->terms, (size_t)cp * sizeof(int));
        if (!e) return -1;
        d->terms = e;
        d->cap_pieces = cp;
    }
    long cs = d->cap_steps;
    if (grow((void **)&d->kinds, &cs, d->total_steps + m, sizeof(int))) return -1;
    if (cs != d->cap_steps) {
        double *a = realloc(d->steps, (size_t)cs * 2 * sizeof(double));
        if (!a) return -1;
        d->steps = a;
        d->cap_steps = cs;
    }
    if (grow((void **)&d->coef, &d->cap_coef, d->total_coef + m * per, sizeof(double)))
        return -1;
    long k = d->n_pieces++;
    d->t0[k] = t0;
    d->t1[k] = t1;
    d->step0[k] = d->total_steps;
    d->n_steps[k] = m;
    d->terms[k] = terms;
    d->width = width;
    if (m) {
        memcpy(d->steps + 2 * d->total_steps, steps, (size_t)m * 2 * sizeof(double));
        memcpy(d->coef + d->total_coef, coef, (size_t)(m * per) * sizeof(double));
        if (kinds) memcpy(d->kinds + d->total_steps, kinds, (size_t)m * sizeof(int));
        else for (long i = 0; i < m; i++) d->kinds[d->total_steps + i] = terms;
    }
    d->total_steps += m;
    d->total_coef += m * per;
    return 0;
}

const ballc_piecewise *ballc_dense_view(ballc_dense *d)
{
    if (grow((void **)&d->view, &d->cap_view, d->n_pieces, sizeof(ballc_interpolant)))
        return NULL;
    long coef = 0;
    for (long k = 0; k < d->n_pieces; k++) {
        ballc_interpolant *f = &d->view[k];
        f->n_steps = d->n_steps[k];
        f->steps = d->steps + 2 * d->step0[k];
        f->coef = d->coef + coef;
        f->kinds = d->kinds + d->step0[k];
        f->terms = d->terms[k];
        f->width = d->width;
        coef += d->n_steps[k] * (long)(1 + d->terms[k]) * d->width;
    }
    d->piecewise.n_pieces = d->n_pieces;
    d->piecewise.ends = d->t1;
    d->piecewise.pieces = d->view;
    return &d->piecewise;
}

int ballc_dense_span(const ballc_dense *d, double t_from, double t_to, ballc_dense *out)
{
    ballc_dense_clear(out);
    long coef = 0;
    int started = 0;
    for (long k = 0; k < d->n_pieces; k++) {
        long per = (long)(1 + d->terms[k]) * d->width, m = d->n_steps[k];
        const double *steps = d->steps + 2 * d->step0[k];
        const double *c = d->coef + coef;
        coef += m * per;
        int last = k == d->n_pieces - 1;
        if (!started && !(d->t1[k] > t_from) && !last) continue;
        started = 1;
        long j0 = m ? first_at_or_after(steps + 1, 2, m, t_from) : 0;
        long j1 = m ? first_at_or_after(steps + 1, 2, m, t_to) : -1;
        if (j1 < j0) j1 = j0 - 1;
        long n = m ? j1 - j0 + 1 : 0;
        if (ballc_dense_add(out, d->t0[k], d->t1[k], n, steps + 2 * j0, c + j0 * per,
                            d->kinds + d->step0[k] + j0, d->terms[k], d->width))
            return -1;
        if (d->t1[k] > t_to) break;
    }
    out->width = d->width;
    return 0;
}
