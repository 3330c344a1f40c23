/* FMI 2.0 co-simulation interface of the motor-chain plant, in C: the plants' shell
 * (fmi_shell.h) around the chain's physics (physics.c).
 *
 * Same variables, value references, checks, messages, timing contract and trace
 * file as the Python plant (plant_models/motorchain/fmu.py with fmu_src/fmukit),
 * which is the reference its tests compare with. plant_variables.h is generated at
 * build time from that class's variable list (cosim/build/cplant.py): names, types,
 * causalities, start values, value-reference macros (VR_<name>, the first element
 * for arrays) and the GUID; chain_size.h fixes n. */
#include "physics.h"
#include "plant_variables.h"

#define PLANT_STATE Physics
#define PLANT_CACHE PhysicsCache
#define PLANT_N N_MASSES

#include "fmi_shell.h"

/* The reference's chain_rate_problems (fmukit/checks.py): Gershgorin's bound on the
 * chain's fastest mode (springs) and decay (dampers), body 0 the motor when attached. */
static void check_rates(Core *c) {
    const double *v = c->v;
    int first = v[VR_attached] != 0.0 ? 0 : 1;
    for (int kind = 0; kind < 2; kind++) {
        int gains = kind == 0 ? VR_k : VR_B;
        for (int body = first; body <= N_MASSES; body++) {
            int inertia = body == 0 ? VR_J_m : VR_J + body - 1;
            double sum = 0.0;
            char parts[512] = "";
            size_t used = 0;
            for (int i = body - 1; i <= body; i++) {
                if (i < 0 || i >= N_MASSES) continue;
                sum += v[gains + i];
                used += (size_t)snprintf(parts + used, sizeof parts - used, "%s%s = %g",
                                         used ? ", " : "", VAR_NAME[gains + i], v[gains + i]);
                if (used >= sizeof parts) used = sizeof parts - 1;
            }
            double bound = 2.0 * sum / v[inertia];
            double rate = kind == 0 ? sqrt(bound) : bound;
            if (rate > FASTEST_RATE)
                add_problem(c,
                            "parameters %s on %s = %g make %s of up to %.3g %s; the FMU "
                            "integrates up to %g %s (soften or lighten the chain, or add "
                            "inertia)",
                            parts, VAR_NAME[inertia], v[inertia], kind == 0 ? "a mode" : "a decay",
                            rate, kind == 0 ? "rad/s" : "1/s", FASTEST_RATE,
                            kind == 0 ? "rad/s" : "1/s");
        }
    }
}

/* The reference's check_parameters, in the same order with the same sentences. */
static void check_parameters(Core *c) {
    if (check_numbers(c)) return;
    check_range(c, VR_J_m, 1, 1);
    check_range(c, VR_J, N_MASSES, 1);
    check_range(c, VR_D_m, 1, 0);
    check_range(c, VR_f_c, 1, 0);
    check_range(c, VR_k, N_MASSES, 0);
    check_range(c, VR_B, N_MASSES, 0);
    check_range(c, VR_i_noise_std, 1, 0);
    check_range(c, VR_current_bandwidth, 1, 0);
    if (!isfinite(c->v[VR_k_t])) {
        char num[64];
        repr_double(num, sizeof num, c->v[VR_k_t]);
        add_problem(c, "parameter k_t = %s is not a finite number", num);
    }
    if (c->v[VR_encoder_cpr] < 0)
        add_problem(c, "parameter encoder_cpr = %lld must be >= 0 (0 = ideal)",
                    (long long)c->v[VR_encoder_cpr]);
    if (!c->problems[0]) check_rates(c);
}

/* ---- outputs ---- */

/* The outputs that are the chain's state at the FMU's time (no sensor, no mean). */
static void write_true_outputs(Core *c) {
    const Physics *p = &c->physics;
    const double *x = p->x;
    double *v = c->v;
    v[VR_theta_m_true] = x[0];
    v[VR_omega_m_true] = x[N_MASSES + 1];
    for (int j = 0; j < N_MASSES; j++) {
        v[VR_theta + j] = x[1 + j];
        v[VR_omega + j] = x[N_MASSES + 2 + j];
    }
    v[VR_tau_reac] = physics_reaction_torque(p);
    v[VR_twist] = x[0] - x[1];
}

static void write_outputs(Core *c, double h /* <= 0: the sample at t0 */) {
    const Physics *p = &c->physics;
    const double *x = p->x;
    double *v = c->v;
    double theta_q = noise_quantize(x[0], c->cpr);
    double i_true, omega_q, tau_mean, noise = 0.0;
    if (h <= 0.0) {
        i_true = 0.0;
        omega_q = x[N_MASSES + 1];
        tau_mean = physics_reaction_torque(p);
    } else {
        i_true = physics_average_current(p, h);
        omega_q = c->cpr > 0 ? (theta_q - c->theta_measured) / h : x[N_MASSES + 1];
        tau_mean = physics_average_reaction(p, h);
        noise = c->noise_std * noise_gaussian(c->seed, c->sample);
    }
    c->theta_measured = theta_q;
    v[VR_i_a] = i_true + noise;
    v[VR_theta_m] = theta_q;
    v[VR_omega_m] = omega_q;
    v[VR_tau_reac_mean] = tau_mean;
    v[VR_i_true] = i_true;
    write_true_outputs(c);
}

static void initialize(Core *c) {
    const double *v = c->v;
    physics_init(&c->physics, v[VR_J_m], v[VR_k_t], v[VR_D_m], v[VR_f_c], v + VR_J, v + VR_k,
                 v + VR_B, v[VR_attached] != 0.0, v[VR_current_bandwidth]);
    c->cpr = (int64_t)v[VR_encoder_cpr];
    c->noise_std = v[VR_i_noise_std];
    c->seed = (uint64_t)(int64_t)v[VR_seed];
    c->sample = 0;
    c->theta_measured = noise_quantize(0.0, c->cpr);
    write_outputs(c, 0.0);
}

static int plant_advance(Core *c, PhysicsCache *cache, double h) {
    return physics_advance(&c->physics, cache, h, c->v[VR_i_ref], c->v + VR_tau_ext);
}

static void plant_cache_clear(PhysicsCache *cache) { physics_cache_clear(cache); }
