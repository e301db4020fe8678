/* A minimal FMI 2.0 Co-Simulation master for the cross-platform tests: loads one FMU binary,
 * instantiates it and runs a script read from stdin, printing every value it reads with 17
 * significant digits. The same source is built natively, with mingw-w64 (run under wine) and with
 * the aarch64 cross gcc (run under qemu-user); tests/fmpy/test_cross_platform.py compares the
 * three transcripts.
 *
 * usage: harness <binary> <guid>   script lines on stdin:
 *   R vr value | I vr value | B vr value   set a Real, Integer or Boolean
 *   X                                      exit initialization mode (entered at start)
 *   S h                                    fmi2DoStep from the current time by h
 *   G vr ... [; vr ... [; vr ...]]         print Reals [; Integers [; Booleans]] (one line)
 *   D unknown known                        print the directional derivative, seed 1
 *   F | L                                  save the FMU state | restore it (and its time)
 *   N                                      a fresh instance (the old one terminated and freed)
 * Exits 1 on fmi2Discard or worse, after printing the call and status; a warning (logged on
 * stderr) lets the run go on, since the transcripts compare numbers. */
#include <stdarg.h>
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

typedef void *Component;
typedef void (*Logger)(void *, const char *, int, const char *, const char *, ...);
typedef struct {
    Logger logger;
    void *(*allocate)(size_t, size_t);
    void (*free)(void *);
    void *step_finished;
    void *environment;
} Callbacks;

static void log_message(void *env, const char *name, int status, const char *category,
                        const char *message, ...) {
    va_list args;
    (void)env;
    fprintf(stderr, "[%s %d %s] ", name, status, category);
    va_start(args, message);
    vfprintf(stderr, message, args);
    va_end(args);
    fputc('\n', stderr);
}

static void *lib;
static void *symbol(const char *name) {
    void *f = SYMBOL(lib, name);
    if (!f) {
        fprintf(stderr, "missing symbol %s\n", name);
        exit(2);
    }
    return f;
}

static void check(const char *call, int status) {
    if (status > 1) {
        printf("%s returned %d\n", call, status);
        exit(1);
    }
}

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: harness <binary> <guid> < script\n");
        return 2;
    }
    lib = LOAD(argv[1]);
    if (!lib) {
        fprintf(stderr, "cannot load %s\n", argv[1]);
        return 2;
    }
    Component (*instantiate)(const char *, int, const char *, const char *, const Callbacks *,
                             int, int) = symbol("fmi2Instantiate");
    int (*setup)(Component, int, double, double, int, double) = symbol("fmi2SetupExperiment");
    int (*enter)(Component) = symbol("fmi2EnterInitializationMode");
    int (*exit_init)(Component) = symbol("fmi2ExitInitializationMode");
    int (*set_real)(Component, const unsigned *, size_t, const double *) = symbol("fmi2SetReal");
    int (*set_integer)(Component, const unsigned *, size_t, const int *) =
        symbol("fmi2SetInteger");
    int (*set_boolean)(Component, const unsigned *, size_t, const int *) =
        symbol("fmi2SetBoolean");
    int (*get_real)(Component, const unsigned *, size_t, double *) = symbol("fmi2GetReal");
    int (*get_integer)(Component, const unsigned *, size_t, int *) = symbol("fmi2GetInteger");
    int (*get_boolean)(Component, const unsigned *, size_t, int *) = symbol("fmi2GetBoolean");
    int (*get_state)(Component, void **) = symbol("fmi2GetFMUstate");
    int (*set_state)(Component, void *) = symbol("fmi2SetFMUstate");
    int (*free_state)(Component, void **) = symbol("fmi2FreeFMUstate");
    int (*derivative)(Component, const unsigned *, size_t, const unsigned *, size_t,
                      const double *, double *) = symbol("fmi2GetDirectionalDerivative");
    void *state = NULL;
    double saved_time = 0.0;
    int (*do_step)(Component, double, double, int) = symbol("fmi2DoStep");
    int (*terminate)(Component) = symbol("fmi2Terminate");
    void (*free_instance)(Component) = symbol("fmi2FreeInstance");
    Callbacks callbacks = {log_message, calloc, free, NULL, NULL};
    Component c = instantiate("harness", 1, argv[2], NULL, &callbacks, 0, 0);
    if (!c) {
        printf("fmi2Instantiate returned NULL\n");
        return 1;
    }
    check("fmi2SetupExperiment", setup(c, 0, 0.0, 0.0, 0, 0.0));
    check("fmi2EnterInitializationMode", enter(c));
    double time = 0.0;
    char line[4096];
    while (fgets(line, sizeof line, stdin)) {
        char *p = line;
        char op = *p++;
        unsigned vr;
        double x;
        int n, k;
        switch (op) {
        case 'R':
            sscanf(p, "%u %lf", &vr, &x);
            check("fmi2SetReal", set_real(c, &vr, 1, &x));
            break;
        case 'I':
        case 'B':
            sscanf(p, "%u %d", &vr, &k);
            check(op == 'I' ? "fmi2SetInteger" : "fmi2SetBoolean",
                  (op == 'I' ? set_integer : set_boolean)(c, &vr, 1, &k));
            break;
        case 'X':
            check("fmi2ExitInitializationMode", exit_init(c));
            break;
        case 'S':
            sscanf(p, "%lf", &x);
            check("fmi2DoStep", do_step(c, time, x, 1));
            time += x;
            break;
        case 'N':
            if (state) check("fmi2FreeFMUstate", free_state(c, &state));
            check("fmi2Terminate", terminate(c));
            free_instance(c);
            c = instantiate("harness", 1, argv[2], NULL, &callbacks, 0, 0);
            if (!c) {
                printf("fmi2Instantiate returned NULL\n");
                return 1;
            }
            check("fmi2SetupExperiment", setup(c, 0, 0.0, 0.0, 0, 0.0));
            check("fmi2EnterInitializationMode", enter(c));
            time = 0.0;
            break;
        case 'G': {
            /* Reals, then after ';' Integers, then after another ';' Booleans. */
            int section = 0;
            for (;;) {
                while (*p == ' ') p++;
                if (*p == ';') {
                    section++;
                    p++;
                    continue;
                }
                if (sscanf(p, "%u%n", &vr, &n) != 1) break;
                p += n;
                if (section == 0) {
                    check("fmi2GetReal", get_real(c, &vr, 1, &x));
                    printf("%.17g ", x);
                } else {
                    check(section == 1 ? "fmi2GetInteger" : "fmi2GetBoolean",
                          (section == 1 ? get_integer : get_boolean)(c, &vr, 1, &k));
                    printf("%d ", k);
                }
            }
            printf("\n");
            break;
        }
        case 'D': {
            /* d unknown / d known with seed 1. */
            unsigned known;
            double seed = 1.0;
            sscanf(p, "%u %u", &vr, &known);
            check("fmi2GetDirectionalDerivative", derivative(c, &vr, 1, &known, 1, &seed, &x));
            printf("%.17g\n", x);
            break;
        }
        case 'F':
            check("fmi2GetFMUstate", get_state(c, &state));
            saved_time = time;
            break;
        case 'L':
            check("fmi2SetFMUstate", set_state(c, state));
            time = saved_time;
            break;
        default:
            break;
        }
    }
    if (state) check("fmi2FreeFMUstate", free_state(c, &state));
    check("fmi2Terminate", terminate(c));
    free_instance(c);
    return 0;
}
