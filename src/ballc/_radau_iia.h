/* radau_iia: the Radau IIA (order 5) step of the integrator (_integrator.h,
 * problem.method = RADAU5_METHOD_RADAU): scipy.integrate.Radau's _step_impl
 * (scipy/integrate/_ivp/radau.py) -- the simplified Newton iteration on the transformed
 * collocation system, the LU of its real and complex matrices (coupled states only,
 * outputs by substitution), the embedded error estimate, the step-size control and
 * the collocation polynomial's dense output terms.  The loop, events and output are
 * _integrator.c's.
 */
#ifndef BALLC_RADAU_IIA_H
#define BALLC_RADAU_IIA_H

#include <complex.h>

/* radau.py module constants (computed as scipy computes them). */
typedef struct {
    double C[3], E[3], T[3][3], TI[3][3], P[3][3];
    double PT[3][3];   /* P transposed: the dense output's coefficients per stage */
    double mu_real;
    double _Complex mu_complex, ti_complex[3];
} radau_iia_constants;

void radau_iia_init_constants(radau_iia_constants *k);

/* The loop's entry points (the solver: _integrator_private.h). */
struct ballc_solver;
/* Radau._step_impl: one accepted step from s->t.  Returns 1 on success, 0 on failure
 * (message set). */
int radau_iia_step(struct ballc_solver *s);
/* The Jacobian at (t, y) into s->J, and its partition into coupled states and outputs.
 * Returns 0, or -1 when it cannot be evaluated. */
int radau_iia_jacobian(struct ballc_solver *s, double t, const double *y);

/* The method's constants (tests only): out[RADAU5_N_CONSTANTS] =
 * C[3], E[3], T[3][3], TI[3][3], P[3][3] (row-major), MU_REAL, MU_COMPLEX (re, im),
 * TI_COMPLEX[3] (re), TI_COMPLEX[3] (im), NEWTON_MAXITER, MIN_FACTOR, MAX_FACTOR. */
#define RADAU5_N_CONSTANTS 45
void radau5_constants(double *out);

#endif
