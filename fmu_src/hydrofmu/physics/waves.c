/* First-order waves (physics/waves.py, the readable reference): a sea state's components,
 * a body's transfer function interpolated at them, the shared per-step phasors, and the
 * excitation and elevation at time t.
 *
 * hf_wave_build runs once per initialization (the sea state the waves.* parameters hold
 * then): it draws the components exactly as physics.waves.components does, with numpy's
 * default_rng (PCG64 seeded through SeedSequence, reproduced here bit for bit: the same seed
 * gives the same wave field in both flavours), and stacks WaveLoad's table.  The phasors
 * (waves.Phasors) p_k = a_k e^{i(w_k t + phi_k)} are advanced once per step for the whole FMU
 * by one complex multiply per component, set exactly every HF_RESYNC steps and whenever t is
 * off the step grid (variable steps, restored states); hf_waves is then
 * out (7) = r(t) sum_k Re(p_k T_k), T_k = [X(w_k, beta_k), e^{-i k.x}].
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "kernels.h"

#define PI 3.14159265358979323846
#define TAIL 0.005          /* waves.TAIL */
#define MAX_OUTSIDE 0.02    /* waves.MAX_OUTSIDE */
#define DIRECTION_TOL 1e-6  /* waves.DIRECTION_TOL */
#define GRID 12000          /* waves._grid */
#define SPREAD_GRID 4001    /* waves._spread */

/* -- numpy's default_rng(seed): SeedSequence, PCG64 (XSL-RR), random() ----------------- */

typedef unsigned __int128 u128;
typedef struct {
    u128 state, inc;
} Pcg64;

static const u128 PCG_MULT = ((u128)0x2360ED051FC65DA4ULL << 64) | 0x4385DF649FCCF645ULL;

static uint32_t hashmix(uint32_t value, uint32_t *hash) {
    value ^= *hash;
    *hash *= 0x931e8875u;
    value *= *hash;
    return value ^ (value >> 16);
}

static uint32_t mix(uint32_t x, uint32_t y) {
    uint32_t r = 0xca01f9ddu * x - 0x4973f715u * y;
    return r ^ (r >> 16);
}

static void pcg_step(Pcg64 *g) { g->state = g->state * PCG_MULT + g->inc; }

static void rng_seed(Pcg64 *g, uint64_t seed) {
    uint32_t entropy[2] = {(uint32_t)seed, (uint32_t)(seed >> 32)}, pool[4], hash = 0x43b0d7e5u, words[8];
    int n = seed >> 32 ? 2 : 1;
    for (int i = 0; i < 4; i++) pool[i] = hashmix(i < n ? entropy[i] : 0u, &hash);
    for (int s = 0; s < 4; s++)
        for (int d = 0; d < 4; d++)
            if (s != d) pool[d] = mix(pool[d], hashmix(pool[s], &hash));
    uint32_t h = 0x8b51f9ddu;   /* generate_state(4, uint64) */
    for (int i = 0; i < 8; i++) {
        uint32_t v = pool[i % 4] ^ h;
        h *= 0x58f38dedu;
        v *= h;
        words[i] = v ^ (v >> 16);
    }
    uint64_t w[4];
    for (int i = 0; i < 4; i++) w[i] = (uint64_t)words[2 * i] | (uint64_t)words[2 * i + 1] << 32;
    g->state = 0;
    g->inc = ((((u128)w[2] << 64) | w[3]) << 1) | 1u;
    pcg_step(g);
    g->state += ((u128)w[0] << 64) | w[1];
    pcg_step(g);
}

static double rng_double(Pcg64 *g) {
    pcg_step(g);
    uint64_t x = (uint64_t)(g->state >> 64) ^ (uint64_t)g->state;
    unsigned rot = (unsigned)(g->state >> 122);
    x = (x >> rot) | (x << ((64 - rot) & 63));
    return (double)(x >> 11) * (1.0 / 9007199254740992.0);
}

/* -- the spectrum --------------------------------------------------------------------- */

double hf_wave_number(double omega, double g, double depth) {   /* waves.wave_number */
    double k = omega * omega / g;
    if (isinf(depth)) return k;
    double shallow = omega / sqrt(g * depth);
    if (k < shallow) k = shallow;
    for (int it = 0; it < 50; it++) {
        double th = tanh(k * depth), f = g * k * th - omega * omega, df = g * th + g * k * depth * (1 - th * th);
        double step = f / (df > 0 ? df : 1.0);
        k -= step;
        if (fabs(step) <= 1e-13 * (k > 1e-12 ? k : 1e-12)) break;
    }
    return k;
}

static double shape(double w, double tp, double gamma) {   /* waves._shape */
    double wp = 2 * PI / tp;
    if (!(w > 0)) return 0.0;
    double base = pow(w, -5.0) * exp(-1.25 * pow(wp / w, 4)), sigma = w <= wp ? 0.07 : 0.09;
    double v = base * pow(gamma, exp(-((w - wp) * (w - wp)) / (2 * sigma * sigma * wp * wp)));
    return isfinite(v) ? v : 0.0;
}

/* np.interp(x, xp, fp) for increasing xp, with its left/right values */
static double interp(double x, const double *xp, const double *fp, int n, double left, double right) {
    if (x < xp[0]) return left;
    if (x > xp[n - 1]) return right;
    if (x == xp[n - 1]) return fp[n - 1];
    int lo = 0, hi = n - 1;   /* xp[lo] <= x < xp[hi] */
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (xp[mid] <= x) lo = mid;
        else hi = mid;
    }
    return (fp[hi] - fp[lo]) / (xp[hi] - xp[lo]) * (x - xp[lo]) + fp[lo];
}

static void linspace(double a, double b, int n, double *out) {
    double step = (b - a) / (n - 1);
    for (int i = 0; i < n; i++) out[i] = a + i * step;
    out[n - 1] = b;
}

typedef struct {
    double w[GRID], s[GRID], c[GRID], m0;
} Spectrum;

/* waves._cumulative and the scale of waves.spectrum */
static void spectrum_grid(Spectrum *sp, double tp, double gamma) {
    double wp = 2 * PI / tp, total = 0.0;
    linspace(wp * 0.2, wp * 12.0, GRID, sp->w);
    for (int i = 0; i < GRID; i++) sp->s[i] = shape(sp->w[i], tp, gamma);
    sp->c[0] = 0.0;
    for (int i = 1; i < GRID; i++) {
        double dw = sp->w[i] - sp->w[i - 1];
        sp->c[i] = sp->c[i - 1] + 0.5 * (sp->s[i] + sp->s[i - 1]) * dw;
        total += dw * (sp->s[i] + sp->s[i - 1]) / 2.0;
    }
    sp->m0 = total;
    double all = sp->c[GRID - 1] + sp->s[GRID - 1] * sp->w[GRID - 1] / 4;
    for (int i = 0; i < GRID; i++) sp->c[i] /= all;
}

/* -- the transfer function: [window_lo, window_hi, x, y, closed, nw, nb, omega (nw),
 * directions (nb), re (nw nb 6), im (nw nb 6)] (TransferFunction.c_params) ------------ */

typedef struct {
    int nw, nb, closed;
    double x, y;
    const double *w, *d;
    double *local;   /* (nw, nb, 6) complex: (re, im) pairs, referred to the body's position */
} Transfer;

static double wrap360(double a) { return a - 360.0 * floor(a / 360.0); }

static int transfer_init(Transfer *T, const double *p, double g, double depth) {
    T->x = p[2], T->y = p[3], T->closed = p[4] != 0.0, T->nw = (int)p[5], T->nb = (int)p[6];
    T->w = p + 7, T->d = T->w + T->nw;
    if (T->nw == 0) return 0;   /* no excitation: the window alone */
    const double *re = T->d + T->nb, *im = re + 6 * T->nw * T->nb;
    T->local = malloc(sizeof(double) * 12 * T->nw * T->nb);
    if (!T->local) return -1;
    for (int i = 0; i < T->nw; i++) {
        double k = hf_wave_number(T->w[i], g, depth);
        for (int j = 0; j < T->nb; j++) {
            double b = T->d[j] * PI / 180.0, ph = k * (T->x * cos(b) + T->y * sin(b)), c = cos(ph), s = sin(ph);
            for (int q = 0; q < 6; q++) {
                int at = (i * T->nb + j) * 6 + q;
                T->local[2 * at] = re[at] * c - im[at] * s;
                T->local[2 * at + 1] = re[at] * s + im[at] * c;
            }
        }
    }
    return 0;
}

/* TransferFunction._direction_weights for one direction over the directions d (nb, sorted
 * in [0, 360)), closed when they go round the circle; -1: outside the computed ones */
int hf_direction_weights(const double *d, int nb, int closed, double beta, int *j0, int *j1, double *frac) {
    beta = wrap360(beta);
    if (closed) {
        if (beta < d[0]) beta += 360.0;   /* below the first: across the wrap from the last */
        int j = 0;   /* searchsorted(ext, beta, 'right') - 1, clipped to 0 ... nb - 1 */
        while (j < nb && (j + 1 < nb ? d[j + 1] : d[0] + 360.0) <= beta) j++;
        double next = j + 1 < nb ? d[j + 1] : d[0] + 360.0;
        *j0 = j, *j1 = (j + 1) % nb, *frac = (beta - d[j]) / (next - d[j]);
        return 0;
    }
    for (int j = 0; j < nb; j++)
        if (fabs(fmod(fmod(beta - d[j] + 180.0, 360.0) + 360.0, 360.0) - 180.0) <= DIRECTION_TOL) {
            beta = d[j];
            break;
        }
    if (beta < d[0] - DIRECTION_TOL || beta > d[nb - 1] + DIRECTION_TOL) return -1;
    if (nb == 1) {
        *j0 = *j1 = 0, *frac = 0.0;
        return 0;
    }
    int j = 0;
    while (j < nb - 2 && d[j + 1] <= beta) j++;
    double f = (beta - d[j]) / (d[j + 1] - d[j]);
    *j0 = j, *j1 = j + 1, *frac = f < 0 ? 0 : f > 1 ? 1 : f;
    return 0;
}

static int direction_weights(const Transfer *T, double beta, int *j0, int *j1, double *frac) {
    return hf_direction_weights(T->d, T->nb, T->closed, beta, j0, j1, frac);
}

/* TransferFunction.at for one component: X (6 complex, (re, im) pairs) referred to the origin */
static int transfer_at(const Transfer *T, double omega, double beta, double g, double depth, double *x,
                       char *message, size_t size) {
    const double *w = T->w;
    int nw = T->nw;
    if (nw == 0) {   /* no excitation */
        memset(x, 0, sizeof(double) * 12);
        return 0;
    }
    if (omega < w[0] * (1 - 1e-9) || omega > w[nw - 1] * (1 + 1e-9)) {
        snprintf(message, size, "omega = %g rad/s is outside the transfer function's frequencies %g...%g rad/s",
                 omega, w[0], w[nw - 1]);
        return -1;
    }
    int i = 0;
    while (i < nw - 2 && w[i + 1] <= omega) i++;
    double fw = 0.0;
    if (nw > 1) {
        fw = (omega - w[i]) / (w[i + 1] - w[i]);
        fw = fw < 0 ? 0 : fw > 1 ? 1 : fw;
    }
    int i1 = i + 1 < nw ? i + 1 : nw - 1, j0, j1;
    double fb;
    if (direction_weights(T, beta, &j0, &j1, &fb)) {
        snprintf(message, size, "wave direction %g deg is outside the computed directions %g...%g deg (they do "
                 "not go round the circle)", wrap360(beta), T->d[0], T->d[T->nb - 1]);
        return -1;
    }
    double k = hf_wave_number(omega, g, depth), b = beta * PI / 180.0, ph = -k * (T->x * cos(b) + T->y * sin(b));
    double c = cos(ph), s = sin(ph);
    for (int q = 0; q < 6; q++)
        for (int p = 0; p < 2; p++) {
#define L(a, bb) T->local[2 * (((a) * T->nb + (bb)) * 6 + q) + p]
            x[2 * q + p] = (1 - fw) * ((1 - fb) * L(i, j0) + fb * L(i, j1)) + fw * ((1 - fb) * L(i1, j0) + fb * L(i1, j1));
#undef L
        }
    for (int q = 0; q < 6; q++) {
        double re = x[2 * q], im = x[2 * q + 1];
        x[2 * q] = re * c - im * s, x[2 * q + 1] = re * s + im * c;
    }
    return 0;
}

/* -- the sea state --------------------------------------------------------------------- */

static int fail(char *field, const char *name, char *message, size_t size, const char *fmt, double a) {
    strcpy(field, name);
    snprintf(message, size, fmt, a);
    return -1;
}

int hf_sea_check(const HfSea *s, char *field, char *m, size_t size) {   /* SeaState.check */
    const double finite[] = {s->hs, s->tp, s->gamma, s->height, s->period, s->phase, s->direction, s->spreading,
                             s->ramp};
    const char *names[] = {"hs", "tp", "gamma", "height", "period", "phase", "direction", "spreading", "ramp"};
    for (int k = 0; k < 9; k++)
        if (!isfinite(finite[k])) return fail(field, names[k], m, size, "must be finite, found %g", finite[k]);
    if (s->spectrum == 0) {
        if (s->height < 0) return fail(field, "height", m, size, "must not be negative, found %g m", s->height);
        if (s->period <= 0) return fail(field, "period", m, size, "must be positive, found %g s", s->period);
    } else {
        if (s->hs < 0) return fail(field, "hs", m, size, "significant wave height must not be negative, found %g m", s->hs);
        if (s->tp <= 0) return fail(field, "tp", m, size, "peak period must be positive, found %g s", s->tp);
        if (s->spectrum == 1 && s->gamma < 1)
            return fail(field, "gamma", m, size, "JONSWAP peak enhancement must be at least 1, found %g", s->gamma);
        if (!(s->components == floor(s->components) && s->components >= 1 && s->components <= 1e7))
            return fail(field, "components", m, size, "must be a positive integer, found %g", s->components);
    }
    if (s->spreading < 0)
        return fail(field, "spreading", m, size, "cos-2s exponent s must not be negative, found %g", s->spreading);
    if (s->ramp < 0) return fail(field, "ramp", m, size, "must not be negative, found %g s", s->ramp);
    if (!(s->depth > 0)) return fail(field, "depth", m, size, "must be positive (inf: deep water), found %g m", s->depth);
    if (!(s->seed == floor(s->seed) && s->seed >= 0 && s->seed < 18446744073709551616.0))
        return fail(field, "seed", m, size, "must be a non-negative integer, found %g", s->seed);
    return 0;
}

/* waves._spread: n direction offsets [deg] from D(theta) ~ cos^2s(theta / 2) */
static int spread(Pcg64 *g, double s, int n, double *out) {
    double *theta = malloc(sizeof(double) * 2 * SPREAD_GRID), *c = theta + SPREAD_GRID;
    if (!theta) return -1;
    linspace(-PI, PI, SPREAD_GRID, theta);
    double prev = pow(cos(theta[0] / 2), 2 * s);
    c[0] = 0.0;
    for (int i = 1; i < SPREAD_GRID; i++) {
        double d = pow(cos(theta[i] / 2), 2 * s);
        c[i] = c[i - 1] + 0.5 * (d + prev) * (theta[i] - theta[i - 1]);
        prev = d;
    }
    double last = c[SPREAD_GRID - 1];
    for (int i = 0; i < SPREAD_GRID; i++) c[i] /= last;
    for (int k = 0; k < n; k++) out[k] = interp(rng_double(g), c, theta, SPREAD_GRID, theta[0], theta[SPREAD_GRID - 1]) * 180.0 / PI;
    free(theta);
    return 0;
}

double *hf_wave_build(const HfSea *sea, const double *transfer, double g, char *field, char *m, size_t size) {
    if (hf_sea_check(sea, field, m, size)) return NULL;
    const double lo_w = transfer[0], hi_w = transfer[1];
    int n = sea->spectrum == 0 ? 1 : (int)sea->components;
    double *params = malloc(sizeof(double) * (2 + 3 * n + 14 * n + n)), *w = malloc(sizeof(double) * 4 * n);
    double *amp = w + n, *beta = amp + n, *phase = beta + n;
    Spectrum *sp = NULL;
    Transfer T = {0};
    if (!params || !w) goto oom;
    if (sea->spectrum == 0) {   /* regular */
        w[0] = 2 * PI / sea->period, amp[0] = sea->height / 2, beta[0] = sea->direction, phase[0] = sea->phase * PI / 180;
        if (!(lo_w - 1e-9 <= w[0] && w[0] <= hi_w + 1e-9)) {
            strcpy(field, "period");
            snprintf(m, size, "%g s (omega = %.4g rad/s) is outside the transfer functions' frequencies %.4g...%.4g rad/s",
                     sea->period, w[0], lo_w, hi_w);
            goto bad;
        }
    } else {
        double gamma = sea->spectrum == 2 ? 1.0 : sea->gamma;
        sp = malloc(sizeof *sp);
        if (!sp) goto oom;
        spectrum_grid(sp, sea->tp, gamma);
        double lo = interp(TAIL / 2, sp->c, sp->w, GRID, sp->w[0], sp->w[GRID - 1]);
        double hi = interp(1 - TAIL / 2, sp->c, sp->w, GRID, sp->w[0], sp->w[GRID - 1]), outside = 1.0;
        lo = lo > lo_w ? lo : lo_w, hi = hi < hi_w ? hi : hi_w;
        if (hi > lo)
            outside = 1 - (interp(hi, sp->w, sp->c, GRID, sp->c[0], 1.0) - interp(lo, sp->w, sp->c, GRID, 0.0, sp->c[GRID - 1]));
        if (outside > MAX_OUTSIDE) {
            strcpy(field, "tp");
            snprintf(m, size, "Tp = %g s: %.3g %% of the spectrum's energy falls outside the transfer functions' "
                     "frequencies %.4g...%.4g rad/s (at most %g %% allowed)", sea->tp, 100 * outside, lo_w, hi_w,
                     100 * MAX_OUTSIDE);
            goto bad;
        }
        Pcg64 rng;
        rng_seed(&rng, (uint64_t)sea->seed);
        double dw = (hi - lo) / n, scale = (sea->hs / 4) * (sea->hs / 4) / sp->m0;
        for (int k = 0; k < n; k++) w[k] = lo + (k + rng_double(&rng)) * dw;
        for (int k = 0; k < n; k++) phase[k] = 0.0 + 2 * PI * rng_double(&rng);
        if (sea->spreading > 0) {
            if (spread(&rng, sea->spreading, n, beta)) goto oom;
            for (int k = 0; k < n; k++) beta[k] = sea->direction + beta[k];
        } else {
            for (int k = 0; k < n; k++) beta[k] = sea->direction;
        }
        for (int k = 0; k < n; k++) amp[k] = sqrt(2 * scale * shape(w[k], sea->tp, gamma) * dw);
    }
    /* WaveLoad: T_k = [X(w, beta), e^{-i k x}], rows 2k, 2k + 1: Re T_k, -Im T_k; a e^{i phi} apart */
    if (transfer_init(&T, transfer, g, sea->depth)) goto oom;
    params[0] = n, params[1] = sea->ramp;
    double *omega = params + 2, *ampl = omega + n, *table = ampl + 2 * n;
    for (int k = 0; k < n; k++) {
        double x[12], kw = hf_wave_number(w[k], g, sea->depth), b = beta[k] * PI / 180.0;
        if (transfer_at(&T, w[k], beta[k], g, sea->depth, x, m, size)) {
            strcpy(field, strncmp(m, "wave direction", 14) == 0 ? "direction" : "omega");
            goto bad;
        }
        double ph = -kw * (T.x * cos(b) + T.y * sin(b));
        omega[k] = w[k];
        ampl[2 * k] = amp[k] * cos(phase[k]), ampl[2 * k + 1] = amp[k] * sin(phase[k]);
        for (int q = 0; q < 6; q++) table[14 * k + q] = x[2 * q], table[14 * k + 7 + q] = -x[2 * q + 1];
        table[14 * k + 6] = cos(ph), table[14 * k + 13] = -sin(ph);
        table[14 * n + k] = beta[k];
    }
    free(T.local), free(sp), free(w);
    return params;
oom:
    strcpy(field, "components");
    snprintf(m, size, "out of memory for %d wave components", n);
bad:
    free(T.local), free(sp), free(w), free(params);
    return NULL;
}

/* -- the phasors (waves.Phasors) ------------------------------------------------------- */

static double ulp(double x) { x = fabs(x); return nextafter(x, INFINITY) - x; }

HfPhasors *hf_phasors_new(const double *omega, const double *amp, int n, double ramp, int resync) {
    HfPhasors *P = calloc(1, sizeof *P);
    double *p = malloc(sizeof(double) * 4 * (n > 0 ? n : 1));
    if (!P || !p) {
        free(P), free(p);
        return NULL;
    }
    P->n = n, P->resync = resync, P->ramp = ramp, P->omega = omega, P->amp = amp;
    P->p = p, P->rot = p + 2 * n, P->t = NAN;
    return P;
}

void hf_phasors_delete(HfPhasors *P) {
    if (P) free(P->p);
    free(P);
}

static void phasors_exact(HfPhasors *P, double t) {
    for (int k = 0; k < P->n; k++) {
        double c = cos(P->omega[k] * t), s = sin(P->omega[k] * t), ar = P->amp[2 * k], ai = P->amp[2 * k + 1];
        P->p[2 * k] = ar * c - ai * s, P->p[2 * k + 1] = ar * s + ai * c;
    }
    P->exact++, P->sync = t, P->j = 0;
}

const double *hf_phasors_at(HfPhasors *P, double t) {
    if (t == P->t) return P->p;
    double prev = P->t;
    P->t = t;
    if (P->has_rot && P->j < P->resync && P->h > 0) {
        double grid = P->sync + (P->j + 1) * P->h, big = fabs(t) > fabs(grid) ? fabs(t) : fabs(grid);
        if (fabs(t - grid) <= HF_GRID_ULPS * ulp(big)) {
            double *p = P->p;
            const double *f = P->rot;
            for (int k = 0; k < P->n; k++) {
                double a = p[2 * k], b = p[2 * k + 1], c = f[2 * k], s = f[2 * k + 1];
                p[2 * k] = a * c - b * s, p[2 * k + 1] = a * s + b * c;
            }
            P->j++, P->rotations++;
            return P->p;
        }
    }
    double h = t - prev;
    phasors_exact(P, t);
    if (!(isfinite(h) && h > 0)) {
        P->h = 0.0, P->has_rot = 0;
    } else if (!P->has_rot || fabs(h - P->h) > HF_GRID_ULPS * ulp(t)) {   /* a new step length */
        for (int k = 0; k < P->n; k++) P->rot[2 * k] = cos(P->omega[k] * h), P->rot[2 * k + 1] = sin(P->omega[k] * h);
        P->h = h, P->has_rot = 1;
    }
    return P->p;
}

/* the phasors' state (an FMU state holds it: a run restored continues bit for bit):
 * [t, sync, j, h, has_rot, p (2n)]; the rotation is recomputed from h */
size_t hf_phasors_state_size(const HfPhasors *P) { return 5 + 2 * (size_t)P->n; }

void hf_phasors_save(const HfPhasors *P, double *to) {
    to[0] = P->t, to[1] = P->sync, to[2] = P->j, to[3] = P->h, to[4] = P->has_rot;
    memcpy(to + 5, P->p, sizeof(double) * 2 * P->n);
}

int hf_phasors_load(HfPhasors *P, const double *from, size_t n) {
    if (n != hf_phasors_state_size(P) || !(from[2] >= 0 && from[2] <= P->resync)) return -1;
    P->t = from[0], P->sync = from[1], P->j = (int)from[2], P->h = from[3], P->has_rot = from[4] != 0.0;
    memcpy(P->p, from + 5, sizeof(double) * 2 * P->n);
    if (P->has_rot)
        for (int k = 0; k < P->n; k++) P->rot[2 * k] = cos(P->omega[k] * P->h), P->rot[2 * k + 1] = sin(P->omega[k] * P->h);
    return 0;
}

double hf_phasors_ramp(const HfPhasors *P) {
    double t = P->t, length = P->ramp;
    if (!(t < length)) return 1.0;
    return t <= 0.0 ? 0.0 : 0.5 * (1.0 - cos(PI * t / length));
}

HfPhasors *hf_wave_phasors(const double *params) {
    int n = (int)params[0];
    return hf_phasors_new(params + 2, params + 2 + n, n, params[1], HF_RESYNC);
}

void hf_waves(const double *params, HfPhasors *P, double t, double *out) {
    int n = (int)params[0];
    const double *table = params + 2 + 3 * n, *p = hf_phasors_at(P, t);
    double acc[7] = {0};   /* (local sums: out may alias, these stay in registers) */
    for (int k = 0; k < n; k++) {
        double re = p[2 * k], im = p[2 * k + 1];
        const double *a = table + 14 * k, *b = a + 7;
        for (int j = 0; j < 7; j++) acc[j] += re * a[j] + im * b[j];
    }
    double r = hf_phasors_ramp(P);
    for (int j = 0; j < 7; j++) out[j] = r * acc[j];
}
