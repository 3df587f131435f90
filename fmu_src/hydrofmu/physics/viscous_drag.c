/* AQWA viscous drag (physics/viscous_drag.py): F_body = -V (w o |w|), w the body velocity
 * in body axes (relative to the current at the reference point if RELATIVE, and to the incident
 * waves' velocity there with waves = true: relative 2). */
#include <math.h>

#include "kernels.h"

void hf_viscous_drag(const double *matrix, int relative, const HfMotion *m, const HfEnv *env, double *out) {
    double v[3] = {m->velocity[0], m->velocity[1], m->velocity[2]}, w[6], q[6], f[6];
    if (relative) {
        double c[3], row[8];
        hf_current_at(env, m->position[2], c);
        if (relative == 2 && env->water && hf_water_at(env->water, m->position, row))   /* waves = true */
            c[0] += row[0], c[1] += row[1], c[2] += row[2];
        v[0] -= c[0], v[1] -= c[1], v[2] -= c[2];
    }
    hf_rotate_back(m->R, v, w);
    hf_rotate_back(m->R, m->velocity + 3, w + 3);
    for (int i = 0; i < 6; i++) q[i] = w[i] * fabs(w[i]), f[i] = 0.0;
    for (int j = 0; j < 6; j++)   /* (column by column: six independent sums, each in row order) */
        for (int i = 0; i < 6; i++) f[i] += matrix[6 * i + j] * q[j];
    for (int i = 0; i < 6; i++) f[i] = -f[i];
    hf_rotate(m->R, f, out);
    hf_rotate(m->R, f + 3, out + 3);
}
