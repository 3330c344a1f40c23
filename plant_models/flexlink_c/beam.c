/* The flexible link's physics; see beam.h. The exact step (matrix exponentials of the
 * augmented system, cached by step and regime, the ladder of h / 2^j for sub-steps, the
 * Taylor series under its last digit) and the friction's regimes and events are the
 * chain plant's (motorchain_c/physics.c), on the beam's matrices. */
#include "beam.h"

#include <math.h>
#include <string.h>

#include "friction_events.h"
#include "matrix_exp.h"

#define NE N_ELEMENTS
#define NQ BEAM_NQ
#define ND (2 * NE + 2) /* nodal degrees of freedom, the clamped root's included */
#define SIZE BEAM_SIZE
#define M BEAM_INPUTS
#define BIG (BEAM_SIZE + BEAM_INPUTS)
#define W NQ             /* index of the hub's velocity in x */
#define CUR (2 * NQ)     /* index of the current in x */
#define MAX_EVENTS_PER_STEP 16

typedef double Square[BIG][BIG];

/* ---- the finite elements ---- */

/* Consistent mass and stiffness of a Hermite cubic element of length l, DOFs
 * (w_a, w'_a, w_b, w'_b). */
static void element(double me[4][4], double ke[4][4], double rhoA, double EI, double l) {
    static const double m[4][4] = {
        {156, 22, 54, -13}, {22, 4, 13, -3}, {54, 13, 156, -22}, {-13, -3, -22, 4}};
    static const double k[4][4] = {{12, 6, -12, 6}, {6, 4, -6, 2}, {-12, -6, 12, -6}, {6, 2, -6, 4}};
    static const int power[4] = {0, 1, 0, 1}; /* each rotation DOF carries a factor l */
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++) {
            double lengths = pow(l, power[r] + power[c]);
            me[r][c] = rhoA * l / 420.0 * m[r][c] * lengths;
            ke[r][c] = EI / (l * l * l) * k[r][c] * lengths;
        }
}

/* Inverse of the leading n × n block of m (ld NQ) into inv; -1 if singular. */
static int inverse(double inv[NQ][NQ], const double m[NQ][NQ], int first) {
    double a[NQ][NQ];
    const int n = NQ - first;
    memset(a, 0, sizeof a);
    memset(inv, 0, sizeof(double) * NQ * NQ);
    for (int r = 0; r < n; r++) {
        for (int c = 0; c < n; c++) a[r][c] = m[first + r][first + c];
        inv[r][r] = 1.0;
    }
    if (mx_solve(&a[0][0], &inv[0][0], n, NQ) != 0) return -1;
    if (first) { /* shift into rows and columns 1 …: the hub's row and column stay 0 */
        for (int r = n - 1; r >= 0; r--)
            for (int c = n - 1; c >= 0; c--) {
                inv[r + 1][c + 1] = inv[r][c];
                inv[r][c] = 0.0;
            }
        for (int i = 0; i < NQ; i++) inv[0][i] = inv[i][0] = 0.0;
    }
    return 0;
}

/* The rows of the accelerations (x rows NQ … 2 NQ − 1) of one regime: q'' = Mi (−K q −
 * C q' + e_0 (k_t i + τ_fric)); Mi = M⁻¹ (moving) or with the hub held (stuck). */
static void accelerations(double a[SIZE][SIZE], double b[SIZE][M], const double mi[NQ][NQ],
                          const double kf[NQ][NQ], const double cf[NQ][NQ], double k_t) {
    for (int j = 0; j < NQ; j++) {
        double *row = a[NQ + j];
        for (int c = 0; c < NQ; c++) {
            double sk = 0.0, sc = 0.0;
            for (int k = 0; k < NQ; k++) {
                sk += mi[j][k] * kf[k][c];
                sc += mi[j][k] * cf[k][c];
            }
            row[c] = -sk;
            row[NQ + c] = -sc;
        }
        row[CUR] = mi[j][0] * k_t;
        b[NQ + j][1] = mi[j][0];
    }
}

/* τ_reac = r V(0) + M(0) of the root element's end forces at the hub: its consistent
 * inertia on the absolute accelerations (r + x) θ'' + w'', its stiffness and damping on
 * the deflection (in the continuum limit − EI w''(0) + r EI w'''(0), with β). */
static void reaction_row(double out[SIZE + M], const double a[SIZE][SIZE], const double b[SIZE][M],
                         const double me[4][4], const double ke[4][4], double r, double l,
                         double beta) {
    double mrow[4], krow[4];
    for (int c = 0; c < 4; c++) {
        mrow[c] = r * me[0][c] + me[1][c];
        krow[c] = r * ke[0][c] + ke[1][c];
    }
    /* absolute accelerations of the root element's DOFs: r θ'', θ'', (r + l) θ'' + w1'',
     * θ'' + w1''' */
    const double on_hub = mrow[0] * r + mrow[1] + mrow[2] * (r + l) + mrow[3];
    for (int c = 0; c < SIZE; c++)
        out[c] = on_hub * a[NQ][c] + mrow[2] * a[NQ + 1][c] + mrow[3] * a[NQ + 2][c];
    for (int c = 0; c < M; c++)
        out[SIZE + c] = on_hub * b[NQ][c] + mrow[2] * b[NQ + 1][c] + mrow[3] * b[NQ + 2][c];
    out[1] += krow[2];
    out[2] += krow[3];
    out[NQ + 1] += beta * krow[2];
    out[NQ + 2] += beta * krow[3];
}

/* Gershgorin's bound of one regime's rate (see Beam.rate). */
static double regime_rate(const double a[SIZE][SIZE]) {
    double stiff = 0.0, damp = 0.0;
    for (int j = 0; j < NQ; j++) {
        double ks = 0.0, ds = 0.0;
        for (int c = 0; c < NQ; c++) {
            ks += fabs(a[NQ + j][c]);
            ds += fabs(a[NQ + j][NQ + c]);
        }
        stiff = fmax(stiff, ks);
        damp = fmax(damp, ds);
    }
    return 2.0 * sqrt(stiff) + damp;
}

/* The mass, stiffness and damping matrices in q, the clamp's DOFs eliminated. */
static void assemble(const BeamParameters *q, double mf[NQ][NQ], double kf[NQ][NQ],
                     double cf[NQ][NQ], double me[4][4], double ke[4][4]) {
    const double l = q->L / NE;
    double mg[ND][ND], kg[ND][ND], t[ND];
    memset(mg, 0, sizeof mg);
    memset(kg, 0, sizeof kg);
    element(me, ke, q->rhoA, q->EI, l);
    for (int e = 0; e < NE; e++)
        for (int r = 0; r < 4; r++)
            for (int c = 0; c < 4; c++) {
                mg[2 * e + r][2 * e + c] += me[r][c];
                kg[2 * e + r][2 * e + c] += ke[r][c];
            }
    mg[2 * NE][2 * NE] += q->m_tip;
    mg[2 * NE + 1][2 * NE + 1] += q->J_tip;
    /* rigid rotation θ: nodal y = (r + x_k) θ, y' = θ (Hermite cubics hold it exactly) */
    for (int k = 0; k <= NE; k++) {
        t[2 * k] = q->r_hub + k * l;
        t[2 * k + 1] = 1.0;
    }
    memset(mf, 0, sizeof(double) * NQ * NQ);
    memset(kf, 0, sizeof(double) * NQ * NQ);
    double j_link = 0.0;
    for (int i = 0; i < ND; i++)
        for (int k = 0; k < ND; k++) j_link += t[i] * mg[i][k] * t[k];
    mf[0][0] = q->J_m + j_link;
    for (int j = 1; j < NQ; j++) {
        double s = 0.0;
        for (int k = 0; k < ND; k++) s += mg[1 + j][k] * t[k];
        mf[0][j] = mf[j][0] = s;
        for (int c = 1; c < NQ; c++) {
            mf[j][c] = mg[1 + j][1 + c];
            kf[j][c] = kg[1 + j][1 + c];
        }
    }
    for (int j = 0; j < NQ; j++)
        for (int c = 0; c < NQ; c++) cf[j][c] = q->beta * kf[j][c];
    cf[0][0] += q->D_m;
}

int beam_init(Beam *p, const BeamParameters *q) {
    double mf[NQ][NQ], kf[NQ][NQ], cf[NQ][NQ], me[4][4], ke[4][4], mi[NQ][NQ];
    memset(p, 0, sizeof *p);
    p->k_t = q->k_t;
    p->f_c = q->f_c;
    p->ideal_current = q->current_bandwidth == 0.0;
    assemble(q, mf, kf, cf, me, ke);
    for (int stuck = 0; stuck < 2; stuck++) {
        double(*a)[SIZE] = stuck ? p->a_stuck : p->a;
        double(*b)[M] = stuck ? p->b_stuck : p->b;
        if (inverse(mi, (const double(*)[NQ])mf, stuck) != 0) return -1;
        for (int j = 0; j < NQ; j++) a[j][NQ + j] = 1.0;
        accelerations(a, b, (const double(*)[NQ])mi, (const double(*)[NQ])kf,
                      (const double(*)[NQ])cf, q->k_t);
        a[CUR][CUR] = -q->current_bandwidth;
        b[CUR][0] = q->current_bandwidth;
        a[CUR + 1][CUR] = 1.0;
        reaction_row(p->reac[stuck], (const double(*)[SIZE])a, (const double(*)[M])b,
                     (const double(*)[4])me, (const double(*)[4])ke, q->r_hub, q->L / NE,
                     q->beta);
        for (int c = 0; c < SIZE; c++) a[CUR + 2][c] = p->reac[stuck][c];
        for (int c = 0; c < M; c++) b[CUR + 2][c] = p->reac[stuck][SIZE + c];
        p->rate = fmax(p->rate, regime_rate((const double(*)[SIZE])a));
    }
    p->rate += fabs(q->current_bandwidth);
    const double l = q->L / NE, element_fastest = 8400.0 * q->EI / (q->rhoA * l * l * l * l);
    p->fastest_mode = sqrt(element_fastest);
    p->fastest_decay = q->beta * element_fastest + q->D_m / q->J_m;
    for (int c = 0; c < SIZE; c++) p->drive[c] = -p->reac[1][c];
    p->drive[CUR] += q->k_t;
    p->stuck = q->f_c > 0.0;
    p->direction = 0.0;
    return 0;
}

/* ---- one step (as motorchain_c/physics.c) ---- */

void beam_cache_clear(BeamCache *cache) {
    cache->count = 0;
    cache->ladder_h[0] = cache->ladder_h[1] = 0.0; /* no step has h = 0 */
}

/* The exponential of the augmented system over tau, e^{[A B; 0 0] τ}, into work[6]
 * (its first SIZE rows are [Φ | Γ]), balanced first: the beam's matrix mixes metres,
 * radians and their rates, and its norm is 1e4 times its spectral radius; NULL if it
 * failed. */
static double (*exponential(const Beam *p, BeamCache *cache, double tau, int stuck))[BIG] {
    double(*big)[BIG] = cache->work[5], (*e)[BIG] = cache->work[6];
    const double(*a)[SIZE] = stuck ? p->a_stuck : p->a;
    const double(*b)[M] = stuck ? p->b_stuck : p->b;
    memset(big, 0, sizeof(Square));
    for (int r = 0; r < SIZE; r++) {
        for (int c = 0; c < SIZE; c++) big[r][c] = tau * a[r][c];
        for (int c = 0; c < M; c++) big[r][SIZE + c] = tau * b[r][c];
    }
    double d[BIG];
    return mx_expm_balanced(&e[0][0], &big[0][0], d, BIG, BIG, &cache->work[0][0][0]) == 0 ? e
                                                                                         : NULL;
}

/* out = E [x; u] (out may be x). */
static void apply(const double (*E)[BIG], const double *x, const double *u, double *out) {
    double y[SIZE];
    for (int r = 0; r < SIZE; r++) {
        double s = 0.0, t = 0.0;
        for (int c = 0; c < SIZE; c++) s += E[r][c] * x[c];
        for (int c = 0; c < M; c++) t += E[r][SIZE + c] * u[c];
        y[r] = s + t;
    }
    memcpy(out, y, sizeof y);
}

static double derivative_row(const Beam *p, const double *x, const double *u, int stuck,
                             int row) {
    const double *a = stuck ? p->a_stuck[row] : p->a[row];
    const double *b = stuck ? p->b_stuck[row] : p->b[row];
    double s = 0.0, t = 0.0;
    for (int c = 0; c < SIZE; c++) s += a[c] * x[c];
    for (int c = 0; c < M; c++) t += b[c] * u[c];
    return s + t;
}

/* out = state after tau, with the exponential of tau cached by (tau, regime). */
static int propagate(const Beam *p, BeamCache *cache, const double *x, const double *u,
                     double tau, int stuck, double *out) {
    int i = 0;
    while (i < cache->count && !(cache->tau[i] == tau && cache->stuck[i] == stuck)) i++;
    if (i == cache->count) {
        double(*e)[BIG] = exponential(p, cache, tau, stuck);
        if (!e) return -1;
        if (cache->count >= BEAM_CACHE) cache->count = 0;
        i = cache->count++;
        cache->tau[i] = tau;
        cache->stuck[i] = stuck;
        memcpy(cache->step[i], e, sizeof cache->step[i]);
    }
    apply((const double(*)[BIG])cache->step[i], x, u, out);
    return 0;
}

/* The ladder of regime `stuck` for step h: rung j = e^{M h / 2^(j+1)}, each by its own
 * matrix exponential. */
static int build_ladder(const Beam *p, BeamCache *cache, double h, int stuck) {
    for (int j = 0; j < BEAM_LADDER; j++) {
        double(*e)[BIG] = exponential(p, cache, ldexp(h, -(j + 1)), stuck);
        if (!e) return -1;
        memcpy(cache->ladder[stuck][j], e, sizeof cache->ladder[stuck][j]);
    }
    cache->ladder_h[stuck] = h;
    return 0;
}

#define SERIES_TERMS (4 * NQ + 40)

/* out = e^{[A B; 0 0] τ} [x; u] by the Taylor series applied to the vector, for τ with
 * τ · rate <= 1/2, summed until two terms in a row change no component; -1 if τ is too
 * long for it. */
static int series(const Beam *p, const double *x, const double *u, double tau, int stuck,
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

static int propagate_once(const Beam *p, BeamCache *cache, const double *x, const double *u,
                          double tau, int stuck, double *out) {
    double(*e)[BIG] = exponential(p, cache, tau, stuck);
    if (!e) return -1;
    apply((const double(*)[BIG])e, x, u, out);
    return 0;
}

/* out = state after a sub-step τ (0 < τ < h): by its Taylor series when the whole step is
 * short, else along the ladder of h, digit by digit, the rest under the last digit by
 * its Taylor series (or an exponential of its own). */
static int propagate_part(const Beam *p, BeamCache *cache, const double *x, const double *u,
                          double tau, double h, int stuck, double *out) {
    if (h * p->rate <= 0.5 && series(p, x, u, tau, stuck, out) == 0) return 0;
    if (cache->ladder_h[stuck] != h && build_ladder(p, cache, h, stuck) != 0) return -1;
    double z[SIZE];
    memcpy(z, x, sizeof z);
    double rest = tau / h;
    for (int j = 0; j < BEAM_LADDER; j++) {
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

static int advance_by(const Beam *p, BeamCache *cache, const double *x, const double *u,
                      double tau, double h, int stuck, double *out) {
    if (tau == h) return propagate(p, cache, x, u, tau, stuck, out);
    return propagate_part(p, cache, x, u, tau, h, stuck, out);
}

/* The torque the friction must hold while the hub is held: k_t i − τ_reac. */
static double drive_torque(const Beam *p, const double *x) {
    double s = 0.0;
    for (int c = 0; c < SIZE; c++) s += p->drive[c] * x[c];
    return s;
}

static double drive_rate(const Beam *p, const double *x, const double *u) {
    double s = 0.0;
    for (int c = 0; c < SIZE; c++)
        if (p->drive[c] != 0.0) s += p->drive[c] * derivative_row(p, x, u, 1, c);
    return s;
}

static double first_reversal(const Beam *p, const double *x0, const double *x1, const double *u,
                             double tau) {
    Event e = {0, x0[W], derivative_row(p, x0, u, 0, W), x1[W], derivative_row(p, x1, u, 0, W),
               tau, p->direction, 0.0};
    return first_root(&e, tau);
}

static double first_breakaway(const Beam *p, const double *x0, const double *x1, const double *u,
                              double tau) {
    Event e = {1,   drive_torque(p, x0), drive_rate(p, x0, u), drive_torque(p, x1),
               drive_rate(p, x1, u), tau, 0.0, p->f_c};
    return first_root(&e, tau);
}

static double copysign_one(double v) { return copysign(1.0, v); }

int beam_advance(Beam *p, BeamCache *cache, double h, double i_ref) {
    double x[SIZE], end[SIZE], u[M];
    memcpy(x, p->x, sizeof x);
    if (p->ideal_current) x[CUR] = i_ref;
    x[CUR + 1] = 0.0;
    x[CUR + 2] = 0.0;
    u[0] = i_ref;
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
            x[W] = 0.0;
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

double beam_reaction_torque(const Beam *p) {
    const double *r = p->reac[p->stuck];
    const double fric = p->stuck || p->f_c == 0.0 ? 0.0 : -p->f_c * p->direction;
    double s = 0.0;
    for (int c = 0; c < SIZE; c++) s += r[c] * p->x[c];
    return s + r[SIZE + 1] * fric;
}

double beam_average_current(const Beam *p, double h) { return p->x[CUR + 1] / h; }

double beam_average_reaction(const Beam *p, double h) { return p->x[CUR + 2] / h; }
