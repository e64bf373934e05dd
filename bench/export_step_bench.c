/*
 * Time per step of hysid's exported C (bench/export_steps.sh compiles it once per model).
 *
 * Compiled with -DFWD=name -DFWD_H='"dir/name.h"' (the forward export) and optionally
 * -DINV=name -DINV_H='"dir/name.h"' (the --inverse export of the same model file). Steps the
 * forward model over N samples of the streaming benches' input (crates/hysid-bench/src/lib.rs:
 * a decaying oscillation with nested minor loops, period 10 000 samples), best of REPEATS
 * runs timed with clock_gettime(CLOCK_MONOTONIC); then the compensator over the forward
 * model's outputs (references the model reaches, as the library bench does). Prints one line
 * per direction: "forward|inverse ns_per_step state_bytes".
 */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include FWD_H
#ifdef INV
#include INV_H
#endif

#define CAT2(a, b) a##b
#define CAT(a, b) CAT2(a, b)

#define N 1000000L
#define PERIOD 10000L
#define REPEATS 7

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static double input(long k) {
    double t = (double)(k % PERIOD) / (double)PERIOD;
    return 2.0 * (1.0 - 0.5 * t) * sin(40.0 * t) + 0.3 * sin(370.0 * t);
}

int main(void) {
    double *u = malloc(N * sizeof *u), *y = malloc(N * sizeof *y);
    double best = INFINITY, sum = 0.0;
    long k;
    int rep;
    CAT(FWD, _state) s;
    if (!u || !y) return 2;
    for (k = 0; k < N; k++) u[k] = input(k);
    for (rep = 0; rep < REPEATS; rep++) {
        double t0, t;
        CAT(FWD, _init)(&s);
        t0 = now();
        for (k = 0; k < N; k++) CAT(FWD, _step)(&s, &u[k], &y[k]);
        t = now() - t0;
        if (t < best) best = t;
        if (s.error) {
            fprintf(stderr, "forward: error flag set\n");
            return 1;
        }
    }
    for (k = 0; k < N; k++) sum += y[k];
    printf("forward %.1f %lu %.17g\n", best / N * 1e9, (unsigned long)sizeof s, sum);
#ifdef INV
    {
        double *v = malloc(N * sizeof *v);
        CAT(INV, _state) c;
        if (!v) return 2;
        best = INFINITY;
        for (rep = 0; rep < REPEATS; rep++) {
            double t0, t;
            CAT(INV, _init)(&c);
            t0 = now();
            for (k = 0; k < N; k++) CAT(INV, _step)(&c, &y[k], &v[k]);
            t = now() - t0;
            if (t < best) best = t;
            if (c.error) {
                fprintf(stderr, "inverse: error flag set\n");
                return 1;
            }
        }
        sum = 0.0;
        for (k = 0; k < N; k++) sum += v[k];
        printf("inverse %.1f %lu %.17g\n", best / N * 1e9, (unsigned long)sizeof c, sum);
        free(v);
    }
#endif
    free(u);
    free(y);
    return 0;
}
