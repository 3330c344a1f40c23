/*
 * The FMI 2.0 co-simulation binary of a Python FMU: binaries/linux64/<modelIdentifier>.so.
 *
 * pythonfmu's own binary ("the core", shipped beside this one as CORE_FILE) calls
 * CPython's C API but links no libpython: loaded into a host that is not Python it
 * fails with undefined symbols. This trampoline links no libpython either and has no
 * RUNPATH; it exports every FMI 2.0 co-simulation function and, at the first
 * fmi2Instantiate, makes sure a CPython >= 3.9 is in the global symbol scope, then
 * dlopen()s the core (RTLD_NOW | RTLD_LOCAL) and forwards every call to it. The core
 * uses the stable ABI only, so one core serves every CPython 3.9 ... 3.13.
 *
 * Finding Python, in this order (the first that answers wins; nothing else is mapped):
 *   1. a Python already in the process: Py_IsInitialized in the global scope (a Python
 *      host, static or shared), else a libpython3.*.so already mapped with
 *      RTLD_LOCAL, promoted with RTLD_NOLOAD | RTLD_GLOBAL. It is used whatever its
 *      version (>= 3.9); no second libpython is ever mapped;
 *   2. the file named by the environment variable ARCOSIM_LIBPYTHON (and only it, when
 *      set);
 *   3. the libpython of each python3, python3.13 ... python3.9 on PATH (through
 *      symlinks and venvs' pyvenv.cfg), then /usr/local/lib, /usr/lib/x86_64-linux-gnu,
 *      /usr/lib64, /usr/lib, $CONDA_PREFIX/lib, ~/.pyenv/versions/<newest first>/lib,
 *      ~/miniconda3/lib, ~/anaconda3/lib, /opt/conda/lib, then the dynamic loader's own
 *      search for libpython3.13.so.1.0 ... libpython3.9.so.1.0.
 * A libpython loaded here is initialized here, before the core sees it: home set
 * through Py_SetPythonHome (the installation the library belongs to, so a user's
 * PYTHONHOME or PYTHONPATH for another Python cannot break it), environment ignored,
 * no signal handlers (Py_InitializeEx(0)), never finalized. Nothing is written to the
 * process environment. When no Python is found, fmi2Instantiate logs what it tried and
 * the variable to set, and returns NULL.
 *
 * What the trampoline adds to the core:
 *   - statuses: a call returns the worst of the core's status and the statuses of the
 *     messages the FMU logged during it (the Python side cannot return fmi2Error; an
 *     invalid parameter logged as an error at exitInitializationMode returns fmi2Error);
 *     the core always logs to the trampoline, which filters by the host's
 *     fmi2SetDebugLogging;
 *   - after the core answered fmi2Fatal its instance is never called again (pythonfmu
 *     0.7 releases the Python objects of the instance and keeps the dangling pointers:
 *     any later call, fmi2FreeInstance included, would crash the host);
 *   - fmi2GetBooleanStatus(fmi2Terminated): fmi2True exactly when the parameters were
 *     refused at exitInitializationMode (every doStep is refused until fmi2Reset or a
 *     restored state); a refused step leaves the state unchanged and answers fmi2False;
 *   - fmi2GetRealStatus(fmi2LastSuccessfulTime): the end of the last accepted step;
 *   - serialized FMU states in an envelope (magic, format version, identity, n, length,
 *     CRC-32) checked before the core sees any byte;
 *   - teardown in any order: a call made once the process's Python has finalized, or
 *     while it finalizes (Py_IsInitialized false, or Py_IsFinalizing -- _Py_IsFinalizing
 *     before 3.13 -- true), never reaches the core, which would take the GIL of a dead
 *     interpreter: it is logged when the host's logger is native code (a ctypes or cffi
 *     logger would need that Python too), fmi2Terminate answers fmi2OK (a host such
 *     as OMSimulator stops terminating its other components on any other status),
 *     fmi2FreeInstance and fmi2FreeFMUstate free the trampoline's part and leak the
 *     core's, every other call answers fmi2Error. While Python lives, any thread may
 *     call (pythonfmu takes the GIL with PyGILState_Ensure).
 *
 * Compiled per build by cosim/build/portable.py with
 *   -DARCOSIM_IDENTIFIER="..." -DARCOSIM_GUID="{...}" -DARCOSIM_BUILD="<package>"
 *   -DARCOSIM_N=<n> -DARCOSIM_CORE="<core file name>"
 * Needs POSIX and glibc's dladdr / dl_iterate_phdr (Linux).
 */
#define _GNU_SOURCE
#include <dirent.h>
#include <dlfcn.h>
#include <errno.h>
#include <limits.h>
#include <link.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <wchar.h>

#include "fmi2Functions.h"
#include "fmu_envelope.h"

#if !defined(ARCOSIM_IDENTIFIER) || !defined(ARCOSIM_GUID) || !defined(ARCOSIM_BUILD) || \
    !defined(ARCOSIM_N) || !defined(ARCOSIM_CORE)
#error "compile with -DARCOSIM_IDENTIFIER, -DARCOSIM_GUID, -DARCOSIM_BUILD, -DARCOSIM_N, -DARCOSIM_CORE"
#endif

#define MIN_MINOR 9  /* CPython 3.9 ... */
#define MAX_MINOR 13 /* ... 3.13, newest tried first */
#define TEXT 4096

/* ------------------------------------------------------------------------------------ */
/* The core's functions                                                                 */

typedef struct {
    fmi2InstantiateTYPE *Instantiate;
    fmi2FreeInstanceTYPE *FreeInstance;
    fmi2SetupExperimentTYPE *SetupExperiment;
    fmi2EnterInitializationModeTYPE *EnterInitializationMode;
    fmi2ExitInitializationModeTYPE *ExitInitializationMode;
    fmi2TerminateTYPE *Terminate;
    fmi2ResetTYPE *Reset;
    fmi2GetRealTYPE *GetReal;
    fmi2GetIntegerTYPE *GetInteger;
    fmi2GetBooleanTYPE *GetBoolean;
    fmi2GetStringTYPE *GetString;
    fmi2SetRealTYPE *SetReal;
    fmi2SetIntegerTYPE *SetInteger;
    fmi2SetBooleanTYPE *SetBoolean;
    fmi2SetStringTYPE *SetString;
    fmi2GetFMUstateTYPE *GetFMUstate;
    fmi2SetFMUstateTYPE *SetFMUstate;
    fmi2FreeFMUstateTYPE *FreeFMUstate;
    fmi2SerializedFMUstateSizeTYPE *SerializedFMUstateSize;
    fmi2SerializeFMUstateTYPE *SerializeFMUstate;
    fmi2DeSerializeFMUstateTYPE *DeSerializeFMUstate;
    fmi2DoStepTYPE *DoStep;
} CoreApi;

static pthread_mutex_t load_lock = PTHREAD_MUTEX_INITIALIZER;
static CoreApi core;
static int core_loaded;

/* Python's C API, as far as the trampoline uses it (stable ABI). */
typedef int (*IsInitializedFn)(void);
typedef const char *(*GetVersionFn)(void);
typedef void (*SetPythonHomeFn)(const wchar_t *);
typedef wchar_t *(*DecodeLocaleFn)(const char *, size_t *);
typedef void (*InitializeExFn)(int);
typedef void *(*SaveThreadFn)(void);

/* dlsym into a function pointer without the object-to-function cast ISO C forbids */
#define LOOKUP(handle, name, target) (*(void **)(&(target)) = dlsym((handle), (name)))

/* Whether the process's Python may still be called: set with the core (under load_lock,
 * before any instance exists). Py_IsFinalizing is 3.13's name, _Py_IsFinalizing 3.9's
 * to 3.12's; both read a flag without the GIL. */
static IsInitializedFn py_initialized;
static IsInitializedFn py_finalizing;

static void watch_python(void) {
    LOOKUP(RTLD_DEFAULT, "Py_IsInitialized", py_initialized);
    if (!LOOKUP(RTLD_DEFAULT, "Py_IsFinalizing", py_finalizing))
        LOOKUP(RTLD_DEFAULT, "_Py_IsFinalizing", py_finalizing);
}

static int python_alive(void) {
    return py_initialized && py_initialized() && !(py_finalizing && py_finalizing());
}

#define PYTHON_GONE                                                                        \
    "the process's Python has finalized or is finalizing: the FMU's Python model cannot " \
    "be called any more (its memory is left to the process's exit)"

/* ------------------------------------------------------------------------------------ */
/* Small text helpers (bounded, always terminated)                                      */

static void append(char *text, size_t size, const char *format, ...) {
    size_t used = strlen(text);
    if (used + 1 >= size) return;
    va_list args;
    va_start(args, format);
    vsnprintf(text + used, size - used, format, args);
    va_end(args);
}

static int is_file(const char *path) {
    struct stat s;
    return stat(path, &s) == 0 && S_ISREG(s.st_mode);
}

/* The minor version X of a file named libpython3.X.so..., or -1. */
static int libpython_minor(const char *path) {
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    int minor = -1, used = 0;
    if (sscanf(base, "libpython3.%d%n", &minor, &used) != 1) return -1;
    if (strncmp(base + used, ".so", 3) != 0) return -1;
    return minor;
}

/* The installation prefix of libpython3.X at `path`: the nearest ancestor holding
 * lib/python3.X/os.py and lib/python3.X/encodings/__init__.py. 0 if found. */
static int python_home(const char *path, int minor, char *home, size_t size) {
    char dir[PATH_MAX], probe[PATH_MAX + 64];
    if (!realpath(path, dir)) return -1;
    for (int up = 0; up < 3; up++) {
        char *slash = strrchr(dir, '/');
        if (!slash) return -1;
        *slash = '\0'; /* dir: the parent */
        const char *root = dir[0] ? dir : "/";
        snprintf(probe, sizeof probe, "%s/lib/python3.%d/os.py", dir, minor);
        if (!is_file(probe)) continue;
        snprintf(probe, sizeof probe, "%s/lib/python3.%d/encodings/__init__.py", dir, minor);
        if (!is_file(probe)) continue;
        snprintf(home, size, "%s", root);
        return 0;
    }
    return -1;
}

/* ------------------------------------------------------------------------------------ */
/* Finding and starting Python                                                          */

typedef struct {
    char tried[TEXT];       /* what was tried, for the message when nothing is found */
    char seen[64][PATH_MAX]; /* libraries already tried (by real path) */
    int nseen;
    char home[PATH_MAX];    /* the home of the libpython last opened */
} Search;

static int already_tried(Search *s, const char *real) {
    for (int i = 0; i < s->nseen; i++)
        if (strcmp(s->seen[i], real) == 0) return 1;
    if (s->nseen < 64) snprintf(s->seen[s->nseen++], sizeof s->seen[0], "%s", real);
    return 0;
}

/* Try one libpython file: it must exist, be 3.9+, have its standard library, load. */
static int try_library(Search *s, const char *path) {
    char real[PATH_MAX];
    if (!realpath(path, real) || !is_file(real)) return 0;
    if (already_tried(s, real)) return 0;
    int minor = libpython_minor(path);
    if (minor < 0) minor = libpython_minor(real);
    if (minor < MIN_MINOR) {
        append(s->tried, sizeof s->tried, "\n  %s: not CPython >= 3.%d", path, MIN_MINOR);
        return 0;
    }
    if (python_home(real, minor, s->home, sizeof s->home) != 0) {
        append(s->tried, sizeof s->tried, "\n  %s: no standard library lib/python3.%d beside it",
               path, minor);
        return 0;
    }
    if (!dlopen(real, RTLD_NOW | RTLD_GLOBAL)) { /* kept open: the interpreter runs in it */
        append(s->tried, sizeof s->tried, "\n  %s: %s", path, dlerror());
        return 0;
    }
    return 1;
}

/* Every libpython3.X.so.1.0 (X newest first) and libpython3.X.so in `dir`. */
static int try_dir(Search *s, const char *dir) {
    char path[PATH_MAX + 64];
    for (int minor = MAX_MINOR; minor >= MIN_MINOR; minor--) {
        snprintf(path, sizeof path, "%s/libpython3.%d.so.1.0", dir, minor);
        if (try_library(s, path)) return 1;
        snprintf(path, sizeof path, "%s/libpython3.%d.so", dir, minor);
        if (try_library(s, path)) return 1;
    }
    return 0;
}

/* The libdirs of an installation prefix. */
static int try_prefix(Search *s, const char *prefix) {
    char dir[PATH_MAX + 32];
    static const char *const sub[] = {"lib", "lib/x86_64-linux-gnu", "lib64"};
    for (size_t i = 0; i < sizeof sub / sizeof sub[0]; i++) {
        snprintf(dir, sizeof dir, "%s/%s", prefix, sub[i]);
        if (try_dir(s, dir)) return 1;
    }
    return 0;
}

/* A python executable on PATH: its venv's base (pyvenv.cfg "home"), else the prefix of
 * the file it resolves to. */
static int try_executable(Search *s, const char *exe) {
    char real[PATH_MAX], prefix[PATH_MAX], cfg[PATH_MAX + 32], line[PATH_MAX + 32];
    if (access(exe, X_OK) != 0 || !realpath(exe, real)) return 0;
    /* a venv: <venv>/bin/python3 with <venv>/pyvenv.cfg naming the base's bin dir */
    snprintf(prefix, sizeof prefix, "%s", exe);
    char *slash = strrchr(prefix, '/');
    if (slash) {
        *slash = '\0';
        snprintf(cfg, sizeof cfg, "%s/../pyvenv.cfg", prefix);
        FILE *f = fopen(cfg, "r");
        if (f) {
            while (fgets(line, sizeof line, f)) {
                char *value = strchr(line, '=');
                if (strncmp(line, "home", 4) != 0 || !value) continue;
                value++;
                while (*value == ' ') value++;
                value[strcspn(value, "\r\n")] = '\0';
                char base[PATH_MAX];
                snprintf(base, sizeof base, "%s/..", value);
                if (realpath(base, prefix) && try_prefix(s, prefix)) {
                    fclose(f);
                    return 1;
                }
            }
            fclose(f);
        }
    }
    /* <prefix>/bin/python3.X */
    snprintf(prefix, sizeof prefix, "%s", real);
    for (int up = 0; up < 2; up++) {
        slash = strrchr(prefix, '/');
        if (!slash) return 0;
        *slash = '\0';
    }
    if (!prefix[0]) return 0;
    if (try_prefix(s, prefix)) return 1;
    if (strcmp(prefix, "/usr") == 0 && try_dir(s, "/usr/lib/x86_64-linux-gnu")) return 1;
    return 0;
}

static int try_path(Search *s) {
    const char *path = getenv("PATH");
    if (!path || !path[0]) {
        append(s->tried, sizeof s->tried, "\n  PATH: empty");
        return 0;
    }
    char copy[TEXT], exe[PATH_MAX];
    snprintf(copy, sizeof copy, "%s", path);
    append(s->tried, sizeof s->tried, "\n  python3, python3.%d ... python3.%d on PATH=%s",
           MAX_MINOR, MIN_MINOR, path);
    for (char *save = NULL, *dir = strtok_r(copy, ":", &save); dir;
         dir = strtok_r(NULL, ":", &save)) {
        if (!dir[0]) continue;
        snprintf(exe, sizeof exe, "%s/python3", dir);
        if (try_executable(s, exe)) return 1;
        for (int minor = MAX_MINOR; minor >= MIN_MINOR; minor--) {
            snprintf(exe, sizeof exe, "%s/python3.%d", dir, minor);
            if (try_executable(s, exe)) return 1;
        }
    }
    return 0;
}

/* ~/.pyenv/versions/3.X.Y/lib, newest minor first. */
static int try_pyenv(Search *s, const char *home) {
    char root[PATH_MAX], dir[PATH_MAX + 300];
    const char *env = getenv("PYENV_ROOT");
    if (env && env[0])
        snprintf(root, sizeof root, "%s/versions", env);
    else
        snprintf(root, sizeof root, "%s/.pyenv/versions", home);
    append(s->tried, sizeof s->tried, "\n  %s/3.*/lib", root);
    for (int minor = MAX_MINOR; minor >= MIN_MINOR; minor--) {
        DIR *d = opendir(root);
        if (!d) return 0;
        struct dirent *e;
        while ((e = readdir(d)) != NULL) {
            int major = 0, m = 0;
            if (sscanf(e->d_name, "%d.%d", &major, &m) != 2 || major != 3 || m != minor) continue;
            snprintf(dir, sizeof dir, "%s/%s/lib", root, e->d_name);
            if (try_dir(s, dir)) {
                closedir(d);
                return 1;
            }
        }
        closedir(d);
    }
    return 0;
}

/* The dynamic loader's own search (ld.so.cache, LD_LIBRARY_PATH) by soname. */
static int try_soname(Search *s) {
    char name[64];
    for (int minor = MAX_MINOR; minor >= MIN_MINOR; minor--) {
        snprintf(name, sizeof name, "libpython3.%d.so.1.0", minor);
        void *handle = dlopen(name, RTLD_NOW | RTLD_NOLOAD);
        if (!handle) handle = dlopen(name, RTLD_LAZY | RTLD_LOCAL);
        if (!handle) continue;
        void *symbol = NULL;
        Dl_info info;
        int found = 0;
        if ((symbol = dlsym(handle, "Py_IsInitialized")) && dladdr(symbol, &info) &&
            info.dli_fname) {
            char path[PATH_MAX];
            snprintf(path, sizeof path, "%s", info.dli_fname);
            dlclose(handle);
            found = try_library(s, path);
        } else {
            dlclose(handle);
        }
        if (found) return 1;
    }
    append(s->tried, sizeof s->tried, "\n  the dynamic loader's search for libpython3.%d.so.1.0 "
           "... libpython3.%d.so.1.0", MAX_MINOR, MIN_MINOR);
    return 0;
}

static int find_mapped(struct dl_phdr_info *info, size_t size, void *data) {
    (void)size;
    const char *name = info->dlpi_name;
    if (!name || !name[0]) return 0;
    const char *base = strrchr(name, '/');
    base = base ? base + 1 : name;
    if (strncmp(base, "libpython3.", 11) != 0) return 0;
    snprintf((char *)data, PATH_MAX, "%s", name);
    return 1;
}

/* The version of the Python in global scope, as 3.X -> X; -1 if unknown. */
static int running_minor(void) {
    GetVersionFn version;
    LOOKUP(RTLD_DEFAULT, "Py_GetVersion", version);
    int major = 0, minor = -1;
    if (!version || sscanf(version(), "%d.%d", &major, &minor) != 2 || major != 3) return -1;
    return minor;
}

static int start_interpreter(const char *home, char *why, size_t size) {
    IsInitializedFn is_initialized;
    SetPythonHomeFn set_home;
    DecodeLocaleFn decode;
    InitializeExFn initialize;
    SaveThreadFn save_thread;
    LOOKUP(RTLD_DEFAULT, "Py_IsInitialized", is_initialized);
    LOOKUP(RTLD_DEFAULT, "Py_SetPythonHome", set_home);
    LOOKUP(RTLD_DEFAULT, "Py_DecodeLocale", decode);
    LOOKUP(RTLD_DEFAULT, "Py_InitializeEx", initialize);
    LOOKUP(RTLD_DEFAULT, "PyEval_SaveThread", save_thread);
    if (!is_initialized || !set_home || !decode || !initialize || !save_thread) {
        snprintf(why, size, "the libpython lacks Py_SetPythonHome or Py_InitializeEx");
        return -1;
    }
    if (is_initialized()) return 0;
    /* kept for the life of the process, as Py_SetPythonHome requires */
    static wchar_t *whome;
    whome = decode(home, NULL);
    if (!whome) {
        snprintf(why, size, "cannot decode the Python home %s", home);
        return -1;
    }
    set_home(whome);
    int *flag;
    LOOKUP(RTLD_DEFAULT, "Py_IgnoreEnvironmentFlag", flag);
    if (flag) *flag = 1; /* the user's PYTHONHOME/PYTHONPATH may be another Python's */
    LOOKUP(RTLD_DEFAULT, "Py_NoUserSiteDirectory", flag);
    if (flag) *flag = 1;
    initialize(0); /* 0: leave the host's signal handlers alone */
    save_thread(); /* release the GIL; pythonfmu takes it per call */
    return 0;
}

/* Make a CPython >= 3.9 available in the global scope and initialized. 0 on success,
 * else -1 with the explanation in `why`. */
static int ensure_python(char *why, size_t size) {
    static Search s; /* large; used under load_lock only */
    memset(&s, 0, sizeof s);
    IsInitializedFn is_initialized, finalizing;
    if (!LOOKUP(RTLD_DEFAULT, "Py_IsFinalizing", finalizing))
        LOOKUP(RTLD_DEFAULT, "_Py_IsFinalizing", finalizing);
    if (finalizing && finalizing()) { /* never start or use a Python on its way out */
        snprintf(why, size, "%s", PYTHON_GONE);
        return -1;
    }
    LOOKUP(RTLD_DEFAULT, "Py_IsInitialized", is_initialized);
    char mapped[PATH_MAX] = "";
    if (!is_initialized && dl_iterate_phdr(find_mapped, mapped) && mapped[0]) {
        /* a libpython loaded privately (RTLD_LOCAL) by someone: promote it, map no other */
        if (!dlopen(mapped, RTLD_NOW | RTLD_NOLOAD | RTLD_GLOBAL)) {
            snprintf(why, size, "%s is loaded in this process but cannot be made global: %s",
                     mapped, dlerror());
            return -1;
        }
        LOOKUP(RTLD_DEFAULT, "Py_IsInitialized", is_initialized);
    }
    if (is_initialized) {
        int minor = running_minor();
        if (minor < MIN_MINOR) {
            snprintf(why, size, "this process already runs Python 3.%d; the FMU needs CPython "
                     ">= 3.%d and cannot load a second Python into the same process", minor,
                     MIN_MINOR);
            return -1;
        }
        if (is_initialized()) return 0;
        /* a libpython in the global scope that nobody started: start it at its own home */
        void *symbol = dlsym(RTLD_DEFAULT, "Py_IsInitialized");
        Dl_info info;
        if (!dladdr(symbol, &info) || !info.dli_fname ||
            python_home(info.dli_fname, minor, s.home, sizeof s.home) != 0) {
            snprintf(why, size, "a Python 3.%d library is loaded but its standard library "
                     "was not found", minor);
            return -1;
        }
        return start_interpreter(s.home, why, size);
    }
    const char *chosen = getenv("ARCOSIM_LIBPYTHON");
    int found = 0;
    if (chosen && chosen[0]) {
        append(s.tried, sizeof s.tried, "\n  ARCOSIM_LIBPYTHON=%s", chosen);
        found = try_library(&s, chosen);
        if (!found && !is_file(chosen)) append(s.tried, sizeof s.tried, ": no such file");
    } else {
        const char *home = getenv("HOME");
        const char *conda = getenv("CONDA_PREFIX");
        char dir[PATH_MAX];
        append(s.tried, sizeof s.tried, "\n  ARCOSIM_LIBPYTHON (not set)");
        found = try_path(&s);
        static const char *const fixed[] = {"/usr/local/lib", "/usr/lib/x86_64-linux-gnu",
                                            "/usr/lib64", "/usr/lib"};
        for (size_t i = 0; !found && i < sizeof fixed / sizeof fixed[0]; i++) {
            found = try_dir(&s, fixed[i]);
            if (!found) append(s.tried, sizeof s.tried, "\n  %s", fixed[i]);
        }
        if (!found && conda && conda[0]) {
            snprintf(dir, sizeof dir, "%s/lib", conda);
            found = try_dir(&s, dir);
            if (!found) append(s.tried, sizeof s.tried, "\n  %s", dir);
        }
        if (!found && home && home[0]) found = try_pyenv(&s, home);
        static const char *const conda_dirs[] = {"miniconda3/lib", "anaconda3/lib"};
        for (size_t i = 0; !found && home && home[0] && i < 2; i++) {
            snprintf(dir, sizeof dir, "%s/%s", home, conda_dirs[i]);
            found = try_dir(&s, dir);
            if (!found) append(s.tried, sizeof s.tried, "\n  %s", dir);
        }
        if (!found) {
            found = try_dir(&s, "/opt/conda/lib");
            if (!found) append(s.tried, sizeof s.tried, "\n  /opt/conda/lib");
        }
        if (!found) found = try_soname(&s);
    }
    if (!found) {
        snprintf(why, size,
                 "no CPython >= 3.%d with a shared libpython was found. Tried, in order:%s\n"
                 "Install one (Debian: the package libpython3.X) or set "
                 "ARCOSIM_LIBPYTHON=/path/to/libpython3.X.so.1.0 in the host's environment",
                 MIN_MINOR, s.tried);
        return -1;
    }
    return start_interpreter(s.home, why, size);
}

/* dlopen the core beside this file and look up its functions. */
static int load_core(char *why, size_t size) {
    Dl_info self;
    if (!dladdr((void *)(uintptr_t)&load_core, &self) || !self.dli_fname) {
        snprintf(why, size, "cannot tell where this binary is (dladdr failed)");
        return -1;
    }
    char path[PATH_MAX];
    snprintf(path, sizeof path, "%s", self.dli_fname);
    char *slash = strrchr(path, '/');
    if (slash)
        snprintf(slash + 1, sizeof path - (size_t)(slash + 1 - path), "%s", ARCOSIM_CORE);
    else
        snprintf(path, sizeof path, "./%s", ARCOSIM_CORE);
    void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!h) {
        snprintf(why, size, "cannot load the FMU's core %s: %s", path, dlerror());
        return -1;
    }
    int missing = 0;
#define CORE(name)                                                  \
    do {                                                            \
        if (!LOOKUP(h, "fmi2" #name, core.name)) missing++;         \
    } while (0)
    CORE(Instantiate);
    CORE(FreeInstance);
    CORE(SetupExperiment);
    CORE(EnterInitializationMode);
    CORE(ExitInitializationMode);
    CORE(Terminate);
    CORE(Reset);
    CORE(GetReal);
    CORE(GetInteger);
    CORE(GetBoolean);
    CORE(GetString);
    CORE(SetReal);
    CORE(SetInteger);
    CORE(SetBoolean);
    CORE(SetString);
    CORE(GetFMUstate);
    CORE(SetFMUstate);
    CORE(FreeFMUstate);
    CORE(SerializedFMUstateSize);
    CORE(SerializeFMUstate);
    CORE(DeSerializeFMUstate);
    CORE(DoStep);
#undef CORE
    if (missing) {
        snprintf(why, size, "the FMU's core %s lacks %d FMI functions", path, missing);
        return -1;
    }
    return 0;
}

/* ------------------------------------------------------------------------------------ */
/* Instances and logging                                                                */

#define INSTANCE_MAGIC 0x41524331u /* "ARC1" */
#define STATE_MAGIC 0x41525331u    /* "ARS1" */
#define MAX_CATEGORIES 16

typedef struct {
    unsigned magic;
    fmi2Component core;
    fmi2CallbackFunctions *core_callbacks; /* given to the core; it keeps the pointer */
    fmi2CallbackLogger host_logger;
    fmi2ComponentEnvironment host_env;
    char name[256];
    int logging;
    size_t ncategories;
    char categories[MAX_CATEGORIES][64];
    fmi2Status worst; /* worst status the FMU logged during the current call */
    int dead;         /* the core answered fmi2Fatal: never called again */
    int init_failed;  /* exitInitializationMode refused the parameters */
    int time_known;
    double time;      /* end of the last accepted step (fmi2LastSuccessfulTime) */
} Instance;

typedef struct {
    unsigned magic;
    fmi2FMUstate core;
    int init_failed, time_known;
    double time;
} State;

static const char *category_of(fmi2Status status) {
    switch (status) {
    case fmi2Warning: return "logStatusWarning";
    case fmi2Discard: return "logStatusDiscard";
    case fmi2Error: return "logStatusError";
    case fmi2Fatal: return "logStatusFatal";
    default: return "logAll";
    }
}

static int category_enabled(const Instance *in, const char *category) {
    if (!in->logging) return 0;
    if (in->ncategories == 0) return 1;
    for (size_t i = 0; i < in->ncategories; i++)
        if (strcmp(in->categories[i], category) == 0 || strcmp(in->categories[i], "logAll") == 0)
            return 1;
    return 0;
}

/* Pass text to a printf-style logger as literal text ('%' doubled, as the plant does). */
static void emit(fmi2CallbackLogger logger, fmi2ComponentEnvironment env, const char *name,
                 fmi2Status status, const char *category, const char *text) {
    if (!logger) return;
    char escaped[2 * TEXT];
    size_t j = 0;
    for (size_t i = 0; text[i] && j + 2 < sizeof escaped; i++) {
        if (text[i] == '%') escaped[j++] = '%';
        escaped[j++] = text[i];
    }
    escaped[j] = '\0';
    logger(env, name, status, category, escaped);
}

static void say(Instance *in, fmi2Status status, const char *format, ...) {
    const char *category = category_of(status);
    if (!category_enabled(in, category)) return;
    char text[TEXT];
    int used = snprintf(text, sizeof text, "%s: ", in->name);
    va_list args;
    va_start(args, format);
    vsnprintf(text + used, sizeof text - (size_t)used, format, args);
    va_end(args);
    emit(in->host_logger, in->host_env, in->name, status, category, text);
}

/* The logger the core calls; its environment is our instance. */
static void relay(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                  fmi2String category, fmi2String message, ...) {
    Instance *in = env;
    if (!in || in->magic != INSTANCE_MAGIC) return;
    if ((status == fmi2Warning || status == fmi2Error) && status > in->worst) in->worst = status;
    const char *cat = category && category[0] ? category : category_of(status);
    if (category_enabled(in, cat))
        emit(in->host_logger, in->host_env, name ? name : in->name, status, cat,
             message ? message : "");
}

static void *allocate(size_t n, size_t size) { return calloc(n, size); }

/* Whether the host's logger runs without Python: code mapped from a file that is not
 * libffi, libpython or a ctypes/cffi module. A ctypes or cffi callback lives in
 * anonymous memory or on libffi's trampoline pages and would take the dead GIL. */
static int native_logger(fmi2CallbackLogger logger) {
    Dl_info info;
    if (!logger || !dladdr((void *)(uintptr_t)logger, &info)) return 0;
    const char *name = info.dli_fname ? info.dli_fname : "";
    const char *base = strrchr(name, '/');
    base = base ? base + 1 : name;
    return !strstr(base, "libffi") && !strstr(base, "libpython") && !strstr(base, "_ctypes") &&
           !strstr(base, "_cffi");
}

/* A call that finds Python gone: say so if that is safe, touch nothing of Python. */
static void python_gone(Instance *in, fmi2Status status, const char *call) {
    const char *category = category_of(status);
    if (!category_enabled(in, category) || !native_logger(in->host_logger)) return;
    char text[TEXT];
    snprintf(text, sizeof text, "%s: %s: %s", in->name, call, PYTHON_GONE);
    emit(in->host_logger, in->host_env, in->name, status, category, text);
}

static int usable_in(Instance *in, const char *call) {
    if (!in || in->magic != INSTANCE_MAGIC) return 0;
    if (in->dead) {
        say(in, fmi2Error, "this instance failed fatally before; only fmi2FreeInstance may be "
            "called now");
        return 0;
    }
    if (!python_alive()) {
        python_gone(in, fmi2Error, call);
        return 0;
    }
    in->worst = fmi2OK;
    return 1;
}

/* A call's final status: the core's, raised to the worst the FMU logged meanwhile. */
static fmi2Status finish(Instance *in, fmi2Status status) {
    if (status == fmi2Fatal) {
        in->dead = 1;
        say(in, fmi2Fatal, "the FMU's Python code failed fatally (see the messages above); "
            "this instance cannot be used any more: free it");
        return fmi2Fatal;
    }
    if (in->worst > status) status = in->worst;
    return status;
}

#define BEGIN(c)                                    \
    Instance *in = (Instance *)(c);                 \
    if (!usable_in(in, __func__)) return fmi2Error
#define FORWARD(call) finish(in, core.call)

/* ------------------------------------------------------------------------------------ */
/* FMI: life cycle                                                                      */

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }

const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                              fmi2Boolean loggingOn) {
    fmi2CallbackLogger logger = functions ? functions->logger : NULL;
    fmi2ComponentEnvironment env = functions ? functions->componentEnvironment : NULL;
    const char *name = instanceName ? instanceName : ARCOSIM_IDENTIFIER;
    char why[2 * TEXT];
    why[0] = '\0';
    if (fmuType != fmi2CoSimulation) {
        snprintf(why, sizeof why, "%s: this FMU supports co-simulation only", name);
    } else if (!fmuGUID || strcmp(fmuGUID, ARCOSIM_GUID) != 0) {
        snprintf(why, sizeof why, "%s: GUID %s does not match this binary's %s", name,
                 fmuGUID ? fmuGUID : "(null)", ARCOSIM_GUID);
    } else {
        pthread_mutex_lock(&load_lock);
        if (!core_loaded) {
            char reason[2 * TEXT - 300];
            if (ensure_python(reason, sizeof reason) == 0 &&
                load_core(reason, sizeof reason) == 0) {
                watch_python();
                core_loaded = 1;
            } else {
                snprintf(why, sizeof why, "%s: cannot start the FMU's Python: %s", name, reason);
            }
        }
        pthread_mutex_unlock(&load_lock);
        if (!why[0] && !python_alive())
            snprintf(why, sizeof why, "%s: %s", name, PYTHON_GONE);
    }
    if (why[0]) { /* logged whatever loggingOn says: there is no instance to ask again */
        emit(logger, env, name, fmi2Error, "logStatusError", why);
        return NULL;
    }
    Instance *in = calloc(1, sizeof *in);
    fmi2CallbackFunctions *callbacks = malloc(sizeof *callbacks);
    if (!in || !callbacks) {
        free(in);
        free(callbacks);
        emit(logger, env, name, fmi2Error, "logStatusError", "out of memory");
        return NULL;
    }
    {   /* the 2014 headers declare the members const: initialize, then copy */
        const fmi2CallbackFunctions mine = {relay, allocate, free, NULL, in};
        memcpy(callbacks, &mine, sizeof mine);
    }
    in->magic = INSTANCE_MAGIC;
    in->core_callbacks = callbacks;
    in->host_logger = logger;
    in->host_env = env;
    in->logging = loggingOn;
    snprintf(in->name, sizeof in->name, "%s", name);
    in->core = core.Instantiate(instanceName, fmuType, fmuGUID, fmuResourceLocation, callbacks,
                                visible, fmi2True /* all messages to relay(), filtered there */);
    if (!in->core) {
        say(in, fmi2Error, "instantiation of the Python model failed (see the messages above)");
        if (!in->logging)
            emit(logger, env, name, fmi2Error, "logStatusError",
                 "instantiation of the Python model failed; turn logging on for its messages");
        in->magic = 0;
        free(callbacks);
        free(in);
        return NULL;
    }
    return in;
}

void fmi2FreeInstance(fmi2Component c) {
    Instance *in = c;
    if (!in || in->magic != INSTANCE_MAGIC) return;
    /* after a fatal error the core's instance holds dangling Python pointers, and with
     * Python gone it cannot be freed: leak it */
    if (!in->dead && python_alive())
        core.FreeInstance(in->core);
    else if (!in->dead)
        python_gone(in, fmi2Warning, "fmi2FreeInstance");
    in->magic = 0;
    free(in->core_callbacks);
    free(in);
}

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t n,
                               const fmi2String categories[]) {
    Instance *in = c;
    if (!in || in->magic != INSTANCE_MAGIC) return fmi2Error;
    in->logging = loggingOn;
    in->ncategories = 0;
    for (size_t i = 0; categories && i < n && i < MAX_CATEGORIES; i++)
        if (categories[i])
            snprintf(in->categories[in->ncategories++], sizeof in->categories[0], "%s",
                     categories[i]);
    return fmi2OK;
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined,
                               fmi2Real stopTime) {
    BEGIN(c);
    fmi2Status s = FORWARD(SetupExperiment(in->core, toleranceDefined, tolerance, startTime,
                                           stopTimeDefined, stopTime));
    if (s <= fmi2Warning) {
        in->time = startTime;
        in->time_known = 1;
    }
    return s;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    BEGIN(c);
    return FORWARD(EnterInitializationMode(in->core));
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    BEGIN(c);
    fmi2Status s = FORWARD(ExitInitializationMode(in->core));
    in->init_failed = s >= fmi2Error;
    return s;
}

fmi2Status fmi2Terminate(fmi2Component c) {
    Instance *given = c;
    if (given && given->magic == INSTANCE_MAGIC && !given->dead && !python_alive()) {
        /* nothing is left to do: Python's finalization closed the model's files */
        python_gone(given, fmi2Warning, "fmi2Terminate");
        return fmi2OK; /* logged as a warning; OMSimulator stops its teardown on anything
                        * but fmi2OK, leaving the other components unterminated */
    }
    BEGIN(c);
    return FORWARD(Terminate(in->core));
}

fmi2Status fmi2Reset(fmi2Component c) {
    BEGIN(c);
    fmi2Status s = FORWARD(Reset(in->core));
    in->init_failed = 0;
    in->time_known = 0;
    return s;
}

/* ------------------------------------------------------------------------------------ */
/* FMI: values and stepping                                                             */

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                       fmi2Real value[]) {
    BEGIN(c);
    return FORWARD(GetReal(in->core, vr, n, value));
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                          fmi2Integer value[]) {
    BEGIN(c);
    return FORWARD(GetInteger(in->core, vr, n, value));
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                          fmi2Boolean value[]) {
    BEGIN(c);
    return FORWARD(GetBoolean(in->core, vr, n, value));
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                         fmi2String value[]) {
    BEGIN(c);
    return FORWARD(GetString(in->core, vr, n, value));
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                       const fmi2Real value[]) {
    BEGIN(c);
    return FORWARD(SetReal(in->core, vr, n, value));
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                          const fmi2Integer value[]) {
    BEGIN(c);
    return FORWARD(SetInteger(in->core, vr, n, value));
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                          const fmi2Boolean value[]) {
    BEGIN(c);
    return FORWARD(SetBoolean(in->core, vr, n, value));
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                         const fmi2String value[]) {
    BEGIN(c);
    return FORWARD(SetString(in->core, vr, n, value));
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noSetPrior) {
    BEGIN(c);
    fmi2Status s = FORWARD(DoStep(in->core, t, h, noSetPrior));
    if (s <= fmi2Warning) {
        in->time = t + h;
        in->time_known = 1;
    }
    return s;
}

fmi2Status fmi2CancelStep(fmi2Component c) {
    BEGIN(c);
    say(in, fmi2Error, "fmi2CancelStep: doStep never runs asynchronously");
    return fmi2Error;
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) {
    (void)s, (void)value;
    BEGIN(c);
    return fmi2Discard; /* doStep never runs asynchronously */
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value) {
    BEGIN(c);
    if (s != fmi2LastSuccessfulTime || !value) return fmi2Discard;
    *value = in->time_known ? in->time : 0.0;
    return fmi2OK;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value) {
    (void)s, (void)value;
    BEGIN(c);
    return fmi2Discard;
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value) {
    BEGIN(c);
    if (s != fmi2Terminated || !value) return fmi2Discard;
    *value = in->init_failed ? fmi2True : fmi2False;
    return fmi2OK;
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value) {
    (void)s, (void)value;
    BEGIN(c);
    return fmi2Discard;
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    (void)vr, (void)n, (void)order, (void)value;
    BEGIN(c);
    say(in, fmi2Error, "input derivatives are not supported (canInterpolateInputs=false)");
    return fmi2Error;
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                        size_t n, const fmi2Integer order[], fmi2Real value[]) {
    (void)vr, (void)n, (void)order, (void)value;
    BEGIN(c);
    say(in, fmi2Error, "output derivatives are not provided");
    return fmi2Error;
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                        const fmi2ValueReference z[], size_t nz,
                                        const fmi2Real du[], fmi2Real dz[]) {
    (void)u, (void)nu, (void)z, (void)nz, (void)du, (void)dz;
    BEGIN(c);
    say(in, fmi2Error, "directional derivatives are not provided");
    return fmi2Error;
}

/* ------------------------------------------------------------------------------------ */
/* FMI: FMU state                                                                       */

static State *state_of(Instance *in, fmi2FMUstate s, const char *call) {
    State *st = s;
    if (!st || st->magic != STATE_MAGIC) {
        say(in, fmi2Error, "%s: the FMU state was not made by this FMU's fmi2GetFMUstate or "
            "fmi2DeSerializeFMUstate (or was freed)", call);
        return NULL;
    }
    return st;
}

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *state) {
    BEGIN(c);
    if (!state) return fmi2Error;
    State *st = *state;
    if (st && !state_of(in, st, "fmi2GetFMUstate")) return fmi2Error;
    int fresh = st == NULL;
    if (fresh && !(st = calloc(1, sizeof *st))) return fmi2Error;
    fmi2FMUstate previous = st->core;
    fmi2FMUstate taken = NULL;
    fmi2Status s = FORWARD(GetFMUstate(in->core, &taken));
    if (s > fmi2Warning) {
        if (fresh) free(st);
        return s;
    }
    if (previous && !in->dead) core.FreeFMUstate(in->core, &previous); /* pythonfmu leaks it */
    st->magic = STATE_MAGIC;
    st->core = taken;
    st->init_failed = in->init_failed;
    st->time_known = in->time_known;
    st->time = in->time;
    *state = st;
    return s;
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state) {
    BEGIN(c);
    State *st = state_of(in, state, "fmi2SetFMUstate");
    if (!st) return fmi2Error;
    fmi2Status s = FORWARD(SetFMUstate(in->core, st->core));
    if (s <= fmi2Warning) {
        in->init_failed = st->init_failed;
        in->time_known = st->time_known;
        in->time = st->time;
    }
    return s;
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *state) {
    Instance *in = c;
    if (!in || in->magic != INSTANCE_MAGIC || !state) return fmi2Error;
    if (!*state) return fmi2OK;
    State *st = state_of(in, *state, "fmi2FreeFMUstate");
    if (!st) return fmi2Error;
    fmi2Status s = fmi2OK;
    if (!in->dead && python_alive()) {
        in->worst = fmi2OK;
        s = FORWARD(FreeFMUstate(in->core, &st->core));
    } else if (!in->dead) {
        python_gone(in, fmi2Warning, "fmi2FreeFMUstate");
        s = fmi2Warning;
    }
    st->magic = 0;
    free(st);
    *state = NULL;
    return s;
}

/* Serialized states travel in the envelope of fmu_envelope.h; this FMU's flags: 1 =
 * parameters refused at initialization, 2 = time known. */
static const char IDENTITY[] = ARCOSIM_IDENTIFIER " " ARCOSIM_GUID " " ARCOSIM_BUILD;
#define IDENTITY_LENGTH (sizeof IDENTITY - 1)
#define OVERHEAD ENVELOPE_OVERHEAD(IDENTITY_LENGTH)

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate state, size_t *size) {
    BEGIN(c);
    State *st = state_of(in, state, "fmi2SerializedFMUstateSize");
    if (!st || !size) return fmi2Error;
    size_t payload = 0;
    fmi2Status s = FORWARD(SerializedFMUstateSize(in->core, st->core, &payload));
    if (s <= fmi2Warning) *size = OVERHEAD + payload;
    return s;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate state, fmi2Byte bytes[],
                                 size_t size) {
    BEGIN(c);
    State *st = state_of(in, state, "fmi2SerializeFMUstate");
    if (!st || !bytes) return fmi2Error;
    size_t payload = 0;
    fmi2Status s = FORWARD(SerializedFMUstateSize(in->core, st->core, &payload));
    if (s > fmi2Warning) return s;
    if (size != OVERHEAD + payload) {
        say(in, fmi2Error, "fmi2SerializeFMUstate: %zu bytes given, %zu needed (ask "
            "fmi2SerializedFMUstateSize)", size, OVERHEAD + payload);
        return fmi2Error;
    }
    unsigned char *out = (unsigned char *)bytes;
    uint32_t flags = (st->init_failed ? 1u : 0u) | (st->time_known ? 2u : 0u);
    envelope_open(out, flags, st->time, (uint32_t)ARCOSIM_N, IDENTITY, IDENTITY_LENGTH, payload);
    s = finish(in, core.SerializeFMUstate(in->core, st->core,
                                          (fmi2Byte *)envelope_payload(out, IDENTITY_LENGTH),
                                          payload));
    if (s > fmi2Warning) return s;
    envelope_seal(out, size);
    return s;
}

static fmi2Status refuse(Instance *in, const char *format, ...) {
    char text[TEXT];
    va_list args;
    va_start(args, format);
    vsnprintf(text, sizeof text, format, args);
    va_end(args);
    say(in, fmi2Error, "fmi2DeSerializeFMUstate refused: %s; nothing was changed", text);
    return fmi2Error;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte bytes[], size_t size,
                                   fmi2FMUstate *state) {
    BEGIN(c);
    if (!state) return fmi2Error;
    if (*state && !state_of(in, *state, "fmi2DeSerializeFMUstate")) return fmi2Error;
    char why[TEXT];
    const unsigned char *payload;
    uint64_t payload_length;
    uint32_t flags;
    double time;
    if (envelope_check((const unsigned char *)bytes, size, IDENTITY, IDENTITY_LENGTH,
                       (uint32_t)ARCOSIM_N, why, sizeof why, &payload, &payload_length, &flags,
                       &time))
        return refuse(in, "%s", why);
    fmi2FMUstate taken = NULL;
    fmi2Status s = finish(in, core.DeSerializeFMUstate(in->core, (const fmi2Byte *)payload,
                                                       (size_t)payload_length, &taken));
    if (s > fmi2Warning) return s;
    State *st = *state;
    if (!st) {
        st = calloc(1, sizeof *st);
        if (!st) return fmi2Error;
    } else if (st->core && !in->dead) {
        core.FreeFMUstate(in->core, &st->core);
    }
    st->magic = STATE_MAGIC;
    st->core = taken;
    st->init_failed = (flags & 1u) != 0;
    st->time_known = (flags & 2u) != 0;
    st->time = time;
    *state = st;
    return s;
}
