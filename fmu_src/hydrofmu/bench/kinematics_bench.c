/* Timing harness of bench/kinematics_cost.py (compiled with physics/waves.c and
 * physics/wave_kinematics.c, never part of an FMU): seconds for `steps` steps of dt of
 * - the excitation kernel hf_waves with the shared phasors (one complex multiply per component),
 * - the same with cos/sin of every component at every step (the kernel before the phasors),
 * - the phasors' advance alone,
 * - the kinematics at one point per step (fixed, or moving with the step).
 * Each returns a checksum in *sum so the work is not optimised away. */
#include <math.h>
#include <time.h>

#include "../physics/kernels.h"

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

double hfb_waves(const double *params, int steps, double dt, double *sum) {
    HfPhasors *P = hf_wave_phasors(params);
    double out[7], s = 0.0, t0 = now();
    for (int i = 0; i < steps; i++) {
        hf_waves(params, P, i * dt, out);
        s += out[0] + out[6];
    }
    double t = now() - t0;
    hf_phasors_delete(P);
    *sum = s;
    return t;
}

double hfb_trig(const double *params, int steps, double dt, double *sum) {
    int n = (int)params[0];
    const double *omega = params + 2, *amp = omega + n, *table = amp + 2 * n;
    double s = 0.0, t0 = now();
    for (int i = 0; i < steps; i++) {
        double out[7] = {0}, t = i * dt;
        for (int k = 0; k < n; k++) {
            double c = cos(omega[k] * t), sn = sin(omega[k] * t), ar = amp[2 * k], ai = amp[2 * k + 1];
            double re = ar * c - ai * sn, im = ar * sn + ai * c;
            const double *a = table + 14 * k, *b = a + 7;
            for (int j = 0; j < 7; j++) out[j] += re * a[j] + im * b[j];
        }
        s += out[0] + out[6];
    }
    *sum = s;
    return now() - t0;
}

double hfb_phasors(const double *params, int steps, double dt, double *sum) {
    HfPhasors *P = hf_wave_phasors(params);
    double s = 0.0, t0 = now();
    for (int i = 0; i < steps; i++) s += hf_phasors_at(P, i * dt)[0];
    double t = now() - t0;
    hf_phasors_delete(P);
    *sum = s;
    return t;
}

double hfb_kin(const double *params, const double *kin, int steps, double dt, int moving, double *sum) {
    HfPhasors *P = hf_wave_phasors(params);
    HfKinPoint *c = hf_kin_point_new((int)params[0]);
    double out[8], s = 0.0, x[3] = {5.0, -3.0, -8.0};
    for (int i = 0; i < steps; i++) hf_phasors_at(P, i * dt);   /* (the phasors' own cost apart) */
    double t0 = now(), spent = 0.0;
    for (int i = 0; i < steps; i++) {
        double a = now();
        const double *p = hf_phasors_at(P, (steps + i) * dt);
        spent += now() - a;
        if (moving) x[0] = 5.0 + 0.5 * sin(0.3 * i * dt), x[2] = -8.0 + 0.3 * cos(0.4 * i * dt);
        hf_kin_at(kin, c, p, hf_phasors_ramp(P), x, 1025.0, out);
        s += out[0] + out[7];
    }
    double t = now() - t0 - spent;
    hf_kin_point_delete(c), hf_phasors_delete(P);
    *sum = s;
    return t;
}
