/*
 * The FMI 2.0 co-simulation layer of hydrofmu's compiled FMUs (fmu.c), written once for
 * every FMU kind, and what a kind provides (models.c): its equations only.
 *
 * An instance holds every Real in one array indexed by value reference (like the Python
 * slaves of fmi/slave.py), the variables' names and causalities (resources/variables.txt)
 * and the model's records (resources/model.txt: "tag n v1 ... vn" per line, written by
 * hydrofmu.fmi.cbuild from the FMU's typed description).
 */
#ifndef HYDROFMU_FMU_H
#define HYDROFMU_FMU_H

#include <stddef.h>

typedef struct {
    char tag[32];
    int n;
    double *v;
} Record;

typedef struct Instance Instance;

typedef struct {
    /* the model's data from its records (NULL records: reset to the start); non-zero: failed, logged */
    int (*setup)(Instance *inst);
    void (*start)(Instance *inst);                       /* leaving initialization mode */
    void (*evaluate)(Instance *inst);                    /* outputs from the inputs as they are */
    void (*step)(Instance *inst, double t, double dt);   /* the physics over [t, t + dt] */
    size_t (*state_size)(const Instance *inst);
    void (*save)(const Instance *inst, double *to);
    int (*load)(Instance *inst, const double *from, size_t n);
    void (*release)(Instance *inst);
} Model;

struct Instance {
    char *name;
    void *logger, *env;     /* the host's fmi2CallbackLogger and its environment */
    int log_on;
    int nvars;
    double *values, *start; /* by value reference; start: the values at instantiation */
    char **names;           /* variable names */
    char *causality;        /* 'p' parameter, 'c' calculated parameter, 'i' input, 'o' output, 'l' local */
    int *outputs, noutputs;
    int *inputs, ninputs;   /* value references of the outputs and of the inputs */
    int *spans, nspans;     /* the outputs as runs of consecutive value references: (first, count) pairs */
    unsigned *checked_vr;   /* the value references of the last fmi2SetReal that were all settable */
    size_t nchecked, checked_cap;
    int checked_running;    /* (settable depends on running) */
    int nrec;
    Record *rec;
    const Model *model;
    void *data;             /* the model's own */
    int running;            /* after initialization: parameters fixed */
    int stale;              /* outputs to evaluate before they are read */
    int suspect;            /* inputs set since the last check may be non-finite */
    int fixed_finite;       /* the parameters and calculated parameters are finite (checked when they are fixed) */
    int clean;              /* every value is known finite: fmi2GetReal copies without checking */
    int changed;            /* inputs or parameters changed since the model's last evaluation (it clears it) */
    int has_next;
    double next_time;       /* where the next fmi2DoStep must start */
    char error[512];        /* a bad input seen since the last step ("" none) */
    int status;             /* the current call's status (fmi2OK ... ) */
};

/* for the models */
void hf_fail(Instance *inst, const char *fmt, ...);   /* one error line for the host, status fmi2Error */
const Record *hf_record(const Instance *inst, const char *tag, int *from);   /* next record with the tag */
int hf_check_finite(Instance *inst, const int *vrs, int n);   /* 1: all finite, else sets inst->error */
void hf_set_error(Instance *inst, const char *fmt, ...);
void hf_warn(Instance *inst, const char *fmt, ...);   /* one warning line for the host (status fmi2Warning) */

extern const Model hf_load_model, hf_connector_model, hf_dynamics_model, hf_floor_model;

#endif
