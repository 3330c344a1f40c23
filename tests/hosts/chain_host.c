/* A minimal FMI 2.0 co-simulation host in C (no Python anywhere), for
 * tests/test_portable_hosts.py: loads unzipped FMUs with dlopen, runs them with the
 * Jacobi schedule of arcosim.host.ssp.run_ssp and writes every requested output at every
 * communication point, then reports whether loading changed the process environment
 * and which libpython files are mapped.
 *
 *   chain_host SPEC OUT
 *
 * SPEC, one item a line:
 *   fmu NAME DIR MODEL_IDENTIFIER GUID      (DIR: the unzipped FMU)
 *   real|int|bool NAME VR VALUE             (a parameter, set before initialization)
 *   string NAME VR VALUE...                 (the rest of the line)
 *   link A VR_OUT B VR_IN                   (Real output of A to Real input of B)
 *   out NAME VR r|b|i                       (an output to record: Real, Boolean or Integer)
 *   run STOP H
 *   sum                                     (optional: sum the time, t += h, as many hosts
 *                                            do; the last step is min(h, STOP - t))
 * OUT: a line per communication point, t then the outputs in "out" order (%.17g);
 * then "environ same|changed", "libpython PATH" lines, "status OK".
 * With CHAIN_HOST_LOCAL_LIBPYTHON=path the host first dlopen()s that libpython with
 * RTLD_LOCAL and does not start it (a host embedding Python privately). */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

extern char **environ;

#define MAX_FMUS 8
#define MAX_ITEMS 512

typedef struct {
    char name[64], dir[1024], id[256], guid[128];
    void *lib;
    fmi2Component c;
    fmi2InstantiateTYPE *instantiate;
    fmi2FreeInstanceTYPE *free_instance;
    fmi2SetupExperimentTYPE *setup;
    fmi2EnterInitializationModeTYPE *enter;
    fmi2ExitInitializationModeTYPE *exit_init;
    fmi2TerminateTYPE *terminate;
    fmi2SetRealTYPE *set_real;
    fmi2SetIntegerTYPE *set_int;
    fmi2SetBooleanTYPE *set_bool;
    fmi2SetStringTYPE *set_string;
    fmi2GetRealTYPE *get_real;
    fmi2GetBooleanTYPE *get_bool;
    fmi2GetIntegerTYPE *get_int;
    fmi2DoStepTYPE *do_step;
} Fmu;

static Fmu fmus[MAX_FMUS];
static int nfmus;

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    (void)env;
    va_list args;
    va_start(args, message);
    fprintf(stderr, "[%s %d %s] ", name ? name : "?", (int)status, category ? category : "");
    vfprintf(stderr, message, args);
    fputc('\n', stderr);
    va_end(args);
}

static Fmu *find(const char *name) {
    for (int i = 0; i < nfmus; i++)
        if (strcmp(fmus[i].name, name) == 0) return &fmus[i];
    fprintf(stderr, "unknown FMU %s\n", name);
    exit(2);
}

static char *environment(void) {
    size_t n = 1;
    for (char **e = environ; *e; e++) n += strlen(*e) + 1;
    char *text = calloc(n, 1);
    for (char **e = environ; *e; e++) {
        strcat(text, *e);
        strcat(text, "\n");
    }
    return text;
}

#define SYM(f, field, symbol)                                            \
    do {                                                                 \
        *(void **)(&(f)->field) = dlsym((f)->lib, symbol);               \
        if (!(f)->field) {                                               \
            fprintf(stderr, "%s: no %s\n", (f)->name, symbol);           \
            exit(2);                                                     \
        }                                                                \
    } while (0)

static void check(fmi2Status s, const char *what, const Fmu *f) {
    if (s > fmi2Warning) {
        fprintf(stderr, "%s: %s returned %d\n", f->name, what, (int)s);
        exit(3);
    }
}

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: chain_host SPEC OUT\n");
        return 2;
    }
    char *before = environment();
    FILE *spec = fopen(argv[1], "r");
    if (!spec) return 2;
    static char kind[MAX_ITEMS][16], a[MAX_ITEMS][64], b[MAX_ITEMS][64], text[MAX_ITEMS][1024];
    static unsigned vr1[MAX_ITEMS], vr2[MAX_ITEMS];
    static double number[MAX_ITEMS];
    int n = 0;
    double stop = 0, h = 0;
    int summing = 0;
    char line[2048];
    const fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    while (fgets(line, sizeof line, spec)) {
        line[strcspn(line, "\n")] = '\0';
        char word[16];
        if (sscanf(line, "%15s", word) != 1) continue;
        if (strcmp(word, "fmu") == 0) {
            Fmu *f = &fmus[nfmus++];
            sscanf(line, "fmu %63s %1023s %255s %127s", f->name, f->dir, f->id, f->guid);
        } else if (strcmp(word, "run") == 0) {
            sscanf(line, "run %lf %lf", &stop, &h);
        } else if (strcmp(word, "sum") == 0) {
            summing = 1;
        } else if (n < MAX_ITEMS) {
            snprintf(kind[n], sizeof kind[n], "%s", word);
            if (strcmp(word, "link") == 0) {
                sscanf(line, "link %63s %u %63s %u", a[n], &vr1[n], b[n], &vr2[n]);
            } else if (strcmp(word, "out") == 0) {
                sscanf(line, "out %63s %u %63s", a[n], &vr1[n], b[n]);
            } else if (strcmp(word, "string") == 0) {
                int used = 0;
                sscanf(line, "string %63s %u %n", a[n], &vr1[n], &used);
                snprintf(text[n], sizeof text[n], "%s", line + used);
            } else {
                char rest[16];
                sscanf(line, "%15s %63s %u %lf", rest, a[n], &vr1[n], &number[n]);
            }
            n++;
        }
    }
    fclose(spec);
    /* a host that embeds a libpython privately (RTLD_LOCAL), not started: the FMU must
     * use that one and map no other */
    const char *local = getenv("CHAIN_HOST_LOCAL_LIBPYTHON");
    if (local && local[0] && !dlopen(local, RTLD_NOW | RTLD_LOCAL)) {
        fprintf(stderr, "%s\n", dlerror());
        return 4;
    }
    for (int i = 0; i < nfmus; i++) {
        Fmu *f = &fmus[i];
        char path[1400], uri[1100];
        snprintf(path, sizeof path, "%s/binaries/linux64/%s.so", f->dir, f->id);
        f->lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
        if (!f->lib) {
            fprintf(stderr, "%s: %s\n", f->name, dlerror());
            return 4;
        }
        SYM(f, instantiate, "fmi2Instantiate");
        SYM(f, free_instance, "fmi2FreeInstance");
        SYM(f, setup, "fmi2SetupExperiment");
        SYM(f, enter, "fmi2EnterInitializationMode");
        SYM(f, exit_init, "fmi2ExitInitializationMode");
        SYM(f, terminate, "fmi2Terminate");
        SYM(f, set_real, "fmi2SetReal");
        SYM(f, set_int, "fmi2SetInteger");
        SYM(f, set_bool, "fmi2SetBoolean");
        SYM(f, set_string, "fmi2SetString");
        SYM(f, get_real, "fmi2GetReal");
        SYM(f, get_bool, "fmi2GetBoolean");
        SYM(f, get_int, "fmi2GetInteger");
        SYM(f, do_step, "fmi2DoStep");
        snprintf(uri, sizeof uri, "file://%s/resources", f->dir);
        f->c = f->instantiate(f->name, fmi2CoSimulation, f->guid, uri, &callbacks, fmi2False,
                              fmi2True);
        if (!f->c) {
            fprintf(stderr, "%s: fmi2Instantiate returned NULL\n", f->name);
            return 5;
        }
        check(f->setup(f->c, fmi2False, 0.0, 0.0, fmi2False, 0.0), "setupExperiment", f);
    }
    for (int k = 0; k < n; k++) {
        Fmu *f = strcmp(kind[k], "link") && strcmp(kind[k], "out") ? find(a[k]) : NULL;
        if (!f) continue;
        fmi2ValueReference vr = vr1[k];
        if (strcmp(kind[k], "real") == 0) {
            fmi2Real x = number[k];
            check(f->set_real(f->c, &vr, 1, &x), "setReal", f);
        } else if (strcmp(kind[k], "int") == 0) {
            fmi2Integer x = (fmi2Integer)number[k];
            check(f->set_int(f->c, &vr, 1, &x), "setInteger", f);
        } else if (strcmp(kind[k], "bool") == 0) {
            fmi2Boolean x = number[k] != 0.0;
            check(f->set_bool(f->c, &vr, 1, &x), "setBoolean", f);
        } else if (strcmp(kind[k], "string") == 0) {
            fmi2String x = text[k];
            check(f->set_string(f->c, &vr, 1, &x), "setString", f);
        }
    }
    for (int i = 0; i < nfmus; i++) {
        check(fmus[i].enter(fmus[i].c), "enterInitializationMode", &fmus[i]);
        check(fmus[i].exit_init(fmus[i].c), "exitInitializationMode", &fmus[i]);
    }
    char *loaded = environment();
    FILE *out = fopen(argv[2], "w");
    if (!out) return 2;
    long steps = (long)(stop / h + 0.5);
    double t = 0.0;
    for (long s = 0;; s++) {
        if (!summing) t = (double)s * h;
        fprintf(out, "%.17g", t);
        for (int k = 0; k < n; k++) {
            if (strcmp(kind[k], "out")) continue;
            Fmu *f = find(a[k]);
            fmi2ValueReference vr = vr1[k];
            double x;
            if (b[k][0] == 'b') {
                fmi2Boolean v;
                check(f->get_bool(f->c, &vr, 1, &v), "getBoolean", f);
                x = v ? 1.0 : 0.0;
            } else if (b[k][0] == 'i') {
                fmi2Integer v;
                check(f->get_int(f->c, &vr, 1, &v), "getInteger", f);
                x = (double)v;
            } else {
                check(f->get_real(f->c, &vr, 1, &x), "getReal", f);
            }
            fprintf(out, ",%.17g", x);
        }
        fputc('\n', out);
        if (summing ? !(t < stop) : s == steps) break;
        double step = summing && stop - t < h ? stop - t : h;
        for (int k = 0; k < n; k++) {
            if (strcmp(kind[k], "link")) continue;
            Fmu *from = find(a[k]), *to = find(b[k]);
            fmi2ValueReference o = vr1[k], in = vr2[k];
            double x;
            check(from->get_real(from->c, &o, 1, &x), "getReal", from);
            check(to->set_real(to->c, &in, 1, &x), "setReal", to);
        }
        for (int i = 0; i < nfmus; i++)
            check(fmus[i].do_step(fmus[i].c, t, step, fmi2True), "doStep", &fmus[i]);
        if (summing) t += step;
    }
    for (int i = 0; i < nfmus; i++) {
        check(fmus[i].terminate(fmus[i].c), "terminate", &fmus[i]);
        fmus[i].free_instance(fmus[i].c);
    }
    char *after = environment();
    fprintf(out, "environ %s\n",
            strcmp(before, loaded) == 0 && strcmp(before, after) == 0 ? "same" : "changed");
    FILE *maps = fopen("/proc/self/maps", "r");
    char seen[16][1024];
    int nseen = 0;
    while (maps && fgets(line, sizeof line, maps)) {
        char *p = strchr(line, '/');
        if (!p) continue;
        p[strcspn(p, "\n")] = '\0';
        const char *base = strrchr(p, '/') + 1;
        if (strncmp(base, "libpython3.", 11) != 0) continue;
        int dup = 0;
        for (int i = 0; i < nseen; i++) dup |= strcmp(seen[i], p) == 0;
        if (!dup && nseen < 16) {
            snprintf(seen[nseen++], sizeof seen[0], "%s", p);
            fprintf(out, "libpython %s\n", p);
        }
    }
    if (maps) fclose(maps);
    fprintf(out, "status OK\n");
    fclose(out);
    return 0;
}
