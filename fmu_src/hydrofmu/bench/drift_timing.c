/* bench/drift_cost.py's timing loop: seconds per call over ``steps`` calls at t = k dt (no
 * ctypes call in the loop) of the shared phasors' advance plus hf_waves (drift NULL) or plus
 * hf_drift (the drift alone on the FMU's phasors, as in a load FMU without excitation output). */
#define _POSIX_C_SOURCE 199309L
#include <time.h>

#include "../physics/kernels.h"

double hf_bench_per_call(const double *wave, double *drift, int steps, double dt) {
    struct timespec a, b;
    double out[7], sink = 0.0;
    HfPhasors *P = hf_wave_phasors(wave);
    if (!P) return -1.0;
    clock_gettime(CLOCK_MONOTONIC, &a);
    for (int k = 0; k < steps; k++) {
        double t = k * dt;
        if (!drift) hf_waves(wave, P, t, out);
        else hf_drift(drift, hf_phasors_at(P, t), t, hf_phasors_ramp(P), out);
        sink += out[0];
    }
    clock_gettime(CLOCK_MONOTONIC, &b);
    hf_phasors_delete(P);
    volatile double keep = sink;
    (void)keep;
    return ((b.tv_sec - a.tv_sec) + 1e-9 * (b.tv_nsec - a.tv_nsec)) / steps;
}
