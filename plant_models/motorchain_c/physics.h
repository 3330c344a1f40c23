/* The plant's physics in C: a port of plant_models/motorchain/physics.py (the
 * reference its tests compare with) and of flexchain/noise.py.
 *
 * N_MASSES (number of load masses n) is fixed at build time (chain_size.h). State vector x
 * (length 2n + 5): angles θ_0 … θ_n (rad), velocities ω_0 … ω_n (rad/s), current i
 * (A), ∫ i dt over the step (A·s), ∫ τ_1 dt over the step (N·m·s). */
#ifndef MOTORCHAIN_PHYSICS_H
#define MOTORCHAIN_PHYSICS_H

#include <stdint.h>

#include "chain_size.h" /* generated at build: #define N_MASSES n */
#include "sensor_noise.h" /* noise_gaussian, noise_quantize, PH_PI (shared) */

#define PH_SIZE (2 * N_MASSES + 5) /* state length */
#define PH_INPUTS (N_MASSES + 2)   /* i_ref, τ_fric, τ_ext,1 … τ_ext,n */
#define PH_CACHE 16                /* discretized matrices kept, by (step, regime) */
#define PH_LADDER 20               /* binary digits of a sub-step: resolution h / 2^20 */

typedef struct {
    double k_t, f_c, k1, B1;
    int ideal_current;
    double a[PH_SIZE][PH_SIZE], b[PH_SIZE][PH_INPUTS];
    double a_stuck[PH_SIZE][PH_SIZE], b_stuck[PH_SIZE][PH_INPUTS];
    double x[PH_SIZE];
    int stuck;
    double direction;
    /* a bound on the chain's fastest rate (1/s): 2 sqrt(max_j sum |K_j.| / J_j) +
     * max_j sum |D_j.| / J_j + current bandwidth (Gershgorin on the chain scaled so
     * that angles and velocities weigh alike); tau * rate <= 1/2 makes a sub-step short
     * enough for its Taylor series */
    double rate;
} Physics;

/* Derived data, rebuilt on demand: not part of an FMU state. */
typedef struct {
    int count;
    double tau[PH_CACHE];
    int stuck[PH_CACHE];
    double step[PH_CACHE][PH_SIZE][PH_SIZE + PH_INPUTS]; /* rows [Φ | Γ] */
    /* Sub-steps of any length τ < h (friction events): the exponentials of h/2^j,
     * j = 1 … PH_LADDER, for one step size and regime each, applied along the
     * binary digits of τ/h (a matrix-vector product per digit instead of a new
     * matrix exponential per event). Rows: [Φ | Γ] of the augmented system. */
    double ladder_h[2];
    double ladder[2][PH_LADDER][PH_SIZE][PH_SIZE + PH_INPUTS];
    /* work space of the matrix exponential (no static buffers: instances may step
     * on several threads at once) */
    double work[7][PH_SIZE + PH_INPUTS][PH_SIZE + PH_INPUTS];
} PhysicsCache;

/* Parameters as in PlantPhysics.__init__; J, k, B have N_MASSES entries. */
void physics_init(Physics *p, double J_m, double k_t, double D_m, double f_c, const double *J,
                  const double *k, const double *B, int attached, double current_bandwidth);

/* Forget every derived matrix (after the parameters or the state changed). */
void physics_cache_clear(PhysicsCache *cache);

/* Integrate from t to t + h (s) with i_ref (A) and tau_ext (N·m, N_MASSES) held.
 * Returns 0, or -1 if a matrix exponential failed (non-finite entries). */
int physics_advance(Physics *p, PhysicsCache *cache, double h, double i_ref,
                    const double *tau_ext);

double physics_reaction_torque(const Physics *p);     /* τ_1 (N·m) */
double physics_average_current(const Physics *p, double h);  /* A */
double physics_average_reaction(const Physics *p, double h); /* N·m */

#endif
