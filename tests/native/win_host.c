/*
 * A minimal FMI 2.0 co-simulation host for Windows (cross-compiled with mingw-w64, run
 * under wine by the tests): LoadLibrary + GetProcAddress, one instance.
 *
 *   win_host DLL GUID RESOURCE_URI STEPS DT INPUTS OUTPUTS
 *
 * Every step sets INPUTS ("vr:value,vr:value"), steps DT seconds and prints "step vr value"
 * for every vr of OUTPUTS ("vr,vr"); log messages are printed as "LOG status: message".
 * Compiled with -I for hydrofmu/bench (fmi2_host.h: the FMI calls).
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <windows.h>

#include "fmi2_host.h"

static void logger(void *env, const char *name, int status, const char *cat, const char *msg, ...) {
    (void)env, (void)name, (void)cat;
    char text[4096];
    va_list ap;
    va_start(ap, msg);
    vsnprintf(text, sizeof text, msg, ap);
    va_end(ap);
    printf("LOG %d: %s\n", status, text);
}

int main(int argc, char **argv) {
    if (argc != 8) {
        fprintf(stderr, "usage: %s DLL GUID RESOURCE_URI STEPS DT INPUTS OUTPUTS\n", argv[0]);
        return 2;
    }
    HMODULE lib = LoadLibraryA(argv[1]);
    if (!lib) {
        printf("LoadLibrary failed: %lu\n", (unsigned long)GetLastError());
        return 1;
    }
    Fmi fmi;
    void **slots = (void **)&fmi; /* members are pointers in the order of fmi_names */
    for (size_t i = 0; i < sizeof fmi_names / sizeof *fmi_names; i++)
        if (!(slots[i] = (void *)GetProcAddress(lib, fmi_names[i]))) {
            printf("missing %s\n", fmi_names[i]);
            return 1;
        }
    unsigned in_vr[64], out_vr[64];
    double in[64], out[64];
    int nin = 0, nout = 0, steps = atoi(argv[4]);
    double dt = atof(argv[5]);
    for (char *p = strtok(argv[6], ","); p && nin < 64; p = strtok(NULL, ","), nin++)
        sscanf(p, "%u:%lf", &in_vr[nin], &in[nin]);
    for (char *p = strtok(argv[7], ","); p && nout < 64; p = strtok(NULL, ","), nout++) sscanf(p, "%u", &out_vr[nout]);
    Callbacks cb = {logger, calloc, free, NULL, NULL};
    C c = fmi.Instantiate("win", 1, argv[2], argv[3], &cb, 0, 0);
    if (!c) {
        printf("instantiate: NULL\n");
        return 1;
    }
    int bad = fmi.SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0) || fmi.EnterInitializationMode(c) ||
              fmi.ExitInitializationMode(c);
    for (int n = 0; n < steps && !bad; n++) {
        bad = fmi.SetReal(c, in_vr, nin, in) || fmi.DoStep(c, n * dt, dt, 1) || fmi.GetReal(c, out_vr, nout, out);
        for (int i = 0; i < nout && !bad; i++) printf("%d %u %.17g\n", n + 1, out_vr[i], out[i]);
    }
    fmi.FreeInstance(c);
    printf(bad ? "an FMI call failed\n" : "host exits normally\n");
    return 0;
}
