/* RIFLEX BODY (physics/lumped.py LumpedBody): weight, buoyancy and quadratic drag at a
 * point of the body (in waves: drag on current + waves - point, and the water's acceleration
 * loads rho AE a_w + added mass a_w, none when the point is dry); its mass matrix and
 * centripetal load.
 * params [offset (3), am, ae, local (0/1), cd (3), added (3)] */
#include <math.h>
#include <string.h>

#include "kernels.h"

int hf_lumped_uses_current(const double *p) { return p[6] != 0.0 || p[7] != 0.0 || p[8] != 0.0; }

int hf_lumped_uses_acceleration(const double *p) {
    return p[3] != 0.0 || p[9] != 0.0 || p[10] != 0.0 || p[11] != 0.0;
}

/* Q (c_i u_i |u_i| if power else c_i u_i) with u = Q^T x, Q = R if local else 1 (LumpedBody._per_axis) */
static void per_axis(const double *p, const HfMotion *m, const double *coef, int power, const double *x, double *out) {
    int local = p[5] != 0.0;
    double u[3];
    if (local) hf_rotate_back(m->R, x, u);
    else memcpy(u, x, sizeof u);
    for (int i = 0; i < 3; i++) u[i] = power ? coef[i] * (u[i] * fabs(u[i])) : coef[i] * u[i];
    if (local) hf_rotate(m->R, u, out);
    else memcpy(out, u, sizeof u);
}

void hf_lumped_load(const double *p, const HfMotion *m, const HfEnv *env, double *out) {
    double r[3], w[3], c[3], u[3], f[3], g[3] = {0, 0, 0};
    hf_rotate(m->R, p, r);
    hf_cross(m->velocity + 3, r, w);
    hf_current_at(env, m->position[2] + r[2], c);
    if (env->water) {   /* in waves: at the point's instantaneous position (LumpedBody.load) */
        double x[3] = {m->position[0] + r[0], m->position[1] + r[1], m->position[2] + r[2]}, row[8], am[3];
        if (hf_water_at(env->water, x, row)) {
            for (int i = 0; i < 3; i++) c[i] += row[i];
            per_axis(p, m, p + 9, 0, row + 3, am);
            for (int i = 0; i < 3; i++) g[i] = env->rho * p[4] * row[3 + i] + am[i];
        } else {   /* dry: no drag */
            for (int i = 0; i < 3; i++) c[i] = m->velocity[i] + w[i];
        }
    }
    for (int i = 0; i < 3; i++) u[i] = c[i] - (m->velocity[i] + w[i]);
    per_axis(p, m, p + 6, 1, u, f);
    for (int i = 0; i < 3; i++) f[i] += g[i];
    f[2] += env->rho * env->g * p[4] - p[3] * env->g;
    out[0] = f[0], out[1] = f[1], out[2] = f[2];
    hf_cross(r, f, out + 3);
}

void hf_lumped_mass_matrix(const double *p, const HfMotion *m, double *m6) {
    double mp[9], r[3];
    int local = p[5] != 0.0;
    for (int i = 0; i < 3; i++)   /* am 1 + Q diag(added) Q^T */
        for (int j = 0; j < 3; j++) {
            double s = 0.0;
            for (int k = 0; k < 3; k++) {
                double qik = local ? m->R[3 * i + k] : (i == k), qjk = local ? m->R[3 * j + k] : (j == k);
                s += qik * p[9 + k] * qjk;
            }
            mp[3 * i + j] = (i == j ? p[3] : 0.0) + s;
        }
    hf_rotate(m->R, p, r);
    hf_point_mass_matrix(mp, r, m6);
}

void hf_lumped_velocity_load(const double *p, const HfMotion *m, double *out) {
    double r[3], wr[3], c[3], a[3], f[3];
    hf_rotate(m->R, p, r);
    hf_cross(m->velocity + 3, r, wr);
    hf_cross(m->velocity + 3, wr, c);
    per_axis(p, m, p + 9, 0, c, a);
    for (int i = 0; i < 3; i++) f[i] = -(p[3] * c[i] + a[i]);
    out[0] = f[0], out[1] = f[1], out[2] = f[2];
    hf_cross(r, f, out + 3);
}
