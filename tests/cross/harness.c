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
 *   G vr ...                               print the Reals (one line)
 *   N                                      a fresh instance (the old one terminated and freed)
 * Exits 1 on any status other than fmi2OK, after printing the call and status. */
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
    if (status != 0) {
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
        case 'G':
            while (sscanf(p, "%u%n", &vr, &n) == 1) {
                p += n;
                check("fmi2GetReal", get_real(c, &vr, 1, &x));
                printf("%.17g ", x);
            }
            printf("\n");
            break;
        default:
            break;
        }
    }
    check("fmi2Terminate", terminate(c));
    free_instance(c);
    return 0;
}
