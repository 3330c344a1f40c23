/* Current-sensor noise and encoder of the plants (a port of flexchain/noise.py), shared
 * header-only by motorchain_c and flexlink_c. */
#ifndef PLANT_SENSOR_NOISE_H
#define PLANT_SENSOR_NOISE_H

#include <math.h>
#include <stdint.h>

/* π as the double nearest to it, the value of Python's math.pi (C99 has no M_PI) */
#define PH_PI 3.14159265358979323846

static inline uint64_t splitmix64(uint64_t z) {
    z += 0x9E3779B97F4A7C15ULL;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

/* flexchain/noise.py: sample k of stream seed, bit-identical to the Python. */
static inline double noise_gaussian(uint64_t seed, uint64_t k) {
    uint64_t base = splitmix64(seed ^ 0x5DEECE66DULL);
    uint64_t a = splitmix64(base + 2 * k);
    uint64_t b = splitmix64(base + 2 * k + 1);
    double u1 = (double)((a >> 11) + 1) * 0x1p-53;
    double u2 = (double)(b >> 11) * 0x1p-53;
    return sqrt(-2.0 * log(u1)) * cos(2.0 * PH_PI * u2);
}

/* Encoder: whole counts, floored; counts_per_rev <= 0 = ideal. */
static inline double noise_quantize(double theta, int64_t counts_per_rev) {
    if (counts_per_rev <= 0) return theta;
    double step = 2.0 * PH_PI / (double)counts_per_rev;
    return floor(theta / step) * step;
}

#endif
