/* Linear hydrostatic restoring F = -C delta (physics/hydrostatics.py, the readable reference):
 * delta = [position - position0, tilt (-n_y, n_x), yaw - yaw0], n = R vertical0 the body's
 * vertical axis in global axes (vertical0 = R0^T e_z).  Global axes, about the reference point.
 * params [C (36, row-major), position0 (3), yaw0, vertical0 (3)]. */
#include "kernels.h"

void hf_hydrostatics(const double *params, const HfMotion *m, double *out) {
    const double *C = params, *p0 = params + 36, *v0 = params + 40;
    double n[3], d[6];
    for (int i = 0; i < 3; i++) d[i] = m->position[i] - p0[i];
    hf_rotate(m->R, v0, n);
    d[3] = -n[1], d[4] = n[0], d[5] = m->attitude[2] - params[39];
    for (int i = 0; i < 6; i++) {
        double s = 0.0;
        for (int j = 0; j < 6; j++) s += C[6 * i + j] * d[j];
        out[i] = -s;
    }
}
