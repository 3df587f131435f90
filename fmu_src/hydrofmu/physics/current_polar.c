/* DeepLines current polar (physics/current_polar.py CurrentPolar.load): coefficients
 * interpolated in the incidence of the water past the load point, q = rho SURFC V^2 / 2. */
#include <math.h>

#include "kernels.h"

static double pymod360(double x) {   /* Python's x % 360.0: the sign of the divisor */
    double r = fmod(x, 360.0);
    if (r != 0.0) {
        if (r < 0.0) r += 360.0;
    } else {
        r = 0.0;
    }
    return r;
}

void hf_current_polar(const double *params, const HfMotion *m, const HfEnv *env, double *out) {
    int n = (int)params[0];
    double xc = params[1], yc = params[2], zc = params[3], surfc = params[4];
    const double *angles = params + 5, *coef = angles + n + 2, *slope = coef + 3 * (n + 2);
    const double *R = m->R, *vel = m->velocity;
    double r[3], c[3], p[3] = {xc, yc, zc};
    hf_rotate(R, p, r);
    hf_current_at(env, m->position[2] + r[2], c);
    if (slope[3 * (n + 1)] != 0.0 && env->water) {   /* waves = true: the waves' velocity at P too */
        double x[3] = {m->position[0] + r[0], m->position[1] + r[1], m->position[2] + r[2]}, row[8];
        if (hf_water_at(env->water, x, row)) c[0] += row[0], c[1] += row[1], c[2] += row[2];
    }
    double ux = c[0] - (vel[0] + vel[4] * r[2] - vel[5] * r[1]);
    double uy = c[1] - (vel[1] + vel[5] * r[0] - vel[3] * r[2]);
    double uz = c[2] - (vel[2] + vel[3] * r[1] - vel[4] * r[0]);
    double bx = R[0] * ux + R[3] * uy + R[6] * uz, by = R[1] * ux + R[4] * uy + R[7] * uz;
    double v2 = bx * bx + by * by;
    double alpha = v2 > 0.0 ? pymod360(atan2(by, bx) / (3.14159265358979323846 / 180.0)) : 0.0;
    if (alpha >= 360.0) alpha = 0.0;
    double q = 0.5 * env->rho * surfc * v2;
    int lo = 0, hi = n + 2;   /* bisect_right(angles, alpha) - 1 */
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (alpha < angles[mid]) hi = mid;
        else lo = mid + 1;
    }
    int i = lo - 1;
    double d = alpha - angles[i];
    const double *ci = coef + 3 * i, *si = slope + 3 * i;
    double c0 = q * (ci[0] + d * si[0]), c1 = q * (ci[1] + d * si[1]), c2 = q * (ci[2] + d * si[2]);
    double fx = R[0] * c0 + R[1] * c1, fy = R[3] * c0 + R[4] * c1, fz = R[6] * c0 + R[7] * c1;
    out[0] = fx, out[1] = fy, out[2] = fz;
    out[3] = r[1] * fz - r[2] * fy + R[2] * c2;
    out[4] = r[2] * fx - r[0] * fz + R[5] * c2;
    out[5] = r[0] * fy - r[1] * fx + R[8] * c2;
}
