/* bench/drift_cost.py's timing loop: seconds per call of hf_waves (kind 0) or hf_drift
 * (kind 1) over ``steps`` calls at t = k dt (no ctypes call in the loop). */
#define _POSIX_C_SOURCE 199309L
#include <time.h>

#include "../physics/kernels.h"

double hf_bench_per_call(double *params, int kind, int steps, double dt) {
    struct timespec a, b;
    double out[7], sink = 0.0;
    clock_gettime(CLOCK_MONOTONIC, &a);
    for (int k = 0; k < steps; k++) {
        if (kind == 0) hf_waves(params, k * dt, out);
        else hf_drift(params, k * dt, out);
        sink += out[0];
    }
    clock_gettime(CLOCK_MONOTONIC, &b);
    volatile double keep = sink;
    (void)keep;
    return ((b.tv_sec - a.tv_sec) + 1e-9 * (b.tv_nsec - a.tv_nsec)) / steps;
}
