/* The plant's sub-steps, out of the FMU, for tests/test_small_steps.py: compiled with
 * plant_models/motorchain_c/physics.c included (its static functions in reach) and a
 * chain_size.h of the test's own.
 *
 *   physics_probe H BANDWIDTH TAU...
 *
 * Builds the paper's bench chain (current loop BANDWIDTH rad/s; 0 = ideal), sets a state
 * with every component nonzero and the inputs u, and prints, all doubles in C99 hex
 * (%a) so that nothing is lost:
 *   a ROW VALUES...      the rows of A (moving regime)
 *   b ROW VALUES...      the rows of B
 *   x VALUES...          the state
 *   u VALUES...          the inputs
 *   rate VALUE           Physics.rate
 *   tau TAU VALUES...    the state after each sub-step TAU of a step H (propagate_part)
 */
#include "physics.c"

#include <stdio.h>
#include <stdlib.h>

static void row(const char *tag, int index, const double *v, int n) {
    if (index >= 0)
        printf("%s %d", tag, index);
    else
        printf("%s", tag);
    for (int i = 0; i < n; i++) printf(" %a", v[i]);
    printf("\n");
}

int main(int argc, char **argv) {
    if (argc < 4) {
        fprintf(stderr, "usage: physics_probe H BANDWIDTH TAU...\n");
        return 2;
    }
    double h = strtod(argv[1], NULL), bandwidth = strtod(argv[2], NULL);
    double J[N], k[N], B[N];
    for (int i = 0; i < N; i++) {
        J[i] = i == N - 1 ? 6.192707e-4 : 5.15299e-4;
        k[i] = 0.1627;
        B[i] = 8.88e-6;
    }
    static Physics p;
    PhysicsCache *cache = calloc(1, sizeof *cache);
    if (!cache) return 3;
    physics_init(&p, 2.09e-5, 0.0406, 2e-5, 2e-3, J, k, B, 1, bandwidth);
    physics_cache_clear(cache);
    double x[SIZE], u[M];
    for (int i = 0; i < SIZE; i++) x[i] = 0.3 + 0.1 * i * (i % 2 ? -1.0 : 1.0);
    for (int i = 0; i < M; i++) u[i] = 0.01 * (i + 1);
    u[0] = 0.48; /* A */
    for (int r = 0; r < SIZE; r++) row("a", r, p.a[r], SIZE);
    for (int r = 0; r < SIZE; r++) row("b", r, p.b[r], M);
    row("x", -1, x, SIZE);
    row("u", -1, u, M);
    printf("rate %a\n", p.rate);
    for (int i = 3; i < argc; i++) {
        double tau = strtod(argv[i], NULL), out[SIZE];
        if (propagate_part(&p, cache, x, u, tau, h, 0, out) != 0) return 4;
        printf("tau %a", tau);
        for (int r = 0; r < SIZE; r++) printf(" %a", out[r]);
        printf("\n");
    }
    free(cache);
    return 0;
}
