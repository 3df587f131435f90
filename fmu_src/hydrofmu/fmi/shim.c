/*
 * FMI 2.0 co-simulation forwarding shim for pythonfmu FMUs.
 *
 * This library is installed as binaries/linux64/<id>.so.  It loads the original
 * pythonfmu binary stored beside it as <id>_pythonfmu.so and forwards every FMI
 * call, with two changes: fmi2DoStep's fmi2Discard becomes fmi2Error, and
 * logging follows the standard (below).  pythonfmu maps a slave's `do_step -> False` to Discard, but
 * hydrofmu slaves only return False on bad input and never complete a partial
 * step, so Error is the status the FMI standard asks for.
 *
 * The FMI types are declared here (ABI-compatible with the standard headers)
 * so the shim builds with nothing but a C compiler and libdl.
 *
 * Logging: pythonfmu 0.7 drops every message, errors included, unless debug
 * logging is on.  FMI 2.0 has loggingOn switch debug logging only, so the shim
 * keeps the inner FMU's logging always on and filters itself: a message reaches
 * the host's logger when its status is fmi2Warning or worse, or when the host
 * turned logging on (fmi2Instantiate's loggingOn, fmi2SetDebugLogging) for its
 * category.  For that the host's handle is the shim's own per-instance struct
 * (Shim below), which wraps pythonfmu's component; the inner FMU is given a
 * callback struct whose componentEnvironment is that Shim, so messages route to
 * the right host even while the inner fmi2Instantiate is still running.
 * pythonfmu hands over message text, not a format: '%' is doubled on the way.
 *
 * Python in a native host: pythonfmu's binary needs libpython's symbols but is not
 * linked against it, so in a process without Python it cannot even be loaded.  Before
 * loading it the shim checks for Python (Py_IsInitialized visible in the process and
 * true); if there is none it loads the libpython of the interpreter named in
 * resources/hydrofmu_python.txt (written at build time: the build's interpreter) or
 * in $HYDROFMU_PYTHON (asked for its libpython), with RTLD_GLOBAL so that extension
 * modules (numpy) find it too, initialises it with that interpreter as program name
 * (so its prefix, venv and site-packages are those of a plain run of it), checks that
 * numpy imports, and releases the GIL.  The interpreter then lives until the process
 * ends: numpy cannot be imported again after Py_Finalize.  pythonfmu then finds Python
 * initialised and leaves it alone.  Every forwarded call holds the GIL (pythonfmu
 * takes it too; PyGILState calls nest), so hosts may call from any thread; each host thread
 * gets one Python thread state at its first call, kept until it ends (keep_thread_state).
 * A failure is kept and reported by fmi2Instantiate as one log message.
 *
 * Instance pool: pythonfmu 0.7's fmi2Instantiate leaks ~1.2 kB of Python objects every
 * time (it inserts a new string into sys.path and runs the slave script again, keeping the
 * list and repr strings of every MRO it inspects), so a host that instantiates and frees
 * over and over grows without bound.  The shim therefore keeps freed pythonfmu components
 * (at most POOL_MAX per loaded FMU) and hands one back to an fmi2Instantiate with the same
 * instance name, type, GUID, resource location and visibility -- everything pythonfmu keeps
 * from its own fmi2Instantiate -- after pythonfmu's fmi2Reset, which builds a new Python
 * slave object exactly as fmi2Instantiate does.  What belongs to the host's instance
 * (logger, componentEnvironment, stepFinished, loggingOn and categories, the memory of the
 * handle) lives in the Shim and is new at every fmi2Instantiate; the pythonfmu component
 * is given the shim's own callbacks (calloc/free, a logger that forwards to whichever host
 * instance holds it now), so it can outlive the host instance that created it.
 * Only instances seen to come back are pooled: those whose fmi2Instantiate arguments were
 * given before in this process.  A host may unload the library in between (fmpy does at
 * every fmi2FreeInstance), so that record is kept in the interpreter (a set of key hashes,
 * sys._hydrofmu_shim_instances, at most SEEN_MAX).  Pooling pins the library, and with it
 * pythonfmu's, in memory (the pooled components call back into it: ~0.35 MB per FMU copy).
 * An FMU copy used once (fmpy's simulate_fmu extracts a fresh copy per run) keeps nothing.
 * HYDROFMU_POOL=0 (read when the library loads) turns pooling off.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <sys/file.h>
#include <unistd.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>

/* ---- FMI 2.0 types (same layout as fmi2TypesPlatform.h / fmi2FunctionTypes.h) ---- */
typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef void *fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef char fmi2Char;
typedef const fmi2Char *fmi2String;
typedef char fmi2Byte;

typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef enum {
    fmi2DoStepStatus, fmi2PendingStatus, fmi2LastSuccessfulTime, fmi2Terminated
} fmi2StatusKind;

typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String, fmi2Status,
                                   fmi2String, fmi2String, ...);
typedef void *(*fmi2CallbackAllocateMemory)(size_t, size_t);
typedef void (*fmi2CallbackFreeMemory)(void *);
typedef void (*fmi2StepFinished)(fmi2ComponentEnvironment, fmi2Status);

typedef struct {
    const fmi2CallbackLogger logger;
    const fmi2CallbackAllocateMemory allocateMemory;
    const fmi2CallbackFreeMemory freeMemory;
    const fmi2StepFinished stepFinished;
    const fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

#define EXPORT __attribute__((visibility("default")))
typedef const fmi2ValueReference *VRs;

/*
 * Every forwarded function that returns fmi2Status, as
 * X(name, parameter list, argument list).  One line per FMI function; the
 * macros below expand it into the pointer table, the symbol lookup and the
 * exported forwarders.
 */
#define FMI_STATUS_FUNCS(X) \
    X(SetupExperiment, (fmi2Component c, fmi2Boolean tolDef, fmi2Real tol, fmi2Real t0, fmi2Boolean stopDef, fmi2Real t1), (c, tolDef, tol, t0, stopDef, t1)) \
    X(EnterInitializationMode, (fmi2Component c), (c)) \
    X(ExitInitializationMode, (fmi2Component c), (c)) \
    X(Terminate, (fmi2Component c), (c)) \
    X(GetReal, (fmi2Component c, VRs vr, size_t n, fmi2Real v[]), (c, vr, n, v)) \
    X(GetInteger, (fmi2Component c, VRs vr, size_t n, fmi2Integer v[]), (c, vr, n, v)) \
    X(GetBoolean, (fmi2Component c, VRs vr, size_t n, fmi2Boolean v[]), (c, vr, n, v)) \
    X(GetString, (fmi2Component c, VRs vr, size_t n, fmi2String v[]), (c, vr, n, v)) \
    X(SetReal, (fmi2Component c, VRs vr, size_t n, const fmi2Real v[]), (c, vr, n, v)) \
    X(SetInteger, (fmi2Component c, VRs vr, size_t n, const fmi2Integer v[]), (c, vr, n, v)) \
    X(SetBoolean, (fmi2Component c, VRs vr, size_t n, const fmi2Boolean v[]), (c, vr, n, v)) \
    X(SetString, (fmi2Component c, VRs vr, size_t n, const fmi2String v[]), (c, vr, n, v)) \
    X(GetFMUstate, (fmi2Component c, fmi2FMUstate *s), (c, s)) \
    X(SetFMUstate, (fmi2Component c, fmi2FMUstate s), (c, s)) \
    X(FreeFMUstate, (fmi2Component c, fmi2FMUstate *s), (c, s)) \
    X(SerializedFMUstateSize, (fmi2Component c, fmi2FMUstate s, size_t *size), (c, s, size)) \
    X(SerializeFMUstate, (fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t size), (c, s, b, size)) \
    X(DeSerializeFMUstate, (fmi2Component c, const fmi2Byte b[], size_t size, fmi2FMUstate *s), (c, b, size, s)) \
    X(GetDirectionalDerivative, (fmi2Component c, VRs unk, size_t nu, VRs kn, size_t nk, const fmi2Real dv[], fmi2Real df[]), (c, unk, nu, kn, nk, dv, df)) \
    X(SetRealInputDerivatives, (fmi2Component c, VRs vr, size_t n, const fmi2Integer ord[], const fmi2Real v[]), (c, vr, n, ord, v)) \
    X(GetRealOutputDerivatives, (fmi2Component c, VRs vr, size_t n, const fmi2Integer ord[], fmi2Real v[]), (c, vr, n, ord, v)) \
    X(CancelStep, (fmi2Component c), (c)) \
    X(GetStatus, (fmi2Component c, const fmi2StatusKind k, fmi2Status *v), (c, k, v)) \
    X(GetIntegerStatus, (fmi2Component c, const fmi2StatusKind k, fmi2Integer *v), (c, k, v)) \
    X(GetBooleanStatus, (fmi2Component c, const fmi2StatusKind k, fmi2Boolean *v), (c, k, v)) \
    X(GetStringStatus, (fmi2Component c, const fmi2StatusKind k, fmi2String *v), (c, k, v))

/* Functions with their own return type or behaviour, written out below. */
#define FMI_OTHER_FUNCS(X) \
    X(const char *, GetTypesPlatform, (void)) \
    X(const char *, GetVersion, (void)) \
    X(fmi2Component, Instantiate, (fmi2String name, fmi2Type type, fmi2String guid, fmi2String res, const fmi2CallbackFunctions *cb, fmi2Boolean visible, fmi2Boolean logging)) \
    X(fmi2Status, SetDebugLogging, (fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cat[])) \
    X(void, FreeInstance, (fmi2Component c)) \
    X(fmi2Status, DoStep, (fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noPrior)) \
    X(fmi2Status, Reset, (fmi2Component c)) \
    X(fmi2Status, GetRealStatus, (fmi2Component c, const fmi2StatusKind k, fmi2Real *v))

/* Table of pointers into the inner library, one typed member per function. */
static struct {
#define STATUS_MEMBER(name, params, args) fmi2Status(*name) params;
#define OTHER_MEMBER(ret, name, params) ret(*name) params;
    FMI_STATUS_FUNCS(STATUS_MEMBER)
    FMI_OTHER_FUNCS(OTHER_MEMBER)
#undef STATUS_MEMBER
#undef OTHER_MEMBER
} inner;

static void *inner_handle;
static int inner_ok;
static char inner_err[16384]; /* room for a few full paths plus dlerror() text */
static pthread_once_t inner_once = PTHREAD_ONCE_INIT;
static int pinned;   /* this library stays loaded until the process exits */
static int no_pool;  /* HYDROFMU_POOL=0: free every instance at fmi2FreeInstance */

/* The GIL functions of the process's Python (PyGILState_STATE is an int-sized enum). */
static int (*gil_ensure)(void);
static void (*gil_release)(int);
static void keep_thread_state(void);
static __thread int kept; /* this thread has a Python thread state that outlives each call */

#define GIL_TAKE                                  \
    if (gil_ensure && !kept) keep_thread_state(); \
    int gil_ = gil_ensure ? gil_ensure() : 0
#define GIL_GIVE if (gil_ensure) gil_release(gil_)

/* Path of the inner library: this file's path with ".so" replaced by "_pythonfmu.so". */
static int inner_path(char *out, size_t size) {
    Dl_info info;
    /* any object inside this library will do; a data address avoids a function-pointer cast */
    if (!dladdr(&inner_once, &info) || !info.dli_fname) {
        snprintf(inner_err, sizeof inner_err, "cannot find the shim's own path (dladdr failed)");
        return 0;
    }
    const char *self = info.dli_fname;
    size_t n = strlen(self);
    if (n >= 3 && strcmp(self + n - 3, ".so") == 0) n -= 3;
    if (snprintf(out, size, "%.*s_pythonfmu.so", (int)n, self) >= (int)size) {
        snprintf(inner_err, sizeof inner_err, "path too long: %s", self);
        return 0;
    }
    return 1;
}

/* ---- starting Python in a process that has none ---- */

#define MINIMUM_PYTHON "3.10"
#define MINIMUM_PYTHON_TUPLE "3, 10"
#define HOWTO "Set HYDROFMU_PYTHON to a Python >= " MINIMUM_PYTHON " interpreter (or venv python) " \
    "that has numpy (and scipy for convolution memory) and a shared libpython (python3 -m sysconfig | grep INSTSONAME), or rebuild the FMU with one."

/*
 * Run in the new interpreter: sys._hydrofmu_check = '' when usable, else why not.  numpy
 * loads here, before any slave: one BLAS thread per process unless the host's environment
 * says otherwise (a host's parallelism is across FMUs; the slaves' products are 6x6-sized),
 * set for the scipy loaded later too (its own BLAS reads the same variables).
 */
static const char CHECK[] =
    "import os, sys\n"
    "for _n in ('OPENBLAS_NUM_THREADS', 'OMP_NUM_THREADS', 'MKL_NUM_THREADS'):\n"
    "    os.environ.setdefault(_n, '1')\n"
    "def _c():\n"
    "    v = '%d.%d.%d' % sys.version_info[:3]\n"
    "    if sys.version_info < (" MINIMUM_PYTHON_TUPLE "):\n"
    "        return 'Python %s at %s is older than " MINIMUM_PYTHON "' % (v, sys.executable)\n"
    "    try:\n"
    "        import numpy\n"
    "    except Exception as e:\n"
    "        return 'Python %s at %s (sys.prefix %s) cannot import numpy: %s: %s' % (\n"
    "            v, sys.executable, sys.prefix, type(e).__name__, e)\n"
    "    return ''\n"
    "sys._hydrofmu_check = _c()\n"
    "del _c, _n\n";

/*
 * What $HYDROFMU_PYTHON is asked: its libpython (the first candidate file that exists,
 * else the bare soname for the loader's search path) and its version.  The build
 * records the same (shim.py: python_record).
 */
static const char QUERY[] =
    "import os, sys, sysconfig as s\n"
    "d, names = s.get_config_var('LIBDIR') or '', [s.get_config_var(k) for k in ('INSTSONAME', 'LDLIBRARY')]\n"
    "c = [os.path.join(d, n) for n in names if n and '.so' in n]\n"
    "print(next((p for p in c if os.path.isfile(p)), names[0] or ''))\n"
    "print('%d.%d' % sys.version_info[:2])\n";

/* The interpreter to start: executable, libpython, version, and where they came from. */
typedef struct {
    char exe[4096], lib[4096], version[64], origin[4200];
} Interpreter;

static void chomp(char *s) {
    size_t n = strlen(s);
    while (n && (s[n - 1] == '\n' || s[n - 1] == '\r')) s[--n] = '\0';
}

/* Read resources/hydrofmu_python.txt (key=value lines) beside the shim's FMU folder. */
static int recorded_interpreter(Interpreter *py, const char *self) {
    char path[4200];
    const char *end = self + strlen(self);
    for (int up = 0; up < 3 && end > self; up++) /* strip /<id>.so, /linux64, /binaries */
        while (end > self && *--end != '/') {}
    snprintf(path, sizeof path, "%.*s/resources/hydrofmu_python.txt", (int)(end - self), self);
    snprintf(py->origin, sizeof py->origin, "recorded at build time in %s", path);
    FILE *f = fopen(path, "r");
    if (!f) {
        snprintf(inner_err, sizeof inner_err, "there is no Python in this process and %s cannot be read. %s",
                 path, HOWTO);
        return 0;
    }
    char line[4200];
    while (fgets(line, sizeof line, f)) {
        chomp(line);
        char *eq = strchr(line, '=');
        if (!eq) continue;
        *eq = '\0';
        if (!strcmp(line, "executable")) snprintf(py->exe, sizeof py->exe, "%s", eq + 1);
        if (!strcmp(line, "libpython")) snprintf(py->lib, sizeof py->lib, "%s", eq + 1);
        if (!strcmp(line, "version")) snprintf(py->version, sizeof py->version, "%s", eq + 1);
    }
    fclose(f);
    if (!py->exe[0] || !py->lib[0]) {
        snprintf(inner_err, sizeof inner_err, "there is no Python in this process and %s names no executable "
                 "and libpython. %s", path, HOWTO);
        return 0;
    }
    return 1;
}

/* Ask the interpreter named by $HYDROFMU_PYTHON for its libpython and version. */
static int asked_interpreter(Interpreter *py, const char *exe) {
    snprintf(py->exe, sizeof py->exe, "%s", exe);
    snprintf(py->origin, sizeof py->origin, "from HYDROFMU_PYTHON=%s", exe);
    /* single-quote the path for the shell: ' becomes '\'' */
    char cmd[4 * sizeof py->exe + 2 * sizeof QUERY + 64], *q = cmd; /* room for the worst escaping */
    q += sprintf(q, "'");
    for (const char *p = py->exe; *p; p++) q += *p == '\'' ? sprintf(q, "'\\''") : sprintf(q, "%c", *p);
    q += sprintf(q, "' -I -S -c \"");
    for (const char *p = QUERY; *p; p++) {
        if (*p == '"' || *p == '\\' || *p == '$' || *p == '`') *q++ = '\\';
        *q++ = *p;
    }
    sprintf(q, "\" 2>&1");
    FILE *f = popen(cmd, "r");
    int ok = f && fgets(py->lib, sizeof py->lib, f) && fgets(py->version, sizeof py->version, f);
    int rc = f ? pclose(f) : -1;
    chomp(py->lib);
    chomp(py->version);
    if (!ok || rc != 0 || !py->lib[0]) {
        snprintf(inner_err, sizeof inner_err,
                 "there is no Python in this process and HYDROFMU_PYTHON=%s could not be asked for its "
                 "libpython (%s%s). %s", exe, py->lib[0] ? "it said: " : "it did not run", py->lib, HOWTO);
        return 0;
    }
    return 1;
}

/* Load, initialise and check the interpreter; on return the GIL is released. */
static int start_interpreter(const Interpreter *pyp);

/*
 * Several FMUs (each its own copy of the shim, with its own statics) may start Python at
 * once from a host's threads.  They serialise on an flock of the libpython file: locks of
 * separate open() calls exclude each other, also within one process.  The one that gets
 * the lock first starts Python; the others then find it initialised.
 */
static int start_python(const char *self) {
    Interpreter py;
    memset(&py, 0, sizeof py);
    const char *env = getenv("HYDROFMU_PYTHON");
    if (env && *env ? !asked_interpreter(&py, env) : !recorded_interpreter(&py, self)) return 0;
    int lock = open(py.lib, O_RDONLY | O_CLOEXEC); /* a bare soname: no file to lock, no lock */
    if (lock >= 0)
        while (flock(lock, LOCK_EX) != 0 && errno == EINTR) {}
    int ok = start_interpreter(&py);
    if (lock >= 0) close(lock); /* releases the lock */
    return ok;
}

static int start_interpreter(const Interpreter *pyp) {
    const Interpreter py = *pyp;
    /* a libpython already loaded (and maybe initialised by another FMU) serves as it is */
    int loaded = dlsym(RTLD_DEFAULT, "Py_IsInitialized") != NULL;
    void *h = loaded ? RTLD_DEFAULT : dlopen(py.lib, RTLD_NOW | RTLD_GLOBAL);
    if (!loaded && !h) {
        const char *e = dlerror();
        snprintf(inner_err, sizeof inner_err,
                 "there is no Python in this process and the libpython of Python %s at %s (%s) cannot be "
                 "loaded: %s. %s", py.version, py.exe, py.origin, e ? e : "unknown error", HOWTO);
        return 0;
    }
    struct {
        int (*IsInitialized)(void);
        wchar_t *(*DecodeLocale)(const char *, size_t *);
        void (*SetProgramName)(const wchar_t *);
        void (*InitializeEx)(int);
        int (*RunSimpleString)(const char *);
        void *(*SysGetObject)(const char *);
        const char *(*AsUTF8)(void *);
        void *(*SaveThread)(void);
    } api;
    const char *names[] = {"Py_IsInitialized", "Py_DecodeLocale", "Py_SetProgramName", "Py_InitializeEx",
                           "PyRun_SimpleString", "PySys_GetObject", "PyUnicode_AsUTF8", "PyEval_SaveThread"};
    void **slots = (void **)&api; /* all members are pointers, in the order of names */
    for (size_t i = 0; i < sizeof names / sizeof *names; i++) {
        if (!(slots[i] = dlsym(h, names[i]))) {
            snprintf(inner_err, sizeof inner_err, "%s (libpython of Python %s at %s, %s) has no %s: not a "
                     "CPython >= " MINIMUM_PYTHON "? %s", py.lib, py.version, py.exe, py.origin, names[i], HOWTO);
            return 0;
        }
    }
    if (api.IsInitialized()) return 1; /* the host's own Python, loaded privately: used as it is */
    /* the program name makes Python find its prefix, venv and site-packages as when run;
       it must stay valid while Python runs: never freed */
    wchar_t *name = api.DecodeLocale(py.exe, NULL);
    if (name) api.SetProgramName(name);
    api.InitializeEx(0); /* 0: leave the host's signal handlers alone */
    api.RunSimpleString(CHECK);
    void *msg = api.SysGetObject("_hydrofmu_check");
    const char *text = msg ? api.AsUTF8(msg) : NULL;
    int ok = text && !*text;
    if (!ok)
        snprintf(inner_err, sizeof inner_err, "there is no Python in this process; started Python %s at %s "
                 "(%s, libpython %s), but %s. %s", py.version, py.exe, py.origin, py.lib,
                 text ? text : "its check did not run (not Python 3?)", HOWTO);
    api.SaveThread(); /* release the GIL: every call takes it, from whatever thread */
    return ok;
}

/*
 * Python's main thread: the thread that initialises Python must outlive every use of
 * it (when it ends, the C library frees memory the interpreter still refers to, and
 * the process later dies at exit), and a host may instantiate from a worker thread
 * that ends.  So a thread of the shim's own starts Python, then sleeps until the
 * process exits, with every signal blocked (they go to the host's threads).  The shim
 * is pinned in memory (RTLD_NODELETE) since that thread sleeps in its code.
 */
static struct {
    pthread_mutex_t lock;
    pthread_cond_t cond;
    const char *self;
    int done, ok;
} starter = {PTHREAD_MUTEX_INITIALIZER, PTHREAD_COND_INITIALIZER, NULL, 0, 0};

static void *python_main(void *arg) {
    (void)arg;
    sigset_t all;
    sigfillset(&all);
    pthread_sigmask(SIG_BLOCK, &all, NULL);
    int ok = start_python(starter.self);
    pthread_mutex_lock(&starter.lock);
    starter.ok = ok;
    starter.done = 1;
    pthread_cond_signal(&starter.cond);
    pthread_mutex_unlock(&starter.lock);
    for (;;) pause();
    return NULL;
}

/* Keep this library loaded until the process exits, whatever the host unloads. */
static void pin(void) {
    Dl_info info;
    if (!pinned && dladdr(&starter, &info) && info.dli_fname)
        pinned = dlopen(info.dli_fname, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE) != NULL;
}

static int python_in_own_thread(const char *self) {
    pin();
    starter.self = self;
    pthread_t t;
    if (pthread_create(&t, NULL, python_main, NULL) != 0) {
        snprintf(inner_err, sizeof inner_err, "cannot create a thread to start Python in");
        return 0;
    }
    pthread_detach(t);
    pthread_mutex_lock(&starter.lock);
    while (!starter.done) pthread_cond_wait(&starter.cond, &starter.lock);
    pthread_mutex_unlock(&starter.lock);
    return starter.ok;
}

/* The Python C API behind seen(); all NULL when one is missing (then nothing is pooled). */
static struct {
    void *(*SysGetObject)(const char *);
    int (*SysSetObject)(const char *, void *);
    void *(*SetNew)(void *);
    ptrdiff_t (*SetSize)(void *);
    int (*SetContains)(void *, void *);
    int (*SetAdd)(void *, void *);
    int (*SetClear)(void *);
    void *(*LongFromU64)(unsigned long long);
    void (*DecRef)(void *);
    void (*ErrClear)(void);
} py;

static void find_python_api(void) {
    const char *names[] = {"PySys_GetObject", "PySys_SetObject", "PySet_New", "PySet_Size", "PySet_Contains",
                           "PySet_Add", "PySet_Clear", "PyLong_FromUnsignedLongLong", "Py_DecRef", "PyErr_Clear"};
    void **slots = (void **)&py; /* all members are pointers, in the order of names */
    for (size_t i = 0; i < sizeof names / sizeof *names; i++)
        if (!(slots[i] = dlsym(RTLD_DEFAULT, names[i]))) {
            memset(&py, 0, sizeof py);
            return;
        }
}

/*
 * One Python thread state per host thread, for good.  PyGILState_Ensure on a thread Python
 * does not know creates a thread state and the matching PyGILState_Release deletes it again,
 * with the frame stack it allocated (an mmap/munmap pair and fresh pages): in a native host
 * every FMI call paid that, and more than the call itself for a cheap one.  So the first call
 * from such a thread creates a state and keeps it (PyGILState_Ensure, then PyEval_SaveThread:
 * the GIL is released, the state stays the thread's, its counter at 1 so that no later
 * Release deletes it); every call after only takes and gives the GIL.  Threads Python knows
 * (a Python host's) and threads whose state another FMU's shim keeps are left as they are.
 * When the thread ends, a thread-specific destructor deletes the state, unless Python is
 * gone or going.  The key is made on first use only (a process has ~1024, and fmpy loads a
 * new copy of the library for every instance) and deleted when the library unloads: the
 * states it kept then stay with their threads (later FMUs use them) until the process ends.
 */
static struct {
    void *(*ThisThreadState)(void);
    void *(*SaveThread)(void);
    void (*RestoreThread)(void *);
    void (*Clear)(void *);
    void (*DeleteCurrent)(void);
    int (*IsInitialized)(void);
    int (*IsFinalizing)(void);
} ts_api;
static pthread_key_t ts_key;
static int ts_key_ok;
static pthread_once_t ts_key_once = PTHREAD_ONCE_INIT;

/* At thread exit the C library has already cleared Python's own thread-specific pointer to
   the state (so no PyGILState_Release): the state is made current, cleared and deleted. */
static void drop_thread_state(void *state) {
    if (!state || !ts_api.DeleteCurrent || !ts_api.IsInitialized() ||
        (ts_api.IsFinalizing && ts_api.IsFinalizing()))
        return;
    ts_api.RestoreThread(state);
    ts_api.Clear(state);
    ts_api.DeleteCurrent(); /* and releases the GIL */
}

static void find_thread_state_api(void) {
    *(void **)&ts_api.ThisThreadState = dlsym(RTLD_DEFAULT, "PyGILState_GetThisThreadState");
    *(void **)&ts_api.SaveThread = dlsym(RTLD_DEFAULT, "PyEval_SaveThread");
    *(void **)&ts_api.RestoreThread = dlsym(RTLD_DEFAULT, "PyEval_RestoreThread");
    *(void **)&ts_api.Clear = dlsym(RTLD_DEFAULT, "PyThreadState_Clear");
    *(void **)&ts_api.DeleteCurrent = dlsym(RTLD_DEFAULT, "PyThreadState_DeleteCurrent");
    if (!ts_api.Clear) ts_api.DeleteCurrent = NULL; /* then a state is kept until the process ends */
    *(void **)&ts_api.IsInitialized = dlsym(RTLD_DEFAULT, "Py_IsInitialized");
    *(void **)&ts_api.IsFinalizing = dlsym(RTLD_DEFAULT, "Py_IsFinalizing"); /* 3.13 on */
    if (!ts_api.IsFinalizing) *(void **)&ts_api.IsFinalizing = dlsym(RTLD_DEFAULT, "_Py_IsFinalizing");
    if (!ts_api.ThisThreadState || !ts_api.SaveThread || !ts_api.RestoreThread || !ts_api.IsInitialized)
        memset(&ts_api, 0, sizeof ts_api);
}

static void make_ts_key(void) {
    ts_key_ok = pthread_key_create(&ts_key, drop_thread_state) == 0;
}

static void keep_thread_state(void) {
    kept = 1;
    if (!ts_api.ThisThreadState || ts_api.ThisThreadState()) return;
    pthread_once(&ts_key_once, make_ts_key);
    gil_ensure();
    void *state = ts_api.SaveThread();
    if (ts_key_ok) pthread_setspecific(ts_key, state); /* else kept until the process ends */
}

/*
 * pythonfmu 0.7 keeps its interpreter guard in a global shared_ptr that two things release
 * at exit: the C++ static destructor (run among the atexit handlers) and its exported
 * destructor function finalizePythonInterpreter (run after them, by the loader), which then
 * decrements the count in the freed block: whether a host dies at exit ("free(): corrupted
 * unsorted chunks") depends on what the heap holds there (a longer folder name made it
 * 8 runs in 10).  Its library is never unloaded (C++ unique symbols), so every process that
 * instantiated one exits through this.  The shim releases the guard itself first, from an
 * atexit handler registered after pythonfmu's static constructors (so it runs before their
 * destructors, or when the host unloads the shim): both later releases then find it empty.
 */
static void (*inner_release_guard)(void);

static void release_guard(void) {
    if (inner_release_guard) inner_release_guard();
    inner_release_guard = NULL;
}

static void load_inner(void) {
    char path[4096];
    if (!inner_path(path, sizeof path)) return;
    int (*initialized)(void);
    *(void **)&initialized = dlsym(RTLD_DEFAULT, "Py_IsInitialized");
    if (!(initialized && initialized()) && !python_in_own_thread(path)) return;
    const char *pool_env = getenv("HYDROFMU_POOL");
    no_pool = pool_env && !strcmp(pool_env, "0");
    find_python_api();
    *(void **)&gil_ensure = dlsym(RTLD_DEFAULT, "PyGILState_Ensure");
    *(void **)&gil_release = dlsym(RTLD_DEFAULT, "PyGILState_Release");
    if (!gil_release) gil_ensure = NULL;
    find_thread_state_api();
    void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!h) {
        const char *e = dlerror();
        snprintf(inner_err, sizeof inner_err, "cannot load %s: %s", path, e ? e : "unknown error");
        return;
    }
    /* Resolve all symbols; any one missing means the inner library is unusable. */
#define RESOLVE(name)                                                                     \
    *(void **)&inner.name = dlsym(h, "fmi2" #name);                                       \
    if (!inner.name) {                                                                    \
        snprintf(inner_err, sizeof inner_err, "%s does not export fmi2" #name, path);     \
        dlclose(h);                                                                       \
        memset(&inner, 0, sizeof inner);                                                  \
        return;                                                                           \
    }
#define RESOLVE_STATUS(name, params, args) RESOLVE(name)
#define RESOLVE_OTHER(ret, name, params) RESOLVE(name)
    FMI_STATUS_FUNCS(RESOLVE_STATUS)
    FMI_OTHER_FUNCS(RESOLVE_OTHER)
#undef RESOLVE_STATUS
#undef RESOLVE_OTHER
#undef RESOLVE
    inner_handle = h;
    inner_ok = 1;
    *(void **)&inner_release_guard = dlsym(h, "finalizePythonInterpreter"); /* pythonfmu 0.7; optional */
    if (inner_release_guard) atexit(release_guard);
}

static int ready(void) {
    pthread_once(&inner_once, load_inner);
    return inner_ok;
}

/* Unload the inner library together with the shim, as the host would have unloaded it. */
__attribute__((destructor)) static void unload_inner(void) {
    if (ts_key_ok) pthread_key_delete(ts_key); /* drop_thread_state goes with the library */
    ts_key_ok = 0;
    if (inner_handle) dlclose(inner_handle);
    inner_handle = NULL;
    inner_ok = 0;
}

/* ---- per-instance data ---- */

struct Shim;

/*
 * A pythonfmu component and what it was instantiated with.  `cb` (given to pythonfmu,
 * which keeps a copy) has this Slot as componentEnvironment, so its messages reach the
 * host instance holding the Slot now (`host`), or nobody while it waits in the pool.
 */
typedef struct Slot {
    fmi2Component inner;          /* pythonfmu's component */
    fmi2CallbackFunctions cb;     /* its callbacks: shim_logger, calloc/free, environment = this Slot */
    struct Shim *host;            /* the host instance using it; NULL while pooled */
    char *key;                    /* pythonfmu's fmi2Instantiate arguments (make_key) ... */
    size_t keylen;
    int again;                    /* ... seen before in this process: worth pooling */
    int dead;                     /* pythonfmu answered fmi2Fatal: never called again (below) */
    struct Slot *next;            /* next pooled Slot */
} Slot;

#define POOL_MAX 8 /* pooled Slots per loaded FMU; more are freed */
static struct {
    pthread_mutex_t lock;
    Slot *idle;
    int nidle;
} pool = {PTHREAD_MUTEX_INITIALIZER, NULL, 0};

/*
 * The host's handle.  Everything the host gave fmi2Instantiate that the logger
 * needs is copied here.  FMI 2.0 forbids concurrent calls on one instance, so no
 * lock is needed for the logging settings.
 */
typedef struct Shim {
    Slot *slot;                   /* the pythonfmu component in use */
    fmi2CallbackLogger logger;    /* the host's logger (may be NULL) ... */
    fmi2StepFinished stepFinished;
    fmi2ComponentEnvironment env; /* ... and its componentEnvironment */
    fmi2CallbackFreeMemory release; /* frees this struct and `cats`: host's freeMemory or free */
    void *(*alloc)(size_t, size_t); /* host's allocateMemory or calloc, paired with `release` */
    int logging;                  /* host's loggingOn */
    size_t ncat;                  /* host's categories; none = all */
    char **cats;                  /* one block: ncat pointers, then the strings */
    fmi2Status worst;             /* worst status logged during the current call */
    int stepped;                  /* a step succeeded since fmi2Instantiate or fmi2Reset */
} Shim;

/*
 * The status that tells the truth: pythonfmu 0.7 can only report a Python callback's
 * trouble as fmi2Fatal (an exception) or, for fmi2DoStep, as fmi2Discard.  hydrofmu's
 * slaves never raise: they log an error instead, and a call that logged an error
 * returns fmi2Error (never less).
 */
static fmi2Status truthful(const Shim *s, fmi2Status st) {
    return st < fmi2Error && s->worst >= fmi2Error ? fmi2Error : st;
}

/* Should a message of this status and category reach the host? */
static int wanted(const Shim *s, fmi2Status st, fmi2String cat) {
    if (st != fmi2OK) return 1; /* Warning, Discard, Error, Fatal: always */
    if (!s->logging) return 0;
    if (s->ncat == 0) return 1;
    for (size_t i = 0; i < s->ncat; i++)
        if (strcmp(s->cats[i], cat ? cat : "") == 0) return 1;
    return 0;
}

/*
 * The inner FMU's logger.  pythonfmu passes the message text as the format with
 * no arguments, so `msg` is literal text: any '%' is doubled before it goes to
 * the host, whose logger treats the message as a printf format.
 */
static void shim_logger(fmi2ComponentEnvironment e, fmi2String name, fmi2Status st,
                        fmi2String cat, fmi2String msg, ...) {
    static const char *by_status[] = {"logStatusOK", "logStatusWarning", "logStatusDiscard",
                                      "logStatusError", "logStatusFatal", "logStatusPending"};
    Shim *s = e ? ((Slot *)e)->host : NULL;
    if (s && st > s->worst && st <= fmi2Fatal) s->worst = st;
    /* never hand the host a NULL string (pythonfmu reports exceptions with no category) */
    if (!cat) cat = st >= fmi2OK && st <= fmi2Pending ? by_status[st] : "";
    if (!name) name = "";
    if (!msg) msg = "(no message)";
    if (!s || !s->logger || !wanted(s, st, cat)) return;
    size_t n = strlen(msg), k = 0;
    for (const char *p = strchr(msg, '%'); p; p = strchr(p + 1, '%')) k++;
    if (k == 0) {
        s->logger(s->env, name, st, cat, msg);
        return;
    }
    char small[1024];
    char *buf = n + k < sizeof small ? small : malloc(n + k + 1);
    if (!buf) {
        s->logger(s->env, name, st, cat, "(message lost: out of memory)");
        return;
    }
    char *q = buf;
    for (const char *p = msg; *p; p++) {
        *q++ = *p;
        if (*p == '%') *q++ = '%';
    }
    *q = '\0';
    s->logger(s->env, name, st, cat, buf);
    if (buf != small) free(buf);
}

static void shim_step_finished(fmi2ComponentEnvironment e, fmi2Status st) {
    const Shim *s = e ? ((Slot *)e)->host : NULL;
    if (s && s->stepFinished) s->stepFinished(s->env, st);
}

/*
 * fmi2Fatal from pythonfmu 0.7 means a Python exception reached it, and its handler has then
 * released the slave object, its class and its message list while keeping the pointers: a
 * later call would use freed objects and fmi2FreeInstance (or the fmi2Reset of the pool)
 * would release them a second time, corrupting the heap of the Python the host runs -- in a
 * Python host, a crash much later, anywhere.  hydrofmu's slaves never raise (slave.guarded,
 * slave.start), so this is a last defence: such a component is never called again, never
 * pooled and never freed (a few hundred bytes left behind).
 */
static fmi2Status after(Shim *s, fmi2Status st) {
    if (st == fmi2Fatal) s->slot->dead = 1;
    return truthful(s, st);
}

/* Can the component still be called?  If not, say why, once per call. */
static int usable(Shim *s) {
    if (!s->slot->dead) return 1;
    shim_logger(s->slot, "", fmi2Error, "logStatusError",
                "hydrofmu shim: this instance stopped at a fatal error; free it and instantiate again");
    return 0;
}

/* ---- plain forwarders: unwrap the Shim, call the inner function ---- */
#define FORWARD(name, params, args)                       \
    EXPORT fmi2Status fmi2##name params {                 \
        if (!ready() || !c) return fmi2Error;             \
        Shim *s_ = c;                                     \
        if (!usable(s_)) return fmi2Error;                \
        c = s_->slot->inner;                              \
        s_->worst = fmi2OK;                               \
        GIL_TAKE;                                         \
        fmi2Status st_ = inner.name args;                 \
        GIL_GIVE;                                         \
        return after(s_, st_);                            \
    }
FMI_STATUS_FUNCS(FORWARD)
#undef FORWARD

/* ---- the rest ---- */
/* Constants of the standard: answered without loading Python or the inner library. */
EXPORT const char *fmi2GetTypesPlatform(void) {
    return "default";
}

EXPORT const char *fmi2GetVersion(void) {
    return "2.0";
}

/* pythonfmu's fmi2Instantiate arguments as one block: name, GUID, resources, type, visible. */
static char *make_key(fmi2String name, fmi2Type type, fmi2String guid, fmi2String res,
                      fmi2Boolean visible, size_t *len) {
    const char *parts[] = {name ? name : "", guid ? guid : "", res ? res : ""};
    size_t n = 2;
    for (int i = 0; i < 3; i++) n += strlen(parts[i]) + 1;
    char *key = malloc(n), *q = key;
    if (!key) return NULL;
    for (int i = 0; i < 3; i++) q = stpcpy(q, parts[i]) + 1;
    *q++ = (char)('0' + type);
    *q = (char)(visible ? '1' : '0');
    *len = n;
    return key;
}

static uint64_t hash(const char *p, size_t n) { /* FNV-1a */
    uint64_t h = 1469598103934665603u;
    while (n--) h = (h ^ (unsigned char)*p++) * 1099511628211u;
    return h;
}

#define SEEN "_hydrofmu_shim_instances"
#define SEEN_MAX 1024

/*
 * Was an instance with this key instantiated before in this process (through any copy of
 * the shim, also one unloaded since)?  Notes the key.  Call with the GIL held.
 */
static int seen(const char *key, size_t len) {
    if (!py.DecRef) return 0;
    void *set = py.SysGetObject(SEEN); /* borrowed */
    if (!set || py.SetSize(set) < 0) {
        py.ErrClear();
        if (!(set = py.SetNew(NULL)) || py.SysSetObject(SEEN, set) < 0) {
            if (set) py.DecRef(set);
            py.ErrClear();
            return 0;
        }
        py.DecRef(set); /* sys holds it */
    }
    void *h = py.LongFromU64(hash(key, len));
    int found = h && py.SetContains(set, h) == 1;
    if (h && !found) {
        if (py.SetSize(set) >= SEEN_MAX) py.SetClear(set);
        py.SetAdd(set, h);
    }
    if (h) py.DecRef(h);
    py.ErrClear();
    return found;
}

/* A pooled Slot with this key, taken out of the pool; else NULL. */
static Slot *take(const char *key, size_t len) {
    pthread_mutex_lock(&pool.lock);
    Slot **p = &pool.idle;
    while (*p && ((*p)->keylen != len || memcmp((*p)->key, key, len))) p = &(*p)->next;
    Slot *slot = *p;
    if (slot) {
        *p = slot->next;
        pool.nidle--;
    }
    pthread_mutex_unlock(&pool.lock);
    return slot;
}

/*
 * Deliver the log messages pythonfmu still holds (a slave that logged in __init__, freed
 * before any other call) with a call that reads no variable: pythonfmu 0.7 crashes in
 * fmi2FreeInstance when messages are queued.  Call with the GIL held.
 */
static void flush(Slot *slot) {
    inner.GetReal(slot->inner, NULL, 0, NULL);
}

/* Free a Slot and its pythonfmu component (a dead one is left as it is: see after()). */
static void drop(Slot *slot) {
    if (slot->inner && !slot->dead) {
        GIL_TAKE;
        flush(slot);
        inner.FreeInstance(slot->inner);
        GIL_GIVE;
    }
    free(slot->key);
    free(slot);
}

/* A pooled Slot made ready for `s` by pythonfmu's fmi2Reset (a new Python slave); NULL if none. */
static Slot *reuse(Shim *s, const char *key, size_t len) {
    Slot *slot = take(key, len);
    if (!slot) return NULL;
    slot->host = s;
    s->worst = fmi2OK;
    GIL_TAKE;
    fmi2Status st = inner.Reset(slot->inner);
    if (st != fmi2Fatal) flush(slot); /* a slave that could not start says so in its log */
    GIL_GIVE;
    if (after(s, st) <= fmi2Warning) return slot;
    slot->host = NULL;
    drop(slot);
    return NULL;
}

EXPORT fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid,
                                     fmi2String res, const fmi2CallbackFunctions *cb,
                                     fmi2Boolean visible, fmi2Boolean logging) {
    fmi2CallbackLogger log = cb ? cb->logger : NULL;
    fmi2ComponentEnvironment env = cb ? cb->componentEnvironment : NULL;
    if (!ready()) {
        if (log) log(env, name ? name : "", fmi2Error, "logStatusError", "hydrofmu shim: %s", inner_err);
        return NULL;
    }
    /* the host's allocator when it gave both halves, else the C library's */
    int host_mem = cb && cb->allocateMemory && cb->freeMemory;
    void *(*alloc)(size_t, size_t) = host_mem ? cb->allocateMemory : calloc;
    Shim *s = alloc(1, sizeof *s);
    size_t len = 0;
    char *key = s ? make_key(name, type, guid, res, visible, &len) : NULL;
    if (!key) {
        if (s) (host_mem ? cb->freeMemory : free)(s);
        if (log) log(env, name ? name : "", fmi2Error, "logStatusError", "hydrofmu shim: out of memory");
        return NULL;
    }
    memset(s, 0, sizeof *s); /* allocateMemory must zero, but a host may not */
    s->logger = log;
    s->env = env;
    s->stepFinished = cb ? cb->stepFinished : NULL;
    s->alloc = alloc;
    s->release = host_mem ? cb->freeMemory : free;
    s->logging = logging != 0;
    s->slot = reuse(s, key, len);
    if (s->slot) {
        free(key);
        return s;
    }
    Slot *slot = calloc(1, sizeof *slot);
    if (!slot) {
        free(key);
        s->release(s);
        if (log) log(env, name ? name : "", fmi2Error, "logStatusError", "hydrofmu shim: out of memory");
        return NULL;
    }
    /* the members are const: build the struct, then copy it in */
    fmi2CallbackFunctions mine = {shim_logger, calloc, free, shim_step_finished, slot};
    memcpy(&slot->cb, &mine, sizeof mine);
    slot->key = key;
    slot->keylen = len;
    slot->host = s;
    s->slot = slot;
    /* inner logging always on: the filtering is done in shim_logger */
    GIL_TAKE;
    slot->again = seen(key, len);
    slot->inner = inner.Instantiate(name, type, guid, res, &slot->cb, visible, 1);
    if (slot->inner) flush(slot);
    GIL_GIVE;
    if (!slot->inner || s->worst >= fmi2Error) { /* a slave that could not start logged why */
        drop(slot);
        s->release(s);
        return NULL;
    }
    return s;
}

EXPORT void fmi2FreeInstance(fmi2Component c) {
    Shim *s = c;
    if (!s) return;
    Slot *slot = s->slot;
    if (ready()) { /* may still log: s stays valid until after */
        if (!slot->dead) {
            GIL_TAKE;
            flush(slot); /* to this host, also when the Slot is pooled */
            GIL_GIVE;
        }
        int keep = 0;
        if (slot->again && !no_pool && !slot->dead) {
            pin(); /* pooled components call back into this library */
            pthread_mutex_lock(&pool.lock);
            keep = pinned && pool.nidle < POOL_MAX;
            if (keep) {
                slot->host = NULL;
                slot->next = pool.idle;
                pool.idle = slot;
                pool.nidle++;
            }
            pthread_mutex_unlock(&pool.lock);
        }
        if (!keep) drop(slot);
    }
    if (s->cats) s->release(s->cats);
    s->release(s);
}

EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n,
                                      const fmi2String cat[]) {
    Shim *s = c;
    if (!ready() || !s) return fmi2Error;
    if (!on) n = 0;
    if (n && !cat) return fmi2Error;
    /* copy the categories into one block: n pointers, then the strings */
    char **cats = NULL;
    if (n) {
        size_t bytes = n * sizeof *cats;
        for (size_t i = 0; i < n; i++) bytes += strlen(cat[i] ? cat[i] : "") + 1;
        cats = s->alloc(1, bytes);
        if (!cats) {
            shim_logger(s, "", fmi2Error, "logStatusError", "hydrofmu shim: out of memory");
            return fmi2Error;
        }
        char *q = (char *)(cats + n);
        for (size_t i = 0; i < n; i++) {
            size_t len = strlen(cat[i] ? cat[i] : "") + 1;
            memcpy(q, cat[i] ? cat[i] : "", len);
            cats[i] = q;
            q += len;
        }
    }
    if (s->cats) s->release(s->cats);
    s->cats = cats;
    s->ncat = n;
    s->logging = on != 0;
    if (!usable(s)) return fmi2Error;
    GIL_TAKE;
    fmi2Status st = inner.SetDebugLogging(s->slot->inner, 1, 0, NULL);
    GIL_GIVE;
    return after(s, st);
}

EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noPrior) {
    if (!ready() || !c) return fmi2Error;
    Shim *sh = c;
    if (!usable(sh)) return fmi2Error;
    sh->worst = fmi2OK;
    GIL_TAKE;
    fmi2Status s = inner.DoStep(sh->slot->inner, t, h, noPrior);
    GIL_GIVE;
    sh->stepped |= s == fmi2OK || s == fmi2Discard; /* when pythonfmu records the time */
    return after(sh, s == fmi2Discard ? fmi2Error : s);
}

EXPORT fmi2Status fmi2Reset(fmi2Component c) {
    if (!ready() || !c) return fmi2Error;
    Shim *sh = c;
    if (!usable(sh)) return fmi2Error;
    sh->worst = fmi2OK;
    sh->stepped = 0;
    GIL_TAKE;
    fmi2Status s = inner.Reset(sh->slot->inner);
    if (s != fmi2Fatal) flush(sh->slot); /* a slave that could not start again says so */
    GIL_GIVE;
    return after(sh, s);
}

/*
 * pythonfmu keeps the last successful time through fmi2Reset, and so from a pooled
 * instance's last use: before a step it is NaN, as pythonfmu says for a new instance.
 */
EXPORT fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind k, fmi2Real *v) {
    if (!ready() || !c) return fmi2Error;
    Shim *sh = c;
    if (k == fmi2LastSuccessfulTime && !sh->stepped && v) {
        *v = NAN;
        return fmi2OK;
    }
    if (!usable(sh)) return fmi2Error;
    sh->worst = fmi2OK;
    GIL_TAKE;
    fmi2Status s = inner.GetRealStatus(sh->slot->inner, k, v);
    GIL_GIVE;
    return after(sh, s);
}
