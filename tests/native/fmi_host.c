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
 *
 * FMI_HOST_PROBE=1: after each step, "tstate k step P" with P the Python thread state the
 * calling thread holds between FMI calls (PyGILState_GetThisThreadState, 0 for none), and
 * once every instance has ended, "threads N": the threads the process still runs.
 * FMI_HOST_HOP=1: every step of an instance (its SetReal, DoStep, GetReal) in a thread of its
 * own, started for that step and ended after it, and Terminate + FreeInstance in another.
 */
#define _GNU_SOURCE /* RTLD_DEFAULT */
#include <dlfcn.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "fmi2_host.h" /* hydrofmu/bench: the FMI calls and the loader */

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

static int probe, hop;

static int thread_count(void) {
    int n = 0;
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    while (f && fgets(line, sizeof line, f))
        if (sscanf(line, "Threads: %d", &n) == 1) break;
    if (f) fclose(f);
    return n;
}

typedef struct {
    Fmi fmi;
    C c;
    long k;
    int n, bad;
    double *in, *out;
} Step;

/* One step of instance k: set, step, get, print (and probe). */
static void *step(void *arg) {
    Step *s = arg;
    const Fmi fmi = s->fmi;
    s->bad = fmi.SetReal(s->c, in_vr, nin, s->in) || fmi.DoStep(s->c, s->n * dt, dt, 1) ||
             fmi.GetReal(s->c, out_vr, nout, s->out);
    pthread_mutex_lock(&print_lock);
    for (int i = 0; i < nout && !s->bad; i++) printf("%ld %d %u %.17g\n", s->k, s->n + 1, out_vr[i], s->out[i]);
    if (probe) {
        void *(*state)(void);
        *(void **)&state = dlsym(RTLD_DEFAULT, "PyGILState_GetThisThreadState");
        printf("tstate %ld %d %p\n", s->k, s->n + 1, state ? state() : NULL);
    }
    pthread_mutex_unlock(&print_lock);
    return NULL;
}

static void *finish(void *arg) {
    Step *s = arg;
    s->fmi.Terminate(s->c);
    s->fmi.FreeInstance(s->c);
    return NULL;
}

/* f(arg) in this thread, or with FMI_HOST_HOP in a new thread, waited for. */
static void call(void *(*f)(void *), void *arg) {
    pthread_t t;
    if (hop && pthread_create(&t, NULL, f, arg) == 0)
        pthread_join(t, NULL);
    else
        f(arg);
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
    Step s = {fmi, c, k, 0, bad, in, out};
    for (; s.n < steps && !s.bad; s.n++) call(step, &s);
    if (s.bad) printf("instance %ld: an FMI call failed\n", k);
    call(finish, &s);
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
    void *handles[16];
    for (int d = 0; d < ndirs; d++)
        if (!(handles[d] = fmi_load(dirs[d], id, &fmis[d]))) return 1;
    probe = getenv("FMI_HOST_PROBE") != NULL;
    hop = getenv("FMI_HOST_HOP") != NULL;
    const char *cyc = getenv("FMI_HOST_CYCLES");
    long n = 0, every = 0;
    if (cyc && sscanf(cyc, "%ld:%ld", &n, &every) >= 1) cycles(n, every);
    pthread_t t[16];
    for (long k = 0; k < threads && k < 16; k++) pthread_create(&t[k], NULL, run, (void *)k);
    for (long k = 0; k < threads && k < 16; k++) pthread_join(t[k], NULL);
    if (probe) printf("threads %d\n", thread_count());
    for (int d = 0; d < ndirs; d++) dlclose(handles[d]);
    printf("host exits normally\n");
    return 0;
}
