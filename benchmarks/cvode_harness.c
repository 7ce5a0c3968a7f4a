/* C side of benchmarks/cvode_c.py: radau5, dop853 and SUNDIALS CVODE, all driven from C, on
 * ballc's compiled right-hand side and analytic Jacobian.  No Python anywhere.
 *
 *   cvode_harness SEGMENT_FILE REPEAT TOL [TOL ...]
 *
 * SEGMENT_FILE (written by cvode_c.py, text, numbers as Python's repr):
 *   line 1: N_STATES N_PARAMETERS N_LATCH n_segments
 *   then one line per segment: flags t0 t1 params[N_PARAMETERS] latch[N_LATCH] y0[N_STATES]
 * For every tolerance (rtol = atol = TOL) and contender, every segment is integrated
 * from y0 at t0 to t1; the CPU time of the whole pass (clock_gettime
 * CLOCK_PROCESS_CPUTIME_ID) is the best of REPEAT passes: REPEAT rounds over all
 * tolerances, the contenders taking turns in a rotated order.  Output, one record a
 * line:
 *   sundials VERSION
 *   run CONTENDER TOL CPU_S NFEV NJEV NSTEP NLU FAILED_SEGMENTS
 *   end CONTENDER TOL SEGMENT y[N_STATES]       (from the last pass)
 *   fail CONTENDER TOL SEGMENT CODE             (a segment that did not reach t1)
 * CONTENDER: radau5, dop853 (radau5_solve with method RADAU5_METHOD_DOP853), cvode_bdf,
 * cvode_adams.  radau5 and dop853 are not run below rtol = 100 machine epsilons (ballc
 * refuses such tolerances: ballc/options.py).
 *
 * SUNDIALS has no headers here (the library comes from the scikit-sundae wheel): the
 * few prototypes below are those of the SUNDIALS 7 API, with sunrealtype = double and
 * sunindextype = int (scikit-sundae's build, sksundae/c_config.pxi; checked at run time
 * through SUNDenseMatrix_Rows / N_VGetLength).  Only opaque pointers cross the boundary:
 * no SUNDIALS struct layout is relied on.
 */
#define _POSIX_C_SOURCE 200809L
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "_integrator.h"
#include "_system.h"

/* ---- SUNDIALS 7 (serial, double, 32-bit index) ---- */
typedef void *SUNContext;
typedef void *N_Vector;
typedef void *SUNMatrix;
typedef void *SUNLinearSolver;
typedef int (*CVRhsFn)(double t, N_Vector y, N_Vector ydot, void *user_data);
typedef int (*CVLsJacFn)(double t, N_Vector y, N_Vector fy, SUNMatrix J, void *user_data,
                         N_Vector tmp1, N_Vector tmp2, N_Vector tmp3);
enum { CV_ADAMS = 1, CV_BDF = 2, CV_NORMAL = 1, CV_SUCCESS = 0, CV_TSTOP_RETURN = 1 };

int SUNContext_Create(int comm, SUNContext *ctx);         /* comm: SUN_COMM_NULL = 0 */
int SUNContext_Free(SUNContext *ctx);
int SUNDIALSGetVersion(char *version, int len);
N_Vector N_VNew_Serial(int length, SUNContext ctx);
double *N_VGetArrayPointer(N_Vector v);
int N_VGetLength(N_Vector v);
void N_VDestroy(N_Vector v);
SUNMatrix SUNDenseMatrix(int rows, int columns, SUNContext ctx);
int SUNDenseMatrix_Rows(SUNMatrix A);
double *SUNDenseMatrix_Data(SUNMatrix A);                  /* column-major */
void SUNMatDestroy(SUNMatrix A);
SUNLinearSolver SUNLinSol_Dense(N_Vector y, SUNMatrix A, SUNContext ctx);
int SUNLinSolFree(SUNLinearSolver S);
void *CVodeCreate(int lmm, SUNContext ctx);
int CVodeInit(void *mem, CVRhsFn f, double t0, N_Vector y0);
int CVodeReInit(void *mem, double t0, N_Vector y0);
int CVodeSStolerances(void *mem, double rtol, double atol);
int CVodeSetUserData(void *mem, void *user_data);
int CVodeSetLinearSolver(void *mem, SUNLinearSolver LS, SUNMatrix A);
int CVodeSetJacFn(void *mem, CVLsJacFn jac);
int CVodeSetMaxNumSteps(void *mem, long mxsteps);
int CVodeSetStopTime(void *mem, double tstop);
int CVode(void *mem, double tout, N_Vector yout, double *tret, int itask);
int CVodeGetNumSteps(void *mem, long *n);
int CVodeGetNumRhsEvals(void *mem, long *n);
int CVodeGetNumJacEvals(void *mem, long *n);
int CVodeGetNumLinSolvSetups(void *mem, long *n);
void CVodeFree(void **mem);

/* ---- segments ---- */
typedef struct {
    int flags;
    double t0, t1;
    double params[BALLC_N_PARAMETERS], latch[BALLC_N_LATCH], y0[BALLC_N_STATES];
    ballc_parameters_t prepared;   /* params and their constants, as radau5's bridge does */
} segment_t;

#define N BALLC_N_STATES

static void die(const char *what) {
    fprintf(stderr, "cvode_harness: %s\n", what);
    exit(2);
}

static segment_t *read_segments(const char *path, int *count) {
    FILE *f = fopen(path, "r");
    int ns, np, nl, m;
    if (!f)
        die("cannot open the segment file");
    if (fscanf(f, "%d %d %d %d", &ns, &np, &nl, &m) != 4 || m <= 0)
        die("bad segment file header");
    if (ns != BALLC_N_STATES || np != BALLC_N_PARAMETERS || nl != BALLC_N_LATCH)
        die("segment file dimensions differ from this build's generated/ballc_kernels.h");
    segment_t *s = calloc((size_t)m, sizeof *s);
    if (!s)
        die("out of memory");
    for (int k = 0; k < m; k++) {
        int ok = fscanf(f, "%d %lf %lf", &s[k].flags, &s[k].t0, &s[k].t1) == 3;
        for (int i = 0; ok && i < BALLC_N_PARAMETERS; i++)
            ok = fscanf(f, "%lf", &s[k].params[i]) == 1;
        for (int i = 0; ok && i < BALLC_N_LATCH; i++)
            ok = fscanf(f, "%lf", &s[k].latch[i]) == 1;
        for (int i = 0; ok && i < N; i++)
            ok = fscanf(f, "%lf", &s[k].y0[i]) == 1;
        if (!ok)
            die("truncated segment file");
        ballc_parameters_init(&s[k].prepared, s[k].params);
    }
    fclose(f);
    *count = m;
    return s;
}

static double cpu_seconds(void) {
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* ---- what one pass over the segments returns ---- */
typedef struct {
    long nfev, njev, nstep, nlu;
    int failed;
    double *y_end;     /* n_segments x N */
    int *code;         /* per segment: 0 reached t1, else the solver's status / flag */
} pass_t;

/* ---- radau5: as src/ballc/_radau5_bridge.pxi (solve_system) sets it up ---- */
static int ball_fun(void *ctx, double t, const double *y, double *f) {
    const segment_t *s = ctx;
    (void)t;
    return ballc_rhs_checked_inputs(y, &s->prepared, s->latch, s->flags, f);
}

static int ball_jac(void *ctx, double t, const double *y, double *jac) {
    const segment_t *s = ctx;
    (void)t;
    return ballc_jacobian_checked_inputs(y, &s->prepared, s->latch, s->flags, jac);
}

static void radau5_pass(segment_t *segs, int m, double tol, int method, pass_t *out) {
    double atol[N], dummy_real[N];
    int dummy_int[1] = {0};
    for (int i = 0; i < N; i++)
        atol[i] = tol, dummy_real[i] = 0.0;
    for (int k = 0; k < m; k++) {
        radau5_problem p;
        radau5_result r;
        memset(&p, 0, sizeof p);
        p.n = N;
        p.fun = ball_fun;
        p.jac = ball_jac;
        p.ctx = &segs[k];
        p.t0 = segs[k].t0;
        p.t_bound = segs[k].t1;
        p.y0 = segs[k].y0;
        p.rtol = tol;
        p.atol = atol;
        p.max_step = INFINITY;
        p.first_step = 0.0;          /* scipy's select_initial_step */
        p.max_nfev = 0;
        p.t_eval = NULL;             /* every step stored, as solve_system with t_eval None */
        p.n_eval = 0;
        p.n_events = 0;
        p.ev_coef = dummy_real;
        p.ev_offset = dummy_real;
        p.ev_nonlinear = dummy_int;
        p.ev_terminal = dummy_int;
        p.ev_direction = dummy_int;
        p.ev_fun = NULL;
        p.dense_output = 0;
        p.controller = 0;            /* scipy's step control: ballc's default */
        p.outputs_checked = 1;       /* ballc_rhs/_jacobian report non-finite outputs */
        p.refine_events = 1;
        p.method = method;           /* RADAU5_METHOD_RADAU or RADAU5_METHOD_DOP853 */
        int rc = radau5_solve(&p, &r);
        if (rc != RADAU5_DONE || r.status != RADAU5_REACHED || r.n_out < 1) {
            out->code[k] = rc != RADAU5_DONE ? rc : (r.status != 0 ? r.status : -9);
            out->failed++;
            for (int i = 0; i < N; i++)
                out->y_end[k * N + i] = NAN;
        } else {
            out->code[k] = 0;
            memcpy(out->y_end + (size_t)k * N, r.y_out + (size_t)(r.n_out - 1) * N,
                   N * sizeof(double));
        }
        out->nfev += r.nfev;
        out->njev += r.njev;
        out->nstep += r.nstep;
        out->nlu += r.nlu;
        radau5_free(&r);
    }
}

/* ---- CVODE: dense direct linear solver, ballc's analytic Jacobian ---- */
typedef struct {
    const segment_t *seg;
    double jac[N * N];   /* ballc's row-major Jacobian, transposed into SUNDIALS' */
} cvode_user_t;

static int cv_rhs(double t, N_Vector y, N_Vector ydot, void *user_data) {
    const cvode_user_t *u = user_data;
    (void)t;
    int rc = ballc_rhs_checked_inputs(N_VGetArrayPointer(y), &u->seg->prepared,
                                      u->seg->latch, u->seg->flags, N_VGetArrayPointer(ydot));
    return rc ? 1 : 0;   /* > 0: recoverable (CVODE retries with a smaller step) */
}

static int cv_jac(double t, N_Vector y, N_Vector fy, SUNMatrix J, void *user_data,
                  N_Vector tmp1, N_Vector tmp2, N_Vector tmp3) {
    cvode_user_t *u = user_data;
    (void)t, (void)fy, (void)tmp1, (void)tmp2, (void)tmp3;
    int rc = ballc_jacobian_checked_inputs(N_VGetArrayPointer(y), &u->seg->prepared,
                                           u->seg->latch, u->seg->flags, u->jac);
    if (rc)
        return 1;
    double *col_major = SUNDenseMatrix_Data(J);
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++)
            col_major[j * N + i] = u->jac[i * N + j];
    return 0;
}

typedef struct {
    SUNContext ctx;
    N_Vector y;
    SUNMatrix A;
    SUNLinearSolver LS;
    void *mem;
    cvode_user_t user;
} cvode_t;

static void check(int flag, const char *what) {
    if (flag < 0) {
        fprintf(stderr, "cvode_harness: %s returned %d\n", what, flag);
        exit(2);
    }
}

/* Created once per contender, re-initialised (CVodeReInit) per segment. */
static void cvode_create(cvode_t *c, int lmm, const segment_t *first) {
    check(SUNContext_Create(0, &c->ctx), "SUNContext_Create");
    c->y = N_VNew_Serial(N, c->ctx);
    c->A = SUNDenseMatrix(N, N, c->ctx);
    if (!c->y || !c->A)
        die("N_VNew_Serial / SUNDenseMatrix failed");
    if (N_VGetLength(c->y) != N || SUNDenseMatrix_Rows(c->A) != N)
        die("sunindextype is not what this harness declares (int)");
    c->LS = SUNLinSol_Dense(c->y, c->A, c->ctx);
    c->mem = CVodeCreate(lmm, c->ctx);
    if (!c->LS || !c->mem)
        die("SUNLinSol_Dense / CVodeCreate failed");
    memcpy(N_VGetArrayPointer(c->y), first->y0, N * sizeof(double));
    c->user.seg = first;
    check(CVodeInit(c->mem, cv_rhs, first->t0, c->y), "CVodeInit");
    check(CVodeSetUserData(c->mem, &c->user), "CVodeSetUserData");
    check(CVodeSetLinearSolver(c->mem, c->LS, c->A), "CVodeSetLinearSolver");
    check(CVodeSetJacFn(c->mem, cv_jac), "CVodeSetJacFn");
    check(CVodeSetMaxNumSteps(c->mem, 1000000000L), "CVodeSetMaxNumSteps");
}

static void cvode_destroy(cvode_t *c) {
    CVodeFree(&c->mem);
    SUNLinSolFree(c->LS);
    SUNMatDestroy(c->A);
    N_VDestroy(c->y);
    SUNContext_Free(&c->ctx);
}

static void cvode_pass(cvode_t *c, segment_t *segs, int m, double tol, pass_t *out) {
    for (int k = 0; k < m; k++) {
        double tret = segs[k].t0;
        long nst = 0, nfe = 0, nje = 0, nsetups = 0;
        c->user.seg = &segs[k];
        memcpy(N_VGetArrayPointer(c->y), segs[k].y0, N * sizeof(double));
        check(CVodeReInit(c->mem, segs[k].t0, c->y), "CVodeReInit");
        check(CVodeSStolerances(c->mem, tol, tol), "CVodeSStolerances");
        check(CVodeSetStopTime(c->mem, segs[k].t1), "CVodeSetStopTime");
        int flag = CVode(c->mem, segs[k].t1, c->y, &tret, CV_NORMAL);
        if (flag < 0 || tret != segs[k].t1) {
            out->code[k] = flag < 0 ? flag : -99;
            out->failed++;
            for (int i = 0; i < N; i++)
                out->y_end[k * N + i] = NAN;
        } else {
            out->code[k] = 0;
            memcpy(out->y_end + (size_t)k * N, N_VGetArrayPointer(c->y), N * sizeof(double));
        }
        /* the counters restart at CVodeReInit: these are this segment's */
        CVodeGetNumSteps(c->mem, &nst);
        CVodeGetNumRhsEvals(c->mem, &nfe);
        CVodeGetNumJacEvals(c->mem, &nje);
        CVodeGetNumLinSolvSetups(c->mem, &nsetups);
        out->nstep += nst;
        out->nfev += nfe;
        out->njev += nje;
        out->nlu += nsetups;
    }
}

/* ---- driver ---- */
enum { RADAU5, DOP853, CVODE_BDF, CVODE_ADAMS, N_CONTENDERS };
static const char *NAMES[N_CONTENDERS] = {"radau5", "dop853", "cvode_bdf", "cvode_adams"};
#define RADAU5_MIN_TOL (100 * DBL_EPSILON)

int main(int argc, char **argv) {
    if (argc < 4)
        die("usage: cvode_harness SEGMENT_FILE REPEAT TOL [TOL ...]");
    int m, repeat = atoi(argv[2]), n_tol = argc - 3;
    if (repeat < 1)
        die("REPEAT must be >= 1");
    segment_t *segs = read_segments(argv[1], &m);
    char version[64] = "?";
    SUNDIALSGetVersion(version, (int)sizeof version);
    printf("sundials %s\n", version);
    cvode_t cv[N_CONTENDERS];
    cvode_create(&cv[CVODE_BDF], CV_BDF, &segs[0]);
    cvode_create(&cv[CVODE_ADAMS], CV_ADAMS, &segs[0]);
    /* per tolerance and contender: the best CPU and the last pass */
    double *tols = malloc((size_t)n_tol * sizeof(double));
    double *best = malloc((size_t)n_tol * N_CONTENDERS * sizeof(double));
    pass_t *last = calloc((size_t)n_tol * N_CONTENDERS, sizeof(pass_t));
    if (!tols || !best || !last)
        die("out of memory");
    for (int a = 0; a < n_tol; a++) {
        tols[a] = strtod(argv[3 + a], NULL);
        for (int c = 0; c < N_CONTENDERS; c++) {
            pass_t *p = &last[a * N_CONTENDERS + c];
            best[a * N_CONTENDERS + c] = INFINITY;
            p->y_end = malloc((size_t)m * N * sizeof(double));
            p->code = malloc((size_t)m * sizeof(int));
            if (!p->y_end || !p->code)
                die("out of memory");
        }
    }
    /* The repeats are the outer loop, so that the passes of one tolerance are spread
     * over the whole run (a burst of load on the shared machine does not hit all of
     * them), and the contenders take turns in a rotated order within each. */
    for (int rep = 0; rep < repeat; rep++) {
        for (int a = 0; a < n_tol; a++) {
            for (int j = 0; j < N_CONTENDERS; j++) {
                int c = (j + rep) % N_CONTENDERS;
                if ((c == RADAU5 || c == DOP853) && tols[a] < RADAU5_MIN_TOL)
                    continue;
                pass_t *p = &last[a * N_CONTENDERS + c];
                p->nfev = p->njev = p->nstep = p->nlu = 0;
                p->failed = 0;
                double started = cpu_seconds();
                if (c == RADAU5 || c == DOP853)
                    radau5_pass(segs, m, tols[a],
                                c == RADAU5 ? RADAU5_METHOD_RADAU : RADAU5_METHOD_DOP853, p);
                else
                    cvode_pass(&cv[c], segs, m, tols[a], p);
                double cpu = cpu_seconds() - started;
                if (cpu < best[a * N_CONTENDERS + c])
                    best[a * N_CONTENDERS + c] = cpu;
            }
        }
    }
    for (int a = 0; a < n_tol; a++) {
        for (int c = 0; c < N_CONTENDERS; c++) {
            const pass_t *p = &last[a * N_CONTENDERS + c];
            if (best[a * N_CONTENDERS + c] < INFINITY) {   /* it ran */
                printf("run %s %.17g %.9g %ld %ld %ld %ld %d\n", NAMES[c], tols[a],
                       best[a * N_CONTENDERS + c], p->nfev, p->njev, p->nstep, p->nlu,
                       p->failed);
                for (int k = 0; k < m; k++) {
                    if (p->code[k])
                        printf("fail %s %.17g %d %d\n", NAMES[c], tols[a], k, p->code[k]);
                    printf("end %s %.17g %d", NAMES[c], tols[a], k);
                    for (int i = 0; i < N; i++)
                        printf(" %.17g", p->y_end[k * N + i]);
                    printf("\n");
                }
            }
            free(p->y_end);
            free(p->code);
        }
    }
    cvode_destroy(&cv[CVODE_BDF]);
    cvode_destroy(&cv[CVODE_ADAMS]);
    free(tols);
    free(best);
    free(last);
    free(segs);
    return 0;
}
