/*
 * The C load kernels of hydrofmu, one C file per physics module (viscous_drag.c beside
 * viscous_drag.py, ...): the same formulas as the Python kernels, which stay the readable
 * reference the tests hold these against.  Conventions are the Python modules' (global
 * axes, z up, loads [F; M about the reference point], attitude (roll, pitch, yaw) with
 * R = Rz(yaw) Ry(pitch) Rx(roll)).  No allocation, no FMI: fmi/fmu.c and fmi/models.c
 * call these.
 */
#ifndef HYDROFMU_KERNELS_H
#define HYDROFMU_KERNELS_H

#include <stddef.h>

/* physics/state.py: a body's motion (R computed from the attitude by hf_motion) */
typedef struct {
    const double *position, *attitude, *velocity, *acceleration;   /* 3, 3, 6, 6 (acceleration may be NULL) */
    double R[9];   /* body-to-global rotation, row-major */
} HfMotion;

/* physics/current.py: a profile's shape, levels z increasing */
typedef struct {
    int n;
    const double *z, *ratio, *turn;
} HfProfile;

/* the incident waves the effects of an FMU see at this step (wave_kinematics.py Water):
 * hf_kin_build's params, a scratch cache, the phasors at this step, ramp r, rho, depth */
typedef struct HfKinPoint HfKinPoint;
typedef struct {
    const double *kin;
    HfKinPoint *cache;
    const double *p;
    double r, rho, depth;
} HfWater;

/* physics/state.py Env: density, gravity, surface current, its profile (NULL: uniform);
 * uniform: the current's components (hf_env sets them); water: the incident waves (NULL: still) */
typedef struct {
    double rho, g, speed, direction;
    const HfProfile *profile;
    double uniform[3];
    const HfWater *water;
} HfEnv;

/* kinematics.c */
void hf_motion(HfMotion *m, const double *position, const double *attitude, const double *velocity,
               const double *acceleration);
void hf_rotation(const double *attitude, double *R);
/* R x, R^T x and a x b (here, inline: every kernel calls them, several times a step) */
static inline void hf_rotate(const double *R, const double *x, double *out) {
    double a = x[0], b = x[1], c = x[2];
    out[0] = R[0] * a + R[1] * b + R[2] * c;
    out[1] = R[3] * a + R[4] * b + R[5] * c;
    out[2] = R[6] * a + R[7] * b + R[8] * c;
}
static inline void hf_rotate_back(const double *R, const double *x, double *out) {
    double a = x[0], b = x[1], c = x[2];
    out[0] = R[0] * a + R[3] * b + R[6] * c;
    out[1] = R[1] * a + R[4] * b + R[7] * c;
    out[2] = R[2] * a + R[5] * b + R[8] * c;
}
static inline void hf_cross(const double *a, const double *b, double *out) {
    double x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2], z = a[0] * b[1] - a[1] * b[0];
    out[0] = x, out[1] = y, out[2] = z;
}
void hf_point_mass_matrix(const double *mass3, const double *r, double *m6);
void hf_current_components(double speed, double direction_deg, double *out);

/* current.c */
void hf_env(HfEnv *env, double rho, double g, double speed, double direction, const HfProfile *profile);
void hf_current_at(const HfEnv *env, double z, double *out);

/* viscous_drag.c: matrix 36 (body axes, row-major), relative 0 (ABSOLUTE), 1 (RELATIVE), 2 (RELATIVE with waves) */
void hf_viscous_drag(const double *matrix, int relative, const HfMotion *m, const HfEnv *env, double *out);

/* current_polar.c: params [n, xc, yc, zc, surfc, angles (n+2), coef ((n+2)*3), slope ((n+1)*3), waves (0/1)] */
void hf_current_polar(const double *params, const HfMotion *m, const HfEnv *env, double *out);

/* waves.c: a sea state (physics.waves.SeaState; spectrum 0 regular, 1 jonswap, 2 pierson_moskowitz) */
typedef struct {
    int spectrum;
    double height, period, phase, hs, tp, gamma, direction, spreading, components, seed, ramp, depth;
} HfSea;
/* 0, or -1 with the bad knob's name in field (16 chars) and why in message */
int hf_sea_check(const HfSea *sea, char *field, char *message, size_t size);
double hf_wave_number(double omega, double g, double depth);
/* the per-step parameters [n, ramp length, omega (n), a e^{i phi} (n (re, im) pairs), table (2n x 7),
 * direction (n, deg)] (malloc'd; NULL: field and message say why) of a sea state and a transfer
 * function [window_lo, window_hi, x, y, closed, nw, nb, omega (nw), directions (nb), re (nw nb 6),
 * im (nw nb 6)] (TransferFunction.c_params; nw = nb = 0: no excitation, the window alone) */
double *hf_wave_build(const HfSea *sea, const double *transfer, double g, char *field, char *message, size_t size);
/* The shared per-step phasors (waves.Phasors): p (n (re, im) pairs) = a_k e^{i(w_k t + phi_k)} at
 * time t, advanced by one complex multiply per component per step, exact every HF_RESYNC steps
 * and off the step grid; one per FMU, every wave effect reads it. */
#define HF_RESYNC 1024     /* waves.RESYNC */
#define HF_GRID_ULPS 4     /* waves.GRID_ULPS */
typedef struct {
    int n, resync, j, has_rot;
    double ramp, t, sync, h;
    const double *omega, *amp;   /* (not owned) */
    double *p, *rot;
    long exact, rotations;
} HfPhasors;
HfPhasors *hf_phasors_new(const double *omega, const double *amp, int n, double ramp, int resync);
void hf_phasors_delete(HfPhasors *P);
const double *hf_phasors_at(HfPhasors *P, double t);
double hf_phasors_ramp(const HfPhasors *P);   /* r(t) at the phasors' time */
size_t hf_phasors_state_size(const HfPhasors *P);
void hf_phasors_save(const HfPhasors *P, double *to);
int hf_phasors_load(HfPhasors *P, const double *from, size_t n);
/* the phasors of hf_wave_build's parameters (which they point into) */
HfPhasors *hf_wave_phasors(const double *params);
/* out: [F (6), elevation] at time t (advances P to t) */
void hf_waves(const double *params, HfPhasors *P, double t, double *out);
int hf_direction_weights(const double *d, int nb, int closed, double beta, int *j0, int *j1, double *frac);

/* drift.c: the wave drift of a body on the components of hf_wave_build's parameters
 * (physics.drift.DriftLoad), the record from Drift.c_params; per step at time t from the shared
 * phasors p there (n (re, im) pairs, un-ramped) and the ramp r: out (6); the full QTF's blocks
 * are kept in params (a pure function of t, physics.drift.DriftLoad.at) */
double *hf_drift_build(const double *wave, const double *record, int nrecord, double g, double depth, char *field,
                       char *message, size_t size);
void hf_drift(double *params, const double *p, double t, double r, double *out);
int hf_drift_record_ok(const double *record, int n);

/* wave_kinematics.c: Airy kinematics of the components at a point.  params [n, g, depth,
 * stretching (0 none, 1 vertical, 2 wheeler, 3 extrapolation), omega (n), k (n), cos beta (n),
 * sin beta (n)] (malloc'd by hf_kin_build); a point's cache of its factors (one per point);
 * out [u (3), a (3), dynamic pressure, elevation] at x (3, global) from the phasors p and ramp r */
#define HF_STRETCHING {"none", "vertical", "wheeler", "extrapolation"}
struct HfKinPoint {
    double x, y, z;
    double *e, *fh, *fv, *fp;
};
/* row (8) of the water at x (3, global); 1 if x is wet (below the instantaneous surface, above the bed) */
int hf_water_at(const HfWater *w, const double *x, double *row);
double *hf_kin_build(const double *omega, const double *direction_deg, int n, double g, double depth, int stretching);
HfKinPoint *hf_kin_point_new(int n);
void hf_kin_point_delete(HfKinPoint *c);
void hf_kin_at(const double *params, HfKinPoint *c, const double *p, double r, const double *x, double rho,
               double *out);

/* hydrostatics.c: params [C (36, row-major), position0 (3), yaw0, vertical0 (3)]: F = -C delta */
void hf_hydrostatics(const double *params, const HfMotion *m, double *out);

/* lumped.c: params [offset (3), am, ae, local (0/1), cd (3), added (3)] */
int hf_lumped_uses_current(const double *params);
int hf_lumped_uses_acceleration(const double *params);
void hf_lumped_load(const double *params, const HfMotion *m, const HfEnv *env, double *out);
void hf_lumped_mass_matrix(const double *params, const HfMotion *m, double *m6);
void hf_lumped_velocity_load(const double *params, const HfMotion *m, double *out);

/* joint.c: params [point_a (3), point_b (3), k_lin, c_lin, k_rot, c_rot, free (3), r_rel0 (9)];
 * b NULL: the earth.  Loads on A and B, gap and rotation vector. */
void hf_joint(const double *params, const HfMotion *a, const HfMotion *b, double *load_a, double *load_b,
              double *gap, double *theta);

/* memory.c: retardation memory of one 6x6 coupling side, F = -int h(s) v(t - s) ds.
 * State space, params [m, mu_re (m), mu_im (m), gam_re (m), gam_im (m), inp (m), out (m)]:
 * complex modes z' = mu z + v[inp], F[out] -= Re(gam z). */
typedef struct {
    int m;
    const double *mu_re, *mu_im, *gam_re, *gam_im, *inp, *out;
    double *z;                   /* 2m: (re, im) per mode */
    double v[6], force[6];       /* velocity and load at the current time */
    double dt, *coef;            /* the last step's coefficients: 8 per mode (e, b_old, b_new, gam) */
    double *base;                /* e z + b_old v of the step from the state now (2m; has_base) */
    int *io;                     /* inp and out as integers (2m) */
    int has_base;
    double pv[6], pforce[6], pdt;   /* the last peek: its velocity, load and step */
    int peeked;
} HfStateSpace;

/* Convolution, params [nseg, nelem, span, g (nseg+1), hl (nseg*nelem), hr (nseg*nelem),
 * out (nelem), in (nelem)]: piecewise-linear kernels (segment rows, element columns) and
 * piecewise-linear velocity history, integrated exactly. */
typedef struct {
    int nseg, nelem;
    double span;
    const double *g, *hl, *hr, *out, *in;
    double *v, *dt;              /* history nodes: v (6 each), dt from the node before */
    int cap, lo, hi;
    double force[6];
    double *key, *w;             /* cached node offsets and their weights (nkey x nelem) */
    int nkey, wcap;
    double *s;                   /* scratch offsets */
    double grid_dt, *grid, *right, *left;   /* a uniform grid of step grid_dt (0: none), its nodes' half hats */
    int ngrid;
    double pforce[6], pv[6], pdt;
    int plo, peeked;
} HfConvolution;

int hf_ss_init(HfStateSpace *ss, const double *params, int n);
void hf_ss_free(HfStateSpace *ss);
void hf_ss_restart(HfStateSpace *ss, const double *v);
void hf_ss_peek(HfStateSpace *ss, double dt, const double *v, double *force);
void hf_ss_advance(HfStateSpace *ss, double dt, const double *v);
size_t hf_ss_state_size(const HfStateSpace *ss);
void hf_ss_save(const HfStateSpace *ss, double *to);
int hf_ss_load(HfStateSpace *ss, const double *from, size_t n);

int hf_conv_init(HfConvolution *cv, const double *params, int n);
void hf_conv_free(HfConvolution *cv);
void hf_conv_restart(HfConvolution *cv, const double *v);
int hf_conv_peek(HfConvolution *cv, double dt, const double *v, double *force);
int hf_conv_advance(HfConvolution *cv, double dt, const double *v);
size_t hf_conv_state_size(const HfConvolution *cv);
void hf_conv_save(const HfConvolution *cv, double *to);
int hf_conv_load(HfConvolution *cv, const double *from, size_t n);

#endif
