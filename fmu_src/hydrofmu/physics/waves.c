/* First-order wave excitation and elevation at time t (physics/waves.py WaveLoad.__call__):
 * out (7) = sum_k cos(w_k t) table[k] + sin(w_k t) table[n + k], times the start ramp
 * r(t) = (1 - cos(pi t / T_r)) / 2 while t < T_r.
 * params [n, T_r, omega (n), table (2n x 7, row-major)]: the components drawn and the
 * transfer functions interpolated at build time (the sea state of the build's waves.*). */
#include <math.h>
#include <string.h>

#include "kernels.h"

void hf_waves(const double *params, double t, double *out) {
    int n = (int)params[0];
    double length = params[1];
    const double *omega = params + 2, *table = omega + n;
    memset(out, 0, sizeof(double) * 7);
    for (int k = 0; k < n; k++) {
        double c = cos(omega[k] * t), s = sin(omega[k] * t);
        const double *a = table + 7 * k, *b = table + 7 * (n + k);
        for (int j = 0; j < 7; j++) out[j] += c * a[j] + s * b[j];
    }
    if (t < length) {
        double r = t <= 0.0 ? 0.0 : 0.5 * (1.0 - cos(3.14159265358979323846 * t / length));
        for (int j = 0; j < 7; j++) out[j] *= r;
    }
}
