/*
 * Retardation memory of physics/memory.py in C: the two evaluators (StateSpace,
 * Convolution) on one 6x6 coupling side, with the same formulas.  memory.py is the
 * reference (and fits the realisations at build time); the build hands these functions
 * the fitted modes and the kernel segments as memory.py holds them.
 */
#include <complex.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "kernels.h"

/* -- state space ------------------------------------------------------------------------ */

/* phi1(x) = (e^x - 1)/x and phi2(x) = (e^x - 1 - x)/x^2 (memory._phi: Taylor below |x| 0.1) */
static void phi(double complex x, double complex *p1, double complex *p2) {
    if (cabs(x) < 0.1) {
        double f[14];   /* f[n] = 1/(n+1)! */
        double fact = 1.0;
        for (int n = 0; n < 13; n++) fact *= n + 1, f[n] = 1.0 / fact;
        double complex s1 = f[11], s2 = f[12];
        for (int n = 10; n >= 0; n--) s1 = s1 * x + f[n], s2 = s2 * x + f[n + 1];
        *p1 = s1, *p2 = s2;
        return;
    }
    double a = sin(0.5 * cimag(x));   /* expm1 of a complex number, as numpy computes it */
    double complex em = (expm1(creal(x)) * cos(cimag(x)) - 2.0 * a * a) + I * (exp(creal(x)) * sin(cimag(x)));
    *p1 = em / x;
    *p2 = (em - x) / (x * x);
}

/* per mode in ss->coef: the step's e, b_old, b_new (re, im each), then gamma (re, im) */
enum { COEF = 8 };

int hf_ss_init(HfStateSpace *ss, const double *params, int n) {
    memset(ss, 0, sizeof *ss);
    if (n < 1) return -1;
    int m = (int)params[0];
    if (m < 0 || n != 1 + 6 * m) return -1;
    ss->m = m;
    ss->mu_re = params + 1, ss->mu_im = ss->mu_re + m, ss->gam_re = ss->mu_im + m, ss->gam_im = ss->gam_re + m;
    ss->inp = ss->gam_im + m, ss->out = ss->inp + m;
    ss->z = calloc(2 * (size_t)m + 1, sizeof(double));
    ss->coef = calloc(COEF * (size_t)m + 1, sizeof(double));
    ss->base = calloc(2 * (size_t)m + 1, sizeof(double));
    ss->io = calloc(2 * (size_t)m + 1, sizeof(int));
    ss->dt = -1.0;
    if (!ss->z || !ss->coef || !ss->base || !ss->io) return -1;
    for (int k = 0; k < m; k++) {
        ss->io[2 * k] = (int)ss->inp[k], ss->io[2 * k + 1] = (int)ss->out[k];
        if (ss->io[2 * k] < 0 || ss->io[2 * k] > 5 || ss->io[2 * k + 1] < 0 || ss->io[2 * k + 1] > 5) return -1;
    }
    return 0;
}

void hf_ss_free(HfStateSpace *ss) {
    free(ss->z), free(ss->coef), free(ss->base), free(ss->io);
    ss->z = ss->coef = ss->base = NULL;
    ss->io = NULL;
}

void hf_ss_restart(HfStateSpace *ss, const double *v) {
    memcpy(ss->v, v, sizeof ss->v);
    ss->peeked = ss->has_base = 0;
}

/* The coefficients of a step of length dt (a constant step: computed once). */
static void ss_coefficients(HfStateSpace *ss, double dt) {
    for (int k = 0; k < ss->m; k++) {
        double complex x = (ss->mu_re[k] + I * ss->mu_im[k]) * dt, p1, p2;
        phi(x, &p1, &p2);
        double complex e = cexp(x), bo = dt * (p1 - p2), bn = dt * p2;
        double *c = ss->coef + COEF * k;
        c[0] = creal(e), c[1] = cimag(e), c[2] = creal(bo), c[3] = cimag(bo), c[4] = creal(bn), c[5] = cimag(bn);
        c[6] = ss->gam_re[k], c[7] = ss->gam_im[k];
    }
    ss->dt = dt;
    ss->has_base = 0;
}

/* The part of the step from the state now that does not depend on the velocity at the step's
 * end (e z + b_old v_old), kept until the state moves: the peeks of one step (the read after
 * fmi2DoStep, the next fmi2DoStep with new inputs) share it. */
static void ss_base(HfStateSpace *ss) {
    for (int k = 0; k < ss->m; k++) {
        const double *c = ss->coef + COEF * k;
        double zr = ss->z[2 * k], zi = ss->z[2 * k + 1], vo = ss->v[ss->io[2 * k]];
        ss->base[2 * k] = c[0] * zr - c[1] * zi + c[2] * vo;
        ss->base[2 * k + 1] = c[1] * zr + c[0] * zi + c[3] * vo;
    }
    ss->has_base = 1;
}

static void ss_prepare(HfStateSpace *ss, double dt) {
    if (dt != ss->dt) ss_coefficients(ss, dt);
    if (!ss->has_base) ss_base(ss);
}

/* The load at the step's end into pforce, nothing moved. */
static void ss_step(HfStateSpace *ss, double dt, const double *v) {
    ss_prepare(ss, dt);
    double *f = ss->pforce;
    for (int i = 0; i < 6; i++) f[i] = 0.0;
    for (int k = 0; k < ss->m; k++) {
        const double *c = ss->coef + COEF * k;
        double vn = v[ss->io[2 * k]];
        double nr = ss->base[2 * k] + c[4] * vn, ni = ss->base[2 * k + 1] + c[5] * vn;
        f[ss->io[2 * k + 1]] += -c[6] * nr + c[7] * ni;
    }
    memcpy(ss->pv, v, sizeof ss->pv);
    ss->pdt = dt;
    ss->peeked = 1;
}

void hf_ss_peek(HfStateSpace *ss, double dt, const double *v, double *force) {
    if (!ss->peeked || ss->pdt != dt || memcmp(ss->pv, v, sizeof ss->pv) != 0) ss_step(ss, dt, v);
    memcpy(force, ss->pforce, sizeof ss->pforce);
}

/* One pass over the modes: the state at the step's end (what ss_step peeks, the same sums in the
 * same order), the next step's base from it (that step starts from this velocity) and the load
 * at the end of a next step of the same length with this velocity held, which is what a master
 * reads after fmi2DoStep before it sets new inputs.  (Sums straight into the struct: small
 * arrays copied after scalar stores stall the copy's loads.) */
void hf_ss_advance(HfStateSpace *ss, double dt, const double *v) {
    ss_prepare(ss, dt);
    double *now = ss->force, *next = ss->pforce;
    for (int i = 0; i < 6; i++) now[i] = next[i] = 0.0;
    for (int k = 0; k < ss->m; k++) {
        const double *c = ss->coef + COEF * k;
        double vn = v[ss->io[2 * k]];
        double zr = ss->base[2 * k] + c[4] * vn, zi = ss->base[2 * k + 1] + c[5] * vn;
        double br = c[0] * zr - c[1] * zi + c[2] * vn, bi = c[1] * zr + c[0] * zi + c[3] * vn;
        double pr = br + c[4] * vn, pi = bi + c[5] * vn;
        int out = ss->io[2 * k + 1];
        ss->z[2 * k] = zr, ss->z[2 * k + 1] = zi;
        ss->base[2 * k] = br, ss->base[2 * k + 1] = bi;
        now[out] += -c[6] * zr + c[7] * zi;
        next[out] += -c[6] * pr + c[7] * pi;
    }
    for (int i = 0; i < 6; i++) ss->v[i] = ss->pv[i] = v[i];
    ss->pdt = dt;
    ss->peeked = ss->has_base = 1;
}

size_t hf_ss_state_size(const HfStateSpace *ss) { return 2 * (size_t)ss->m + 12; }

void hf_ss_save(const HfStateSpace *ss, double *to) {
    memcpy(to, ss->z, sizeof(double) * 2 * ss->m);
    memcpy(to + 2 * ss->m, ss->v, sizeof ss->v);
    memcpy(to + 2 * ss->m + 6, ss->force, sizeof ss->force);
}

int hf_ss_load(HfStateSpace *ss, const double *from, size_t n) {
    if (n != hf_ss_state_size(ss)) return -1;
    memcpy(ss->z, from, sizeof(double) * 2 * ss->m);
    memcpy(ss->v, from + 2 * ss->m, sizeof ss->v);
    memcpy(ss->force, from + 2 * ss->m + 6, sizeof ss->force);
    ss->peeked = ss->has_base = 0;
    return 0;
}

/* -- convolution ------------------------------------------------------------------------ */

int hf_conv_init(HfConvolution *cv, const double *params, int n) {
    memset(cv, 0, sizeof *cv);
    if (n < 3) return -1;
    int nseg = (int)params[0], ne = (int)params[1];
    if (nseg < 0 || ne < 0 || n != 3 + (nseg + 1) + 2 * nseg * ne + 2 * ne) return -1;
    cv->nseg = nseg, cv->nelem = ne, cv->span = params[2];
    cv->g = params + 3, cv->hl = cv->g + nseg + 1, cv->hr = cv->hl + nseg * ne;
    cv->out = cv->hr + nseg * ne, cv->in = cv->out + ne;
    cv->cap = 64;
    cv->v = calloc(6 * (size_t)cv->cap, sizeof(double));
    cv->dt = calloc((size_t)cv->cap, sizeof(double));
    cv->lo = 0, cv->hi = 1;
    return cv->v && cv->dt ? 0 : -1;
}

void hf_conv_free(HfConvolution *cv) {
    free(cv->v), free(cv->dt), free(cv->key), free(cv->w), free(cv->s), free(cv->grid), free(cv->right), free(cv->left);
    cv->v = cv->dt = cv->key = cv->w = cv->s = cv->grid = cv->right = cv->left = NULL;
    cv->grid_dt = 0.0, cv->ngrid = 0;
}

void hf_conv_restart(HfConvolution *cv, const double *v) {
    memcpy(cv->v + 6 * (cv->hi - 1), v, sizeof(double) * 6);
    cv->peeked = 0;
}

/* Room for one more node: grow when over half full, else compact (memory.Convolution._make_room). */
static int make_room(HfConvolution *cv) {
    int n = cv->hi - cv->lo;
    if (2 * n > cv->cap) {
        double *v = realloc(cv->v, sizeof(double) * 12 * cv->cap), *dt = realloc(cv->dt, sizeof(double) * 2 * cv->cap);
        if (v) cv->v = v;
        if (dt) cv->dt = dt;
        if (!v || !dt) return -1;
        memset(cv->v + 6 * cv->cap, 0, sizeof(double) * 6 * cv->cap);
        memset(cv->dt + cv->cap, 0, sizeof(double) * cv->cap);
        cv->cap *= 2;
    } else {
        memmove(cv->v, cv->v + 6 * cv->lo, sizeof(double) * 6 * n);
        memmove(cv->dt, cv->dt + cv->lo, sizeof(double) * n);
        cv->lo = 0, cv->hi = n;
    }
    return 0;
}

static int upper(const double *a, int n, double x) {   /* searchsorted(a, x, 'right') */
    int lo = 0, hi = n;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (x < a[mid]) hi = mid;
        else lo = mid + 1;
    }
    return lo;
}

/* W[k, e] = int h_e(sigma) phi_k(sigma) dsigma, phi_k the hat function of node offset s_k
 * (memory.Convolution._weights): on every piece between the merged breakpoints of s and g,
 * h and the two hats are linear, so the integral is exact.  The part over [s_k, s_k+1] goes
 * to right, the part over [s_k-1, s_k] to left: the same array for W, two for the halves. */
static void weights(HfConvolution *cv, const double *s, int ns, double *right, double *left) {
    const double *g = cv->g;
    int ng = cv->nseg + 1, ne = cv->nelem, nseg = cv->nseg;
    memset(right, 0, sizeof(double) * ns * ne);
    memset(left, 0, sizeof(double) * ns * ne);
    double top = fmin(s[ns - 1], g[ng - 1]);
    int i = 0, j = 0, have = 0;
    double prev_raw = 0.0, a = 0.0;   /* the last point of the union (before merging twins), the last kept */
    while (i < ns || j < ng) {
        double p;
        if (j >= ng || (i < ns && s[i] < g[j])) p = s[i++];
        else if (i >= ns || g[j] < s[i]) p = g[j++];
        else p = s[i++], j++;   /* equal: one point */
        if (have && p == prev_raw) continue;   /* (union1d: unique) */
        if (p > top) break;
        int keep = !have || p - prev_raw > 1e-12 * top;
        prev_raw = p;
        if (!keep) continue;
        if (!have) {
            a = p, have = 1;
            continue;
        }
        double b = p, length = b - a, mid = 0.5 * (a + b);
        int js = upper(g, ng, mid) - 1, k = upper(s, ns, mid) - 1;
        if (js > nseg - 1) js = nseg - 1;
        if (k > ns - 2) k = ns - 2;
        double glen = g[js + 1] - g[js], aa = (a - g[js]) / glen, ab = (b - g[js]) / glen;
        double slen = s[k + 1] - s[k], la = (a - s[k]) / slen, lb = (b - s[k]) / slen;
        double c = length / 6.0;
        double fa = c * (2 * la + lb), fb = c * (la + 2 * lb);
        double na = c * (2 * (1 - la) + 1 - lb), nb = c * (1 - la + 2 * (1 - lb));
        double kl = (1 - aa) * na + (1 - ab) * nb, kr = aa * na + ab * nb;
        double fl = (1 - aa) * fa + (1 - ab) * fb, fr = aa * fa + ab * fb;
        const double *hl = cv->hl + js * ne, *hr = cv->hr + js * ne;
        double *wk = right + k * ne, *wf = left + (k + 1) * ne;
        for (int e = 0; e < ne; e++) {
            wk[e] += kl * hl[e] + kr * hr[e];
            wf[e] += fl * hl[e] + fr * hr[e];
        }
        a = b;
    }
}

/* The weights of offsets s (ns nodes, steps dt[hi - 1], dt[hi - 2], ...) into cv->w from the
 * half hats of a uniform grid when every step is the same (memory.Convolution._weights_of:
 * while the history fills, s is the start of one grid and only its last hat is cut short);
 * -1: not such offsets (or out of memory), the caller computes them. */
static int grid_weights(HfConvolution *cv, const double *s, int ns, int hi) {
    double dt = cv->dt[hi - 1];
    if (!(dt > 0.0)) return -1;
    for (int k = 1; k < ns; k++)
        if (cv->dt[hi - k] != dt) return -1;
    int ne = cv->nelem;
    if (cv->grid_dt != dt) {
        int n = (int)ceil(cv->span / dt) + 2;   /* nodes of a full history, and one */
        double *grid = realloc(cv->grid, sizeof(double) * n);
        if (!grid) return -1;
        cv->grid = grid;
        grid[0] = 0.0;
        for (int k = 1; k < n; k++) grid[k] = grid[k - 1] + dt;   /* (the sums evaluate makes) */
        int m = 0;   /* searchsorted(grid, span, 'left') + 1 */
        while (m < n && grid[m] < cv->span) m++;
        m = m + 1 < n ? m + 1 : n;
        double *right = realloc(cv->right, sizeof(double) * m * (ne ? ne : 1));
        if (right) cv->right = right;
        double *left = realloc(cv->left, sizeof(double) * m * (ne ? ne : 1));
        if (left) cv->left = left;
        if (!right || !left) return -1;
        weights(cv, grid, m, right, left);
        cv->grid_dt = dt, cv->ngrid = m;
    }
    if (ns > cv->ngrid || cv->grid[ns - 1] != s[ns - 1]) return -1;
    for (int q = 0; q < ns * ne; q++) cv->w[q] = cv->left[q];   /* (the last node's right half: none) */
    for (int q = 0; q < (ns - 1) * ne; q++) cv->w[q] += cv->right[q];
    return 0;
}

/* F at node hi - 1 from the nodes lo ... hi - 1 into force; the first node still needed into *lo_out. */
static int evaluate(HfConvolution *cv, int hi, double *force, int *lo_out) {
    int lo = cv->lo, ns = hi - lo;
    if (ns > cv->wcap) {
        int cap = 2 * ns;
        double *s = realloc(cv->s, sizeof(double) * cap), *key = realloc(cv->key, sizeof(double) * cap);
        double *w = realloc(cv->w, sizeof(double) * cap * (cv->nelem ? cv->nelem : 1));
        if (s) cv->s = s;
        if (key) cv->key = key;
        if (w) cv->w = w;
        if (!s || !key || !w) return -1;
        cv->wcap = cap;
    }
    double *s = cv->s;
    s[0] = 0.0;
    for (int k = 1; k < ns; k++) s[k] = s[k - 1] + cv->dt[hi - k];
    int k = 0;   /* searchsorted(s, span, 'left') */
    while (k < ns && s[k] < cv->span) k++;
    if (k < ns - 1) {   /* nodes beyond the first past the span never matter again */
        lo = hi - (k + 1);
        ns = k + 1;
    }
    *lo_out = lo;
    memset(force, 0, sizeof(double) * 6);
    if (!cv->nelem || ns < 2 || cv->span == 0.0) return 0;
    if (ns != cv->nkey || memcmp(s, cv->key, sizeof(double) * ns) != 0) {
        if (grid_weights(cv, s, ns, hi)) weights(cv, s, ns, cv->w, cv->w);
        memcpy(cv->key, s, sizeof(double) * ns);
        cv->nkey = ns;
    }
    for (int e = 0; e < cv->nelem; e++) {
        double f = 0.0;
        int in = (int)cv->in[e];
        for (int q = 0; q < ns; q++) f += cv->w[q * cv->nelem + e] * cv->v[6 * (hi - 1 - q) + in];
        force[(int)cv->out[e]] -= f;
    }
    return 0;
}

int hf_conv_peek(HfConvolution *cv, double dt, const double *v, double *force) {
    if (cv->hi == cv->cap && make_room(cv)) return -1;
    memcpy(cv->v + 6 * cv->hi, v, sizeof(double) * 6);
    cv->dt[cv->hi] = dt;
    if (evaluate(cv, cv->hi + 1, cv->pforce, &cv->plo)) return -1;
    memcpy(cv->pv, v, sizeof cv->pv);
    cv->pdt = dt;
    cv->peeked = 1;
    if (force) memcpy(force, cv->pforce, sizeof cv->pforce);
    return 0;
}

int hf_conv_advance(HfConvolution *cv, double dt, const double *v) {
    if (!cv->peeked || cv->pdt != dt || memcmp(cv->pv, v, sizeof cv->pv) != 0)
        if (hf_conv_peek(cv, dt, v, NULL)) return -1;
    memcpy(cv->force, cv->pforce, sizeof cv->force);
    cv->lo = cv->plo;
    cv->hi += 1;
    cv->peeked = 0;
    return 0;
}

/* [n nodes, dt (n - 1), v (6n), force (6)] */
size_t hf_conv_state_size(const HfConvolution *cv) {
    size_t n = (size_t)(cv->hi - cv->lo);
    return 1 + (n - 1) + 6 * n + 6;
}

void hf_conv_save(const HfConvolution *cv, double *to) {
    int n = cv->hi - cv->lo;
    to[0] = n;
    memcpy(to + 1, cv->dt + cv->lo + 1, sizeof(double) * (n - 1));
    memcpy(to + n, cv->v + 6 * cv->lo, sizeof(double) * 6 * n);
    memcpy(to + 7 * n, cv->force, sizeof cv->force);
}

int hf_conv_load(HfConvolution *cv, const double *from, size_t size) {
    if (size < 1) return -1;
    int n = (int)from[0];
    if (n < 1 || size != (size_t)(7 * n + 6)) return -1;
    int cap = 2 * n > 64 ? 2 * n : 64;
    double *v = calloc(6 * (size_t)cap, sizeof(double)), *dt = calloc((size_t)cap, sizeof(double));
    if (!v || !dt) {
        free(v), free(dt);
        return -1;
    }
    free(cv->v), free(cv->dt);
    cv->v = v, cv->dt = dt, cv->cap = cap;
    memcpy(dt + 1, from + 1, sizeof(double) * (n - 1));
    memcpy(v, from + n, sizeof(double) * 6 * n);
    memcpy(cv->force, from + 7 * n, sizeof cv->force);
    cv->lo = 0, cv->hi = n;
    cv->peeked = 0;
    return 0;
}
