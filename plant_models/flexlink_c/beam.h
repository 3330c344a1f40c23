/* The flexible link's physics in C: a motor-driven hub (inertia J_m, everything rigid on
 * the shaft) with an Euler–Bernoulli beam clamped to it at radius r, small deflection in
 * the rotating frame, an optional tip mass and tip inertia, stiffness-proportional
 * damping, discretized by N_ELEMENTS Hermite cubic elements; the motor, its current loop,
 * Coulomb friction and sensors are the chain plant's (motorchain_c/physics.c).
 *
 * Absolute deflection y(x, t) = (r + x) θ + w(x, t), clamped: w(0) = w'(0) = 0.
 * Generalized coordinates q (length NQ = 2 N_ELEMENTS + 1): θ, then w_k, w'_k of node
 * k = 1 … N_ELEMENTS (node k at x = k L / N_ELEMENTS). State vector x (length 2 NQ + 3):
 * q (rad, m, rad), q' (rad/s, m/s, rad/s), current i (A), ∫ i dt over the step (A·s),
 * ∫ τ_reac dt over the step (N·m·s). Inputs u: i_ref (A), friction torque (N·m). */
#ifndef FLEXLINK_BEAM_H
#define FLEXLINK_BEAM_H

#include <stdint.h>

#include "link_size.h"    /* generated at build: #define N_ELEMENTS n */
#include "sensor_noise.h" /* noise_gaussian, noise_quantize (shared with the chain) */

#define BEAM_NQ (2 * N_ELEMENTS + 1)   /* generalized coordinates */
#define BEAM_SIZE (2 * BEAM_NQ + 3)    /* state length */
#define BEAM_INPUTS 2                  /* i_ref, τ_fric */
#define BEAM_CACHE 16                  /* discretized matrices kept, by (step, regime) */
#define BEAM_LADDER 20                 /* binary digits of a sub-step: resolution h / 2^20 */

typedef struct {
    double J_m, k_t, D_m, f_c;     /* motor: kg·m², N·m/A, N·m·s/rad, N·m */
    double EI, rhoA, L;            /* beam: N·m², kg/m, m */
    double m_tip, J_tip, r_hub;    /* kg, kg·m², m */
    double beta;                   /* stiffness-proportional damping (s) */
    double current_bandwidth;      /* rad/s; 0 = ideal current */
} BeamParameters;

typedef struct {
    double k_t, f_c;
    int ideal_current;
    double a[BEAM_SIZE][BEAM_SIZE], b[BEAM_SIZE][BEAM_INPUTS];
    double a_stuck[BEAM_SIZE][BEAM_SIZE], b_stuck[BEAM_SIZE][BEAM_INPUTS];
    /* τ_reac = reac[stuck] · [x; u]: the root element's end forces (inertia, stiffness,
     * damping) as moment + r × shear, in each regime */
    double reac[2][BEAM_SIZE + BEAM_INPUTS];
    /* while stuck, the torque the friction must hold: drive · x = k_t i − τ_reac */
    double drive[BEAM_SIZE];
    double x[BEAM_SIZE];
    int stuck;
    double direction;
    /* a bound on the fastest rate (1/s): 2 sqrt(max row sum |M⁻¹K|) + max row sum
     * |M⁻¹C| + current bandwidth, over both regimes; tau * rate <= 1/2 makes a
     * sub-step short enough for its Taylor series */
    double rate;
    /* bounds on the fastest mode (rad/s) and decay (1/s) for the parameter checks: no
     * mode of the assembled beam is faster than the fastest of one free element,
     * λ ≤ 8400 EI / (ρA l⁴) (tip mass, tip inertia and hub only add mass), and no decay
     * faster than β λ + D_m / J_m */
    double fastest_mode, fastest_decay;
} Beam;

/* Derived data, rebuilt on demand: not part of an FMU state. */
typedef struct {
    int count;
    double tau[BEAM_CACHE];
    int stuck[BEAM_CACHE];
    double step[BEAM_CACHE][BEAM_SIZE][BEAM_SIZE + BEAM_INPUTS]; /* rows [Φ | Γ] */
    double ladder_h[2];
    double ladder[2][BEAM_LADDER][BEAM_SIZE][BEAM_SIZE + BEAM_INPUTS];
    double work[7][BEAM_SIZE + BEAM_INPUTS][BEAM_SIZE + BEAM_INPUTS];
} BeamCache;

/* Build the matrices; 0, or -1 if the mass matrix is singular. */
int beam_init(Beam *p, const BeamParameters *q);

/* Forget every derived matrix (after the parameters or the state changed). */
void beam_cache_clear(BeamCache *cache);

/* Integrate from t to t + h (s) with i_ref (A) held. 0, or -1 if a matrix exponential
 * failed (non-finite entries). */
int beam_advance(Beam *p, BeamCache *cache, double h, double i_ref);

double beam_reaction_torque(const Beam *p);            /* τ_reac now (N·m) */
double beam_average_current(const Beam *p, double h);  /* A */
double beam_average_reaction(const Beam *p, double h); /* N·m */

#endif
