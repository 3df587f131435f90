/* Incident-wave kinematics (physics/wave_kinematics.py, the readable reference): Airy velocity,
 * acceleration, dynamic pressure and elevation of the first-order components at a point, from
 * the shared phasors (waves.c HfPhasors), deep or finite depth, with the stretching above the
 * mean water level; zero out of the water.
 *
 * params [n, g, depth, stretching (0 none, 1 vertical, 2 wheeler, 3 extrapolation), omega (n),
 * k (n), cos beta (n), sin beta (n)] (hf_kin_build, malloc'd).  A point's cache (HfKinPoint)
 * keeps e^{-i k.x} and the depth factors while the point does not move.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "kernels.h"

#define PI 3.14159265358979323846

double *hf_kin_build(const double *omega, const double *direction_deg, int n, double g, double depth, int stretching) {
    double *p = malloc(sizeof(double) * (4 + 4 * (size_t)n));
    if (!p) return NULL;
    p[0] = n, p[1] = g, p[2] = depth, p[3] = stretching;
    for (int k = 0; k < n; k++) {
        double b = direction_deg[k] * PI / 180.0;
        p[4 + k] = omega[k], p[4 + n + k] = hf_wave_number(omega[k], g, depth);
        p[4 + 2 * n + k] = cos(b), p[4 + 3 * n + k] = sin(b);
    }
    return p;
}

HfKinPoint *hf_kin_point_new(int n) {
    HfKinPoint *c = calloc(1, sizeof *c);
    double *m = malloc(sizeof(double) * 5 * (n > 0 ? (size_t)n : 1));
    if (!c || !m) {
        free(c), free(m);
        return NULL;
    }
    c->e = m, c->fh = m + 2 * n, c->fv = m + 3 * n, c->fp = m + 4 * n;
    c->x = c->y = c->z = NAN;
    return c;
}

void hf_kin_point_delete(HfKinPoint *c) {
    if (c) free(c->e);
    free(c);
}

/* F_h, F_v, F_p of wave number k at height z (the formulas as they stand), depth h */
static void factors(double k, double z, double h, double *fh, double *fv, double *fp) {
    double e = exp(k * z);
    if (isinf(h)) {
        *fh = *fv = *fp = e;
        return;
    }
    double far = exp(-k * (z + 2 * h)), d = exp(-2 * k * h);
    *fh = (e + far) / (1 - d), *fv = (e - far) / (1 - d), *fp = (e + far) / (1 + d);
}

/* the factors at z by the stretching (not Wheeler's) */
static void stretched(int stretching, double k, double z, double h, double *fh, double *fv, double *fp) {
    if (z <= 0 || stretching == 0) {
        factors(k, z, h, fh, fv, fp);
    } else if (stretching == 1) {
        factors(k, 0.0, h, fh, fv, fp);
    } else {   /* extrapolation: F(0) + z F'(0) */
        double th = isinf(h) ? 1.0 : tanh(k * h), kz = k * z;
        *fh = 1.0 / th + kz, *fv = 1 + kz / th, *fp = 1 + kz * th;
    }
}

void hf_kin_at(const double *params, HfKinPoint *c, const double *p, double r, const double *x, double rho,
               double *out) {
    int n = (int)params[0], stretching = (int)params[3];
    double g = params[1], h = params[2];
    const double *w = params + 4, *kk = w + n, *cb = kk + n, *sb = cb + n;
    if (x[0] != c->x || x[1] != c->y) {   /* e^{-i k.x} */
        for (int k = 0; k < n; k++) {
            double ph = -kk[k] * (x[0] * cb[k] + x[1] * sb[k]);
            c->e[2 * k] = cos(ph), c->e[2 * k + 1] = sin(ph);
        }
        c->x = x[0], c->y = x[1];
    }
    double eta = 0.0;
    for (int k = 0; k < n; k++) eta += p[2 * k] * c->e[2 * k] - p[2 * k + 1] * c->e[2 * k + 1];
    eta *= r;
    double z = x[2];
    memset(out, 0, sizeof(double) * 8);
    out[7] = eta;
    if (z > eta || z < -h) return;   /* out of the water */
    int wheeler = stretching == 2;
    double zs = z;
    if (wheeler) zs = isinf(h) ? z - eta : h * (z - eta) / (h + eta);
    if (wheeler || z != c->z) {
        for (int k = 0; k < n; k++) {
            if (wheeler) factors(kk[k], zs < 0 ? zs : 0.0, h, c->fh + k, c->fv + k, c->fp + k);
            else stretched(stretching, kk[k], z, h, c->fh + k, c->fv + k, c->fp + k);
        }
        c->z = wheeler ? NAN : z;
    }
    double u0 = 0, u1 = 0, u2 = 0, a0 = 0, a1 = 0, a2 = 0, pd = 0;
    for (int k = 0; k < n; k++) {
        double pr = p[2 * k], pi = p[2 * k + 1], er = c->e[2 * k], ei = c->e[2 * k + 1];
        double re = pr * er - pi * ei, im = pr * ei + pi * er, wk = w[k], w2 = wk * wk;
        double hre = c->fh[k] * re, him = c->fh[k] * im;
        u0 += wk * cb[k] * hre, u1 += wk * sb[k] * hre, u2 -= wk * c->fv[k] * im;   /* w = dη/dt at z = 0 */
        a0 -= w2 * cb[k] * him, a1 -= w2 * sb[k] * him, a2 -= w2 * c->fv[k] * re;
        pd += c->fp[k] * re;
    }
    out[0] = r * u0, out[1] = r * u1, out[2] = r * u2, out[3] = r * a0, out[4] = r * a1, out[5] = r * a2;
    out[6] = r * rho * g * pd;
}

int hf_water_at(const HfWater *w, const double *x, double *row) {
    hf_kin_at(w->kin, w->cache, w->p, w->r, x, w->rho, row);
    return x[2] <= row[7] && x[2] >= -w->depth;
}
