/* FMI 2.0 co-simulation interface of the flexible-link plant, in C: the plants' shell
 * (motorchain_c/fmi_shell.h: variables, value references, guards, messages, timing
 * contract, trace file, FMU states) around the beam's physics (beam.c).
 * plant_variables.h is generated at build time from the variable list in
 * cosim/build/clink.py; link_size.h fixes the number of elements. */
#include "beam.h"
#include "plant_variables.h"

#define PLANT_STATE Beam
#define PLANT_CACHE BeamCache
#define PLANT_N N_ELEMENTS

#include "fmi_shell.h"

/* The beam's fastest mode and decay (bounds, Beam.fastest_mode and fastest_decay)
 * within what the FMU integrates (fmukit/checks.py FASTEST_RATE). */
static void check_rate(Core *c) {
    const double *v = c->v;
    const double mode = c->physics.fastest_mode, decay = c->physics.fastest_decay;
    if (mode > FASTEST_RATE)
        add_problem(c,
                    "parameters EI = %g, rhoA = %g, L = %g on %d elements make modes of up to "
                    "%.3g rad/s; the FMU integrates up to %g rad/s (build with fewer "
                    "elements, or soften the link)",
                    v[VR_EI], v[VR_rhoA], v[VR_L], N_ELEMENTS, mode, FASTEST_RATE);
    else if (decay > FASTEST_RATE)
        add_problem(c,
                    "parameters beta = %g, EI = %g, rhoA = %g, L = %g on %d elements make "
                    "decays of up to %.3g 1/s (beta times the fastest element's mode "
                    "squared); the FMU integrates up to %g 1/s (lower beta, or build with "
                    "fewer elements)",
                    v[VR_beta], v[VR_EI], v[VR_rhoA], v[VR_L], N_ELEMENTS, decay, FASTEST_RATE);
}

static BeamParameters parameters(const double *v) {
    BeamParameters q = {v[VR_J_m], v[VR_k_t],  v[VR_D_m],   v[VR_f_c],   v[VR_EI],
                        v[VR_rhoA], v[VR_L],   v[VR_m_tip], v[VR_J_tip], v[VR_r_hub],
                        v[VR_beta], v[VR_current_bandwidth]};
    return q;
}

/* The checks, in the order of the variables; the beam's matrices are built here (into
 * the state, which initialize completes) to check its rates. */
static void check_parameters(Core *c) {
    if (check_numbers(c)) return;
    check_range(c, VR_J_m, 1, 1);
    check_range(c, VR_D_m, 1, 0);
    check_range(c, VR_f_c, 1, 0);
    check_range(c, VR_EI, 1, 1);
    check_range(c, VR_rhoA, 1, 1);
    check_range(c, VR_L, 1, 1);
    check_range(c, VR_m_tip, 1, 0);
    check_range(c, VR_J_tip, 1, 0);
    check_range(c, VR_r_hub, 1, 0);
    check_range(c, VR_beta, 1, 0);
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
    if (c->problems[0]) return;
    BeamParameters q = parameters(c->v);
    if (beam_init(&c->physics, &q) != 0)
        add_problem(c, "the link's mass matrix is singular (check rhoA, L, J_m)");
    else
        check_rate(c);
}

/* ---- outputs ---- */

/* The outputs that are the link's state at the FMU's time (no sensor, no mean). */
static void write_true_outputs(Core *c) {
    const Beam *p = &c->physics;
    const double *x = p->x;
    double *v = c->v;
    v[VR_theta_m_true] = x[0];
    v[VR_omega_m_true] = x[BEAM_NQ];
    for (int k = 0; k < N_ELEMENTS; k++) {
        v[VR_w + k] = x[1 + 2 * k];
        v[VR_w_slope + k] = x[2 + 2 * k];
        v[VR_w_rate + k] = x[BEAM_NQ + 1 + 2 * k];
        v[VR_w_slope_rate + k] = x[BEAM_NQ + 2 + 2 * k];
    }
    v[VR_w_tip] = x[2 * N_ELEMENTS - 1];
    v[VR_alpha_tip] = x[2 * N_ELEMENTS - 1] / v[VR_L];
    v[VR_tau_reac] = beam_reaction_torque(p);
}

static void write_outputs(Core *c, double h /* <= 0: the sample at t0 */) {
    const Beam *p = &c->physics;
    const double *x = p->x;
    double *v = c->v;
    double theta_q = noise_quantize(x[0], c->cpr);
    double i_true, omega_q, tau_mean, noise = 0.0;
    if (h <= 0.0) {
        i_true = 0.0;
        omega_q = x[BEAM_NQ];
        tau_mean = beam_reaction_torque(p);
    } else {
        i_true = beam_average_current(p, h);
        omega_q = c->cpr > 0 ? (theta_q - c->theta_measured) / h : x[BEAM_NQ];
        tau_mean = beam_average_reaction(p, h);
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

/* After check_parameters built the matrices: the rest of the state. */
static void initialize(Core *c) {
    const double *v = c->v;
    c->cpr = (int64_t)v[VR_encoder_cpr];
    c->noise_std = v[VR_i_noise_std];
    c->seed = (uint64_t)(int64_t)v[VR_seed];
    c->sample = 0;
    c->theta_measured = noise_quantize(0.0, c->cpr);
    write_outputs(c, 0.0);
}

static int plant_advance(Core *c, BeamCache *cache, double h) {
    return beam_advance(&c->physics, cache, h, c->v[VR_i_ref]);
}

static void plant_cache_clear(BeamCache *cache) { beam_cache_clear(cache); }
