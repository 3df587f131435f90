/*
 * A native libcosim host for the tests: no Python in the process.
 *
 *   cosim_run CONFIG STOP STEP OUTDIR
 *
 * CONFIG is an OspSystemStructure.xml or a .ssp file (libcosim's SSP loader; its
 * algorithm and step come from the file); STOP in seconds; STEP, in seconds, is the
 * fixed-step algorithm's step for an .ssp and must be 0 to take the file's; libcosim's
 * file observer writes one CSV per simulator into OUTDIR.  Exit 0 on success, else 1 with libcosim's error printed.
 * libcosim logs to the console from severity COSIM_LOG_LEVEL on (0 trace … 3 warning, the
 * default, … 5 fatal).
 * Declarations from libcosimc's cosim.h, written out so that only the library is needed.
 */
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct cosim_execution_s cosim_execution;
typedef struct cosim_observer_s cosim_observer;
cosim_execution *cosim_osp_config_execution_create(const char *path, bool start_defined, int64_t start);
cosim_execution *cosim_ssp_execution_create(const char *path, bool start_defined, int64_t start);
cosim_execution *cosim_ssp_fixed_step_execution_create(const char *path, bool start_defined, int64_t start,
                                                      int64_t step);
cosim_observer *cosim_file_observer_create(const char *dir);
int cosim_execution_add_observer(cosim_execution *e, cosim_observer *o);
int cosim_execution_simulate_until(cosim_execution *e, int64_t t);
int cosim_execution_destroy(cosim_execution *e);
int cosim_observer_destroy(cosim_observer *o);
const char *cosim_last_error_message(void);
int cosim_log_setup_simple_console_logging(void);
int cosim_log_set_output_level(int level);

static int fail(const char *what) {
    printf("%s failed: %s\n", what, cosim_last_error_message());
    return 1;
}

int main(int argc, char **argv) {
    if (argc != 5) {
        fprintf(stderr, "usage: %s CONFIG STOP STEP OUTDIR\n", argv[0]);
        return 2;
    }
    const char *config = argv[1];
    int64_t stop = (int64_t)(atof(argv[2]) * 1e9 + 0.5), step = (int64_t)(atof(argv[3]) * 1e9 + 0.5);
    cosim_log_setup_simple_console_logging();
    const char *level = getenv("COSIM_LOG_LEVEL");
    cosim_log_set_output_level(level ? atoi(level) : 3); /* default: warnings and errors */
    size_t n = strlen(config);
    int ssp = n > 4 && strcmp(config + n - 4, ".ssp") == 0;
    cosim_execution *ex = !ssp ? cosim_osp_config_execution_create(config, true, 0)
                          : step ? cosim_ssp_fixed_step_execution_create(config, true, 0, step)
                                 : cosim_ssp_execution_create(config, true, 0);
    if (!ex) return fail("create");
    cosim_observer *obs = cosim_file_observer_create(argv[4]);
    if (!obs || cosim_execution_add_observer(ex, obs) < 0) return fail("file observer");
    if (cosim_execution_simulate_until(ex, stop) < 0) return fail("simulate");
    cosim_execution_destroy(ex);
    cosim_observer_destroy(obs);
    return 0;
}
