/* The FMI 2.0 co-simulation shell of the project's C plants: the chain
 * (motorchain_c/fmu.c) and the flexible link (flexlink_c/fmu.c). One home for what they
 * share: the variables by value reference, the state machine's guards, messages in the
 * reference's words, the checks every Real parameter gets, the timing contract, the
 * trace file, FMU states and their serialization.
 *
 * A plant's fmu.c includes its physics and plant_variables.h (generated at build time:
 * names, types, causalities, start values, VR_<name> macros, the GUID), defines
 *   PLANT_STATE  the physics' type (part of an FMU state),
 *   PLANT_CACHE  its derived data's type (not part of an FMU state),
 *   PLANT_N      the size in the state envelope (masses, elements),
 * includes this file, and then defines the hooks declared below.
 *
 * Failure handling follows the project's convention: invalid parameters are
 * logged at exitInitializationMode and every later doStep answers fmi2Discard
 * with the same message; a bad step (non-finite input, step size <= 0,
 * communication point other than the FMU's time) is refused with fmi2Discard and
 * leaves the state untouched. A step under SMALLEST_STEP (a summing host's rounding
 * residue, e.g. 1e-13 s) is integrated exactly but takes no new sample: the measured
 * outputs and the means over a step keep their values. */
#ifndef PLANT_FMI_SHELL_H
#define PLANT_FMI_SHELL_H

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "fmu_envelope.h"

#define TEXT 2048
#define PATH 1024
/* LARGEST, SMALLEST_STEP, STEP_JITTER and FASTEST_RATE come with plant_variables.h,
 * from fmukit/checks.py (the same for every FMU). */

/* Everything an FMU state holds (copied whole by get/set/serialize). */
typedef struct {
    double v[N_VARS]; /* Real, Integer and Boolean values by value reference */
    char trace_file[PATH];
    double time;
    int time_known, initialized;
    char problems[TEXT];
    PLANT_STATE physics;
    int64_t cpr;
    double noise_std, theta_measured;
    uint64_t seed, sample;
} Core;

typedef struct {
    Core core;
    PLANT_CACHE *cache;
    FILE *trace;
    /* the host's logger, copied: the FMI 2.0 (2014) headers declare the members of
     * fmi2CallbackFunctions const, so a struct holding one cannot be assigned */
    fmi2CallbackLogger logger;
    fmi2ComponentEnvironment environment;
    char name[256];
    int logging;
    int mode; /* where the FMI 2.0 co-simulation state machine stands: one of MODE_* */
    double h_taken; /* the step last integrated (s): see STEP_JITTER */
} Plant;

/* The states of FMI 2.0's co-simulation state machine an instance can be in, as bits,
 * so that a call names the states it is allowed in (as Reference-FMUs do). A failed
 * exitInitializationMode leads to MODE_STEP like a good one: by the project's
 * convention every later doStep answers fmi2Discard with the refused parameters. */
enum {
    MODE_INSTANTIATED = 1,
    MODE_INITIALIZATION = 2,
    MODE_STEP = 4, /* stepComplete: initialized, stepping */
    MODE_TERMINATED = 8,
    MODE_ANY = 15
};

/* ---- messages ---- */

/* Python's repr of a float: shortest digits that read back the same, with ".0" on
 * integral values, so messages match the reference FMU word for word. */
static void repr_double(char *out, size_t size, double x) {
    if (isnan(x)) {
        snprintf(out, size, "nan");
        return;
    }
    if (isinf(x)) {
        snprintf(out, size, x > 0 ? "inf" : "-inf");
        return;
    }
    int digits = 1;
    for (; digits < 17; digits++) {
        snprintf(out, size, "%.*e", digits - 1, x);
        if (strtod(out, NULL) == x) break;
    }
    snprintf(out, size, "%.*e", digits - 1, x);
    int exponent = atoi(strchr(out, 'e') + 1);
    if (exponent < -4 || exponent >= 16) return; /* Python's switch to 1e-05, 1e+16 */
    int decimals = digits - 1 - exponent;
    snprintf(out, size, "%.*f", decimals > 0 ? decimals : 0, x);
    if (decimals <= 0) strncat(out, ".0", size - strlen(out) - 1);
}

static void log_message(Plant *p, fmi2Status status, const char *format, ...) {
    if (!p->logging || p->logger == NULL) return;
    static const char *const category[] = {"logAll", "logStatusWarning", "logStatusDiscard",
                                           "logStatusError", "logStatusFatal", "logAll"};
    char text[TEXT + 512];
    int used = snprintf(text, sizeof text, "%s: ", p->name);
    va_list args;
    va_start(args, format);
    vsnprintf(text + used, sizeof text - used, format, args);
    va_end(args);
    /* the logger formats its message with printf rules: pass % through literally */
    char escaped[2 * sizeof text];
    size_t j = 0;
    for (size_t i = 0; text[i] && j + 2 < sizeof escaped; i++) {
        if (text[i] == '%') escaped[j++] = '%';
        escaped[j++] = text[i];
    }
    escaped[j] = '\0';
    p->logger(p->environment, p->name, status, category[status <= fmi2Pending ? status : 0],
              escaped);
}

static void add_problem(Core *c, const char *format, ...) {
    size_t used = strlen(c->problems);
    if (used) used += (size_t)snprintf(c->problems + used, TEXT - used, "; ");
    if (used >= TEXT) return;
    va_list args;
    va_start(args, format);
    vsnprintf(c->problems + used, TEXT - used, format, args);
    va_end(args);
}

/* ---- parameters ---- */

static void check_range(Core *c, int vr, int count, int positive) {
    for (int i = 0; i < count; i++) {
        double x = c->v[vr + i];
        char num[64];
        repr_double(num, sizeof num, x);
        if (!isfinite(x))
            add_problem(c, "parameter %s = %s is not a finite number", VAR_NAME[vr + i], num);
        else if (positive ? !(x > 0.0) : !(x >= 0.0))
            add_problem(c, "parameter %s = %s must be %s", VAR_NAME[vr + i], num,
                        positive ? "> 0" : ">= 0");
    }
}

/* The reference's FmuSlave._number_problems: every Real parameter a finite number
 * within ±LARGEST. Returns the number of problems. */
static int check_numbers(Core *c) {
    int found = 0;
    for (int vr = 0; vr < N_VARS; vr++) {
        if (VAR_CAUSALITY[vr] != C_PARAMETER || VAR_TYPE[vr] != T_REAL) continue;
        double x = c->v[vr];
        char num[64];
        repr_double(num, sizeof num, x);
        if (!isfinite(x)) {
            add_problem(c, "parameter %s = %s is not a finite number", VAR_NAME[vr], num);
            found++;
        } else if (fabs(x) > LARGEST) {
            add_problem(c,
                        "parameter %s = %s is beyond \302\261%g, the range the FMU computes "
                        "in (SI units)",
                        VAR_NAME[vr], num, LARGEST);
            found++;
        }
    }
    return found;
}

/* ---- the plant's hooks (defined by its fmu.c after this file) ---- */

/* The parameters' checks after check_numbers, each problem by add_problem. */
static void check_parameters(Core *c);
/* The physics from the parameters, and the outputs at the start time. */
static void initialize(Core *c);
/* The outputs after a step of h (s); h <= 0: the sample at the start time. */
static void write_outputs(Core *c, double h);
/* The outputs that are the state itself (after a step too short for a sample). */
static void write_true_outputs(Core *c);
/* Integrate the physics over h (s) with the inputs in c->v; 0, or -1 if it failed. */
static int plant_advance(Core *c, PLANT_CACHE *cache, double h);
/* Forget the derived data (after the parameters or the state changed). */
static void plant_cache_clear(PLANT_CACHE *cache);

/* ---- trace file ---- */

static void write_trace(Plant *p) {
    char num[64];
    repr_double(num, sizeof num, p->core.time_known ? p->core.time : 0.0);
    fputs(num, p->trace);
    for (int vr = 0; vr < N_VARS; vr++)
        if (VAR_CAUSALITY[vr] == C_OUTPUT) {
            repr_double(num, sizeof num, p->core.v[vr]);
            fputc(',', p->trace);
            fputs(num, p->trace);
        }
    fputc('\n', p->trace);
    fflush(p->trace);
}

static void open_trace(Plant *p) {
    const char *path = p->core.trace_file;
    if (!path[0]) return;
    FILE *f = fopen(path, "r");
    if (f) {
        fclose(f);
        add_problem(&p->core, "trace_file '%s' exists; choose a new name (it is never overwritten)",
                    path);
        return;
    }
    p->trace = fopen(path, "wx");
    if (!p->trace) {
        add_problem(&p->core, "trace_file '%s' cannot be written", path);
        return;
    }
    fputs("time", p->trace);
    for (int vr = 0; vr < N_VARS; vr++)
        if (VAR_CAUSALITY[vr] == C_OUTPUT) fprintf(p->trace, ",%s", VAR_NAME[vr]);
    fputc('\n', p->trace);
    write_trace(p);
}

/* ---- FMI: guards ---- */

static const char *mode_name(int mode) {
    switch (mode) {
    case MODE_INSTANTIATED: return "instantiated (before fmi2EnterInitializationMode)";
    case MODE_INITIALIZATION: return "initialization mode";
    case MODE_STEP: return "initialized (stepping)";
    default: return "terminated";
    }
}

/* Whether `call` may run now: never on a NULL instance (fmi2Error, nothing to log
 * through); in a state outside `modes` it is logged and answers fmi2Error. */
static int allowed(Plant *p, int modes, const char *call) {
    if (!p) return 0;
    if (p->mode & modes) return 1;
    log_message(p, fmi2Error, "%s is not allowed when the FMU is %s (FMI 2.0 co-simulation "
                "state machine); call refused, nothing changed", call, mode_name(p->mode));
    return 0;
}

/* A NULL array with a nonzero length, or a NULL result pointer: logged, fmi2Error. */
static int given(Plant *p, const void *pointer, const char *what, const char *call) {
    if (pointer) return 1;
    log_message(p, fmi2Error, "%s: %s is NULL; call refused", call, what);
    return 0;
}

#define BEGIN(c, modes)                      \
    Plant *p = (Plant *)(c);                 \
    if (!allowed(p, (modes), __func__)) return fmi2Error

/* ---- FMI: instance life cycle ---- */

static void reset_core(Core *c) {
    memset(c, 0, sizeof *c);
    for (int vr = 0; vr < N_VARS; vr++) c->v[vr] = VAR_START[vr];
}

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }

const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                              fmi2Boolean loggingOn) {
    (void)fmuResourceLocation;
    (void)visible;
    Plant probe = {0};
    if (functions) {
        probe.logger = functions->logger;
        probe.environment = functions->componentEnvironment;
    }
    snprintf(probe.name, sizeof probe.name, "%s", instanceName ? instanceName : "plant");
    probe.logging = 1;
    if (fmuType != fmi2CoSimulation) {
        log_message(&probe, fmi2Error, "this FMU supports co-simulation only");
        return NULL;
    }
    if (!fmuGUID || strcmp(fmuGUID, MODEL_GUID) != 0) {
        log_message(&probe, fmi2Error, "GUID %s does not match this binary's %s",
                    fmuGUID ? fmuGUID : "(null)", MODEL_GUID);
        return NULL;
    }
    Plant *p = calloc(1, sizeof *p);
    PLANT_CACHE *cache = calloc(1, sizeof *cache);
    if (!p || !cache) {
        free(p);
        free(cache);
        log_message(&probe, fmi2Error, "out of memory");
        return NULL;
    }
    *p = probe;
    p->logging = loggingOn;
    p->cache = cache;
    p->mode = MODE_INSTANTIATED;
    reset_core(&p->core);
    return p;
}

void fmi2FreeInstance(fmi2Component c) {
    Plant *p = c;
    if (!p) return;
    if (p->trace) fclose(p->trace);
    free(p->cache);
    free(p);
}

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t n,
                               const fmi2String categories[]) {
    (void)n;
    (void)categories;
    BEGIN(c, MODE_ANY);
    p->logging = loggingOn;
    return fmi2OK;
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined,
                               fmi2Real stopTime) {
    (void)toleranceDefined;
    (void)tolerance;
    (void)stopTimeDefined;
    (void)stopTime;
    BEGIN(c, MODE_INSTANTIATED);
    p->core.time = startTime;
    p->core.time_known = 1;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    BEGIN(c, MODE_INSTANTIATED);
    p->mode = MODE_INITIALIZATION;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    BEGIN(c, MODE_INITIALIZATION);
    Core *core = &p->core;
    p->mode = MODE_STEP;
    core->problems[0] = '\0';
    check_parameters(core);
    if (!core->problems[0]) {
        initialize(core);
        plant_cache_clear(p->cache);
        open_trace(p);
    }
    core->initialized = 1;
    if (core->problems[0]) {
        log_message(p, fmi2Error, "%s", core->problems);
        return fmi2Error;
    }
    return fmi2OK;
}

static void close_trace(Plant *p) {
    if (p->trace) {
        fclose(p->trace);
        p->trace = NULL;
    }
}

fmi2Status fmi2Terminate(fmi2Component c) {
    BEGIN(c, MODE_STEP);
    close_trace(p);
    p->mode = MODE_TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c) {
    BEGIN(c, MODE_ANY);
    close_trace(p);
    reset_core(&p->core);
    plant_cache_clear(p->cache);
    p->mode = MODE_INSTANTIATED;
    return fmi2OK;
}

/* ---- FMI: stepping ---- */

static int step_problem(Plant *p, double t, double h) {
    Core *c = &p->core;
    char a[64], b[64];
    if (!(isfinite(h) && h > 0.0)) {
        repr_double(a, sizeof a, h);
        log_message(p, fmi2Discard, "step size %s s refused: it must be a finite number > 0", a);
        return 1;
    }
    if (!isfinite(t)) {
        repr_double(a, sizeof a, t);
        log_message(p, fmi2Discard, "communication point %s s refused: it must be finite", a);
        return 1;
    }
    if (c->time_known && fabs(t - c->time) > 1e-9 * fmax(1.0, fabs(t))) {
        repr_double(a, sizeof a, t);
        repr_double(b, sizeof b, c->time);
        log_message(p, fmi2Discard,
                    "communication point %s s refused: the FMU is at t = %s s (restore a saved "
                    "FMU state to step from another time)",
                    a, b);
        return 1;
    }
    for (int vr = 0; vr < N_VARS; vr++)
        if (VAR_CAUSALITY[vr] == C_INPUT && !isfinite(c->v[vr])) {
            repr_double(a, sizeof a, c->v[vr]);
            log_message(p, fmi2Discard, "input %s = %s is not finite; step refused",
                        VAR_NAME[vr], a);
            return 1;
        } else if (VAR_CAUSALITY[vr] == C_INPUT && fabs(c->v[vr]) > LARGEST) {
            repr_double(a, sizeof a, c->v[vr]);
            log_message(p, fmi2Discard,
                        "input %s = %s is beyond \302\261%g (SI units); step refused",
                        VAR_NAME[vr], a, LARGEST);
            return 1;
        }
    return 0;
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noSetPrior) {
    (void)noSetPrior;
    /* before initialization: fmi2Discard with the project's message (below) */
    BEGIN(c, MODE_INSTANTIATED | MODE_INITIALIZATION | MODE_STEP);
    Core *core = &p->core;
    if (!core->initialized) {
        log_message(p, fmi2Discard,
                    "doStep called before initialization finished; call "
                    "fmi2EnterInitializationMode and fmi2ExitInitializationMode first");
        return fmi2Discard;
    }
    if (core->problems[0]) {
        log_message(p, fmi2Discard, "cannot step: %s", core->problems);
        return fmi2Discard;
    }
    if (step_problem(p, t, h)) return fmi2Discard;
    /* a step within STEP_JITTER of the last is that step (a host's clock rounding) */
    if (fabs(h - p->h_taken) > STEP_JITTER * p->h_taken) p->h_taken = h;
    double t_end = t + h;
    h = p->h_taken;
    PLANT_STATE saved = core->physics;
    if (plant_advance(core, p->cache, h)) {
        core->physics = saved;
        log_message(p, fmi2Discard,
                    "internal error, step refused: the state is no longer finite (check the "
                    "parameters and inputs)");
        return fmi2Discard;
    }
    double outputs[N_VARS];
    memcpy(outputs, core->v, sizeof outputs);
    double theta_measured = core->theta_measured;
    uint64_t sample = core->sample;
    if (h < SMALLEST_STEP) { /* a host's rounding residue: the plant moves, no new sample */
        write_true_outputs(core);
    } else {
        core->sample++;
        write_outputs(core, h);
    }
    for (int vr = 0; vr < N_VARS; vr++)
        if (VAR_CAUSALITY[vr] == C_OUTPUT && !isfinite(core->v[vr])) {
            char a[64], b[64];
            repr_double(a, sizeof a, t);
            repr_double(b, sizeof b, h);
            log_message(p, fmi2Discard,
                        "the step from t = %s s by %s s gave a non-finite %s; step refused, "
                        "the state is as it was",
                        a, b, VAR_NAME[vr]);
            core->physics = saved;
            memcpy(core->v, outputs, sizeof outputs);
            core->theta_measured = theta_measured;
            core->sample = sample;
            return fmi2Discard;
        }
    core->time = t_end;
    core->time_known = 1;
    if (p->trace) write_trace(p);
    return fmi2OK;
}

fmi2Status fmi2CancelStep(fmi2Component c) {
    BEGIN(c, MODE_ANY);
    log_message(p, fmi2Error, "fmi2CancelStep: doStep never runs asynchronously");
    return fmi2Error;
}

/* ---- FMI: values ---- */

static const char *const TYPE_NAME[] = {"Real", "Integer", "Boolean", "String"};

static fmi2Status check_refs(Plant *p, const fmi2ValueReference vr[], size_t n, int type,
                             const char *call) {
    for (size_t i = 0; i < n; i++)
        if (vr[i] >= N_VARS || VAR_TYPE[vr[i]] != type) {
            log_message(p, fmi2Error, "%s%s: value reference %u is not a %s variable", call,
                        TYPE_NAME[type], vr[i], TYPE_NAME[type]);
            return fmi2Error;
        }
    return fmi2OK;
}

#define GETTABLE (MODE_INITIALIZATION | MODE_STEP | MODE_TERMINATED)
#define SETTABLE (MODE_INSTANTIATED | MODE_INITIALIZATION | MODE_STEP)

static fmi2Status get_numbers(Plant *p, const fmi2ValueReference vr[], size_t n, int type,
                              double *reals, int *ints, const char *call) {
    if (!allowed(p, GETTABLE, call)) return fmi2Error;
    if (n == 0) return fmi2OK;
    if (!given(p, vr, "vr", call) || !given(p, reals ? (void *)reals : (void *)ints, "value", call))
        return fmi2Error;
    if (check_refs(p, vr, n, type, "get") != fmi2OK) return fmi2Error;
    for (size_t i = 0; i < n; i++) {
        double x = p->core.v[vr[i]];
        if (reals)
            reals[i] = x;
        else
            ints[i] = (int)x;
    }
    return fmi2OK;
}

/* Whether a value may be set now; logs and returns the status when it may not. */
static fmi2Status settable(Plant *p, fmi2ValueReference vr) {
    if (VAR_CAUSALITY[vr] == C_OUTPUT) {
        log_message(p, fmi2Warning, "%s is an output and cannot be set; ignored", VAR_NAME[vr]);
        return fmi2Warning;
    }
    if (p->core.initialized && VAR_CAUSALITY[vr] == C_PARAMETER) {
        log_message(p, fmi2Warning,
                    "parameter %s is fixed after initialization; the new value is ignored (set "
                    "it before exitInitializationMode)",
                    VAR_NAME[vr]);
        return fmi2Warning;
    }
    return fmi2OK;
}

static fmi2Status set_numbers(Plant *p, const fmi2ValueReference vr[], size_t n, int type,
                              const double *reals, const int *ints, const char *call) {
    if (!allowed(p, SETTABLE, call)) return fmi2Error;
    if (n == 0) return fmi2OK;
    if (!given(p, vr, "vr", call) ||
        !given(p, reals ? (const void *)reals : (const void *)ints, "value", call))
        return fmi2Error;
    if (check_refs(p, vr, n, type, "set") != fmi2OK) return fmi2Error;
    fmi2Status status = fmi2OK;
    for (size_t i = 0; i < n; i++) {
        fmi2Status s = settable(p, vr[i]);
        if (s != fmi2OK) {
            status = s;
            continue;
        }
        double x = reals ? reals[i] : (double)ints[i];
        p->core.v[vr[i]] = type == T_BOOLEAN ? (x != 0.0) : x;
    }
    return status;
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                       fmi2Real value[]) {
    return get_numbers(c, vr, n, T_REAL, value, NULL, __func__);
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                          fmi2Integer value[]) {
    return get_numbers(c, vr, n, T_INTEGER, NULL, value, __func__);
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                          fmi2Boolean value[]) {
    return get_numbers(c, vr, n, T_BOOLEAN, NULL, value, __func__);
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                         fmi2String value[]) {
    BEGIN(c, GETTABLE);
    if (n == 0) return fmi2OK;
    if (!given(p, vr, "vr", __func__) || !given(p, value, "value", __func__)) return fmi2Error;
    if (check_refs(p, vr, n, T_STRING, "get") != fmi2OK) return fmi2Error;
    for (size_t i = 0; i < n; i++) value[i] = p->core.trace_file; /* the only String */
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                       const fmi2Real value[]) {
    return set_numbers(c, vr, n, T_REAL, value, NULL, __func__);
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                          const fmi2Integer value[]) {
    return set_numbers(c, vr, n, T_INTEGER, NULL, value, __func__);
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                          const fmi2Boolean value[]) {
    return set_numbers(c, vr, n, T_BOOLEAN, NULL, value, __func__);
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                         const fmi2String value[]) {
    BEGIN(c, SETTABLE);
    if (n == 0) return fmi2OK;
    if (!given(p, vr, "vr", __func__) || !given(p, value, "value", __func__)) return fmi2Error;
    if (check_refs(p, vr, n, T_STRING, "set") != fmi2OK) return fmi2Error;
    fmi2Status status = fmi2OK;
    for (size_t i = 0; i < n; i++) {
        fmi2Status s = settable(p, vr[i]);
        if (s != fmi2OK) {
            status = s;
            continue;
        }
        const char *text = value[i] ? value[i] : "";
        if (strlen(text) >= PATH) {
            log_message(p, fmi2Error, "%s: path longer than %d characters", VAR_NAME[vr[i]],
                        PATH - 1);
            return fmi2Error;
        }
        strcpy(p->core.trace_file, text);
    }
    return status;
}

/* ---- FMI: FMU state ---- */

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *state) {
    BEGIN(c, MODE_ANY);
    if (!given(p, state, "state", __func__)) return fmi2Error;
    Core *copy = *state ? (Core *)*state : malloc(sizeof(Core));
    if (!copy) return fmi2Error;
    *copy = p->core;
    *state = copy;
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state) {
    BEGIN(c, MODE_ANY);
    if (!given(p, state, "state", __func__)) return fmi2Error;
    p->core = *(const Core *)state;
    if (p->mode != MODE_TERMINATED)
        p->mode = p->core.initialized ? MODE_STEP : MODE_INSTANTIATED;
    plant_cache_clear(p->cache); /* derived data: rebuilt on demand */
    return fmi2OK;
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *state) {
    BEGIN(c, MODE_ANY);
    if (!given(p, state, "state", __func__)) return fmi2Error;
    free(*state);
    *state = NULL;
    return fmi2OK;
}

/* A serialized state is the Core in the envelope every arcosim FMU uses
 * (fmu_envelope.h); this FMU's flags are 0. */
static const char IDENTITY[] = MODEL_IDENTIFIER " " MODEL_GUID " " PLANT_BUILD;
#define IDENTITY_LENGTH (sizeof IDENTITY - 1)
#define SERIALIZED (ENVELOPE_OVERHEAD(IDENTITY_LENGTH) + sizeof(Core))

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate state, size_t *size) {
    BEGIN(c, MODE_ANY);
    if (!given(p, state, "state", __func__) || !given(p, size, "size", __func__))
        return fmi2Error;
    *size = SERIALIZED;
    return fmi2OK;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate state, fmi2Byte bytes[],
                                 size_t size) {
    BEGIN(c, MODE_ANY);
    if (!given(p, state, "state", __func__) || !given(p, bytes, "bytes", __func__))
        return fmi2Error;
    if (size != SERIALIZED) {
        log_message(p, fmi2Error, "serializeFMUstate: %zu bytes given, %zu needed (ask "
                    "fmi2SerializedFMUstateSize)", size, (size_t)SERIALIZED);
        return fmi2Error;
    }
    const Core *core = state;
    unsigned char *out = (unsigned char *)bytes;
    envelope_open(out, 0, core->time, PLANT_N, IDENTITY, IDENTITY_LENGTH, sizeof(Core));
    memcpy(envelope_payload(out, IDENTITY_LENGTH), core, sizeof(Core));
    envelope_seal(out, SERIALIZED);
    return fmi2OK;
}

static fmi2Status refuse(Plant *p, const char *why) {
    log_message(p, fmi2Error, "fmi2DeSerializeFMUstate refused: %s; nothing was changed", why);
    return fmi2Error;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte bytes[], size_t size,
                                   fmi2FMUstate *state) {
    BEGIN(c, MODE_ANY);
    if (!given(p, bytes, "bytes", __func__) || !given(p, state, "state", __func__))
        return fmi2Error;
    char why[TEXT];
    const unsigned char *payload;
    uint64_t payload_length;
    uint32_t flags;
    double time;
    if (envelope_check((const unsigned char *)bytes, size, IDENTITY, IDENTITY_LENGTH, PLANT_N,
                       why, sizeof why, &payload, &payload_length, &flags, &time))
        return refuse(p, why);
    if (payload_length != sizeof(Core)) {
        snprintf(why, sizeof why, "its payload has %llu bytes, a state of this FMU %zu",
                 (unsigned long long)payload_length, sizeof(Core));
        return refuse(p, why);
    }
    Core *copy = *state ? (Core *)*state : malloc(sizeof(Core));
    if (!copy) return fmi2Error;
    memcpy(copy, payload, sizeof(Core));
    *state = copy;
    return fmi2OK;
}

/* ---- FMI: not supported ---- */

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                        const fmi2ValueReference z[], size_t nz,
                                        const fmi2Real du[], fmi2Real dz[]) {
    (void)u, (void)nu, (void)z, (void)nz, (void)du, (void)dz;
    BEGIN(c, MODE_ANY);
    log_message(p, fmi2Error, "directional derivatives are not provided");
    return fmi2Error;
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    (void)vr, (void)n, (void)order, (void)value;
    BEGIN(c, MODE_ANY);
    log_message(p, fmi2Error, "input derivatives are not supported (canInterpolateInputs=false)");
    return fmi2Error;
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                        size_t n, const fmi2Integer order[], fmi2Real value[]) {
    (void)vr, (void)n, (void)order, (void)value;
    BEGIN(c, MODE_ANY);
    log_message(p, fmi2Error, "output derivatives are not provided");
    return fmi2Error;
}

#define STATUS_MODES (MODE_STEP | MODE_TERMINATED)

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) {
    (void)s, (void)value;
    BEGIN(c, STATUS_MODES);
    return fmi2Discard; /* doStep never runs asynchronously */
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value) {
    BEGIN(c, STATUS_MODES);
    if (!given(p, value, "value", __func__)) return fmi2Error;
    if (s != fmi2LastSuccessfulTime) return fmi2Discard;
    *value = p->core.time;
    return fmi2OK;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value) {
    (void)s, (void)value;
    BEGIN(c, STATUS_MODES);
    return fmi2Discard;
}

/* fmi2Terminated: true exactly when the parameters were refused at
 * exitInitializationMode (every doStep is refused until fmi2Reset or a restored state);
 * a refused step leaves the state unchanged and the master may retry: false. The
 * Python FMUs answer the same (cosim/build/native/fmu_trampoline.c). */
fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value) {
    BEGIN(c, STATUS_MODES);
    if (!given(p, value, "value", __func__)) return fmi2Error;
    if (s != fmi2Terminated) return fmi2Discard;
    *value = p->core.initialized && p->core.problems[0] ? fmi2True : fmi2False;
    return fmi2OK;
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value) {
    (void)s, (void)value;
    BEGIN(c, STATUS_MODES);
    return fmi2Discard;
}

#endif
