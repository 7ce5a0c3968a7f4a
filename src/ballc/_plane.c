/* See _plane.h. */
#include <math.h>

#include "_plane.h"

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

void ballc_plane_init(ballc_plane_t *plane, const double *point, const double *normal,
                      const double *gravity, int deflection, int rolling)
{
    double *t1 = plane->frame[0], *t2 = plane->frame[1], *n = plane->frame[2];
    double length = sqrt(dot3(normal, normal));
    for (int i = 0; i < 3; i++) {
        plane->point[i] = point[i];
        n[i] = normal[i] / length;
    }
    int k = 0;   /* the axis the normal has least of */
    for (int i = 1; i < 3; i++)
        if (fabs(n[i]) < fabs(n[k])) k = i;
    double along = n[k];   /* e_k . n */
    for (int i = 0; i < 3; i++) t1[i] = (i == k) - along * n[i];
    double t1_length = sqrt(dot3(t1, t1));
    for (int i = 0; i < 3; i++) t1[i] /= t1_length;
    t2[0] = n[1] * t1[2] - n[2] * t1[1];
    t2[1] = n[2] * t1[0] - n[0] * t1[2];
    t2[2] = n[0] * t1[1] - n[1] * t1[0];
    plane->gravity_into = -dot3(n, gravity);
    plane->deflection = deflection;
    plane->rolling = rolling;
}

void ballc_plane_state_columns(const ballc_plane_t *plane, const double *local, int rows,
                               int n_states, double *jac)
{
    const double (*f)[3] = plane->frame;
    const int NC = BALLC_N_CONTACT_STATES, NS = n_states;
    for (int r = 0; r < rows; r++, local += NC, jac += NS) {
        for (int j = 0; j < NS; j++) jac[j] = 0.0;
        const double *w = local + BALLC_CONTACT_STATE_OMEGA_X, *v = local + BALLC_CONTACT_STATE_VX;
        for (int i = 0; i < 3; i++) {
            jac[BALLC_STATE_X + i] = local[BALLC_CONTACT_STATE_Z] * f[2][i];
            jac[BALLC_STATE_OMEGA_X + i] = w[0] * f[0][i] + w[1] * f[1][i] + w[2] * f[2][i];
            jac[BALLC_STATE_VX + i] = v[0] * f[0][i] + v[1] * f[1][i] + v[2] * f[2][i];
        }
        jac[plane->deflection] = local[BALLC_CONTACT_STATE_DEFLECTION_X];
        jac[plane->deflection + 1] = local[BALLC_CONTACT_STATE_DEFLECTION_Y];
        if (plane->rolling >= 0) {
            jac[plane->rolling] = local[BALLC_CONTACT_STATE_ROLLING_X];
            jac[plane->rolling + 1] = local[BALLC_CONTACT_STATE_ROLLING_Y];
            jac[plane->rolling + 2] = local[BALLC_CONTACT_STATE_TWISTING];
        }
    }
}

void ballc_plane_rows_to_inertial(const ballc_plane_t *plane, double *m, int columns,
                                  int first_row, int count)
{
    const double (*f)[3] = plane->frame;
    for (int k = 0; k < count; k++) {
        double *r0 = m + (first_row + 3 * k) * columns, *r1 = r0 + columns, *r2 = r1 + columns;
        for (int j = 0; j < columns; j++) {
            double a = r0[j], b = r1[j], c = r2[j];
            r0[j] = f[0][0] * a + f[1][0] * b + f[2][0] * c;
            r1[j] = f[0][1] * a + f[1][1] * b + f[2][1] * c;
            r2[j] = f[0][2] * a + f[1][2] * b + f[2][2] * c;
        }
    }
}
