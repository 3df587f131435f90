/* Second-order wave drift (physics/drift.py, the readable reference): a body's mean drift,
 * Newman's approximation or the full difference-frequency QTF on the components of the sea
 * that waves.c drew (hf_wave_build's parameters: one sea for every load of the FMU).
 *
 * hf_drift_build runs once per initialization, after hf_wave_build: it reads each component's
 * frequency and direction, interpolates the data at them as DriftLoad does (the QTF on its
 * value at the body's place, the phase e^{-i(k_i d_i - k_j d_j)} put back exactly), and stacks
 * the per-step coefficients.  hf_drift is the per-step kernel on the FMU's shared phasors
 * p_k = a_k e^{i(w_k t + phi_k)} (waves.c's HfPhasors, advanced once a step for every wave load)
 * and the ramp r; the load is quadratic in the ramped phasors r p:
 *   mean:   F = r^2 sum_k |p_k|^2 Q_kk = r^2 F_mean (a_k fixed: F_mean once)
 *   newman: F = r^2 (|sum_k p_k s+_k|^2 - |sum_k p_k s-_k|^2), s = sqrt(Q+-) e^{-i k_k d_k}
 *   qtf:    F = r^2 sum_i sum_{d=0..D} Re{w_d Q(i, i + d) p_i conj(p_{i+d})}, w_0 = 1, w_d = 2
 *   qtf by blocks (hf_drift with t, drift.py's DriftLoad.at): on the block [bL, (b + 1)L) of
 *           absolute time the direct sum at its K Chebyshev nodes, once, then per step the
 *           Chebyshev series at tau (Clenshaw), when K h <= L/2 (h the last step length)
 * Values are interpolated in heading in the frame turning with the wave (drift.py, Headings):
 * the record holds them in each heading's (each pair's mean heading's) frame and the
 * interpolated value is turned back to the component's direction.
 * Record (Drift.c_params): [method, cutoff (-1: none), x, y, nw, w (nw), data]; data:
 * mean/newman [nb, closed, directions (nb), values (nw nb 6)]; qtf [nh, closed, bidirectional,
 * nu, closed (unidirectional), uni (nu), headings (nh), x, y, re (nw nw nh nh 6), im (same)].
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "kernels.h"

#define PI 3.14159265358979323846
#define DIRECTION_TOL 1e-6   /* waves.DIRECTION_TOL */

/* physics.drift._locate: (i0, i1, frac) of x on the increasing grid w (nw); -1 outside */
static int locate(const double *w, int nw, double x, int *i0, int *i1, double *f) {
    if (x < w[0] * (1 - 1e-9) || x > w[nw - 1] * (1 + 1e-9)) return -1;
    if (nw == 1) {
        *i0 = *i1 = 0, *f = 0.0;
        return 0;
    }
    int i = 0;
    while (i < nw - 2 && w[i + 1] <= x) i++;
    double fr = (x - w[i]) / (w[i + 1] - w[i]);
    *i0 = i, *i1 = i + 1, *f = fr < 0 ? 0 : fr > 1 ? 1 : fr;
    return 0;
}

static double angle_gap(double a, double b) {   /* |a - b| on the circle [deg] */
    double d = fmod(fmod(a - b + 180.0, 360.0) + 360.0, 360.0) - 180.0;
    return fabs(d);
}

#define BLOCK_X 40.0     /* drift.py's BLOCK_X and BLOCK_TOL */
#define BLOCK_TOL 1e-15
#define HEAD 13          /* params: [method, n, D, F_mean (6), L, K (0: no blocks), t_last, block, coefficients...] */

/* drift.turn(back=True) of one value (6 complex as (re, im) pairs when stride 2, 6 reals when 1):
 * the horizontal pairs (1, 2) and (4, 5) from the frame of heading beta [deg] to global axes */
static void turn_back(double *v, double beta, int stride) {
    double b = beta * PI / 180.0, c = cos(b), s = sin(b);
    for (int i = 0; i < 4; i += 3)
        for (int part = 0; part < stride; part++) {
            double x = v[stride * i + part], y = v[stride * (i + 1) + part];
            v[stride * i + part] = c * x - s * y, v[stride * (i + 1) + part] = c * y + s * x;
        }
}

static double mean_heading(double a, double b) {   /* drift.mean_heading */
    double d = fmod(fmod(b - a + 180.0, 360.0) + 360.0, 360.0) - 180.0;
    return a + 0.5 * d;
}

/* drift.block_plan: K of the blocks of length L = 2 BLOCK_X / mu_max (0: no block) */
static int block_terms(void) {
    double x = BLOCK_X, term = 1.0;
    int n = 0;
    while (!(n + 1 > x / 2 && 4 * term / (1 - x / (2 * (n + 1))) <= BLOCK_TOL)) {
        n++;
        term *= x / (2 * n);
    }
    return n;
}

static int say(char *field, const char *name, char *m, size_t size, const char *text, ...) {
    va_list args;
    va_start(args, text);
    strcpy(field, name);
    vsnprintf(m, size, text, args);
    va_end(args);
    return -1;
}

#define OMEGA_TEXT "omega = %g rad/s is outside the drift data's frequencies %g...%g rad/s"
#define SPREAD_TEXT "the full QTF in a spread sea needs bidirectional data (every heading pair (beta1, beta2) of the " \
                    "file's headings); this QTF holds unidirectional pairs only: use method = \"newman\" or "  \
                    "\"mean\", or a long-crested sea"
#define DIRECTION_TEXT "wave direction %g deg is outside the drift data's directions %g...%g deg"

typedef struct {   /* the QTF record, its local values computed for g and depth */
    int nw, nh, closed, bidirectional, nu, closed_uni;
    const double *w, *h;
    double *uni_d;   /* (nu) the unidirectional headings */
    int *uni;
    double *local;   /* (nw nw nh nh 6) complex, (re, im) pairs */
} Qtf;

static int qtf_init(Qtf *Q, const double *p, double g, double depth) {
    Q->nw = (int)p[0], Q->w = p + 1;
    p = Q->w + Q->nw;
    Q->nh = (int)p[0], Q->closed = p[1] != 0.0, Q->bidirectional = p[2] != 0.0, Q->nu = (int)p[3];
    Q->closed_uni = p[4] != 0.0;
    const double *uni = p + 5;
    Q->h = uni + Q->nu;
    double x = Q->h[Q->nh], y = Q->h[Q->nh + 1];
    const double *re = Q->h + Q->nh + 2;
    size_t cells = (size_t)Q->nw * Q->nw * Q->nh * Q->nh * 6;
    const double *im = re + cells;
    Q->uni = malloc(sizeof(int) * (Q->nu + 1)), Q->uni_d = malloc(sizeof(double) * (Q->nu + 1));
    Q->local = malloc(sizeof(double) * 2 * cells);
    double *kd = malloc(sizeof(double) * (Q->nw * Q->nh + 1));
    if (!Q->uni || !Q->uni_d || !Q->local || !kd) {
        free(kd);
        return -1;
    }
    for (int u = 0; u < Q->nu; u++) Q->uni[u] = (int)uni[u], Q->uni_d[u] = Q->h[Q->uni[u]];
    for (int i = 0; i < Q->nw; i++) {
        double k = hf_wave_number(Q->w[i], g, depth);
        for (int a = 0; a < Q->nh; a++) {
            double b = Q->h[a] * PI / 180.0;
            kd[i * Q->nh + a] = k * (x * cos(b) + y * sin(b));
        }
    }
    size_t at = 0;   /* local = Q e^{i(k_i d_a - k_j d_b)}: the value at the body's place */
    for (int i = 0; i < Q->nw; i++)
        for (int j = 0; j < Q->nw; j++)
            for (int a = 0; a < Q->nh; a++)
                for (int b = 0; b < Q->nh; b++) {
                    double ph = kd[i * Q->nh + a] - kd[j * Q->nh + b], c = cos(ph), s = sin(ph);
                    for (int q = 0; q < 6; q++, at++) {
                        Q->local[2 * at] = re[at] * c - im[at] * s;
                        Q->local[2 * at + 1] = re[at] * s + im[at] * c;
                    }
                }
    free(kd);
    return 0;
}

/* QTF.at for one pair at the body's place: q (6 complex, (re, im) pairs) */
static int qtf_at(const Qtf *Q, double wi, double wj, double bi, double bj, double *q, char *field, char *m,
                  size_t size) {
    int i0, i1, j0, j1, ha[4], hb[4], nc;
    double fi, fj, wt[4];
    if (locate(Q->w, Q->nw, wi, &i0, &i1, &fi)) return say(field, "omega", m, size, OMEGA_TEXT, wi, Q->w[0], Q->w[Q->nw - 1]);
    if (locate(Q->w, Q->nw, wj, &j0, &j1, &fj)) return say(field, "omega", m, size, OMEGA_TEXT, wj, Q->w[0], Q->w[Q->nw - 1]);
    if (!Q->bidirectional) {
        int u0, u1;
        double f;
        if (angle_gap(bi, bj) > DIRECTION_TOL) return say(field, "spreading", m, size, SPREAD_TEXT);
        if (Q->nu == 0 || hf_direction_weights(Q->uni_d, Q->nu, Q->closed_uni, bi, &u0, &u1, &f))
            return say(field, "direction", m, size, DIRECTION_TEXT, bi, Q->nu ? Q->uni_d[0] : 0,
                       Q->nu ? Q->uni_d[Q->nu - 1] : 0);
        nc = 2, ha[0] = hb[0] = Q->uni[u0], ha[1] = hb[1] = Q->uni[u1], wt[0] = 1 - f, wt[1] = f;
    } else {
        int a0, a1, b0, b1;
        double fa, fb;
        if (hf_direction_weights(Q->h, Q->nh, Q->closed, bi, &a0, &a1, &fa))
            return say(field, "direction", m, size, DIRECTION_TEXT, bi, Q->h[0], Q->h[Q->nh - 1]);
        if (hf_direction_weights(Q->h, Q->nh, Q->closed, bj, &b0, &b1, &fb))
            return say(field, "direction", m, size, DIRECTION_TEXT, bj, Q->h[0], Q->h[Q->nh - 1]);
        nc = 4;
        ha[0] = a0, hb[0] = b0, wt[0] = (1 - fa) * (1 - fb);
        ha[1] = a0, hb[1] = b1, wt[1] = (1 - fa) * fb;
        ha[2] = a1, hb[2] = b0, wt[2] = fa * (1 - fb);
        ha[3] = a1, hb[3] = b1, wt[3] = fa * fb;
    }
    memset(q, 0, sizeof(double) * 12);
    const int wi_[2] = {i0, i1}, wj_[2] = {j0, j1};
    const double fw_i[2] = {1 - fi, fi}, fw_j[2] = {1 - fj, fj};
    for (int c = 0; c < nc; c++)
        for (int a = 0; a < 2; a++)
            for (int b = 0; b < 2; b++) {
                double wgt = wt[c] * fw_i[a] * fw_j[b];
                size_t at = ((((size_t)wi_[a] * Q->nw + wj_[b]) * Q->nh + ha[c]) * Q->nh + hb[c]) * 6;
                for (int k = 0; k < 12; k++) q[k] += wgt * Q->local[2 * at + k];
            }
    turn_back(q, mean_heading(bi, bj), 2);
    return 0;
}

/* MeanDrift.at for one component (TransferFunction's rules, real values) */
static int mean_at(const double *p, double w, double beta, double *out, char *field, char *m, size_t size) {
    int nw = (int)p[0];
    const double *ws = p + 1, *rest = ws + nw;
    int nb = (int)rest[0], closed = rest[1] != 0.0;
    const double *d = rest + 2, *v = d + nb;
    int i0, i1, j0, j1;
    double fw, fb;
    if (locate(ws, nw, w, &i0, &i1, &fw)) return say(field, "omega", m, size, OMEGA_TEXT, w, ws[0], ws[nw - 1]);
    if (hf_direction_weights(d, nb, closed, beta, &j0, &j1, &fb))
        return say(field, "direction", m, size, DIRECTION_TEXT, beta, d[0], d[nb - 1]);
    for (int q = 0; q < 6; q++) {
#define V(a, b) v[((a) * nb + (b)) * 6 + q]
        out[q] = (1 - fw) * ((1 - fb) * V(i0, j0) + fb * V(i0, j1)) + fw * ((1 - fb) * V(i1, j0) + fb * V(i1, j1));
#undef V
    }
    turn_back(out, beta, 1);
    return 0;
}

int hf_drift_record_ok(const double *r, int n) {   /* the record's sizes agree with its length */
    if (n < 6 || r[0] < 0 || r[0] > 2) return 0;
    int nw = (int)r[4];
    if (nw < 1 || n < 5 + nw + 5) return 0;
    const double *d = r + 5 + nw;
    if (r[0] < 2) {
        int nb = (int)d[0];
        return nb >= 1 && n == 5 + nw + 2 + nb + 6 * nw * nb;
    }
    int nh = (int)d[0], nu = (int)d[3];
    return nh >= 1 && nu >= 0 && nu <= nh && n == 5 + nw + 5 + nu + nh + 2 + 12 * nw * nw * nh * nh;
}

/* params: [method, n, D, F_mean (6), L, K, t_last, block, coefficients]: mean none, newman s+ and
 * s- (n 6 complex each), qtf the band (n (D + 1) 6 complex, the pair (j, i) folded in: 2 Q off the
 * diagonal) then the blocks' data: A_k = a_k e^{i phi_k} (n complex), w (n), the nodes on [0, L]
 * (K), the DCT (K K), the block's coefficients (K 6), node values (K 6), phasors (n complex) */
double *hf_drift_build(const double *wave, const double *record, int nrecord, double g, double depth, char *field,
                       char *m, size_t size) {
    (void)nrecord;
    int method = (int)record[0], n = (int)wave[0];
    double cutoff = record[1], x = record[2], y = record[3];
    const double *data = record + 4, *omega = wave + 2, *ampl = omega + n, *beta = ampl + 2 * n + 14 * n;
    Qtf Q = {0};
    int D = 0;
    if (method == 2) {
        for (int k = 1; k < n; k++)
            if (angle_gap(beta[k], beta[0]) > DIRECTION_TOL && !((int)data[1 + (int)data[0] + 2])) {
                say(field, "spreading", m, size, SPREAD_TEXT);
                return NULL;
            }
        if (qtf_init(&Q, data, g, depth)) goto oom;
        D = n - 1;
        if (n > 1 && cutoff >= 0) {   /* the largest offset d with w[k + d] - w[k] <= cutoff for some k */
            D = 0;
            for (int k = 0; k < n; k++) {
                int j = k;
                while (j + 1 < n && omega[j + 1] <= omega[k] + cutoff * (1 + 1e-12)) j++;
                if (j - k > D) D = j - k;
            }
        }
    }
    size_t ncoef = method == 0 ? 0 : method == 1 ? 24 * (size_t)n : 12 * (size_t)n * (D + 1);
    double mu_max = n > 1 ? omega[n - 1] - omega[0] : 0.0;
    if (cutoff >= 0 && cutoff < mu_max) mu_max = cutoff;
    int K = method == 2 && mu_max > 0 ? block_terms() : 0;
    size_t nblock = K ? 5 * (size_t)n + (size_t)K * (K + 13) : 0;
    double *p = calloc(HEAD + ncoef + nblock, sizeof(double));
    if (!p) goto oom;
    p[0] = method, p[1] = n, p[2] = D;
    p[9] = K ? 2 * BLOCK_X / mu_max : 0.0, p[10] = K, p[11] = NAN, p[12] = NAN;
    double *mean = p + 3, *coef = p + HEAD;
    if (K) {
        double *A = coef + ncoef, *w = A + 2 * n, *nodes = w + n, *dct = nodes + K;
        for (int k = 0; k < n; k++) A[2 * k] = ampl[2 * k], A[2 * k + 1] = ampl[2 * k + 1], w[k] = omega[k];
        for (int k = 0; k < K; k++) {
            double theta = (2 * k + 1) * PI / (2 * K);
            nodes[k] = 0.5 * p[9] * (1 + cos(theta));
            for (int m = 0; m < K; m++) dct[m * K + k] = (m ? 2.0 : 1.0) / K * cos(m * theta);
        }
    }
    if (method < 2) {
        for (int k = 0; k < n; k++) {
            double q[6] = {0}, a2 = ampl[2 * k] * ampl[2 * k] + ampl[2 * k + 1] * ampl[2 * k + 1];
            if (mean_at(data, omega[k], beta[k], q, field, m, size)) goto bad;
            double b = beta[k] * PI / 180.0, ph = -hf_wave_number(omega[k], g, depth) * (x * cos(b) + y * sin(b));
            double c = cos(ph), s = sin(ph);
            for (int j = 0; j < 6; j++) {
                mean[j] += a2 * q[j];
                if (method == 1) {   /* s+- e^{-i k d}: (re, im) pairs, s+ then s- */
                    double sp = sqrt(q[j] > 0 ? q[j] : 0), sm = sqrt(q[j] < 0 ? -q[j] : 0);
                    coef[12 * k + 2 * j] = sp * c, coef[12 * k + 2 * j + 1] = sp * s;
                    coef[12 * (n + k) + 2 * j] = sm * c, coef[12 * (n + k) + 2 * j + 1] = sm * s;
                }
            }
        }
    } else {
        for (int i = 0; i < n; i++) {
            double bi = beta[i] * PI / 180.0, di = hf_wave_number(omega[i], g, depth) * (x * cos(bi) + y * sin(bi));
            for (int d = 0; d <= D && i + d < n; d++) {
                int j = i + d;
                if (cutoff >= 0 && omega[j] - omega[i] > cutoff * (1 + 1e-12)) continue;
                double *q = coef + 12 * ((size_t)i * (D + 1) + d), bj = beta[j] * PI / 180.0;
                if (qtf_at(&Q, omega[i], omega[j], beta[i], beta[j], q, field, m, size)) goto bad;
                /* back to the origin: e^{-i(k_i d_i - k_j d_j)}; the pair (j, i) is the conjugate: 2 Re */
                double ph = -(di - hf_wave_number(omega[j], g, depth) * (x * cos(bj) + y * sin(bj)));
                double c = cos(ph) * (d > 0 ? 2.0 : 1.0), s = sin(ph) * (d > 0 ? 2.0 : 1.0);
                for (int k = 0; k < 6; k++) {
                    double re = q[2 * k], im = q[2 * k + 1];
                    q[2 * k] = re * c - im * s, q[2 * k + 1] = re * s + im * c;
                }
            }
        }
    }
    free(Q.uni), free(Q.uni_d), free(Q.local);
    return p;
oom:
    strcpy(field, "components");
    snprintf(m, size, "out of memory for the drift of %d wave components", n);
    free(Q.uni), free(Q.uni_d), free(Q.local);
    return NULL;
bad:
    free(Q.uni), free(Q.uni_d), free(Q.local), free(p);
    return NULL;
}

/* the QTF's direct sum on the phasors z (n complex) into out (6) */
static void qtf_sum(const double *params, const double *z, double *out) {
    int n = (int)params[1], D = (int)params[2];
    memset(out, 0, sizeof(double) * 6);
    for (int i = 0; i < n; i++) {
        double zr = z[2 * i], zi = z[2 * i + 1];
        int last = i + D < n ? i + D : n - 1;
        const double *q = params + HEAD + 12 * (size_t)i * (D + 1);
        for (int j = i; j <= last; j++, q += 12) {   /* p_i conj(p_j) */
            double xr = zr * z[2 * j] + zi * z[2 * j + 1], xi = zi * z[2 * j] - zr * z[2 * j + 1];
            for (int k = 0; k < 6; k++) out[k] += xr * q[2 * k] - xi * q[2 * k + 1];
        }
    }
}

/* the Chebyshev coefficients of block b (the direct sum at its K nodes) */
static void qtf_block(double *params, double b) {
    int n = (int)params[1], D = (int)params[2], K = (int)params[10];
    double L = params[9];
    double *A = params + HEAD + 12 * (size_t)n * (D + 1), *w = A + 2 * n, *nodes = w + n, *dct = nodes + K;
    double *c = dct + (size_t)K * K, *vals = c + 6 * K, *z = vals + 6 * K;
    for (int k = 0; k < K; k++) {
        double t = b * L + nodes[k];
        for (int m = 0; m < n; m++) {
            double cs = cos(w[m] * t), sn = sin(w[m] * t);
            z[2 * m] = A[2 * m] * cs - A[2 * m + 1] * sn, z[2 * m + 1] = A[2 * m] * sn + A[2 * m + 1] * cs;
        }
        qtf_sum(params, z, vals + 6 * k);
    }
    for (int m = 0; m < K; m++)
        for (int j = 0; j < 6; j++) {
            double sum = 0.0;
            for (int k = 0; k < K; k++) sum += dct[m * K + k] * vals[6 * k + j];
            c[6 * m + j] = sum;
        }
    params[12] = b;
}

void hf_drift(double *params, const double *z, double t, double r, double *out) {
    int method = (int)params[0], n = (int)params[1];
    const double *coef = params + HEAD;
    double r2 = r * r;
    if (method == 0) {   /* |p_k| = a_k: the mean is fixed, ramped */
        for (int j = 0; j < 6; j++) out[j] = r2 * params[3 + j];
        return;
    }
    memset(out, 0, sizeof(double) * 6);
    if (method == 1) {
        double pr[6] = {0}, pi[6] = {0}, mr[6] = {0}, mi[6] = {0};
        for (int k = 0; k < n; k++) {
            double zr = z[2 * k], zi = z[2 * k + 1];
            const double *sp = coef + 12 * k, *sm = coef + 12 * (n + k);
            for (int j = 0; j < 6; j++) {
                pr[j] += zr * sp[2 * j] - zi * sp[2 * j + 1], pi[j] += zr * sp[2 * j + 1] + zi * sp[2 * j];
                mr[j] += zr * sm[2 * j] - zi * sm[2 * j + 1], mi[j] += zr * sm[2 * j + 1] + zi * sm[2 * j];
            }
        }
        for (int j = 0; j < 6; j++) out[j] = r2 * (pr[j] * pr[j] + pi[j] * pi[j] - mr[j] * mr[j] - mi[j] * mi[j]);
        return;
    }
    int K = (int)params[10];
    double L = params[9], step = isnan(params[11]) ? INFINITY : fabs(t - params[11]);
    params[11] = t;
    double b = K ? floor(t / L) : 0.0;
    if (!K || (params[12] != b && !(step > 0 && K * step <= 0.5 * L))) {   /* the direct sum */
        qtf_sum(params, z, out);
        for (int k = 0; k < 6; k++) out[k] *= r2;
        return;
    }
    if (params[12] != b) qtf_block(params, b);
    const double *c = params + HEAD + 12 * (size_t)n * ((int)params[2] + 1) + 3 * (size_t)n + (size_t)K * (K + 1);
    double tau = 2 * (t - b * L) / L - 1;
    tau = tau < -1 ? -1 : tau > 1 ? 1 : tau;
    for (int j = 0; j < 6; j++) {   /* Clenshaw: sum_m c_m T_m(tau) */
        double b1 = 0.0, b2 = 0.0;
        for (int m = K - 1; m >= 1; m--) {
            double b0 = 2 * tau * b1 - b2 + c[6 * m + j];
            b2 = b1, b1 = b0;
        }
        out[j] = r2 * (c[j] + tau * b1 - b2);
    }
}
