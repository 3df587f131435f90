/* RIFLEX CONB joint (physics/joint.py BallJoint.loads_and_deformation): penalty spring-
 * damper on the gap of the joint points and on the relative rotation's logarithm.
 * params [point_a (3), point_b (3), k_lin, c_lin, k_rot, c_rot, free (3), r_rel0 (9)]
 * (the node's own loads: lumped.c, added by the caller). */
#include <math.h>

#include "kernels.h"

/* rotation vector of a rotation matrix (joint._log_rotation) */
static void log_rotation(const double *r, double *out) {
    double wx = 0.5 * (r[7] - r[5]), wy = 0.5 * (r[2] - r[6]), wz = 0.5 * (r[3] - r[1]);
    double s = sqrt(wx * wx + wy * wy + wz * wz), c = 0.5 * (r[0] + r[4] + r[8] - 1.0);
    double angle = atan2(s, c), k;
    if (angle < 1e-4) {
        k = 1.0 + angle * angle / 6.0;
    } else if (c >= 0.0) {
        k = angle / s;
    } else {   /* the column of sym(rot) - c 1 with the largest diagonal entry is parallel to the axis */
        double cols[3][3] = {{r[0] - c, 0.5 * (r[3] + r[1]), 0.5 * (r[6] + r[2])},
                             {0.5 * (r[1] + r[3]), r[4] - c, 0.5 * (r[7] + r[5])},
                             {0.5 * (r[2] + r[6]), 0.5 * (r[5] + r[7]), r[8] - c}};
        int i = 0;
        for (int q = 1; q < 3; q++)
            if (cols[q][q] > cols[i][i]) i = q;
        double nx = cols[i][0], ny = cols[i][1], nz = cols[i][2], norm = sqrt(nx * nx + ny * ny + nz * nz);
        k = nx * wx + ny * wy + nz * wz >= 0.0 ? angle / norm : -angle / norm;
        out[0] = nx * k, out[1] = ny * k, out[2] = nz * k;
        return;
    }
    out[0] = wx * k, out[1] = wy * k, out[2] = wz * k;
}

void hf_joint(const double *p, const HfMotion *a, const HfMotion *b, double *load_a, double *load_b,
              double *gap, double *theta) {
    static const double EYE[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    const double *ra = a->R, *rb = b ? b->R : EYE, *va = a->velocity;
    double rA[3], rB[3] = {0, 0, 0}, pB[3], vB[3] = {0, 0, 0}, wB[3] = {0, 0, 0}, cA[3], f[3];
    hf_rotate(ra, p, rA);
    if (!b) {
        pB[0] = p[3], pB[1] = p[4], pB[2] = p[5];
    } else {
        double c[3];
        hf_rotate(rb, p + 3, rB);
        for (int i = 0; i < 3; i++) pB[i] = b->position[i] + rB[i], wB[i] = b->velocity[3 + i];
        hf_cross(wB, rB, c);
        for (int i = 0; i < 3; i++) vB[i] = b->velocity[i] + c[i];
    }
    double d[3];
    for (int i = 0; i < 3; i++) d[i] = pB[i] - a->position[i] - rA[i];
    hf_cross(va + 3, rA, cA);
    for (int i = 0; i < 3; i++) f[i] = p[6] * d[i] + p[7] * (vB[i] - va[i] - cA[i]);
    /* R_def = R_A^T R_B R_rel0^T, row i = R_rel0 (R_B^T (column i of R_A)) */
    double rdef[9];
    for (int i = 0; i < 3; i++) {
        double col[3] = {ra[i], ra[3 + i], ra[6 + i]}, ab[3];
        hf_rotate_back(rb, col, ab);
        hf_rotate(p + 13, ab, rdef + 3 * i);
    }
    log_rotation(rdef, theta);
    double dw[3] = {wB[0] - va[3], wB[1] - va[4], wB[2] - va[5]}, wrel[3], mb[3], mm[3], u[3], t[3];
    hf_rotate_back(ra, dw, wrel);
    for (int i = 0; i < 3; i++) mb[i] = p[10 + i] != 0.0 ? 0.0 : p[8] * theta[i] + p[9] * wrel[i];
    hf_rotate(ra, mb, mm);
    hf_cross(rA, f, u);
    hf_cross(rB, f, t);
    for (int i = 0; i < 3; i++) {
        load_a[i] = f[i], load_a[3 + i] = u[i] + mm[i];
        load_b[i] = -f[i], load_b[3 + i] = -t[i] - mm[i];
        gap[i] = d[i];
    }
}
