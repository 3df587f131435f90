/*
 * What a native FMI 2.0 co-simulation host of hydrofmu calls, and how it loads an unzipped
 * FMU: shared by the timing host (bench/native_host.c) and the tests' host
 * (tests/native/fmi_host.c, compiled with -I for this folder).  Declared here, ABI-compatible
 * with the standard headers, so the hosts build with nothing but a C compiler and libdl.
 */
#include <stdio.h>

typedef void *C;
typedef struct {
    void (*logger)(void *, const char *, int, const char *, const char *, ...);
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(void *, int);
    void *componentEnvironment;
} Callbacks;

typedef struct {
    C (*Instantiate)(const char *, int, const char *, const char *, const Callbacks *, int, int);
    int (*SetupExperiment)(C, int, double, double, int, double);
    int (*EnterInitializationMode)(C), (*ExitInitializationMode)(C), (*Terminate)(C);
    void (*FreeInstance)(C);
    int (*SetReal)(C, const unsigned *, size_t, const double *);
    int (*GetReal)(C, const unsigned *, size_t, double *);
    int (*DoStep)(C, double, double, int);
} Fmi;

/* the members of Fmi, in order */
static const char *fmi_names[] = {"fmi2Instantiate", "fmi2SetupExperiment", "fmi2EnterInitializationMode",
                                  "fmi2ExitInitializationMode", "fmi2Terminate", "fmi2FreeInstance",
                                  "fmi2SetReal", "fmi2GetReal", "fmi2DoStep"};

#ifndef _WIN32   /* (tests/native/win_host.c loads with LoadLibrary) */
#include <dlfcn.h>

/* dlopen DIR/binaries/linux64/ID.so and fill `fmi`: the handle, or NULL with the reason printed. */
static void *fmi_load(const char *dir, const char *id, Fmi *fmi) {
    const char **names = fmi_names;
    char lib[4200];
    snprintf(lib, sizeof lib, "%s/binaries/linux64/%s.so", dir, id);
    void *h = dlopen(lib, RTLD_NOW | RTLD_LOCAL);
    if (!h) {
        printf("dlopen failed: %s\n", dlerror());
        return NULL;
    }
    void **slots = (void **)fmi; /* members are pointers in the order of names */
    for (size_t i = 0; i < sizeof fmi_names / sizeof *fmi_names; i++)
        if (!(slots[i] = dlsym(h, names[i]))) {
            printf("missing %s\n", names[i]);
            dlclose(h);
            return NULL;
        }
    return h;
}
#endif
