/*
 * FMI 2.0 co-simulation entry points of hydrofmu's compiled FMUs, shared by every FMU kind
 * (models.c holds the kinds' equations).  The semantics are those of the Python slaves
 * (fmi/slave.py ArraySlave): feedthrough outputs evaluated when read, parameters fixed
 * after initialization, a non-finite input or output, a time jump or a bad FMU state is
 * fmi2Error with one log line naming the variable, and no entry point crashes on bad
 * arguments (NULL instance, value reference out of range, NULL arrays).
 *
 * One evaluation per step: fmi2DoStep checks the inputs, moves the model over the step and
 * evaluates the outputs at its end once (their finiteness checked there); fmi2GetReal then
 * copies them.  Outputs are evaluated again only when an input changes (fmi2SetReal of the
 * value an input already holds changes nothing), and then only what depends on it.
 *
 * What the hot path skips it knows: the value references of the last fmi2SetReal were all
 * settable (unless initialization has ended since), the inputs are finite unless a value set
 * was not (each set value's bits are looked at as it is stored; a NaN left in place keeps its
 * input suspect), and after a step that checked its inputs and outputs (parameters checked
 * when initialization fixed them) fmi2GetReal copies without checking again.
 *
 * Resources: variables.txt ("hydrofmu-c 1 <guid>", then "<causality> <name>" per value
 * reference) and model.bin (records: 32-byte tag, int64 count, that many float64, little
 * endian), both written by hydrofmu.fmi.cbuild.
 */
#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "fmu.h"

#define INST(c) ((Instance *)(c))
#define STATE_MAGIC 0x31534648u   /* "HFS1" */

static char *copy(const char *text) {   /* strdup, which C99 lacks */
    char *out = malloc(strlen(text) + 1);
    if (out) strcpy(out, text);
    return out;
}

/* -- logging ---------------------------------------------------------------------------- */

/* The message is handed over as the format, its '%' doubled: a host that formats it (as
 * FMI says) and one that prints it as it is (a logger that reads no variable arguments:
 * fmpy's ctypes callbacks) both show the text. */
static void say(Instance *inst, fmi2Status status, const char *category, const char *text) {
    fmi2CallbackLogger logger = (fmi2CallbackLogger)inst->logger;
    char escaped[2048];
    size_t o = 0;
    for (const char *p = text; *p && o + 2 < sizeof escaped; p++) {
        if (*p == '%') escaped[o++] = '%';
        escaped[o++] = *p;
    }
    escaped[o] = 0;
    if (logger) logger(inst->env, inst->name ? inst->name : "", status, category, escaped);
}

/* "<instance>: <message>" to the host's logger */
static void vsay(Instance *inst, fmi2Status status, const char *category, const char *fmt, va_list ap) {
    char text[1024];
    int at = snprintf(text, sizeof text, "%s: ", inst->name ? inst->name : "");
    vsnprintf(text + at, sizeof text - at, fmt, ap);
    say(inst, status, category, text);
}

void hf_fail(Instance *inst, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    vsay(inst, fmi2Error, "logStatusError", fmt, ap);
    va_end(ap);
    inst->status = fmi2Error;
}

void hf_warn(Instance *inst, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    vsay(inst, fmi2Warning, "logStatusWarning", fmt, ap);
    va_end(ap);
}

void hf_set_error(Instance *inst, const char *fmt, ...) {
    if (inst->error[0]) return;   /* the first one counts */
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(inst->error, sizeof inst->error, fmt, ap);
    va_end(ap);
}

const Record *hf_record(const Instance *inst, const char *tag, int *from) {
    for (int k = from ? *from : 0; k < inst->nrec; k++)
        if (strcmp(inst->rec[k].tag, tag) == 0) {
            if (from) *from = k + 1;
            return &inst->rec[k];
        }
    return NULL;
}

/* The top bit set when x is inf or NaN: its exponent bits are all ones, and adding one there
 * carries into the top bit.  OR-ed over many values, integer operations only: no chain of
 * floating-point additions to wait for, no false alarm from a sum of large values. */
static inline uint64_t not_finite_bit(double x) {
    uint64_t b;
    memcpy(&b, &x, sizeof b);
    return (b & 0x7ff0000000000000u) + 0x0010000000000000u;
}

/* 1 when none of the values at vrs is inf or NaN */
static int all_finite(const double *values, const int *vrs, int n) {
    uint64_t bits = 0;
    for (int k = 0; k < n; k++) bits |= not_finite_bit(values[vrs[k]]);
    return !(bits >> 63);
}

int hf_check_finite(Instance *inst, const int *vrs, int n) {
    if (all_finite(inst->values, vrs, n)) return 1;
    for (int k = 0; k < n; k++)
        if (!isfinite(inst->values[vrs[k]])) {
            hf_set_error(inst, "input %s = %g is not finite", inst->names[vrs[k]], inst->values[vrs[k]]);
            return 0;
        }
    return 1;
}

/* -- resources -------------------------------------------------------------------------- */

/* The folder of a file URI (file:///a/b, file:/a/b, %xx escapes; file:///C:/x on Windows). */
static char *uri_path(const char *uri) {
    if (!uri) return NULL;
    const char *p = uri;
    if (strncmp(p, "file://", 7) == 0) {
        p += 7;
        if (strncmp(p, "localhost/", 10) == 0) p += 9;
    } else if (strncmp(p, "file:", 5) == 0) {
        p += 5;
    }
#ifdef _WIN32
    if (p[0] == '/' && isalpha((unsigned char)p[1]) && p[2] == ':') p++;
#endif
    char *out = malloc(strlen(p) + 2), *o = out;
    if (!out) return NULL;
    for (; *p; p++) {
        if (*p == '%' && isxdigit((unsigned char)p[1]) && isxdigit((unsigned char)p[2])) {
            char hex[3] = {p[1], p[2], 0};
            *o++ = (char)strtol(hex, NULL, 16);
            p += 2;
        } else {
            *o++ = *p;
        }
    }
    *o = 0;
    return out;
}

static FILE *open_in(const char *folder, const char *file, const char *mode) {
    size_t n = strlen(folder) + strlen(file) + 2;
    char *path = malloc(n);
    if (!path) return NULL;
    size_t len = strlen(folder);
    snprintf(path, n, "%s%s%s", folder, len && folder[len - 1] == '/' ? "" : "/", file);
    FILE *f = fopen(path, mode);
    free(path);
    return f;
}

static int read_variables(Instance *inst, const char *folder, const char *guid) {
    FILE *f = open_in(folder, "variables.txt", "r");
    if (!f) {
        hf_fail(inst, "cannot open %s/variables.txt (the FMU's resources)", folder);
        return -1;
    }
    char line[4096], head[32], version[32], id[256];
    int ok = fgets(line, sizeof line, f) && sscanf(line, "%31s %31s %255s", head, version, id) == 3 &&
             strcmp(head, "hydrofmu-c") == 0 && strcmp(version, "1") == 0;
    if (!ok) {
        fclose(f);
        hf_fail(inst, "%s/variables.txt is not a hydrofmu compiled-FMU variable list", folder);
        return -1;
    }
    if (guid && strcmp(guid, id) != 0) {
        fclose(f);
        hf_fail(inst, "fmi2Instantiate: GUID %s does not match this FMU's %s", guid, id);
        return -1;
    }
    int cap = 64, n = 0;
    inst->names = calloc(cap, sizeof(char *));
    inst->causality = calloc(cap, 1);
    while (inst->names && inst->causality && fgets(line, sizeof line, f)) {
        size_t len = strcspn(line, "\r\n");
        line[len] = 0;
        if (len < 3) continue;
        if (n == cap) {
            cap *= 2;
            char **names = realloc(inst->names, cap * sizeof(char *));
            char *caus = realloc(inst->causality, cap);
            if (names) inst->names = names;
            if (caus) inst->causality = caus;
            if (!names || !caus) break;
        }
        inst->causality[n] = line[0];
        inst->names[n] = copy(line + 2);
        if (!inst->names[n]) break;
        n++;
    }
    fclose(f);
    inst->nvars = n;
    if (!inst->names || !inst->causality) return -1;
    inst->noutputs = inst->ninputs = 0;
    inst->outputs = calloc(n + 1, sizeof(int));
    inst->inputs = calloc(n + 1, sizeof(int));
    if (!inst->outputs || !inst->inputs) return -1;
    for (int k = 0; k < n; k++) {
        if (inst->causality[k] == 'o') inst->outputs[inst->noutputs++] = k;
        if (inst->causality[k] == 'i') inst->inputs[inst->ninputs++] = k;
    }
    inst->spans = calloc(2 * (size_t)n + 2, sizeof(int));
    if (!inst->spans) return -1;
    for (int k = 0; k < inst->noutputs; k++) {
        int *last = inst->spans + 2 * (inst->nspans - 1);
        if (inst->nspans && last[0] + last[1] == inst->outputs[k]) last[1]++;
        else inst->spans[2 * inst->nspans] = inst->outputs[k], inst->spans[2 * inst->nspans + 1] = 1, inst->nspans++;
    }
    return 0;
}

static int64_t le64(const unsigned char *b) {
    uint64_t v = 0;
    for (int k = 7; k >= 0; k--) v = (v << 8) | b[k];
    return (int64_t)v;
}

static double ledouble(const unsigned char *b) {
    uint64_t v = (uint64_t)le64(b);
    double d;
    memcpy(&d, &v, sizeof d);
    return d;
}

static int read_model(Instance *inst, const char *folder) {
    FILE *f = open_in(folder, "model.bin", "rb");
    if (!f) {
        hf_fail(inst, "cannot open %s/model.bin (the FMU's resources)", folder);
        return -1;
    }
    int cap = 16;
    inst->rec = calloc(cap, sizeof(Record));
    unsigned char head[40], num[8];
    while (inst->rec && fread(head, 1, 40, f) == 40) {
        int64_t n = le64(head + 32);
        if (n < 0 || n > 100000000) break;
        if (inst->nrec == cap) {
            Record *r = realloc(inst->rec, 2 * cap * sizeof(Record));
            if (!r) break;
            inst->rec = r, cap *= 2;
        }
        Record *r = &inst->rec[inst->nrec];
        memcpy(r->tag, head, 31);
        r->tag[31] = 0;
        r->n = (int)n;
        r->v = malloc(sizeof(double) * (n ? n : 1));
        if (!r->v) break;
        int64_t k = 0;
        for (; k < n && fread(num, 1, 8, f) == 8; k++) r->v[k] = ledouble(num);
        inst->nrec++;
        if (k < n) break;
    }
    int bad = ferror(f) || !feof(f) || !inst->rec;
    fclose(f);
    if (bad) {
        hf_fail(inst, "%s/model.bin is damaged (its records do not read back)", folder);
        return -1;
    }
    return 0;
}

/* -- instance --------------------------------------------------------------------------- */

static void free_instance(Instance *inst) {
    if (!inst) return;
    if (inst->model && inst->model->release) inst->model->release(inst);
    for (int k = 0; k < inst->nvars && inst->names; k++) free(inst->names[k]);
    for (int k = 0; k < inst->nrec; k++) free(inst->rec[k].v);
    free(inst->names), free(inst->causality), free(inst->outputs), free(inst->inputs), free(inst->rec);
    free(inst->spans), free(inst->checked_vr);
    free(inst->values), free(inst->start), free(inst->name);
    free(inst);
}

/* A fresh start: the start values, the model's data anew. */
static int restart(Instance *inst) {
    if (inst->model->release) inst->model->release(inst);
    inst->data = NULL;
    memcpy(inst->values, inst->start, sizeof(double) * inst->nvars);
    inst->running = 0, inst->stale = 1, inst->suspect = 1, inst->changed = 1, inst->has_next = 0, inst->error[0] = 0;
    inst->clean = 0;
    return inst->model->setup(inst);
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn) {
    (void)visible;
    Instance *inst = calloc(1, sizeof(Instance));
    if (!inst) return NULL;
    inst->name = copy(instanceName ? instanceName : "");
    if (functions) inst->logger = (void *)functions->logger, inst->env = functions->componentEnvironment;
    inst->log_on = loggingOn;
    inst->status = fmi2OK;
    if (fmuType != fmi2CoSimulation) {
        hf_fail(inst, "fmi2Instantiate: this FMU is for co-simulation only");
        free_instance(inst);
        return NULL;
    }
    char *folder = uri_path(fmuResourceLocation);
    int ok = folder && read_variables(inst, folder, fmuGUID) == 0 && read_model(inst, folder) == 0;
    if (!folder) hf_fail(inst, "fmi2Instantiate: no resource location given");
    free(folder);
    if (ok) {
        const Record *kind = hf_record(inst, "kind", NULL), *start = hf_record(inst, "start", NULL);
        static const Model *const models[] = {&hf_load_model, &hf_connector_model, &hf_dynamics_model,
                                              &hf_floor_model};
        int k = kind && kind->n == 1 ? (int)kind->v[0] : -1;
        ok = k >= 0 && k < 4 && start && start->n == inst->nvars;
        if (!ok) {
            hf_fail(inst, "fmi2Instantiate: model.bin has no FMU kind or its start values do not match variables.txt");
        } else {
            inst->model = models[k];
            inst->values = malloc(sizeof(double) * (inst->nvars + 1));
            inst->start = malloc(sizeof(double) * (inst->nvars + 1));
            ok = inst->values && inst->start;
            if (ok) {
                memcpy(inst->start, start->v, sizeof(double) * inst->nvars);
                ok = restart(inst) == 0;
            }
        }
    }
    if (!ok) {
        free_instance(inst);
        return NULL;
    }
    return inst;
}

void fmi2FreeInstance(fmi2Component c) { free_instance(INST(c)); }

/* entry guard: a NULL instance is an error without a logger to tell */
#define ENTER(c)                     \
    Instance *inst = INST(c);        \
    if (!inst) return fmi2Error;     \
    inst->status = fmi2OK

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String categories[]) {
    (void)n, (void)categories;
    ENTER(c);
    inst->log_on = on;
    return fmi2OK;
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    (void)toleranceDefined, (void)tolerance, (void)stopTimeDefined, (void)stopTime;
    ENTER(c);
    inst->next_time = startTime, inst->has_next = 1;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    ENTER(c);
    return fmi2OK;
}

/* 1: every value that is neither an input nor an output is finite (they are fixed from here on) */
static int fixed_finite(const Instance *inst) {
    for (int k = 0; k < inst->nvars; k++)
        if (inst->causality[k] != 'i' && inst->causality[k] != 'o' && !isfinite(inst->values[k])) return 0;
    return 1;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    ENTER(c);
    inst->fixed_finite = fixed_finite(inst), inst->clean = 0;
    inst->model->start(inst);
    inst->running = 1, inst->stale = 1;
    return (fmi2Status)inst->status;
}

fmi2Status fmi2Terminate(fmi2Component c) {
    ENTER(c);
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c) {
    ENTER(c);
    if (restart(inst) != 0) hf_fail(inst, "fmi2Reset: the model could not be set up again");
    return (fmi2Status)inst->status;
}

static int bad_refs(Instance *inst, const char *call, const fmi2ValueReference *vr, size_t n, const void *array) {
    if (n && (!vr || !array)) {
        hf_fail(inst, "%s: NULL value references or values for %zu variables", call, n);
        return 1;
    }
    for (size_t k = 0; k < n; k++)
        if (vr[k] >= (fmi2ValueReference)inst->nvars) {
            hf_fail(inst, "%s: value reference %u out of range 0...%d", call, vr[k], inst->nvars - 1);
            return 1;
        }
    return 0;
}

/* 1: the inputs are finite (checked once after they were set), else inst->error names one */
static int inputs_finite(Instance *inst) {
    if (inst->suspect && hf_check_finite(inst, inst->inputs, inst->ninputs)) inst->suspect = 0;
    return !inst->suspect;
}

static void evaluate(Instance *inst) {
    if (!inputs_finite(inst)) return;   /* (stale stays: the next read fails too) */
    inst->stale = 0, inst->clean = 0;
    inst->model->evaluate(inst);
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real value[]) {
    ENTER(c);
    if (bad_refs(inst, "fmi2GetReal", vr, n, value)) return fmi2Error;
    if (inst->stale) evaluate(inst);
    if (inst->error[0]) {   /* kept: the next fmi2DoStep fails on it too */
        for (size_t k = 0; k < n; k++) value[k] = inst->values[vr[k]];
        hf_fail(inst, "%s", inst->error);
        return fmi2Error;
    }
    if (inst->clean) {   /* (checked at the end of the step) */
        for (size_t k = 0; k < n; k++) value[k] = inst->values[vr[k]];
        return fmi2OK;
    }
    uint64_t bits = 0;
    for (size_t k = 0; k < n; k++) bits |= not_finite_bit(value[k] = inst->values[vr[k]]);
    if (bits >> 63)
        for (size_t k = 0; k < n; k++)
            if (!isfinite(value[k])) {
                hf_fail(inst, "%s %s = %g is not finite", inst->causality[vr[k]] == 'o' ? "output" : "variable",
                        inst->names[vr[k]], value[k]);
                break;
            }
    return (fmi2Status)inst->status;
}

/* 1: every reference can be set now, else logged (the first that cannot) */
static int settable(Instance *inst, const fmi2ValueReference vr[], size_t n) {
    for (size_t k = 0; k < n; k++) {
        char cs = vr[k] < (fmi2ValueReference)inst->nvars ? inst->causality[vr[k]] : 0;
        if (cs == 'i' || (cs == 'p' && !inst->running)) continue;
        if (!cs) {
            hf_fail(inst, "fmi2SetReal: value reference %u out of range 0...%d", vr[k], inst->nvars - 1);
            return 0;
        }
        const char *why = cs == 'p' ? "a parameter, fixed after initialization"
                        : cs == 'o' ? "not settable (output)"
                        : cs == 'c' ? "not settable (calculatedParameter)" : "not settable (local)";
        hf_fail(inst, "cannot set %s: %s", inst->names[vr[k]], why);
        return 0;
    }
    return 1;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real value[]) {
    ENTER(c);
    if (n && (!vr || !value)) {
        hf_fail(inst, "fmi2SetReal: NULL value references or values for %zu variables", n);
        return fmi2Error;
    }
    /* every reference checked before any value is set; a master sets the same references at
     * every step, and those it set last are known good (while running does not change) */
    int known = n && n == inst->nchecked && inst->running == inst->checked_running &&
                memcmp(vr, inst->checked_vr, n * sizeof *vr) == 0;
    if (!known) {
        if (!settable(inst, vr, n)) return fmi2Error;
        if (n > inst->checked_cap) {
            unsigned *more = realloc(inst->checked_vr, n * sizeof *more);
            if (more) inst->checked_vr = more, inst->checked_cap = n;
        }
        if (n <= inst->checked_cap) {
            memcpy(inst->checked_vr, vr, n * sizeof *vr);
            inst->nchecked = n, inst->checked_running = inst->running;
        }
    }
    /* changed: any bit differs (the same NaN set again is no change: its input stays suspect
     * until a check passes); bad: a value set is not finite (integer operations: no chains) */
    uint64_t changed = 0, bad = 0, old, new;
    for (size_t k = 0; k < n; k++) {
        memcpy(&old, inst->values + vr[k], sizeof old);
        memcpy(&new, value + k, sizeof new);
        changed |= old ^ new;
        bad |= not_finite_bit(value[k]);
        inst->values[vr[k]] = value[k];
    }
    if (changed) {
        inst->stale = 1, inst->changed = 1, inst->clean = 0;
        if (bad >> 63) inst->suspect = 1;   /* (else the inputs are as finite as they were) */
        inst->error[0] = 0;   /* new inputs: the next evaluation checks them afresh */
    }
    return fmi2OK;
}

/* hydrofmu has only Reals: any other reference is an error, not a crash */
static fmi2Status no_such(fmi2Component c, const char *call, size_t n) {
    ENTER(c);
    if (n) hf_fail(inst, "%s: this FMU has no variables of that type", call);
    return (fmi2Status)inst->status;
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer value[]) {
    (void)vr, (void)value;
    return no_such(c, "fmi2GetInteger", n);
}
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean value[]) {
    (void)vr, (void)value;
    return no_such(c, "fmi2GetBoolean", n);
}
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String value[]) {
    (void)vr, (void)value;
    return no_such(c, "fmi2GetString", n);
}
fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer value[]) {
    (void)vr, (void)value;
    return no_such(c, "fmi2SetInteger", n);
}
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean value[]) {
    (void)vr, (void)value;
    return no_such(c, "fmi2SetBoolean", n);
}
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String value[]) {
    (void)vr, (void)value;
    return no_such(c, "fmi2SetString", n);
}

static int outputs_finite(Instance *inst) {
    uint64_t bits = 0;   /* (run by run: no index to load per value) */
    for (int r = 0; r < inst->nspans; r++) {
        const double *x = inst->values + inst->spans[2 * r];
        for (int k = 0; k < inst->spans[2 * r + 1]; k++) bits |= not_finite_bit(x[k]);
    }
    if (!(bits >> 63)) return 1;
    for (int k = 0; k < inst->noutputs; k++) {
        int vr = inst->outputs[k];
        if (!isfinite(inst->values[vr])) {
            hf_fail(inst, "output %s = %g is not finite", inst->names[vr], inst->values[vr]);
            return 0;
        }
    }
    return 1;
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    (void)noSetFMUStatePriorToCurrentPoint;
    ENTER(c);
    if (!(h > 0.0 && isfinite(h)))
        hf_set_error(inst, "communication step %g must be positive and finite", h);
    else if (inst->has_next && fabs(t - inst->next_time) > 1e-6 * h + 1e-12 * fabs(inst->next_time))
        hf_set_error(inst, "communication point %.17g is not where the last step ended (%.17g); restore an FMU "
                     "state (fmi2SetFMUstate) to go back or forward", t, inst->next_time);
    if (!inst->error[0] && inputs_finite(inst)) {
        /* the outputs at the step's start are not evaluated unless read: the step needs the
         * inputs only, and the outputs at its end (evaluated once, here) are what a master reads */
        inst->model->step(inst, t, h);
        if (!inst->error[0]) {
            inst->next_time = t + h, inst->has_next = 1;   /* (the outputs' time: waves) */
            if (inst->stale) evaluate(inst);
            if (!inst->error[0] && !outputs_finite(inst)) return fmi2Error;
            /* inputs and outputs checked, the rest fixed and checked: reads need no check */
            inst->clean = !inst->error[0] && !inst->suspect && !inst->stale && inst->fixed_finite;
        }
    }
    if (inst->error[0]) {
        hf_fail(inst, "at t=%.17g: %s", t, inst->error);
        inst->error[0] = 0;
        return fmi2Error;
    }
    return (fmi2Status)inst->status;
}

fmi2Status fmi2CancelStep(fmi2Component c) {
    ENTER(c);
    hf_fail(inst, "fmi2CancelStep: steps are synchronous, nothing to cancel");
    return fmi2Error;
}

/* -- FMU state: [magic, size, running, has_next, next_time, values, the model's] -------- */

typedef struct {
    size_t n;
    double d[];
} State;

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *out) {
    ENTER(c);
    if (!out) {
        hf_fail(inst, "fmi2GetFMUstate: NULL state pointer");
        return fmi2Error;
    }
    size_t nm = inst->model->state_size(inst), n = 3 + (size_t)inst->nvars + nm;
    State *s = *out ? (State *)*out : NULL;
    if (s && s->n != n) {   /* a state of another size: make a new one */
        free(s);
        s = NULL;
    }
    if (!s) s = malloc(sizeof(State) + sizeof(double) * n);
    if (!s) {
        *out = NULL;
        hf_fail(inst, "fmi2GetFMUstate: out of memory");
        return fmi2Error;
    }
    s->n = n;
    s->d[0] = inst->running, s->d[1] = inst->has_next, s->d[2] = inst->next_time;
    memcpy(s->d + 3, inst->values, sizeof(double) * inst->nvars);
    inst->model->save(inst, s->d + 3 + inst->nvars);
    *out = s;
    return fmi2OK;
}

static fmi2Status set_state(Instance *inst, const double *d, size_t n) {
    double *old = malloc(sizeof(double) * (inst->nvars + 1));
    int ok = old && n >= 3 + (size_t)inst->nvars;
    if (ok) {   /* the values first: a model may rebuild itself from them */
        memcpy(old, inst->values, sizeof(double) * inst->nvars);
        memcpy(inst->values, d + 3, sizeof(double) * inst->nvars);
        ok = inst->model->load(inst, d + 3 + inst->nvars, n - 3 - inst->nvars) == 0;
        if (!ok) memcpy(inst->values, old, sizeof(double) * inst->nvars);
    }
    free(old);
    if (!ok) {
        hf_fail(inst, "fmi2SetFMUstate: not a state of this FMU (wrong size or kind)");
        return fmi2Error;
    }
    inst->running = d[0] != 0.0, inst->has_next = d[1] != 0.0, inst->next_time = d[2];
    inst->stale = 1, inst->suspect = 1, inst->changed = 1, inst->error[0] = 0;
    inst->fixed_finite = fixed_finite(inst), inst->clean = 0;
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state) {
    ENTER(c);
    if (!state) {
        hf_fail(inst, "fmi2SetFMUstate: NULL state");
        return fmi2Error;
    }
    State *s = state;
    return set_state(inst, s->d, s->n);
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *state) {
    (void)c;
    if (state) {
        free(*state);
        *state = NULL;
    }
    return fmi2OK;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate state, size_t *size) {
    ENTER(c);
    if (!state || !size) {
        hf_fail(inst, "fmi2SerializedFMUstateSize: NULL state or size");
        return fmi2Error;
    }
    *size = 16 + sizeof(double) * ((State *)state)->n;
    return fmi2OK;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate state, fmi2Byte bytes[], size_t size) {
    ENTER(c);
    State *s = state;
    if (!s || !bytes || size != 16 + sizeof(double) * s->n) {
        hf_fail(inst, "fmi2SerializeFMUstate: NULL state or buffer, or a buffer of the wrong size");
        return fmi2Error;
    }
    uint64_t head[2] = {STATE_MAGIC, (uint64_t)s->n};
    memcpy(bytes, head, 16);
    memcpy(bytes + 16, s->d, sizeof(double) * s->n);
    return fmi2OK;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte bytes[], size_t size, fmi2FMUstate *state) {
    ENTER(c);
    uint64_t head[2] = {0, 0};
    if (bytes && size >= 16) memcpy(head, bytes, 16);
    if (!state || !bytes || head[0] != STATE_MAGIC || size != 16 + sizeof(double) * head[1] ||
        head[1] < 3 + (uint64_t)inst->nvars) {
        hf_fail(inst, "fmi2DeSerializeFMUstate: the bytes are not a serialized state of this FMU");
        return fmi2Error;
    }
    State *s = malloc(sizeof(State) + sizeof(double) * head[1]);
    if (!s) {
        hf_fail(inst, "fmi2DeSerializeFMUstate: out of memory");
        return fmi2Error;
    }
    s->n = head[1];
    memcpy(s->d, bytes + 16, sizeof(double) * s->n);
    if (*state) free(*state);
    *state = s;
    return fmi2OK;
}

/* -- not provided (capability flags false) ---------------------------------------------- */

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                        const fmi2ValueReference z[], size_t nz, const fmi2Real du[], fmi2Real dz[]) {
    (void)u, (void)nu, (void)z, (void)nz, (void)du, (void)dz;
    ENTER(c);
    hf_fail(inst, "fmi2GetDirectionalDerivative: not provided by this FMU");
    return fmi2Error;
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    (void)vr, (void)n, (void)order, (void)value;
    ENTER(c);
    hf_fail(inst, "fmi2SetRealInputDerivatives: not provided by this FMU");
    return fmi2Error;
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                        const fmi2Integer order[], fmi2Real value[]) {
    (void)vr, (void)n, (void)order, (void)value;
    ENTER(c);
    hf_fail(inst, "fmi2GetRealOutputDerivatives: not provided by this FMU");
    return fmi2Error;
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) {
    (void)s;
    ENTER(c);
    if (value) *value = fmi2OK;
    return fmi2Discard;
}
fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value) {
    (void)s;
    ENTER(c);
    if (value) *value = inst->has_next ? inst->next_time : 0.0;
    return s == fmi2LastSuccessfulTime ? fmi2OK : fmi2Discard;
}
fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value) {
    (void)s, (void)value;
    ENTER(c);
    return fmi2Discard;
}
fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value) {
    (void)s;
    ENTER(c);
    if (value) *value = fmi2False;
    return fmi2Discard;
}
fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value) {
    (void)s;
    ENTER(c);
    if (value) *value = "";
    return fmi2Discard;
}
