/* A minimal FMI 3.0 Co-Simulation master for the cross-platform tests of the FMI 3.0 FMUs: loads
 * one binary, instantiates it through fmi3InstantiateCoSimulation and runs a script read from
 * stdin, printing every Float64 it reads with 17 significant digits. Built natively, with
 * mingw-w64 (run under wine) and with the aarch64 cross gcc (run under qemu-user);
 * tests/fmpy/test_fmi3_cross_platform.py compares the transcripts.
 *
 * usage: fmi3_harness <binary> <instantiationToken>   script lines on stdin:
 *   F vr value     fmi3SetFloat64
 *   X              exit initialization mode (entered at start)
 *   S h            fmi3DoStep from the current time by h
 *   G vr ...       print Float64 values (one line)
 * Exits 1 on fmi3Discard or worse, after printing the call and its status. */
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef _WIN32
#include <windows.h>
#define LOAD(path) ((void *)LoadLibraryA(path))
#define SYMBOL(lib, name) ((void *)GetProcAddress((HMODULE)(lib), name))
#else
#include <dlfcn.h>
#define LOAD(path) dlopen(path, RTLD_NOW | RTLD_LOCAL)
#define SYMBOL(lib, name) dlsym(lib, name)
#endif

typedef void *Instance;
typedef void (*Log)(void *, int, const char *, const char *);
typedef Instance (*InstantiateCS)(const char *, const char *, const char *, bool, bool, bool, bool,
                                  const unsigned *, size_t, void *, Log, void *);
typedef int (*EnterInit)(Instance, bool, double, double, bool, double);
typedef int (*Call)(Instance);
typedef int (*SetF64)(Instance, const unsigned *, size_t, const double *, size_t);
typedef int (*GetF64)(Instance, const unsigned *, size_t, double *, size_t);
typedef int (*DoStep)(Instance, double, double, bool, bool *, bool *, bool *, double *);

static void log_message(void *env, int status, const char *category, const char *message) {
    (void)env;
    fprintf(stderr, "[%d] %s: %s\n", status, category, message);
}

static void *symbol(void *lib, const char *name) {
    void *f = SYMBOL(lib, name);
    if (!f) {
        printf("missing %s\n", name);
        exit(2);
    }
    return f;
}

static void check(const char *call, int status) {
    if (status >= 2) {
        printf("%s returned %d\n", call, status);
        exit(1);
    }
}

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: fmi3_harness <binary> <instantiationToken>\n");
        return 2;
    }
    void *lib = LOAD(argv[1]);
    if (!lib) {
        printf("cannot load %s\n", argv[1]);
        return 2;
    }
    InstantiateCS instantiate = (InstantiateCS)symbol(lib, "fmi3InstantiateCoSimulation");
    EnterInit enter = (EnterInit)symbol(lib, "fmi3EnterInitializationMode");
    Call exit_init = (Call)symbol(lib, "fmi3ExitInitializationMode");
    Call terminate = (Call)symbol(lib, "fmi3Terminate");
    void (*free_instance)(Instance) = (void (*)(Instance))symbol(lib, "fmi3FreeInstance");
    SetF64 set = (SetF64)symbol(lib, "fmi3SetFloat64");
    GetF64 get = (GetF64)symbol(lib, "fmi3GetFloat64");
    DoStep step = (DoStep)symbol(lib, "fmi3DoStep");
    Instance inst = instantiate("cross", argv[2], NULL, false, false, false, false, NULL, 0, NULL,
                                log_message, NULL);
    if (!inst) {
        printf("fmi3InstantiateCoSimulation returned NULL\n");
        return 1;
    }
    check("fmi3EnterInitializationMode", enter(inst, false, 0.0, 0.0, false, 0.0));
    double time = 0.0;
    char line[4096];
    while (fgets(line, sizeof line, stdin)) {
        char *p = line + 1;
        if (line[0] == 'F') {
            unsigned vr = (unsigned)strtoul(p, &p, 10);
            double x = strtod(p, &p);
            check("fmi3SetFloat64", set(inst, &vr, 1, &x, 1));
        } else if (line[0] == 'X') {
            check("fmi3ExitInitializationMode", exit_init(inst));
        } else if (line[0] == 'S') {
            double h = strtod(p, &p);
            bool event, terminated, early;
            double last;
            check("fmi3DoStep", step(inst, time, h, true, &event, &terminated, &early, &last));
            time = last;
        } else if (line[0] == 'G') {
            unsigned vrs[256];
            size_t n = 0;
            for (char *end;; p = end) {
                unsigned long vr = strtoul(p, &end, 10);
                if (end == p || n == 256) break;
                vrs[n++] = (unsigned)vr;
            }
            double values[256];
            check("fmi3GetFloat64", get(inst, vrs, n, values, n));
            for (size_t i = 0; i < n; i++) printf(i ? " %.17g" : "%.17g", values[i]);
            printf("\n");
        }
    }
    check("fmi3Terminate", terminate(inst));
    free_instance(inst);
    return 0;
}
