/*
 * The three kinds of hydrofmu FMU in C, each only its equations (fmi/slave.py's LoadSlave,
 * ConnectorSlave, DynamicsSlave; the FMI layer is fmu.c, the kernels physics/<name>.c).  Their
 * records (model.bin) are written by hydrofmu.fmi.cbuild from the slave the Python flavour
 * builds from the same typed description: value references, start values and kernel
 * parameters come from there, never from a second list.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../physics/kernels.h"
#include "fmu.h"

/* rigid.c */
int hf_rigid_steps(const double *model, const double *table, int steps, const double *load, const double *rate,
                   double *y, double *acc, double *work);

static int ivr(double x) { return (int)x; }

enum { SEA_KNOBS = 11 };   /* cbuild.SEA_KNOBS: height, period, phase, hs, tp, gamma, direction, spreading,
                              components, seed, ramp */

static int *int_list(const double *v, int n) {
    int *out = malloc(sizeof(int) * (n + 1));
    if (out)
        for (int k = 0; k < n; k++) out[k] = ivr(v[k]);
    return out;
}

/* out -= m x, m 6x6 row-major: an acceleration load -M a applied in explicit mode */
static void minus_product(double *out, const double *m, const double *x) {
    for (int i = 0; i < 6; i++) {
        double s = 0.0;
        for (int j = 0; j < 6; j++) s += m[6 * i + j] * x[j];
        out[i] -= s;
    }
}

/* -- environment (ArraySlave.add_environment / env) -------------------------------------- */

typedef struct {
    int current, rho, g;   /* value references (current -1: no current inputs) */
    HfProfile profile;
    int has_profile;
    HfEnv last;            /* the environment of the last values (its current computed once) */
    int has_last;
} EnvRefs;

static int env_setup(Instance *inst, EnvRefs *e) {
    const Record *r = hf_record(inst, "env", NULL), *p = hf_record(inst, "profile", NULL);
    if (!r || r->n != 3) return -1;
    e->current = ivr(r->v[0]), e->rho = ivr(r->v[1]), e->g = ivr(r->v[2]);
    e->has_profile = p != NULL;
    if (p) {
        int n = ivr(p->v[0]);
        if (p->n != 1 + 3 * n || n < 1) return -1;
        e->profile = (HfProfile){n, p->v + 1, p->v + 1 + n, p->v + 1 + 2 * n};
    }
    return 0;
}

/* the environment of the values now (the same as the last while they do not change: a
 * master reads the outputs after a step with the inputs of the step's start) */
static const HfEnv *env_now(const Instance *inst, EnvRefs *e) {
    const double *v = inst->values;
    double speed = e->current >= 0 ? v[e->current] : 0.0, direction = e->current >= 0 ? v[e->current + 1] : 0.0;
    HfEnv *l = &e->last;
    if (!e->has_last || l->rho != v[e->rho] || l->g != v[e->g] || l->speed != speed || l->direction != direction) {
        hf_env(l, v[e->rho], v[e->g], speed, direction, e->has_profile ? &e->profile : NULL);
        e->has_last = 1;
    }
    return l;
}

/* motion of a body from [position, attitude, velocity, acceleration (-1: none)] references;
 * its rotation kept while the attitude does not change */
static const double ZERO6[6] = {0};

typedef struct {
    int refs[4];
    double attitude[3];   /* the attitude m.R was computed for */
    int has_R;
    HfMotion m;           /* (kept here, filled in place: no copy of R per evaluation) */
} Side;

static const HfMotion *motion_of(const Instance *inst, Side *s) {
    const double *v = inst->values, *att = v + s->refs[1];
    if (!s->has_R || memcmp(att, s->attitude, sizeof s->attitude) != 0) {
        memcpy(s->attitude, att, sizeof s->attitude);
        hf_rotation(att, s->m.R);
        s->has_R = 1;
    }
    s->m.attitude = att;
    hf_motion(&s->m, v + s->refs[0], NULL, v + s->refs[2], s->refs[3] >= 0 ? v + s->refs[3] : ZERO6);
    return &s->m;
}

/* -- retardation memory seen through FMI (slave.FeedthroughMemory) ----------------------- */

typedef struct {
    int kind;   /* 1 state space, 2 convolution */
    HfStateSpace ss;
    HfConvolution cv;
    const double *params;
    int nparams;
    double pending;   /* the interval the next commit closes (0: none yet) */
} Memory;

static int memory_init(Memory *m) {
    m->pending = 0.0;
    return m->kind == 1 ? hf_ss_init(&m->ss, m->params, m->nparams) : hf_conv_init(&m->cv, m->params, m->nparams);
}

static void memory_free(Memory *m) {
    if (m->kind == 1) hf_ss_free(&m->ss);
    else hf_conv_free(&m->cv);
}

static int memory_force(Memory *m, const double *v, double *force) {
    if (m->pending <= 0.0) {
        memcpy(force, m->kind == 1 ? m->ss.force : m->cv.force, sizeof(double) * 6);
        return 0;
    }
    if (m->kind == 1) {
        hf_ss_peek(&m->ss, m->pending, v, force);
        return 0;
    }
    return hf_conv_peek(&m->cv, m->pending, v, force);
}

static int memory_commit(Memory *m, const double *v, double dt) {
    int bad = 0;
    if (m->pending > 0.0) {
        if (m->kind == 1) hf_ss_advance(&m->ss, m->pending, v);
        else bad = hf_conv_advance(&m->cv, m->pending, v);
    } else if (m->kind == 1) {
        hf_ss_restart(&m->ss, v);
    } else {
        hf_conv_restart(&m->cv, v);
    }
    m->pending = dt;
    return bad;
}

static size_t memory_size(const Memory *m) {
    return 1 + (m->kind == 1 ? hf_ss_state_size(&m->ss) : hf_conv_state_size(&m->cv));
}

static void memory_save(const Memory *m, double *to) {
    to[0] = m->pending;
    if (m->kind == 1) hf_ss_save(&m->ss, to + 1);
    else hf_conv_save(&m->cv, to + 1);
}

static int memory_load(Memory *m, const double *from, size_t n) {
    m->pending = from[0];
    return m->kind == 1 ? hf_ss_load(&m->ss, from + 1, n - 1) : hf_conv_load(&m->cv, from + 1, n - 1);
}

/* -- the scene's waves in an FMU (ArraySlave._add_waves / _start_waves) ------------------ */

typedef struct {
    const double *waves, *transfer;   /* the 'waves' and 'transfer' records (NULL: no waves) */
    const double *kinrec;             /* the 'kinematics' record (NULL: none) */
    int nkinrec;
    double *wave;                     /* waves.c's per-step parameters (NULL: not drawn yet) */
    HfPhasors *phasors;               /* the FMU's one set of wave phasors */
    double *kin;                      /* wave_kinematics.c's parameters (NULL: no kinematics) */
    HfKinPoint *cache, **points;      /* the effects' scratch cache; one per named point */
    HfWater water;
    int feels, npoints, rho;          /* effects feel the water; points; rho's value reference */
    const double *driftrec;           /* the 'drift' record after its output (NULL: no drift) */
    int ndriftrec;
    double *drift;                    /* drift.c's parameters (on the same components) */
} Sea;

static void sea_release(Sea *S) {
    hf_phasors_delete(S->phasors), free(S->wave), free(S->kin), free(S->drift), hf_kin_point_delete(S->cache);
    for (int k = 0; S->points && k < S->npoints; k++) hf_kin_point_delete(S->points[k]);
    free(S->points);
    S->phasors = NULL, S->wave = S->kin = S->drift = NULL, S->cache = NULL, S->points = NULL;
}

/* the 'waves', 'transfer' and 'kinematics' records; -1: of the wrong size */
static int sea_setup(Instance *inst, Sea *S) {
    const Record *w = hf_record(inst, "waves", NULL), *t = hf_record(inst, "transfer", NULL),
                 *k = hf_record(inst, "kinematics", NULL), *d = hf_record(inst, "drift", NULL);
    if (!w && !t && !k && !d) return 0;
    if (d) {   /* [output, Drift.c_params] */
        if (d->n < 2 || !hf_drift_record_ok(d->v + 1, (int)d->n - 1)) return -1;
        S->driftrec = d->v + 1, S->ndriftrec = (int)d->n - 1;
    }
    if (!w || !t || w->n != 5 + 2 * SEA_KNOBS) return -1;
    int nw = t->n >= 7 ? ivr(t->v[5]) : -1, nb = t->n >= 7 ? ivr(t->v[6]) : -1;
    if (!((nw == 0 && nb == 0 && t->n == 7) || (nw >= 1 && nb >= 1 && t->n == 7 + nw + nb + 12 * nw * nb))) return -1;
    S->waves = w->v, S->transfer = t->v;
    if (k) {   /* [stretching, feels, rho, npoints, (on_body, x, y, z, out) per point] */
        if (k->n < 4 || k->n != 4 + 5 * ivr(k->v[3])) return -1;
        S->kinrec = k->v, S->nkinrec = (int)k->n, S->feels = k->v[1] != 0.0, S->rho = ivr(k->v[2]);
        S->npoints = ivr(k->v[3]);
    }
    return 0;
}

/* the waves of the sea state the waves.* parameters (and g) hold now; -1: a knob that is not
 * a usable sea state (logged naming it), or out of memory */
static int sea_draw(Instance *inst, Sea *S) {
    const double *w = S->waves, *v = inst->values;
    double knob[SEA_KNOBS];
    for (int k = 0; k < SEA_KNOBS; k++) knob[k] = w[5 + 2 * k] >= 0 ? v[ivr(w[5 + 2 * k])] : w[6 + 2 * k];
    HfSea sea = {ivr(w[3]), knob[0], knob[1], knob[2], knob[3], knob[4], knob[5], knob[6], knob[7], knob[8], knob[9],
                 knob[10], w[4]};
    char field[16] = "", message[400] = "";
    sea_release(S);
    S->wave = hf_wave_build(&sea, S->transfer, v[ivr(w[2])], field, message, sizeof message);
    if (!S->wave) {
        hf_fail(inst, "waves.%s: %s", field, message);
        return -1;
    }
    int n = (int)S->wave[0];
    S->phasors = hf_wave_phasors(S->wave);
    if (!S->phasors) goto oom;
    if (S->driftrec) {   /* the body's wave drift on the same components (ArraySlave._start_waves) */
        S->drift = hf_drift_build(S->wave, S->driftrec, S->ndriftrec, v[ivr(w[2])], w[4], field, message,
                                  sizeof message);
        if (!S->drift) {
            sea_release(S);
            hf_fail(inst, "waves.%s: %s", field, message);
            return -1;
        }
    }
    if (S->kinrec) {
        const double *beta = S->wave + 2 + 3 * n + 14 * n;
        S->kin = hf_kin_build(S->wave + 2, beta, n, v[ivr(w[2])], w[4], ivr(S->kinrec[0]));
        S->cache = hf_kin_point_new(n);
        S->points = calloc(S->npoints + 1, sizeof *S->points);
        if (!S->kin || !S->cache || !S->points) goto oom;
        for (int k = 0; k < S->npoints; k++)
            if (!(S->points[k] = hf_kin_point_new(n))) goto oom;
        S->water = (HfWater){S->kin, S->cache, NULL, 0.0, 0.0, w[4]};
    }
    return 0;
oom:
    sea_release(S);
    hf_fail(inst, "out of memory for the wave kinematics");
    return -1;
}

/* the phasors at t (one advance a step for the whole FMU) and the water the effects see;
 * -1: the waves could not be drawn */
static int sea_advance(Instance *inst, Sea *S, double t) {
    if (!S->wave && sea_draw(inst, S)) {   /* (a state restored into an instance not started) */
        hf_set_error(inst, "the waves.* parameters are not a usable sea state");
        return -1;
    }
    const double *p = hf_phasors_at(S->phasors, t);
    if (S->kin) S->water.p = p, S->water.r = hf_phasors_ramp(S->phasors), S->water.rho = inst->values[S->rho];
    return 0;
}

/* the FMU state's part of the waves: [n, the phasors' state (n values; 0: not drawn)] */
static size_t sea_state_size(const Sea *S) {
    return S->waves ? 1 + (S->phasors ? hf_phasors_state_size(S->phasors) : 0) : 0;
}

static void sea_save(const Sea *S, double *to) {
    if (!S->waves) return;
    to[0] = S->phasors ? (double)hf_phasors_state_size(S->phasors) : 0.0;
    if (S->phasors) hf_phasors_save(S->phasors, to + 1);
}

/* from [from, end): the waves' part (drawn first from the restored waves.* values when this
 * instance has not drawn them); the values it used, or -1 */
static long sea_load(Instance *inst, Sea *S, const double *from, const double *end) {
    if (!S->waves) return 0;
    if (from >= end) return -1;
    size_t n = (size_t)from[0];
    if (from + 1 + n > end) return -1;
    if (n == 0) return 1;
    if (!S->wave && sea_draw(inst, S)) return -1;
    return hf_phasors_load(S->phasors, from + 1, n) ? -1 : (long)(1 + n);
}

/* the named points' outputs [u (3), a (3), p_d, elevation] (LoadSlave.evaluate) */
static void sea_points(Instance *inst, Sea *S, const HfMotion *m) {
    for (int k = 0; k < S->npoints; k++) {
        const double *q = S->kinrec + 4 + 5 * k;
        double x[3];
        if (q[0] != 0.0) {   /* on the body: position + R offset */
            hf_rotate(m->R, q + 1, x);
            for (int i = 0; i < 3; i++) x[i] += m->position[i];
        } else {
            memcpy(x, q + 1, sizeof x);
        }
        hf_kin_at(S->kin, S->points[k], S->water.p, S->water.r, x, S->water.rho, inst->values + ivr(q[4]));
    }
}

/* -- load FMU (LoadSlave) --------------------------------------------------------------- */

enum { DRAG = 1, POLAR = 2, LUMPED = 3, HYDROSTATICS = 4 };

typedef struct {
    int kind, out;
    const double *params;
} Effect;

typedef struct {
    int out, velocity, acceleration;   /* value references (acceleration -1: export mode) */
    const double *mass;                /* 36, load = -mass a_source */
    Memory memory;                     /* kind 0: no kernels */
} Coupling;

typedef struct {
    Side motion;
    int explicit_, total, effects_done;
    EnvRefs env;
    Sea sea;                               /* the scene's waves (sea.waves NULL: none) */
    int wave_force, wave_elevation;        /* (-1: no excitation on this body) */
    int drift_force;                       /* (-1: no wave drift) */
    Effect *effects;
    int neffects;
    Coupling *couplings;
    int ncouplings;
} Load;

static void load_release(Instance *inst) {
    Load *L = inst->data;
    if (!L) return;
    for (int k = 0; k < L->ncouplings; k++)
        if (L->couplings[k].memory.kind) memory_free(&L->couplings[k].memory);
    sea_release(&L->sea);
    free(L->effects), free(L->couplings), free(L);
    inst->data = NULL;
}

static int load_setup(Instance *inst) {
    Load *L = calloc(1, sizeof(Load));
    inst->data = L;
    const Record *r = hf_record(inst, "motion", NULL), *t = hf_record(inst, "total", NULL),
                 *x = hf_record(inst, "explicit", NULL);
    if (!L || !r || r->n != 4 || !t || t->n != 1 || !x || env_setup(inst, &L->env))
        goto bad;
    for (int k = 0; k < 4; k++) L->motion.refs[k] = ivr(r->v[k]);
    L->total = ivr(t->v[0]), L->explicit_ = x->v[0] != 0.0;
    L->effects = calloc(inst->nrec, sizeof(Effect));
    L->couplings = calloc(inst->nrec, sizeof(Coupling));
    if (!L->effects || !L->couplings) goto bad;
    for (int k = 0; k < inst->nrec; k++) {   /* effects and couplings in the slave's order */
        const Record *e = &inst->rec[k];
        int kind = strcmp(e->tag, "drag") == 0 ? DRAG : strcmp(e->tag, "polar") == 0 ? POLAR
                 : strcmp(e->tag, "lumped") == 0 ? LUMPED : strcmp(e->tag, "hydrostatics") == 0 ? HYDROSTATICS : 0;
        if (kind) {
            static const int sizes[] = {0, 38, -1, 13, 44};
            if (e->n < 2 || (sizes[kind] > 0 && e->n != sizes[kind]) ||
                (kind == POLAR && e->n != 1 + 5 + (ivr(e->v[1]) + 2) * 4 + (ivr(e->v[1]) + 1) * 3 + 1))
                goto bad;
            L->effects[L->neffects++] = (Effect){kind, ivr(e->v[0]), e->v + 1};
        } else if (strcmp(e->tag, "coupling") == 0) {
            if (e->n != 3 + 36) goto bad;
            Coupling *c = &L->couplings[L->ncouplings++];
            c->out = ivr(e->v[0]), c->velocity = ivr(e->v[1]), c->acceleration = ivr(e->v[2]), c->mass = e->v + 3;
        } else if (strcmp(e->tag, "statespace") == 0 || strcmp(e->tag, "convolution") == 0) {
            if (!L->ncouplings) goto bad;
            Memory *m = &L->couplings[L->ncouplings - 1].memory;
            m->kind = e->tag[0] == 's' ? 1 : 2, m->params = e->v, m->nparams = e->n;
            if (memory_init(m)) goto bad;
        }
    }
    if (sea_setup(inst, &L->sea)) goto bad;
    if (L->sea.waves) L->wave_force = ivr(L->sea.waves[0]), L->wave_elevation = ivr(L->sea.waves[1]);
    L->drift_force = L->sea.driftrec ? ivr(L->sea.driftrec[-1]) : -1;
    if (L->sea.driftrec && !L->sea.waves) goto bad;
    return 0;
bad:
    hf_fail(inst, "model.bin: the load model's records are incomplete or of the wrong size");
    return -1;
}

static void load_start(Instance *inst) {   /* fresh memories (LoadSlave.start_physics) */
    Load *L = inst->data;
    if (L->sea.waves && sea_draw(inst, &L->sea)) return;
    for (int k = 0; k < L->ncouplings; k++) {
        Memory *m = &L->couplings[k].memory;
        if (!m->kind) continue;
        memory_free(m);
        if (memory_init(m)) hf_fail(inst, "out of memory");
        else if (m->kind == 1) hf_ss_restart(&m->ss, inst->values + L->couplings[k].velocity);
        else hf_conv_restart(&m->cv, inst->values + L->couplings[k].velocity);
    }
    inst->stale = 1;
}

static void load_evaluate(Instance *inst) {
    Load *L = inst->data;
    /* the effects depend on the inputs and parameters only: after a step without a set
     * (a master reading the outputs) only the memories move */
    int inputs_set = inst->changed || !L->effects_done || L->sea.feels;   /* (fmu.c has checked the inputs) */
    inst->changed = 0;
    /* the waves first: the FMU's one advance of the phasors this step, then every effect reads them */
    if (L->sea.waves && inst->running && sea_advance(inst, &L->sea, inst->has_next ? inst->next_time : 0.0)) return;
    int wet = L->sea.feels && L->sea.phasors;
    /* (each load written straight into its outputs: a small array copied there just after
     * its scalar stores would stall the copy's loads) */
    double *v = inst->values, m6[36], extra[6];
    const HfMotion *m = NULL;
    const HfEnv *env = NULL;
    if ((inputs_set && L->neffects) || L->sea.npoints) m = motion_of(inst, &L->motion);
    if (inputs_set && L->neffects) env = env_now(inst, &L->env), L->env.last.water = wet ? &L->sea.water : NULL;
    for (int k = 0; k < L->neffects && inputs_set; k++) {   /* BodyLoads.effect_loads */
        const Effect *e = &L->effects[k];
        double *out = v + e->out;
        if (e->kind == HYDROSTATICS) {
            hf_hydrostatics(e->params, m, out);
        } else if (e->kind == DRAG) {
            hf_viscous_drag(e->params + 1, (int)e->params[0], m, env, out);   /* 0, 1, 2 (waves) */
        } else if (e->kind == POLAR) {
            hf_current_polar(e->params, m, env, out);
        } else {
            hf_lumped_load(e->params, m, env, out);
            if (hf_lumped_uses_acceleration(e->params)) {
                if (L->explicit_) {
                    hf_lumped_mass_matrix(e->params, m, m6);
                    minus_product(out, m6, m->acceleration);
                }
                hf_lumped_velocity_load(e->params, m, extra);
                for (int i = 0; i < 6; i++) out[i] += extra[i];
            }
        }
    }
    L->effects_done = 1;
    for (int k = 0; k < L->ncouplings; k++) {
        Coupling *c = &L->couplings[k];
        double *out = v + c->out;
        for (int i = 0; i < 6; i++) out[i] = 0.0;
        if (c->memory.kind && memory_force(&c->memory, v + c->velocity, out)) {
            hf_set_error(inst, "out of memory in the retardation memory");
            return;
        }
        if (c->acceleration >= 0) minus_product(out, c->mass, v + c->acceleration);
    }
    if (L->sea.waves && inst->running && L->wave_force >= 0) {   /* a function of time only */
        double w[7];
        hf_waves(L->sea.wave, L->sea.phasors, inst->has_next ? inst->next_time : 0.0, w);
        memcpy(v + L->wave_force, w, sizeof(double) * 6);
        v[L->wave_elevation] = w[6];
    }
    if (L->sea.waves && inst->running && L->sea.drift) {   /* on the phasors advanced above */
        double t = inst->has_next ? inst->next_time : 0.0;
        hf_drift(L->sea.drift, hf_phasors_at(L->sea.phasors, t), t, hf_phasors_ramp(L->sea.phasors), v + L->drift_force);
    }
    if (L->sea.waves && inst->running && L->sea.npoints) sea_points(inst, &L->sea, m);
    double *total = v + L->total;
    for (int i = 0; i < 6; i++) total[i] = 0.0;
    for (int k = 0; k < L->neffects; k++)
        for (int i = 0; i < 6; i++) total[i] += v[L->effects[k].out + i];
    for (int k = 0; k < L->ncouplings; k++)
        for (int i = 0; i < 6; i++) total[i] += v[L->couplings[k].out + i];
    for (int i = 0; i < 6 && L->sea.waves && L->wave_force >= 0; i++) total[i] += v[L->wave_force + i];
    for (int i = 0; i < 6 && L->drift_force >= 0; i++) total[i] += v[L->drift_force + i];
}

static void load_step(Instance *inst, double t, double dt) {
    (void)t;
    Load *L = inst->data;
    for (int k = 0; k < L->ncouplings; k++) {
        Coupling *c = &L->couplings[k];
        if (c->memory.kind && memory_commit(&c->memory, inst->values + c->velocity, dt))
            hf_set_error(inst, "out of memory in the retardation memory");
    }
    if (L->ncouplings > 0 || L->sea.waves) inst->stale = 1;   /* memory and wave outputs move with time */
}

static size_t load_state_size(const Instance *inst) {
    const Load *L = inst->data;
    size_t n = 0;
    for (int k = 0; k < L->ncouplings; k++)
        if (L->couplings[k].memory.kind) n += 1 + memory_size(&L->couplings[k].memory);
    return n + sea_state_size(&L->sea);
}

static void load_save(const Instance *inst, double *to) {
    const Load *L = inst->data;
    for (int k = 0; k < L->ncouplings; k++) {
        const Memory *m = &L->couplings[k].memory;
        if (!m->kind) continue;
        size_t n = memory_size(m);
        to[0] = (double)n;
        memory_save(m, to + 1);
        to += 1 + n;
    }
    sea_save(&L->sea, to);
}

static int load_load(Instance *inst, const double *from, size_t size) {
    Load *L = inst->data;
    const double *end = from + size;
    for (int k = 0; k < L->ncouplings; k++) {
        Memory *m = &L->couplings[k].memory;
        if (!m->kind) continue;
        if (from >= end) return -1;
        size_t n = (size_t)from[0];
        if (from + 1 + n > end || n < 1 || memory_load(m, from + 1, n)) return -1;
        from += 1 + n;
    }
    long used = sea_load(inst, &L->sea, from, end);
    return used >= 0 && from + used == end ? 0 : -1;
}

const Model hf_load_model = {load_setup, load_start, load_evaluate, load_step, load_state_size, load_save, load_load,
                             load_release};

/* -- connector FMU (ConnectorSlave) ------------------------------------------------------ */

typedef struct {
    Side a, b;
    int has_b, force_a, force_b, gap, rotation, explicit_;
    EnvRefs env;
    const double *joint, *node;
    Sea sea;   /* the scene's waves: the node feels them */
} Connector;

static void connector_release(Instance *inst) {
    Connector *C = inst->data;
    if (C) sea_release(&C->sea);
    free(C);
    inst->data = NULL;
}

static int connector_setup(Instance *inst) {
    Connector *C = calloc(1, sizeof(Connector));
    inst->data = C;
    const Record *s = hf_record(inst, "sides", NULL), *j = hf_record(inst, "joint", NULL),
                 *n = hf_record(inst, "node", NULL), *o = hf_record(inst, "outputs", NULL),
                 *x = hf_record(inst, "explicit", NULL);
    if (!C || !s || s->n != 8 || !j || j->n != 22 || !n || n->n != 12 || !o || o->n != 4 || !x ||
        env_setup(inst, &C->env) || sea_setup(inst, &C->sea)) {
        hf_fail(inst, "model.bin: the connector model's records are incomplete or of the wrong size");
        return -1;
    }
    for (int k = 0; k < 4; k++) C->a.refs[k] = ivr(s->v[k]), C->b.refs[k] = ivr(s->v[4 + k]);
    C->has_b = C->b.refs[0] >= 0;
    C->joint = j->v, C->node = n->v, C->explicit_ = x->v[0] != 0.0;
    C->force_a = ivr(o->v[0]), C->force_b = ivr(o->v[1]), C->gap = ivr(o->v[2]), C->rotation = ivr(o->v[3]);
    return 0;
}

static void connector_start(Instance *inst) {
    Connector *C = inst->data;
    if (C->sea.waves && sea_draw(inst, &C->sea)) return;
    inst->stale = 1;
}

static void connector_evaluate(Instance *inst) {
    Connector *C = inst->data;   /* (fmu.c has checked the inputs) */
    double *v = inst->values, la[6], lb[6], gap[3], theta[3], node[6], m6[36];
    const HfMotion *a = motion_of(inst, &C->a), *b = C->has_b ? motion_of(inst, &C->b) : NULL;
    if (C->sea.waves && inst->running && sea_advance(inst, &C->sea, inst->has_next ? inst->next_time : 0.0)) return;
    const HfEnv *env = env_now(inst, &C->env);
    C->env.last.water = C->sea.feels && C->sea.phasors ? &C->sea.water : NULL;
    hf_joint(C->joint, a, b, la, lb, gap, theta);
    hf_lumped_load(C->node, a, env, node);   /* BallJoint: the node's loads on A */
    for (int i = 0; i < 6; i++) la[i] += node[i];
    if (hf_lumped_uses_acceleration(C->node)) {
        if (C->explicit_) {
            hf_lumped_mass_matrix(C->node, a, m6);
            minus_product(la, m6, a->acceleration);
        }
        hf_lumped_velocity_load(C->node, a, node);
        for (int i = 0; i < 6; i++) la[i] += node[i];
    }
    memcpy(v + C->force_a, la, sizeof la);
    memcpy(v + C->force_b, lb, sizeof lb);
    memcpy(v + C->gap, gap, sizeof gap);
    memcpy(v + C->rotation, theta, sizeof theta);
}

static void connector_step(Instance *inst, double t, double dt) {
    (void)t, (void)dt;
    if (((Connector *)inst->data)->sea.waves) inst->stale = 1;   /* the node's wave loads move with time */
}
static void nothing(Instance *inst) { (void)inst; }
static size_t no_state_size(const Instance *inst) { (void)inst; return 0; }
static void no_save(const Instance *inst, double *to) { (void)inst, (void)to; }
static int no_load(Instance *inst, const double *from, size_t n) { (void)inst, (void)from; return n == 0 ? 0 : -1; }

static size_t connector_state_size(const Instance *inst) { return sea_state_size(&((const Connector *)inst->data)->sea); }
static void connector_save(const Instance *inst, double *to) { sea_save(&((const Connector *)inst->data)->sea, to); }
static int connector_load(Instance *inst, const double *from, size_t n) {
    long used = sea_load(inst, &((Connector *)inst->data)->sea, from, from + n);
    return used >= 0 && (size_t)used == n ? 0 : -1;
}

const Model hf_connector_model = {connector_setup, connector_start, connector_evaluate, connector_step,
                                  connector_state_size, connector_save, connector_load, connector_release};

/* -- dynamics FMU (DynamicsSlave over rigid.c) -------------------------------------------- */

typedef struct {
    const double *body;   /* mass, inertia (9), cog (3), stiffness (36), damping (36) */
    int position, attitude, velocity, acceleration, added, nloads;
    int *loads;
} Body;

typedef struct {
    int n, ncross, linear;
    double substep, gimbal_tol, linear_range, capsize, watch;   /* rigid_body.LINEAR_RANGE, CAPSIZE [rad] */
    Body *bodies;
    int (*cross)[3];      /* target, source, value reference of the 6x6 block */
    double *model, *work, *y, *saved, *acc, *load, *rate, *last, *table;
    double last_dt;
    int has_last, started;
    int *inputs, ninputs;
} Dynamics;

static void dynamics_release(Instance *inst) {
    Dynamics *D = inst->data;
    if (!D) return;
    for (int i = 0; i < D->n && D->bodies; i++) free(D->bodies[i].loads);
    free(D->bodies), free(D->cross), free(D->model), free(D->work), free(D->y), free(D->saved), free(D->acc), free(D->load);
    free(D->rate), free(D->last), free(D->table), free(D->inputs), free(D);
    inst->data = NULL;
}

static int dynamics_setup(Instance *inst) {
    Dynamics *D = calloc(1, sizeof(Dynamics));
    inst->data = D;
    const Record *d = hf_record(inst, "dynamics", NULL);
    if (!D || !d || d->n != 5) goto bad;
    D->substep = d->v[0], D->linear = d->v[1] != 0.0, D->gimbal_tol = d->v[2];
    D->linear_range = d->v[3], D->capsize = d->v[4], D->watch = D->linear_range;
    int from = 0;
    while (hf_record(inst, "body", &from)) D->n++;
    from = 0;
    while (hf_record(inst, "cross", &from)) D->ncross++;
    int n = D->n, N = 6 * n;
    if (!n) goto bad;
    D->bodies = calloc(n, sizeof(Body));
    D->cross = calloc(D->ncross + 1, sizeof *D->cross);
    D->model = calloc(2 + 11 * n + 3 * N * N + N, sizeof(double));
    D->work = calloc(36 * n * n + 30 * n + 7 * 12 * n, sizeof(double));
    D->y = calloc(2 * N, sizeof(double)), D->saved = calloc(2 * N, sizeof(double)), D->acc = calloc(N, sizeof(double));
    D->load = calloc(N, sizeof(double)), D->rate = calloc(N, sizeof(double)), D->last = calloc(N, sizeof(double));
    D->table = calloc(2 + 49 + 14, sizeof(double));
    D->inputs = calloc(inst->nvars + 1, sizeof(int));
    if (!D->bodies || !D->cross || !D->model || !D->work || !D->y || !D->saved || !D->acc || !D->load || !D->rate || !D->last ||
        !D->table || !D->inputs)
        goto bad;
    from = 0;
    for (int i = 0; i < n; i++) {
        const Record *b = hf_record(inst, "body", &from);
        if (b->n < 85 + 6 || b->n != 91 + ivr(b->v[90])) goto bad;
        Body *B = &D->bodies[i];
        B->body = b->v;
        B->position = ivr(b->v[85]), B->attitude = ivr(b->v[86]), B->velocity = ivr(b->v[87]);
        B->acceleration = ivr(b->v[88]), B->added = ivr(b->v[89]), B->nloads = ivr(b->v[90]);
        B->loads = int_list(b->v + 91, B->nloads);
        if (!B->loads) goto bad;
        for (int k = 0; k < B->nloads; k++)
            for (int q = 0; q < 6; q++) D->inputs[D->ninputs++] = B->loads[k] + q;
    }
    from = 0;
    for (int k = 0; k < D->ncross; k++) {
        const Record *c = hf_record(inst, "cross", &from);
        if (c->n != 3) goto bad;
        for (int q = 0; q < 3; q++) D->cross[k][q] = ivr(c->v[q]);
    }
    return 0;
bad:
    hf_fail(inst, "model.bin: the dynamics model's records are incomplete or of the wrong size");
    return -1;
}

/* the summed load of every body from the inputs */
static void summed_loads(Instance *inst, Dynamics *D) {
    for (int i = 0; i < D->n; i++) {
        double *l = D->load + 6 * i;
        memset(l, 0, sizeof(double) * 6);
        for (int k = 0; k < D->bodies[i].nloads; k++)
            for (int q = 0; q < 6; q++) l[q] += inst->values[D->bodies[i].loads[k] + q];
    }
}

static void publish(Instance *inst, Dynamics *D) {
    for (int i = 0; i < D->n; i++) {
        const Body *B = &D->bodies[i];
        memcpy(inst->values + B->position, D->y + 12 * i, sizeof(double) * 3);
        memcpy(inst->values + B->attitude, D->y + 12 * i + 3, sizeof(double) * 3);
        memcpy(inst->values + B->velocity, D->y + 12 * i + 6, sizeof(double) * 6);
        memcpy(inst->values + B->acceleration, D->acc + 6 * i, sizeof(double) * 6);
    }
}

/* rigid.c's model from the bodies' data and the parameters as they are now (rigid_body._Equations),
 * the pose and state from the start values */
static void build_model(Instance *inst) {
    Dynamics *D = inst->data;
    int n = D->n, N = 6 * n;
    const double *v = inst->values;
    double *model = D->model, *props = model + 2, *cnst = props + 11 * n, *kd = cnst + N * N, *k_eta0 = kd + 2 * N * N;
    memset(model, 0, sizeof(double) * (2 + 11 * n + 3 * N * N + N));
    model[0] = n, model[1] = D->gimbal_tol;
    for (int i = 0; i < n; i++) {
        const Body *B = &D->bodies[i];
        const double m = B->body[0], *I = B->body + 1, *c = B->body + 10, *K = B->body + 13, *Dm = B->body + 49;
        double cc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2], io[9];
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) io[3 * a + b] = I[3 * a + b] + m * ((a == b ? cc : 0.0) - c[a] * c[b]);
        double *p = props + 11 * i;
        int has_cog = c[0] != 0.0 || c[1] != 0.0 || c[2] != 0.0;
        p[0] = m, p[1] = has_cog;
        for (int a = 0; a < 3; a++) p[2 + a] = has_cog ? c[a] : 0.0;
        p[5] = io[0], p[6] = io[1], p[7] = io[2], p[8] = io[4], p[9] = io[5], p[10] = io[8];
        for (int r = 0; r < 6; r++)
            for (int q = 0; q < 6; q++) cnst[(6 * i + r) * N + 6 * i + q] = v[B->added + 6 * r + q];
        for (int r = 0; r < 3; r++) cnst[(6 * i + r) * N + 6 * i + r] += m;
        double eta0[6];   /* the initial pose: outputs hold their start values until a step */
        memcpy(eta0, inst->start + B->position, sizeof(double) * 3);
        memcpy(eta0 + 3, inst->start + B->attitude, sizeof(double) * 3);
        for (int r = 0; r < 6; r++) {
            double s = 0.0;
            for (int q = 0; q < 6; q++) {
                kd[(6 * i + r) * 2 * N + 12 * i + q] = K[6 * r + q];
                kd[(6 * i + r) * 2 * N + 12 * i + 6 + q] = Dm[6 * r + q];
                s += K[6 * r + q] * eta0[q];
            }
            k_eta0[6 * i + r] = s;
        }
        memcpy(D->y + 12 * i, eta0, sizeof eta0);
        memcpy(D->y + 12 * i + 6, inst->start + B->velocity, sizeof(double) * 6);
    }
    for (int k = 0; k < D->ncross; k++) {
        int a = D->cross[k][0], b = D->cross[k][1];
        for (int r = 0; r < 6; r++)
            for (int q = 0; q < 6; q++) cnst[(6 * a + r) * N + 6 * b + q] += v[D->cross[k][2] + 6 * r + q];
    }
    D->has_last = 0;
    D->started = 1;
}

static void dynamics_start(Instance *inst) {
    Dynamics *D = inst->data;
    const double *v = inst->values;
    build_model(inst);
    /* the initial acceleration under the loads the inputs hold now (zero steps: the end's) */
    double sum = 0.0;
    for (int k = 0; k < D->ninputs; k++) sum += v[D->inputs[k]];
    if (isfinite(sum)) {
        summed_loads(inst, D);
        D->table[0] = 4;
        if (hf_rigid_steps(D->model, D->table, 0, D->load, NULL, D->y, D->acc, D->work) == 0) publish(inst, D);
    }
}

/* the Runge-Kutta tables of rigid_body.py: classic RK4, Butcher's RK6 */
static const double RK4_A[16] = {0, 0, 0, 0, 0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 1, 0};
static const double RK4_B[4] = {1.0 / 6, 1.0 / 3, 1.0 / 3, 1.0 / 6}, RK4_C[4] = {0, 0.5, 0.5, 1};
static const double RK6_A[49] = {0, 0, 0, 0, 0, 0, 0,
                                 1.0 / 3, 0, 0, 0, 0, 0, 0,
                                 0, 2.0 / 3, 0, 0, 0, 0, 0,
                                 1.0 / 12, 1.0 / 3, -1.0 / 12, 0, 0, 0, 0,
                                 -1.0 / 16, 9.0 / 8, -3.0 / 16, -3.0 / 8, 0, 0, 0,
                                 0, 9.0 / 8, -3.0 / 8, -3.0 / 4, 1.0 / 2, 0, 0,
                                 9.0 / 44, -9.0 / 11, 63.0 / 44, 18.0 / 11, 0, -16.0 / 11, 0};
static const double RK6_B[7] = {11.0 / 120, 0, 27.0 / 40, 27.0 / 40, -4.0 / 15, -4.0 / 15, 11.0 / 120};
static const double RK6_C[7] = {0, 1.0 / 3, 2.0 / 3, 1.0 / 3, 1.0 / 2, 1.0 / 2, 1};

/* slave.DynamicsSlave._watch_range: past the linear range one warning per run, past the
 * capsize angle the step fails */
static void watch_range(Instance *inst, Dynamics *D, double t) {
    int worst = -1;
    double big = D->watch;
    for (int i = 0; i < D->n; i++)
        for (int k = 3; k < 5; k++)
            if (fabs(D->y[12 * i + k]) > big) big = fabs(D->y[12 * i + k]), worst = 12 * i + k;
    if (worst < 0) return;
    int k = worst % 12;
    const char *var = inst->names[D->bodies[worst / 12].attitude + k - 3], *which = k == 3 ? "roll" : "pitch";
    double deg = D->y[worst] * 57.29577951308232;
    if (big > D->capsize) {
        hf_set_error(inst, "capsized: %s (%s) = %.1f deg at t = %g s: |roll| or |pitch| past %g deg, far outside "
                           "the linear hydrostatics and first-order wave loads", var, which, deg, t,
                     D->capsize * 57.29577951308232);
        return;
    }
    hf_warn(inst, "left the linear range: %s (%s) = %.1f deg at t = %g s, past %g deg: the hydrostatics and "
                  "first-order wave loads assume small angles (said once per run)", var, which, deg, t,
            D->linear_range * 57.29577951308232);
    D->watch = D->capsize;
}

static void dynamics_step(Instance *inst, double t, double dt) {
    Dynamics *D = inst->data;
    int N = 6 * D->n;
    /* (fmu.c has checked the inputs before the step) */
    summed_loads(inst, D);
    const double *rate = NULL;
    if (D->linear) {   /* first-order hold: the load's slope over the last step */
        for (int r = 0; r < N; r++) D->rate[r] = D->has_last ? (D->load[r] - D->last[r]) / D->last_dt : D->load[r] * 0.0;
        memcpy(D->last, D->load, sizeof(double) * N);
        D->last_dt = dt, D->has_last = 1;
        rate = D->rate;
    }
    int rk4 = dt <= D->substep * (1.0 + 1e-12), steps = 1;
    if (!rk4) {
        steps = (int)ceil(dt / (5 * D->substep) * (1.0 - 1e-12));
        if (steps < 1) steps = 1;
    }
    int ns = rk4 ? 4 : 7;
    const double *a = rk4 ? RK4_A : RK6_A, *b = rk4 ? RK4_B : RK6_B, *c = rk4 ? RK4_C : RK6_C;
    double h = dt / steps, *tab = D->table;
    tab[0] = ns, tab[1] = h;
    for (int k = 0; k < ns * ns; k++) tab[2 + k] = h * a[k];
    for (int k = 0; k < ns; k++) tab[2 + ns * ns + k] = h * b[k], tab[2 + ns * ns + ns + k] = h * c[k];
    memcpy(D->saved, D->y, sizeof(double) * 2 * N);
    int status = hf_rigid_steps(D->model, tab, steps, D->load, rate, D->y, D->acc, D->work);
    if (status != 0) {   /* the state stays at the step's start */
        memcpy(D->y, D->saved, sizeof(double) * 2 * N);
        hf_set_error(inst, status == 1 ? "capsized: pitch reached +-90 degrees: the ZYX Euler-angle rates are "
                                         "singular there; the rigid body cannot go on"
                                       : "the rigid-body step is not finite (a singular mass matrix or non-finite loads)");
        return;
    }
    publish(inst, D);
    watch_range(inst, D, t + dt);
}

/* [y (12n), has_last, last_dt, last (6n)] */
static size_t dynamics_state_size(const Instance *inst) {
    const Dynamics *D = inst->data;
    return 18 * (size_t)D->n + 2;
}

static void dynamics_save(const Instance *inst, double *to) {
    const Dynamics *D = inst->data;
    memcpy(to, D->y, sizeof(double) * 12 * D->n);
    to[12 * D->n] = D->has_last, to[12 * D->n + 1] = D->last_dt;
    memcpy(to + 12 * D->n + 2, D->last, sizeof(double) * 6 * D->n);
}

static int dynamics_load(Instance *inst, const double *from, size_t n) {
    Dynamics *D = inst->data;
    if (n != dynamics_state_size(inst)) return -1;
    if (!D->started) build_model(inst);   /* a state restored into an instance not yet started */
    memcpy(D->y, from, sizeof(double) * 12 * D->n);
    D->has_last = from[12 * D->n] != 0.0, D->last_dt = from[12 * D->n + 1];
    memcpy(D->last, from + 12 * D->n + 2, sizeof(double) * 6 * D->n);
    return 0;
}

const Model hf_dynamics_model = {dynamics_setup, dynamics_start, nothing, dynamics_step, dynamics_state_size,
                                 dynamics_save, dynamics_load, dynamics_release};

/* -- the native floor (hydrofmu bench): doStep copies the inputs to the outputs ------------ */

typedef struct {
    int n, *in, *out;
} Floor;

static void floor_release(Instance *inst) {
    Floor *F = inst->data;
    if (F) free(F->in), free(F->out), free(F);
    inst->data = NULL;
}

static int floor_setup(Instance *inst) {
    Floor *F = calloc(1, sizeof(Floor));
    inst->data = F;
    const Record *r = hf_record(inst, "copy", NULL);
    if (!F || !r || r->n % 2) {
        hf_fail(inst, "model.bin: the floor's records are incomplete");
        return -1;
    }
    F->n = r->n / 2, F->in = int_list(r->v, F->n), F->out = int_list(r->v + F->n, F->n);
    return F->in && F->out ? 0 : -1;
}

static void floor_step(Instance *inst, double t, double dt) {
    (void)t, (void)dt;
    Floor *F = inst->data;
    for (int k = 0; k < F->n; k++) inst->values[F->out[k]] = inst->values[F->in[k]];
}

const Model hf_floor_model = {floor_setup, nothing, nothing, floor_step, no_state_size, no_save, no_load,
                              floor_release};
