/* Dense output in C: the compiled integrators' interpolants (ballc.dense).
 *
 * One segment's interpolant (dense.CompiledInterpolant) holds, per accepted step,
 * (t_old, t_new), y_old and the step's terms, x = (t - t_old) / (t_new - t_old):
 *   radau5 (3 terms, as scipy's RadauDenseOutput): y = y_old + x (q1 + x (q2 + x q3));
 *   dop853 (7 terms F0..F6, as scipy's Dop853DenseOutput):
 *     y = y_old + x (F0 + (1 - x) (F1 + x (F2 + (1 - x) (F3 + x (F4 + (1 - x) (F5 + x F6))))));
 *   method "auto": each step its own kind, a radau5 step's rows padded to 7 terms.
 * The step used at t is the first whose t_new >= t (the last beyond them, the first
 * before them).  A piecewise solution (dense.PiecewiseSolution) joins segments: at a
 * time two pieces share, the later one.  This is the one evaluation of those
 * interpolants: Python's CompiledInterpolant calls it through the bridge, and the
 * orbit's measurement (_orbit.c) calls it on the C loop's own dense output.
 */
#ifndef BALLC_DENSE_H
#define BALLC_DENSE_H

/* y(t) at n times into y (n rows of the solution's width): 0, or nonzero when the
 * values cannot be given (a callback's error) */
typedef int (*ballc_states_fn)(void *ctx, long n, const double *t, double *y);

typedef struct {
    long n_steps;
    const double *steps;   /* n_steps x 2: t_old, t_new */
    const double *coef;    /* n_steps x (1 + terms) width: y_old, then the terms' rows */
    const int *kinds;      /* n_steps: 3 or 7 terms; NULL: every step ``terms`` */
    int terms, width;
} ballc_interpolant;

/* y (width) at t; a segment without steps gives NaN */
void ballc_interpolant_at(const ballc_interpolant *f, double t, double *y);

typedef struct {
    long n_pieces;
    const double *ends;              /* each piece's end time, increasing */
    const ballc_interpolant *pieces;
} ballc_piecewise;

void ballc_piecewise_at(const ballc_piecewise *s, double t, double *y);

/* ballc_states_fn of a ballc_piecewise (ctx) */
int ballc_piecewise_states(void *ctx, long n, const double *t, double *y);

/* An owning buffer of segments' interpolants, added one after the other (an orbit's
 * trial, _orbit.c): the pieces [t0, t1] and their steps. */
typedef struct {
    long n_pieces, cap_pieces;
    double *t0, *t1;
    long *step0, *n_steps;
    int *terms;
    long total_steps, cap_steps, total_coef, cap_coef;
    double *steps, *coef;
    int *kinds;
    int width;
    /* the view evaluated (ballc_dense_view) */
    ballc_interpolant *view;
    long cap_view;
    ballc_piecewise piecewise;
} ballc_dense;

void ballc_dense_clear(ballc_dense *d);   /* no pieces, buffers kept */
void ballc_dense_free(ballc_dense *d);
/* add the segment [t0, t1] with its m steps (dense_t, dense_c, dense_kind of width
 * (1 + terms) width each): 0, or -1 out of memory */
int ballc_dense_add(ballc_dense *d, double t0, double t1, long m, const double *steps,
                    const double *coef, const int *kinds, int terms, int width);
/* the piecewise solution over the buffer (valid until the next add): NULL out of memory */
const ballc_piecewise *ballc_dense_view(ballc_dense *d);
/* into ``out`` (cleared first): the part of ``d`` that y(t) for t in [t_from, t_to]
 * evaluates -- the pieces from the first ending after t_from to the first ending after
 * t_to, and in each the steps from the first with t_new >= t_from to the first with
 * t_new >= t_to: the same values there, from less memory.  0, or -1 out of memory */
int ballc_dense_span(const ballc_dense *d, double t_from, double t_to, ballc_dense *out);

/* Make room for ``need`` elements of ``size`` bytes in the array *p of capacity *cap
 * (doubled from 16 until it fits; *p and *cap updated): 0, or -1 out of memory (*p kept). */
int ballc_grow(void **p, long *cap, long need, size_t size);

#endif
