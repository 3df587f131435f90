/*
 * The rigid-body equations of motion of physics/rigid_body.py (_Equations) and their
 * explicit Runge-Kutta steps, in C: the same formulas, term for term, for the dynamics
 * partner's per-step path, where Python's cost per arithmetic operation dominated
 * (~60 us of a ~150 us coupled step went into four evaluations of a 12x12 system).
 * rigid_body.py stays the reference: every failure here (gimbal lock, a singular or
 * non-finite system) is reported by status only, and the caller redoes the step in
 * Python, which raises the error the user sees.
 *
 * Layout, n bodies, N = 6n:
 *   model = [n, gimbal_tol, props (11 per body), const (N*N), kd (N*2N), k_eta0 (N)]
 *     gimbal_tol: |cos(theta)| below which the Euler-angle rates are singular (rigid_body.py)
 *     props: m, has_cog, cx, cy, cz, I00, I01, I02, I11, I12, I22 (inertia about O, body axes)
 *     const: the constant mass matrix (added mass, m*1), row-major
 *     kd:    [K | D] per body on the natural state order, K*eta + D*nu = kd*y
 *   y = [eta_1; nu_1; eta_2; nu_2; ...] (12 per body), loads [F_1; M_1; ...] (6 per body)
 *   table = [ns, h, a (ns*ns), b (ns), c (ns)], a, b and c already multiplied by the step h
 *   work: N*N + 5N + ns*2N doubles
 */
#include <math.h>
#include <string.h>

#define EXPORT __attribute__((visibility("default")))

enum { HF_OK = 0, HF_GIMBAL = 1, HF_NONFINITE = 2 };

/* Solve a*x = b in place (b becomes x) by Gaussian elimination with partial pivoting;
 * HF_NONFINITE on a zero or non-finite pivot. */
static int solve(int N, double *a, double *b) {
    for (int k = 0; k < N; k++) {
        int p = k;
        double best = fabs(a[k * N + k]);
        for (int r = k + 1; r < N; r++)
            if (fabs(a[r * N + k]) > best) best = fabs(a[r * N + k]), p = r;
        if (!(best > 0.0) || !isfinite(best)) return HF_NONFINITE;
        if (p != k) {
            for (int c = k; c < N; c++) {
                double t = a[k * N + c];
                a[k * N + c] = a[p * N + c], a[p * N + c] = t;
            }
            double t = b[k];
            b[k] = b[p], b[p] = t;
        }
        double inv = 1.0 / a[k * N + k];
        for (int r = k + 1; r < N; r++) {
            double f = a[r * N + k] * inv;
            if (f == 0.0) continue;
            for (int c = k + 1; c < N; c++) a[r * N + c] -= f * a[k * N + c];
            b[r] -= f * b[k];
        }
    }
    for (int k = N - 1; k >= 0; k--) {
        double s = b[k];
        for (int c = k + 1; c < N; c++) s -= a[k * N + c] * b[c];
        b[k] = s / a[k * N + k];
    }
    return HF_OK;
}

/*
 * dy = [eta rates; accelerations] of every body at state y under `force` (the load plus
 * K*eta0).  signs: the sign of cos(theta) of each body at the step's start (NULL: now);
 * a cos(theta) below gimbal_tol on that side is HF_GIMBAL.
 */
static int deriv(const double *model, const double *force, const double *signs, const double *y,
                 double *dy, double *mat, double *rhs) {
    int n = (int)model[0], N = 6 * n;
    const double gimbal_tol = model[1], *props = model + 2, *cnst = props + 11 * n, *kd = cnst + N * N;
    memcpy(mat, cnst, sizeof(double) * N * N);
    for (int r = 0; r < N; r++) {   /* rhs = K*eta0 + load - [K | D]*y */
        double s = force[r];
        const double *row = kd + r * 2 * N;
        for (int c = 0; c < 2 * N; c++) s -= row[c] * y[c];
        rhs[r] = s;
    }
    for (int i = 0; i < n; i++) {
        const double *p = props + 11 * i, *eta = y + 12 * i, *nu = eta + 6;
        double m = p[0], cf = cos(eta[3]), sf = sin(eta[3]), ct = cos(eta[4]), st = sin(eta[4]);
        double cp = cos(eta[5]), sp = sin(eta[5]);
        double sign = signs ? signs[i] : (ct > 0.0 ? 1.0 : -1.0);
        if (!(ct * sign >= gimbal_tol)) return HF_GIMBAL;
        /* R = Rz(psi) Ry(theta) Rx(phi) */
        double R[3][3] = {{cp * ct, cp * st * sf - sp * cf, cp * st * cf + sp * sf},
                          {sp * ct, sp * st * sf + cp * cf, sp * st * cf - cp * sf},
                          {-st, ct * sf, ct * cf}};
        double wx = nu[3], wy = nu[4], wz = nu[5];
        double phi_dot = (cp * wx + sp * wy) / ct;
        double *d = dy + 12 * i;
        d[0] = nu[0], d[1] = nu[1], d[2] = nu[2];
        d[3] = phi_dot, d[4] = cp * wy - sp * wx, d[5] = wz + st * phi_dot;
        /* inertia about O in global axes, R*I_O*R^T, and omega x (I_O*omega) */
        double Ib[3][3] = {{p[5], p[6], p[7]}, {p[6], p[8], p[9]}, {p[7], p[9], p[10]}}, RI[3][3], I[3][3];
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++)
                RI[a][b] = R[a][0] * Ib[0][b] + R[a][1] * Ib[1][b] + R[a][2] * Ib[2][b];
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) {
                I[a][b] = RI[a][0] * R[b][0] + RI[a][1] * R[b][1] + RI[a][2] * R[b][2];
                mat[(6 * i + 3 + a) * N + 6 * i + 3 + b] += I[a][b];
            }
        double hx = I[0][0] * wx + I[0][1] * wy + I[0][2] * wz;
        double hy = I[1][0] * wx + I[1][1] * wy + I[1][2] * wz;
        double hz = I[2][0] * wx + I[2][1] * wy + I[2][2] * wz;
        rhs[6 * i + 3] -= wy * hz - wz * hy;
        rhs[6 * i + 4] -= wz * hx - wx * hz;
        rhs[6 * i + 5] -= wx * hy - wy * hx;
        if (p[1] == 0.0) continue;
        double rx = R[0][0] * p[2] + R[0][1] * p[3] + R[0][2] * p[4];
        double ry = R[1][0] * p[2] + R[1][1] * p[3] + R[1][2] * p[4];
        double rz = R[2][0] * p[2] + R[2][1] * p[3] + R[2][2] * p[4];
        /* m[r]x below the diagonal (rotation rows), -m[r]x above it */
        double X[3][3] = {{0.0, -m * rz, m * ry}, {m * rz, 0.0, -m * rx}, {-m * ry, m * rx, 0.0}};
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) {
                mat[(6 * i + 3 + a) * N + 6 * i + b] += X[a][b];
                mat[(6 * i + a) * N + 6 * i + 3 + b] -= X[a][b];
            }
        double ux = wy * rz - wz * ry, uy = wz * rx - wx * rz, uz = wx * ry - wy * rx;   /* omega x r */
        rhs[6 * i] -= m * (wy * uz - wz * uy);
        rhs[6 * i + 1] -= m * (wz * ux - wx * uz);
        rhs[6 * i + 2] -= m * (wx * uy - wy * ux);
    }
    if (solve(N, mat, rhs) != HF_OK) return HF_NONFINITE;
    for (int i = 0; i < n; i++)
        memcpy(dy + 12 * i + 6, rhs + 6 * i, sizeof(double) * 6);
    return HF_OK;
}

/*
 * `steps` internal steps of the Runge-Kutta method in `table` from y (overwritten with
 * the state at the end), under load + rate*t (rate NULL: the load held); acc gets the
 * accelerations at the end under the load there.  Returns HF_OK, HF_GIMBAL or
 * HF_NONFINITE (then y and acc hold nothing usable).
 */
EXPORT int hf_rigid_steps(const double *model, const double *table, int steps, const double *load,
                          const double *rate, double *y, double *acc, double *work) {
    int n = (int)model[0], N = 6 * n, ns = (int)table[0];
    const double h = table[1], *a = table + 2, *b = a + ns * ns, *c = b + ns, *k_eta0 = model + 2 + 11 * n + 3 * N * N;
    double *mat = work, *rhs = mat + N * N, *force = rhs + N, *signs = force + N, *ys = signs + N;
    double *k = ys + 2 * N;   /* ns stage derivatives of 2N each */
    for (int i = 0; i < n; i++) signs[i] = cos(y[12 * i + 4]) > 0.0 ? 1.0 : -1.0;
    for (int m = 0; m < steps; m++) {
        for (int s = 0; s < ns; s++) {
            memcpy(ys, y, sizeof(double) * 2 * N);
            for (int j = 0; j < s; j++)
                if (a[s * ns + j] != 0.0)
                    for (int q = 0; q < 2 * N; q++) ys[q] += a[s * ns + j] * k[j * 2 * N + q];
            double t = m * h + c[s];
            for (int r = 0; r < N; r++) force[r] = k_eta0[r] + load[r] + (rate ? rate[r] * t : 0.0);
            int st = deriv(model, force, signs, ys, k + s * 2 * N, mat, rhs);
            if (st != HF_OK) return st;
        }
        for (int s = 0; s < ns; s++)
            for (int q = 0; q < 2 * N; q++) y[q] += b[s] * k[s * 2 * N + q];
    }
    for (int r = 0; r < N; r++) force[r] = k_eta0[r] + load[r] + (rate ? rate[r] * steps * h : 0.0);
    int st = deriv(model, force, NULL, y, ys, mat, rhs);
    if (st != HF_OK) return st;
    for (int q = 0; q < 2 * N; q++)
        if (!isfinite(y[q])) return HF_NONFINITE;
    for (int i = 0; i < n; i++) {
        memcpy(acc + 6 * i, ys + 12 * i + 6, sizeof(double) * 6);
        for (int q = 0; q < 6; q++)
            if (!isfinite(acc[6 * i + q])) return HF_NONFINITE;
    }
    return HF_OK;
}
