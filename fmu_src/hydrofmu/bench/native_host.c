/*
 * A native FMI 2.0 co-simulation host for timing (bench/native.py): no Python of its own.
 *
 *   native_host DIR ID GUID STEPS DT INPUTS OUTPUTS [VARY]
 *
 * DIR is an unzipped FMU, ID its model identifier.  One instance in the main thread:
 * dlopen, fmi2Instantiate and initialisation (the startup), then STEPS steps of
 * fmi2SetReal(INPUTS "vr:value,...") + fmi2DoStep(DT) + fmi2GetReal(OUTPUTS "vr,..."),
 * then fmi2Terminate + fmi2FreeInstance.  VARY 1: the inputs change at every step (each
 * one's value, then that plus 1e-6 of it and 1e-9, alternately: what a master sets as the
 * partners move; an FMU cannot keep its outputs from the step before); default 0: the same
 * values every step.  Prints one JSON line:
 * {"startup_s": ..., "step_s": seconds per step, "free_s": ..., "failed": 0 or 1}.
 */
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fmi2_host.h"

static void logger(void *env, const char *name, int status, const char *cat, const char *msg, ...) {
    (void)env, (void)name;
    fprintf(stderr, "LOG %d %s: %s\n", status, cat ? cat : "", msg ? msg : "");
}

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

int main(int argc, char **argv) {
    if (argc != 8 && argc != 9) {
        fprintf(stderr, "usage: %s DIR ID GUID STEPS DT INPUTS OUTPUTS [VARY]\n", argv[0]);
        return 2;
    }
    int vary = argc == 9 && atoi(argv[8]) != 0;
    const char *dir = argv[1], *id = argv[2], *guid = argv[3];
    long steps = atol(argv[4]);
    double dt = atof(argv[5]), in[64], out[64], moved[64];
    unsigned in_vr[64], out_vr[64];
    int nin = 0, nout = 0;
    for (char *p = strtok(argv[6], ","); p && nin < 64; p = strtok(NULL, ","), nin++)
        sscanf(p, "%u:%lf", &in_vr[nin], &in[nin]);
    for (char *p = strtok(argv[7], ","); p && nout < 64; p = strtok(NULL, ","), nout++)
        sscanf(p, "%u", &out_vr[nout]);
    for (int k = 0; k < nin; k++) moved[k] = in[k] + 1e-6 * in[k] + 1e-9;
    char uri[4200];
    snprintf(uri, sizeof uri, "file://%s/resources", dir);
    double t0 = now();
    Fmi fmi;
    if (!fmi_load(dir, id, &fmi)) return 1;
    Callbacks cb = {logger, calloc, free, NULL, NULL};
    C c = fmi.Instantiate("timed", 1, guid, uri, &cb, 0, 0);
    if (!c) {
        printf("instantiate: NULL\n");
        return 1;
    }
    int bad = fmi.SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0) || fmi.EnterInitializationMode(c) ||
              fmi.ExitInitializationMode(c);
    double t1 = now();
    for (long n = 0; n < steps && !bad; n++)
        bad = fmi.SetReal(c, in_vr, nin, vary && (n & 1) ? moved : in) || fmi.DoStep(c, n * dt, dt, 1) ||
              fmi.GetReal(c, out_vr, nout, out);
    double t2 = now();
    fmi.Terminate(c);
    fmi.FreeInstance(c);
    double t3 = now();
    printf("{\"startup_s\": %.9g, \"step_s\": %.9g, \"free_s\": %.9g, \"failed\": %d}\n", t1 - t0,
           (t2 - t1) / (steps > 0 ? steps : 1), t3 - t2, bad);
    return 0;
}
