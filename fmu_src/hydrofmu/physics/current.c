/* The current at a height (physics/current.py CurrentProfile.shape and state.Env.current_xyz). */
#include <string.h>

#include "kernels.h"

/* linear in x between the points xs (increasing), the end values outside (current._interp) */
static double interp(double x, const double *xs, const double *ys, int n) {
    int k = 0, hi = n;   /* bisect_right */
    while (k < hi) {
        int mid = (k + hi) / 2;
        if (x < xs[mid]) hi = mid;
        else k = mid + 1;
    }
    if (k == 0) return ys[0];
    if (k == n) return ys[n - 1];
    double t = (x - xs[k - 1]) / (xs[k] - xs[k - 1]);
    return ys[k - 1] + t * (ys[k] - ys[k - 1]);
}

void hf_env(HfEnv *env, double rho, double g, double speed, double direction, const HfProfile *profile) {
    env->rho = rho, env->g = g, env->speed = speed, env->direction = direction, env->profile = profile;
    env->water = NULL;
    hf_current_components(speed, direction, env->uniform);
}

void hf_current_at(const HfEnv *env, double z, double *out) {
    const HfProfile *p = env->profile;
    if (!p) {
        out[0] = env->uniform[0], out[1] = env->uniform[1], out[2] = env->uniform[2];
        return;
    }
    double ratio = interp(z, p->z, p->ratio, p->n), turn = interp(z, p->z, p->turn, p->n);
    hf_current_components(env->speed * ratio, env->direction + turn, out);
}
