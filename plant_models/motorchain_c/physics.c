/* The plant's physics in C; see physics.h. Every function mirrors one of
 * plant_models/motorchain/physics.py, operation for operation, so that both give
 * the same numbers to rounding. */
#include "physics.h"

#include <math.h>
#include <string.h>

#include "friction_events.h"
#include "matrix_exp.h"

#define N N_MASSES
#define SIZE PH_SIZE
#define M PH_INPUTS
#define BIG (PH_SIZE + PH_INPUTS)
#define CUR (2 * N + 2) /* index of the current in x */
#define MAX_EVENTS_PER_STEP 16

/* ---- the matrix exponential (matrix_exp.h, shared with flexlink_c) ---- */

typedef double Square[BIG][BIG];

/* e = expm(a), with work[0 … 4] as scratch. */
static int expm(Square e, Square a_in, int n, Square *work) {
    return mx_expm(&e[0][0], &a_in[0][0], n, BIG, &work[0][0][0]);
}

/* ---- the chain's matrices ---- */

static void spring_matrix(double m[N + 1][N + 1], const double *g) {
    memset(m, 0, sizeof(double) * (N + 1) * (N + 1));
    for (int i = 1; i <= N; i++) {
        m[i - 1][i - 1] += g[i - 1];
        m[i][i] += g[i - 1];
        m[i - 1][i] -= g[i - 1];
        m[i][i - 1] -= g[i - 1];
    }
}

void physics_init(Physics *p, double J_m, double k_t, double D_m, double f_c, const double *J,
                  const double *k, const double *B, int attached, double current_bandwidth) {
    memset(p, 0, sizeof *p);
    p->k_t = k_t;
    p->f_c = f_c;
    p->k1 = attached ? k[0] : 0.0;
    p->B1 = attached ? B[0] : 0.0;
    p->ideal_current = current_bandwidth == 0.0;
    double inertias[N + 1], ks[N], Bs[N];
    inertias[0] = J_m;
    for (int i = 0; i < N; i++) {
        inertias[i + 1] = J[i];
        ks[i] = i == 0 ? p->k1 : k[i];
        Bs[i] = i == 0 ? p->B1 : B[i];
    }
    double stiffness[N + 1][N + 1], damping[N + 1][N + 1];
    spring_matrix(stiffness, ks);
    spring_matrix(damping, Bs);
    damping[0][0] += D_m;
    const int qi = CUR + 1, qtau = CUR + 2;
    for (int j = 0; j <= N; j++) {
        p->a[j][N + 1 + j] = 1.0;
        double *row = p->a[N + 1 + j];
        for (int col = 0; col <= N; col++) {
            row[col] = -stiffness[j][col] / inertias[j];
            row[N + 1 + col] = -damping[j][col] / inertias[j];
        }
        if (j == 0) {
            row[CUR] = k_t / J_m;
            p->b[N + 1][1] = 1.0 / J_m;
        } else {
            p->b[N + 1 + j][1 + j] = 1.0 / inertias[j];
        }
    }
    p->a[CUR][CUR] = -current_bandwidth;
    p->b[CUR][0] = current_bandwidth;
    p->a[qi][CUR] = 1.0;
    p->a[qtau][0] = ks[0];
    p->a[qtau][1] = -ks[0];
    p->a[qtau][N + 1] = Bs[0];
    p->a[qtau][N + 2] = -Bs[0];
    memcpy(p->a_stuck, p->a, sizeof p->a);
    memcpy(p->b_stuck, p->b, sizeof p->b);
    memset(p->a_stuck[N + 1], 0, sizeof p->a_stuck[N + 1]);
    memset(p->b_stuck[N + 1], 0, sizeof p->b_stuck[N + 1]);
    p->stuck = f_c > 0.0;
    p->direction = 0.0;
    double stiff = 0.0, damp = 0.0;
    for (int j = 0; j <= N; j++) {
        double ks_j = 0.0, ds_j = 0.0;
        for (int col = 0; col <= N; col++) {
            ks_j += fabs(p->a[N + 1 + j][col]);
            ds_j += fabs(p->a[N + 1 + j][N + 1 + col]);
        }
        stiff = fmax(stiff, ks_j);
        damp = fmax(damp, ds_j);
    }
    p->rate = 2.0 * sqrt(stiff) + damp + fabs(current_bandwidth);
}

/* ---- one step ---- */

void physics_cache_clear(PhysicsCache *cache) {
    cache->count = 0;
    cache->ladder_h[0] = cache->ladder_h[1] = 0.0; /* no step has h = 0 */
}

/* The exponential of the augmented system over tau, e^{[A B; 0 0] τ}, into work[6]
 * (its first SIZE rows are [Φ | Γ]); NULL if it failed. */
static double (*exponential(const Physics *p, PhysicsCache *cache, double tau, int stuck))[BIG] {
    double(*big)[BIG] = cache->work[5], (*e)[BIG] = cache->work[6];
    const double(*a)[SIZE] = stuck ? p->a_stuck : p->a;
    const double(*b)[M] = stuck ? p->b_stuck : p->b;
    memset(big, 0, sizeof(Square));
    for (int r = 0; r < SIZE; r++) {
        for (int c = 0; c < SIZE; c++) big[r][c] = tau * a[r][c];
        for (int c = 0; c < M; c++) big[r][SIZE + c] = tau * b[r][c];
    }
    return expm(e, big, BIG, cache->work) == 0 ? e : NULL;
}

/* out = Φ x + Γ u, with E's rows [Φ | Γ] (the sums in the reference's order). */
/* One row of out = E [x; u]: the state part and the input part summed apart, in order. */
static double apply_row(const double *e, const double *x, const double *u) {
    double s = 0.0, t = 0.0;
    for (int c = 0; c < SIZE; c++) s += e[c] * x[c];
    for (int c = 0; c < M; c++) t += e[SIZE + c] * u[c];
    return s + t;
}

/* out = E [x; u] (out may be x). Four rows at a time: four independent sums keep the
 * floating-point unit busy (one sum waits on its previous addition), and each row is
 * still summed in the same order as apply_row, so the result is the same to the bit. */
static void apply(const double (*E)[BIG], const double *x, const double *u, double *out) {
    double y[SIZE];
    int r = 0;
    for (; r + 4 <= SIZE; r += 4) {
        const double *e0 = E[r], *e1 = E[r + 1], *e2 = E[r + 2], *e3 = E[r + 3];
        double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
        double t0 = 0.0, t1 = 0.0, t2 = 0.0, t3 = 0.0;
        for (int c = 0; c < SIZE; c++) {
            const double xc = x[c];
            s0 += e0[c] * xc;
            s1 += e1[c] * xc;
            s2 += e2[c] * xc;
            s3 += e3[c] * xc;
        }
        for (int c = 0; c < M; c++) {
            const double uc = u[c];
            t0 += e0[SIZE + c] * uc;
            t1 += e1[SIZE + c] * uc;
            t2 += e2[SIZE + c] * uc;
            t3 += e3[SIZE + c] * uc;
        }
        y[r] = s0 + t0;
        y[r + 1] = s1 + t1;
        y[r + 2] = s2 + t2;
        y[r + 3] = s3 + t3;
    }
    for (; r < SIZE; r++) y[r] = apply_row(E[r], x, u);
    memcpy(out, y, sizeof y);
}

static double derivative_row(const Physics *p, const double *x, const double *u, int stuck,
                             int row) {
    const double *a = stuck ? p->a_stuck[row] : p->a[row];
    const double *b = stuck ? p->b_stuck[row] : p->b[row];
    double s = 0.0, t = 0.0;
    for (int c = 0; c < SIZE; c++) s += a[c] * x[c];
    for (int c = 0; c < M; c++) t += b[c] * u[c];
    return s + t;
}

/* out = state after tau, with the exponential of tau cached by (tau, regime). */
static int propagate(const Physics *p, PhysicsCache *cache, const double *x, const double *u,
                     double tau, int stuck, double *out) {
    int i = 0;
    while (i < cache->count && !(cache->tau[i] == tau && cache->stuck[i] == stuck)) i++;
    if (i == cache->count) {
        double(*e)[BIG] = exponential(p, cache, tau, stuck);
        if (!e) return -1;
        if (cache->count >= PH_CACHE) cache->count = 0;
        i = cache->count++;
        cache->tau[i] = tau;
        cache->stuck[i] = stuck;
        memcpy(cache->step[i], e, sizeof cache->step[i]);
    }
    apply((const double(*)[BIG])cache->step[i], x, u, out);
    return 0;
}

/* Build the ladder of regime `stuck` for step h: rung j = e^{M h / 2^(j+1)}, each by its
 * own matrix exponential. (Squaring up from the smallest would be cheaper but doubles
 * the rounding error of I + small with every squaring: 2^20 × 1e-16.) */
static int build_ladder(const Physics *p, PhysicsCache *cache, double h, int stuck) {
    for (int j = 0; j < PH_LADDER; j++) {
        double(*e)[BIG] = exponential(p, cache, ldexp(h, -(j + 1)), stuck);
        if (!e) return -1;
        memcpy(cache->ladder[stuck][j], e, sizeof cache->ladder[stuck][j]);
    }
    cache->ladder_h[stuck] = h;
    return 0;
}

/* The Taylor series' longest run: enough for every body to feel a sub-step taken from
 * rest (a body d springs down the chain first moves in the term 2d + 1). */
#define SERIES_TERMS (4 * N + 40)

/* out = e^{[A B; 0 0] τ} [x; u], by the Taylor series applied to the vector, for τ with
 * τ · rate ≤ 1/2: each term is at most half the one before (in the scaling of
 * Physics.rate, in which rounding is the same), so summing until two terms in a row
 * change no component of the sum is exact to rounding. -1 if τ is too long for it. */
static int series(const Physics *p, const double *x, const double *u, double tau, int stuck,
                  double *out) {
    if (!(tau * p->rate <= 0.5)) return -1;
    double sum[SIZE], term[SIZE], next[SIZE];
    const double(*a)[SIZE] = stuck ? p->a_stuck : p->a;
    memcpy(sum, x, sizeof sum);
    for (int r = 0; r < SIZE; r++) term[r] = tau * derivative_row(p, x, u, stuck, r);
    int quiet = 0;
    for (int k = 1; k <= SERIES_TERMS && quiet < 2; k++) {
        int changed = 0;
        for (int r = 0; r < SIZE; r++) {
            double s = sum[r] + term[r];
            changed |= s != sum[r];
            sum[r] = s;
        }
        quiet = changed ? 0 : quiet + 1;
        const double f = tau / (k + 1);
        for (int r = 0; r < SIZE; r++) {
            double s = 0.0;
            for (int c = 0; c < SIZE; c++) s += a[r][c] * term[c];
            next[r] = f * s;
        }
        memcpy(term, next, sizeof term);
    }
    memcpy(out, sum, sizeof sum);
    return 0;
}

/* out = state after τ by a matrix exponential of its own (not cached). */
static int propagate_once(const Physics *p, PhysicsCache *cache, const double *x,
                          const double *u, double tau, int stuck, double *out) {
    double(*e)[BIG] = exponential(p, cache, tau, stuck);
    if (!e) return -1;
    apply((const double(*)[BIG])e, x, u, out);
    return 0;
}

/* out = state after a sub-step τ (0 < τ < h) of regime `stuck`: by its Taylor series when
 * the whole step is short for the chain (no ladder is built for a step of a
 * nanosecond), else along the ladder of h, digit by digit; what is left under the last
 * digit (h / 2^20, 1 ns at 1 ms) by its Taylor series, exact to rounding (or, for a
 * step too long for that, by a matrix exponential of its own). */
static int propagate_part(const Physics *p, PhysicsCache *cache, const double *x, const double *u,
                          double tau, double h, int stuck, double *out) {
    if (h * p->rate <= 0.5 && series(p, x, u, tau, stuck, out) == 0) return 0;
    if (cache->ladder_h[stuck] != h && build_ladder(p, cache, h, stuck) != 0) return -1;
    double z[SIZE];
    memcpy(z, x, sizeof z);
    double rest = tau / h;
    for (int j = 0; j < PH_LADDER; j++) {
        double digit = ldexp(1.0, -(j + 1));
        if (rest >= digit) {
            rest -= digit;
            apply((const double(*)[BIG])cache->ladder[stuck][j], z, u, z);
        }
    }
    const double dt = rest * h;
    if (dt <= 0.0) {
        memcpy(out, z, sizeof z);
        return 0;
    }
    if (series(p, z, u, dt, stuck, out) == 0) return 0;
    return propagate_once(p, cache, z, u, dt, stuck, out);
}

/* A full step (τ = h) uses the cached exponential of h; a part of one, the ladder. */
static int advance_by(const Physics *p, PhysicsCache *cache, const double *x, const double *u,
                      double tau, double h, int stuck, double *out) {
    if (tau == h) return propagate(p, cache, x, u, tau, stuck, out);
    return propagate_part(p, cache, x, u, tau, h, stuck, out);
}

static double drive_torque(const Physics *p, const double *x) {
    return p->k_t * x[CUR] - (p->k1 * (x[0] - x[1]) + p->B1 * (x[N + 1] - x[N + 2]));
}

/* hermite, Event and first_root: friction_events.h (shared with flexlink_c) */

static double first_reversal(const Physics *p, const double *x0, const double *x1,
                             const double *u, double tau) {
    const int w = N + 1;
    Event e = {0, x0[w], derivative_row(p, x0, u, 0, w), x1[w], derivative_row(p, x1, u, 0, w),
               tau, p->direction, 0.0};
    return first_root(&e, tau);
}

static double drive_rate(const Physics *p, const double *x, const double *u) {
    double fI = derivative_row(p, x, u, 1, CUR);
    double f1 = derivative_row(p, x, u, 1, N + 1);
    double f2 = derivative_row(p, x, u, 1, N + 2);
    return p->k_t * fI - (p->k1 * (x[N + 1] - x[N + 2]) + p->B1 * (f1 - f2));
}

static double first_breakaway(const Physics *p, const double *x0, const double *x1,
                              const double *u, double tau) {
    Event e = {1,   drive_torque(p, x0), drive_rate(p, x0, u), drive_torque(p, x1),
               drive_rate(p, x1, u), tau, 0.0, p->f_c};
    return first_root(&e, tau);
}

static double copysign_one(double v) { return copysign(1.0, v); }

int physics_advance(Physics *p, PhysicsCache *cache, double h, double i_ref,
                    const double *tau_ext) {
    double x[SIZE], end[SIZE], u[M];
    memcpy(x, p->x, sizeof x);
    if (p->ideal_current) x[CUR] = i_ref;
    x[CUR + 1] = 0.0;
    x[CUR + 2] = 0.0;
    u[0] = i_ref;
    for (int i = 0; i < N; i++) u[2 + i] = tau_ext[i];
    if (p->f_c == 0.0) {
        u[1] = 0.0;
        return propagate(p, cache, x, u, h, 0, p->x);
    }
    double t = 0.0;
    int events;
    for (events = 0; events < MAX_EVENTS_PER_STEP; events++) {
        double tau = h - t, s;
        if (tau <= 1e-12 * h) break;
        if (p->stuck) {
            double drive = drive_torque(p, x);
            if (fabs(drive) > p->f_c) {
                p->stuck = 0;
                p->direction = copysign_one(drive);
                continue;
            }
            u[1] = 0.0;
            if (advance_by(p, cache, x, u, tau, h, 1, end) != 0) return -1;
            s = first_breakaway(p, x, end, u, tau);
        } else {
            u[1] = -p->f_c * p->direction;
            if (advance_by(p, cache, x, u, tau, h, 0, end) != 0) return -1;
            s = first_reversal(p, x, end, u, tau);
        }
        if (s < 0.0) {
            memcpy(p->x, end, sizeof end);
            return 0;
        }
        if (advance_by(p, cache, x, u, s, h, p->stuck, x) != 0) return -1;
        t += s;
        if (p->stuck) {
            double drive = drive_torque(p, x);
            p->stuck = 0;
            p->direction = copysign_one(drive);
        } else {
            x[N + 1] = 0.0;
            double drive = drive_torque(p, x);
            if (fabs(drive) <= p->f_c)
                p->stuck = 1;
            else
                p->direction = copysign_one(drive);
        }
    }
    if (events == MAX_EVENTS_PER_STEP) { /* pathological chatter: finish in this regime */
        u[1] = p->stuck ? 0.0 : -p->f_c * p->direction;
        if (advance_by(p, cache, x, u, h - t, h, p->stuck, x) != 0) return -1;
    }
    memcpy(p->x, x, sizeof x);
    return 0;
}

double physics_reaction_torque(const Physics *p) {
    const double *x = p->x;
    return p->k1 * (x[0] - x[1]) + p->B1 * (x[N + 1] - x[N + 2]);
}

double physics_average_current(const Physics *p, double h) { return p->x[CUR + 1] / h; }

double physics_average_reaction(const Physics *p, double h) { return p->x[CUR + 2] / h; }
