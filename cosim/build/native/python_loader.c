/*
 * libarcosim_python.so: lets a pythonfmu FMU load in a host that is not Python.
 *
 * pythonfmu's binary deliberately does not link libpython: in a Python host the
 * symbols come from the interpreter. In a C/C++ host (ecos, FMI Library tools)
 * they are missing. The build adds this library as a needed library of the FMU's
 * binary (RUNPATH $ORIGIN); it is itself linked against the build's libpython, so
 * the symbols resolve, and its constructor
 *   - re-opens libpython with RTLD_GLOBAL, so C extension modules (math, ...) that
 *     the interpreter imports later find the symbols too;
 *   - when no interpreter runs yet and PYTHONHOME is unset, points PYTHONHOME at
 *     the build's Python, whose standard library matches this libpython (otherwise
 *     pythonfmu's Py_Initialize() takes the first python3 on PATH).
 * In a Python host both steps change nothing.
 */
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>

#ifndef ARCOSIM_LIBPYTHON
#error "compile with -DARCOSIM_LIBPYTHON=\"libpython3.X.so.1.0\""
#endif
#ifndef ARCOSIM_PYTHONHOME
#error "compile with -DARCOSIM_PYTHONHOME=\"/prefix/of/the/build/python\""
#endif

int Py_IsInitialized(void);

__attribute__((constructor)) static void arcosim_python_loader(void)
{
    void *handle = dlopen(ARCOSIM_LIBPYTHON, RTLD_NOW | RTLD_GLOBAL | RTLD_NOLOAD);
    if (handle == NULL) {
        handle = dlopen(ARCOSIM_LIBPYTHON, RTLD_NOW | RTLD_GLOBAL);
    }
    if (handle == NULL) {
        fprintf(stderr, "arcosim: cannot load %s: %s\n", ARCOSIM_LIBPYTHON, dlerror());
        return;
    }
    if (!Py_IsInitialized() && getenv("PYTHONHOME") == NULL) {
        setenv("PYTHONHOME", ARCOSIM_PYTHONHOME, 0);
    }
}
