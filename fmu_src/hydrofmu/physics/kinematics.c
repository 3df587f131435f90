/* Rigid-body kinematics of physics/kinematics.py in C (same conventions, same formulas). */
#include <math.h>
#include <string.h>

#include "kernels.h"

static const double DEG = 3.14159265358979323846 / 180.0;   /* Python's math.radians factor */

/* R = Rz(psi) Ry(theta) Rx(phi), row-major */
void hf_rotation(const double *attitude, double *R) {
    double cf = cos(attitude[0]), sf = sin(attitude[0]), ct = cos(attitude[1]), st = sin(attitude[1]);
    double cp = cos(attitude[2]), sp = sin(attitude[2]);
    double r[9] = {cp * ct, cp * st * sf - sp * cf, cp * st * cf + sp * sf,
                   sp * ct, sp * st * sf + cp * cf, sp * st * cf - cp * sf,
                   -st, ct * sf, ct * cf};
    memcpy(R, r, sizeof r);
}

/* (R from hf_rotation unless the caller has set m->R for this attitude: pass NULL attitude) */
void hf_motion(HfMotion *m, const double *position, const double *attitude, const double *velocity,
               const double *acceleration) {
    m->position = position, m->velocity = velocity, m->acceleration = acceleration;
    if (attitude) {
        m->attitude = attitude;
        hf_rotation(attitude, m->R);
    }
}

/* M6 = [[M, -M S], [S M, -S M S]], S = [r]x (kinematics.point_mass_matrix) */
void hf_point_mass_matrix(const double *mass3, const double *r, double *m6) {
    double S[9] = {0.0, -r[2], r[1], r[2], 0.0, -r[0], -r[1], r[0], 0.0}, MS[9], SM[9], SMS[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double ms = 0.0, sm = 0.0;
            for (int k = 0; k < 3; k++) ms += mass3[3 * i + k] * S[3 * k + j], sm += S[3 * i + k] * mass3[3 * k + j];
            MS[3 * i + j] = ms, SM[3 * i + j] = sm;
        }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double v = 0.0;
            for (int k = 0; k < 3; k++) v += SM[3 * i + k] * S[3 * k + j];
            SMS[3 * i + j] = v;
        }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            m6[6 * i + j] = mass3[3 * i + j];
            m6[6 * i + 3 + j] = -MS[3 * i + j];
            m6[6 * (3 + i) + j] = SM[3 * i + j];
            m6[6 * (3 + i) + 3 + j] = -SMS[3 * i + j];
        }
}

void hf_current_components(double speed, double direction_deg, double *out) {
    double d = direction_deg * DEG;
    out[0] = speed * cos(d), out[1] = speed * sin(d), out[2] = 0.0;
}
