/*
 * A minimal generic FMI 2.0 co-simulation host for the tests: dlopen + the fmi2
 * functions, no Python in the process.
 *
 *   fmi_host DIR ID GUID THREADS STEPS DT INPUTS OUTPUTS
 *
 * DIR is an unzipped FMU, ID its model identifier; DIR may list copies of the FMU
 * ("a,b"), each loaded as a library of its own, instance k using copy k mod n.
 * THREADS instances run at once, instance k in its own thread; every step it sets INPUTS ("vr:value,vr:value", values
 * times k+1) then steps DT seconds and prints "k step vr value" for every vr of OUTPUTS
 * ("vr,vr").  Log messages are printed as "LOG status category: message" (a NULL
 * category as "NULL-CATEGORY").  A failed fmi2Instantiate prints "instantiate: NULL" and
 * the host goes on to exit 0: an FMU failing must not take its host down.
 *
 * FMI_HOST_CYCLES=N:EVERY first instantiates "instance0" of the first copy N times, each
 * time initialised and stepped once with the inputs times 7 (values the run never sets),
 * then freed, and prints "rss CYCLE KB" (resident memory) every EVERY cycles; the run
 * follows, so its instance 0 comes after N instances of the same name.
 */
#include <dlfcn.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

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

static Fmi fmis[16];
static const char *dirs[16], *id, *guid;
static int ndirs;
static int steps, nin, nout;
static double dt, in_val[64];
static unsigned in_vr[64], out_vr[64];
static pthread_mutex_t print_lock = PTHREAD_MUTEX_INITIALIZER;

static void logger(void *env, const char *name, int status, const char *cat, const char *msg, ...) {
    (void)env;
    (void)name;
    char text[4096];
    va_list ap;
    va_start(ap, msg);
    vsnprintf(text, sizeof text, msg ? msg : "NULL-MESSAGE", ap);
    va_end(ap);
    pthread_mutex_lock(&print_lock);
    printf("LOG %d %s: %s\n", status, cat ? cat : "NULL-CATEGORY", text);
    fflush(stdout);
    pthread_mutex_unlock(&print_lock);
}

static long rss_kb(void) {
    long pages = 0, resident = 0;
    FILE *f = fopen("/proc/self/statm", "r");
    if (f) {
        if (fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
        fclose(f);
    }
    return resident * (sysconf(_SC_PAGESIZE) / 1024);
}

static void cycles(long n, long every) {
    const Fmi fmi = fmis[0];
    char uri[4200];
    snprintf(uri, sizeof uri, "file://%s/resources", dirs[0]);
    Callbacks cb = {logger, calloc, free, NULL, NULL};
    double in[64];
    for (int i = 0; i < nin; i++) in[i] = in_val[i] * 7.0;
    for (long k = 1; k <= n; k++) {
        C c = fmi.Instantiate("instance0", 1, guid, uri, &cb, 0, 0);
        if (!c) {
            printf("instantiate: NULL\n");
            return;
        }
        if (fmi.SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0) || fmi.EnterInitializationMode(c) ||
            fmi.ExitInitializationMode(c) || fmi.SetReal(c, in_vr, nin, in) || fmi.DoStep(c, 0.0, dt, 1))
            printf("cycle %ld: an FMI call failed\n", k);
        fmi.Terminate(c);
        fmi.FreeInstance(c);
        if (every > 0 && k % every == 0) printf("rss %ld %ld\n", k, rss_kb());
    }
}

static void *run(void *arg) {
    long k = (long)arg;
    const Fmi fmi = fmis[k % ndirs];
    char uri[4200], name[32];
    snprintf(uri, sizeof uri, "file://%s/resources", dirs[k % ndirs]);
    snprintf(name, sizeof name, "instance%ld", k);
    Callbacks cb = {logger, calloc, free, NULL, NULL};
    C c = fmi.Instantiate(name, 1 /* co-simulation */, guid, uri, &cb, 0, 0);
    if (!c) {
        printf("instantiate: NULL\n");
        return NULL;
    }
    int bad = fmi.SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0) || fmi.EnterInitializationMode(c) ||
              fmi.ExitInitializationMode(c);
    double in[64], out[64];
    for (int i = 0; i < nin; i++) in[i] = in_val[i] * (double)(k + 1);
    for (int n = 0; n < steps && !bad; n++) {
        bad = fmi.SetReal(c, in_vr, nin, in) || fmi.DoStep(c, n * dt, dt, 1) || fmi.GetReal(c, out_vr, nout, out);
        pthread_mutex_lock(&print_lock);
        for (int i = 0; i < nout && !bad; i++) printf("%ld %d %u %.17g\n", k, n + 1, out_vr[i], out[i]);
        pthread_mutex_unlock(&print_lock);
    }
    if (bad) printf("instance %ld: an FMI call failed\n", k);
    fmi.Terminate(c);
    fmi.FreeInstance(c);
    return NULL;
}

int main(int argc, char **argv) {
    if (argc != 9) {
        fprintf(stderr, "usage: %s DIR ID GUID THREADS STEPS DT INPUTS OUTPUTS\n", argv[0]);
        return 2;
    }
    id = argv[2], guid = argv[3];
    for (char *p = strtok(argv[1], ","); p && ndirs < 16; p = strtok(NULL, ",")) dirs[ndirs++] = p;
    int threads = atoi(argv[4]);
    steps = atoi(argv[5]), dt = atof(argv[6]);
    for (char *p = strtok(argv[7], ","); p && nin < 64; p = strtok(NULL, ","), nin++)
        sscanf(p, "%u:%lf", &in_vr[nin], &in_val[nin]);
    for (char *p = strtok(argv[8], ","); p && nout < 64; p = strtok(NULL, ","), nout++)
        sscanf(p, "%u", &out_vr[nout]);
    const char *names[] = {"fmi2Instantiate", "fmi2SetupExperiment", "fmi2EnterInitializationMode",
                           "fmi2ExitInitializationMode", "fmi2Terminate", "fmi2FreeInstance",
                           "fmi2SetReal", "fmi2GetReal", "fmi2DoStep"};
    void *handles[16];
    for (int d = 0; d < ndirs; d++) {
        char lib[4200];
        snprintf(lib, sizeof lib, "%s/binaries/linux64/%s.so", dirs[d], id);
        if (!(handles[d] = dlopen(lib, RTLD_NOW | RTLD_LOCAL))) {
            printf("dlopen failed: %s\n", dlerror());
            return 1;
        }
        void **slots = (void **)&fmis[d]; /* members are pointers in the order of names */
        for (size_t i = 0; i < sizeof names / sizeof *names; i++)
            if (!(slots[i] = dlsym(handles[d], names[i]))) {
                printf("missing %s\n", names[i]);
                return 1;
            }
    }
    const char *cyc = getenv("FMI_HOST_CYCLES");
    long n = 0, every = 0;
    if (cyc && sscanf(cyc, "%ld:%ld", &n, &every) >= 1) cycles(n, every);
    pthread_t t[16];
    for (long k = 0; k < threads && k < 16; k++) pthread_create(&t[k], NULL, run, (void *)k);
    for (long k = 0; k < threads && k < 16; k++) pthread_join(t[k], NULL);
    for (int d = 0; d < ndirs; d++) dlclose(handles[d]);
    printf("host exits normally\n");
    return 0;
}
