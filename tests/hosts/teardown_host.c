/* A C host that embeds Python, for tests/test_teardown.py: the habits of OMSimulator's
 * Python API and of hosts that step from worker threads.
 *
 *   teardown_host LIBPYTHON FMU_DIR MODEL_IDENTIFIER GUID MODE
 *
 * LIBPYTHON is opened RTLD_GLOBAL and started (Py_InitializeEx(0); its home from
 * PYTHONHOME), as a host linked with it would; FMU_DIR is the unzipped FMU. MODE:
 *   finalize-first  instantiate, initialize, one step; Py_FinalizeEx; then a step (must
 *                   answer fmi2Error), fmi2Terminate (fmi2OK), fmi2FreeFMUstate of a
 *                   state taken before, fmi2FreeInstance, and a new fmi2Instantiate (NULL)
 *   thread          release the GIL; instantiate and initialize on the main thread, 50
 *                   steps on a second thread, 50 more on the main one; terminate, free,
 *                   take the GIL back and finalize
 * Prints one line per check and "done"; exits 0 when every check held, 1 otherwise. The
 * logger prints every message to stdout as "log STATUS MESSAGE". */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

static int failures;

#define CHECK(what, ok)                                     \
    do {                                                    \
        int ok_ = (ok);                                     \
        printf("%s %s\n", ok_ ? "ok" : "FAILED", (what));   \
        fflush(stdout);                                     \
        if (!ok_) failures++;                               \
    } while (0)

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    (void)env, (void)name, (void)category;
    va_list args;
    va_start(args, message);
    printf("log %d ", (int)status);
    vprintf(message, args);
    printf("\n");
    fflush(stdout);
    va_end(args);
}

typedef struct {
    fmi2InstantiateTYPE *instantiate;
    fmi2FreeInstanceTYPE *free_instance;
    fmi2SetupExperimentTYPE *setup;
    fmi2EnterInitializationModeTYPE *enter;
    fmi2ExitInitializationModeTYPE *exit_init;
    fmi2TerminateTYPE *terminate;
    fmi2DoStepTYPE *do_step;
    fmi2GetRealTYPE *get_real;
    fmi2GetFMUstateTYPE *get_state;
    fmi2FreeFMUstateTYPE *free_state;
} Api;

static Api api;
static fmi2Component instance;
static double t;

#define SYM(lib, field, name)                                       \
    do {                                                            \
        *(void **)(&api.field) = dlsym((lib), (name));              \
        if (!api.field) {                                           \
            fprintf(stderr, "no %s\n", (name));                     \
            exit(2);                                                \
        }                                                           \
    } while (0)

static void *steps(void *arg) {
    int *ok = arg;
    *ok = 1;
    for (int k = 0; k < 50; k++, t += 1e-3)
        if (api.do_step(instance, t, 1e-3, fmi2True) != fmi2OK) *ok = 0;
    return NULL;
}

int main(int argc, char **argv) {
    if (argc != 6) {
        fprintf(stderr, "usage: teardown_host LIBPYTHON FMU_DIR MODEL_IDENTIFIER GUID MODE\n");
        return 2;
    }
    const char *mode = argv[5];
    void *python = dlopen(argv[1], RTLD_NOW | RTLD_GLOBAL);
    if (!python) {
        fprintf(stderr, "%s\n", dlerror());
        return 2;
    }
    void (*initialize)(int);
    int (*finalize)(void);
    void *(*save_thread)(void);
    void (*restore_thread)(void *);
    *(void **)(&initialize) = dlsym(python, "Py_InitializeEx");
    *(void **)(&finalize) = dlsym(python, "Py_FinalizeEx");
    *(void **)(&save_thread) = dlsym(python, "PyEval_SaveThread");
    *(void **)(&restore_thread) = dlsym(python, "PyEval_RestoreThread");
    if (!initialize || !finalize || !save_thread || !restore_thread) return 2;
    initialize(0);

    char path[2048], uri[2048];
    snprintf(path, sizeof path, "%s/binaries/linux64/%s.so", argv[2], argv[3]);
    snprintf(uri, sizeof uri, "file://%s/resources", argv[2]);
    void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "%s\n", dlerror());
        return 2;
    }
    SYM(lib, instantiate, "fmi2Instantiate");
    SYM(lib, free_instance, "fmi2FreeInstance");
    SYM(lib, setup, "fmi2SetupExperiment");
    SYM(lib, enter, "fmi2EnterInitializationMode");
    SYM(lib, exit_init, "fmi2ExitInitializationMode");
    SYM(lib, terminate, "fmi2Terminate");
    SYM(lib, do_step, "fmi2DoStep");
    SYM(lib, get_real, "fmi2GetReal");
    SYM(lib, get_state, "fmi2GetFMUstate");
    SYM(lib, free_state, "fmi2FreeFMUstate");
    const fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};

    void *gil = strcmp(mode, "thread") == 0 ? save_thread() : NULL;
    instance = api.instantiate("teardown", fmi2CoSimulation, argv[4], uri, &callbacks, fmi2False,
                               fmi2True);
    CHECK("instantiate", instance != NULL);
    if (!instance) return 1;
    CHECK("setup", api.setup(instance, fmi2False, 0.0, 0.0, fmi2False, 0.0) == fmi2OK);
    CHECK("enter", api.enter(instance) == fmi2OK);
    CHECK("exit", api.exit_init(instance) == fmi2OK);
    CHECK("step", api.do_step(instance, t, 1e-3, fmi2True) == fmi2OK);
    t += 1e-3;

    if (strcmp(mode, "finalize-first") == 0) {
        fmi2FMUstate state = NULL;
        CHECK("get state", api.get_state(instance, &state) == fmi2OK);
        CHECK("finalize", finalize() == 0);
        CHECK("step after finalize: fmi2Error",
              api.do_step(instance, t, 1e-3, fmi2True) == fmi2Error);
        const fmi2ValueReference vr = 0;
        double x = 0.0;
        CHECK("getReal after finalize: fmi2Error",
              api.get_real(instance, &vr, 1, &x) == fmi2Error);
        CHECK("terminate after finalize: fmi2OK", api.terminate(instance) == fmi2OK);
        CHECK("free state after finalize", api.free_state(instance, &state) <= fmi2Warning &&
                                               state == NULL);
        api.free_instance(instance);
        fmi2Component again = api.instantiate("again", fmi2CoSimulation, argv[4], uri,
                                              &callbacks, fmi2False, fmi2True);
        CHECK("instantiate after finalize: NULL", again == NULL);
    } else if (strcmp(mode, "thread") == 0) {
        pthread_t worker;
        int ok = 0;
        CHECK("start thread", pthread_create(&worker, NULL, steps, &ok) == 0);
        pthread_join(worker, NULL);
        CHECK("50 steps on a second thread", ok);
        steps(&ok);
        CHECK("50 steps on the main thread", ok);
        CHECK("terminate", api.terminate(instance) == fmi2OK);
        api.free_instance(instance);
        restore_thread(gil);
        CHECK("finalize", finalize() == 0);
    } else {
        fprintf(stderr, "unknown mode %s\n", mode);
        return 2;
    }
    printf("done\n");
    return failures ? 1 : 0;
}
