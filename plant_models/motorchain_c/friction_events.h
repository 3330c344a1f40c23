/* The friction events of the plants' hub (motorchain_c/physics.c, flexlink_c/beam.c),
 * shared header-only: a reversal of the motor's velocity or a breakaway of its drive
 * torque, located on the cubic Hermite interpolant of the signal over a sub-step. */
#ifndef PLANT_FRICTION_EVENTS_H
#define PLANT_FRICTION_EVENTS_H

#include <math.h>

static inline double hermite(double y0, double d0, double y1, double d1, double tau, double s) {
    double r = s / tau;
    double h00 = (1 + 2 * r) * ((1 - r) * (1 - r));
    double h10 = r * ((1 - r) * (1 - r));
    double h01 = r * r * (3 - 2 * r);
    double h11 = r * r * (r - 1);
    return h00 * y0 + h10 * tau * d0 + h01 * y1 + h11 * tau * d1;
}

/* An event on the Hermite interpolant: reversal (sign·y < 0) or breakaway (|y| > f_c). */
typedef struct {
    int breakaway;
    double y0, d0, y1, d1, tau, sign, f_c;
} Event;

static inline int event_at(const Event *e, double s) {
    double y = hermite(e->y0, e->d0, e->y1, e->d1, e->tau, s);
    return e->breakaway ? fabs(y) > e->f_c : e->sign * y < 0.0;
}

/* Smallest s in (0, tau] where the event becomes true, or -1 (bisection on a grid). */
static inline double first_root(const Event *e, double tau) {
    const int samples = 32;
    double lo = 0.0;
    for (int j = 1; j <= samples; j++) {
        double hi = tau * j / samples;
        if (event_at(e, hi)) {
            for (int it = 0; it < 60; it++) {
                double mid = 0.5 * (lo + hi);
                if (event_at(e, mid))
                    hi = mid;
                else
                    lo = mid;
                if (hi - lo <= 1e-15 * tau) break;
            }
            return hi;
        }
        lo = hi;
    }
    return -1.0;
}

#endif
