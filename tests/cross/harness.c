/* A minimal FMI 2.0 master for the cross-platform tests: loads one FMU binary, instantiates it as
 * Co-Simulation or Model Exchange and runs a script read from stdin, printing every value it reads
 * with 17 significant digits. The same source is built natively, with mingw-w64 (run under wine)
 * and with the aarch64 cross gcc (run under qemu-user), all with -ffp-contract=off so that the
 * Euler update below rounds alike everywhere; tests/fmpy/test_cross_platform.py compares the
 * three transcripts.
 *
 * usage: harness <binary> <guid> [me <states> <event indicators>]   script lines on stdin:
 *   R vr value | I vr value | B vr value   set a Real, Integer or Boolean
 *   X                                      exit initialization mode (entered at start); in Model
 *                                          Exchange then the event iteration and continuous time
 *   S h                                    Co-Simulation: fmi2DoStep from the current time by h;
 *                                          Model Exchange: K explicit Euler substeps over h (each
 *                                          ending at a time event if one comes first), with event
 *                                          mode at time, state and step events
 *   K n                                    Model Exchange: n substeps per S (default 1)
 *   G vr ... [; vr ... [; vr ...]]         print Reals [; Integers [; Booleans]]
 *   Z                                      Model Exchange: print states, derivatives, indicators
 *   D unknown known                        print the directional derivative, seed 1
 *   F | L                                  save the FMU state | restore it (and its time)
 *   P | Q                                  serialize the FMU state (print its size) | deserialize
 *                                          those bytes into a new FMU state and restore it
 *   N                                      a fresh instance (the old one terminated and freed)
 * Every printed line starts with a tag (r i b: Real, Integer, Boolean outputs; d: a directional
 * derivative; x f z: states, derivatives, event indicators; s: a serialized state's size; e: the
 * number of events so far) so that the test counts what it compared. Exits 1 on fmi2Discard or
 * worse, after printing the call and status; a warning (logged on stderr) lets the run go on,
 * since the transcripts compare numbers. */
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

#define MAX_STATES 64

typedef void *Component;
typedef void (*Logger)(void *, const char *, int, const char *, const char *, ...);
typedef struct {
    Logger logger;
    void *(*allocate)(size_t, size_t);
    void (*free)(void *);
    void *step_finished;
    void *environment;
} Callbacks;

typedef struct {
    int new_discrete_states_needed;
    int terminate_simulation;
    int nominals_changed;
    int values_changed;
    int next_event_time_defined;
    double next_event_time;
} EventInfo;

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

/* Model Exchange entry points and the integrator's state. */
static int (*new_discrete_states)(Component, EventInfo *);
static int (*enter_event_mode)(Component);
static int (*enter_continuous_time_mode)(Component);
static int (*completed_integrator_step)(Component, int, int *, int *);
static int (*set_time)(Component, double);
static int (*set_states)(Component, const double *, size_t);
static int (*get_states)(Component, double *, size_t);
static int (*get_derivatives)(Component, double *, size_t);
static int (*get_indicators)(Component, double *, size_t);
static size_t nx, nz;
static EventInfo event_info;
static int events;

/* Event mode until the FMU needs no more discrete-state iterations, then continuous time. */
static void event_iteration(Component c) {
    event_info.new_discrete_states_needed = 1;
    while (event_info.new_discrete_states_needed) {
        check("fmi2NewDiscreteStates", new_discrete_states(c, &event_info));
        if (event_info.terminate_simulation) {
            printf("fmi2NewDiscreteStates asked to terminate\n");
            exit(1);
        }
    }
    check("fmi2EnterContinuousTimeMode", enter_continuous_time_mode(c));
}

/* One explicit Euler substep from `*time` to `end`, with event mode at a state event (an
 * indicator changes sign), a time event reached, or when the FMU asks after the step. */
static void euler_substep(Component c, double *time, double end) {
    double x[MAX_STATES], dx[MAX_STATES], z0[MAX_STATES], z1[MAX_STATES];
    int step_event = 0, terminate = 0, state_event = 0;
    size_t i;
    check("fmi2GetContinuousStates", get_states(c, x, nx));
    check("fmi2GetDerivatives", get_derivatives(c, dx, nx));
    check("fmi2GetEventIndicators", get_indicators(c, z0, nz));
    for (i = 0; i < nx; i++) x[i] += (end - *time) * dx[i];
    *time = end;
    check("fmi2SetTime", set_time(c, *time));
    check("fmi2SetContinuousStates", set_states(c, x, nx));
    check("fmi2GetEventIndicators", get_indicators(c, z1, nz));
    for (i = 0; i < nz; i++) state_event |= (z0[i] > 0) != (z1[i] > 0);
    check("fmi2CompletedIntegratorStep", completed_integrator_step(c, 1, &step_event, &terminate));
    if (terminate) {
        printf("fmi2CompletedIntegratorStep asked to terminate\n");
        exit(1);
    }
    if (state_event || step_event ||
        (event_info.next_event_time_defined && *time >= event_info.next_event_time)) {
        check("fmi2EnterEventMode", enter_event_mode(c));
        event_iteration(c);
        events++;
    }
}

static void print_reals(char tag, const double *v, size_t n) {
    size_t i;
    printf("%c", tag);
    for (i = 0; i < n; i++) printf(" %.17g", v[i]);
    printf("\n");
}

int main(int argc, char **argv) {
    int model_exchange = argc == 6 && strcmp(argv[3], "me") == 0;
    if (argc != 3 && !model_exchange) {
        fprintf(stderr, "usage: harness <binary> <guid> [me <states> <indicators>] < script\n");
        return 2;
    }
    if (model_exchange) {
        nx = (size_t)atoi(argv[4]);
        nz = (size_t)atoi(argv[5]);
        if (nx > MAX_STATES || nz > MAX_STATES) {
            fprintf(stderr, "at most %d states and event indicators\n", MAX_STATES);
            return 2;
        }
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
    int (*serialized_size)(Component, void *, size_t *) = symbol("fmi2SerializedFMUstateSize");
    int (*serialize)(Component, void *, char *, size_t) = symbol("fmi2SerializeFMUstate");
    int (*deserialize)(Component, const char *, size_t, void **) =
        symbol("fmi2DeSerializeFMUstate");
    int (*derivative)(Component, const unsigned *, size_t, const unsigned *, size_t,
                      const double *, double *) = symbol("fmi2GetDirectionalDerivative");
    int (*do_step)(Component, double, double, int) =
        model_exchange ? NULL : symbol("fmi2DoStep");
    int (*terminate)(Component) = symbol("fmi2Terminate");
    void (*free_instance)(Component) = symbol("fmi2FreeInstance");
    if (model_exchange) {
        new_discrete_states = symbol("fmi2NewDiscreteStates");
        enter_event_mode = symbol("fmi2EnterEventMode");
        enter_continuous_time_mode = symbol("fmi2EnterContinuousTimeMode");
        completed_integrator_step = symbol("fmi2CompletedIntegratorStep");
        set_time = symbol("fmi2SetTime");
        set_states = symbol("fmi2SetContinuousStates");
        get_states = symbol("fmi2GetContinuousStates");
        get_derivatives = symbol("fmi2GetDerivatives");
        get_indicators = symbol("fmi2GetEventIndicators");
    }
    void *state = NULL;
    char *bytes = NULL;
    size_t size = 0;
    double saved_time = 0.0, serialized_time = 0.0;
    /* A restored state brings back the event information of its time, as a master keeps it. */
    EventInfo saved_events = {0}, serialized_events = {0};
    int substeps = 1;
    Callbacks callbacks = {log_message, calloc, free, NULL, NULL};
    Component c = NULL;
    double time = 0.0;
    char line[4096];
    /* The first instance is made as `N` makes every later one. */
    int fresh = 1;
    while (fresh || fgets(line, sizeof line, stdin)) {
        char *p = line;
        char op = fresh ? 'N' : *p++;
        unsigned vr;
        double x;
        int n, k;
        fresh = 0;
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
            if (model_exchange) event_iteration(c);
            break;
        case 'K':
            sscanf(p, "%d", &substeps);
            break;
        case 'S':
            sscanf(p, "%lf", &x);
            if (model_exchange) {
                /* Substep ends are fractions of the step, not sums, so that rounding cannot
                 * pile up; a time event inside a substep ends it there. */
                double start = time, end = time + x;
                for (k = 1; k <= substeps; k++) {
                    double target = k == substeps ? end : start + x * k / substeps;
                    while (time < target) {
                        double stop = target;
                        if (event_info.next_event_time_defined &&
                            event_info.next_event_time > time && event_info.next_event_time < stop)
                            stop = event_info.next_event_time;
                        euler_substep(c, &time, stop);
                    }
                }
                time = end;
            } else {
                check("fmi2DoStep", do_step(c, time, x, 1));
                time += x;
            }
            break;
        case 'N':
            if (c) {
                if (state) check("fmi2FreeFMUstate", free_state(c, &state));
                check("fmi2Terminate", terminate(c));
                free_instance(c);
            }
            c = instantiate("harness", model_exchange ? 0 : 1, argv[2], NULL, &callbacks, 0, 0);
            if (!c) {
                printf("fmi2Instantiate returned NULL\n");
                return 1;
            }
            check("fmi2SetupExperiment", setup(c, 0, 0.0, 0.0, 0, 0.0));
            check("fmi2EnterInitializationMode", enter(c));
            time = 0.0;
            events = 0;
            memset(&event_info, 0, sizeof event_info);
            break;
        case 'G': {
            /* Reals, then after ';' Integers, then after another ';' Booleans: one line each. */
            int section = 0;
            printf("r");
            for (;;) {
                while (*p == ' ') p++;
                if (*p == ';') {
                    section++;
                    printf("\n%c", section == 1 ? 'i' : 'b');
                    p++;
                    continue;
                }
                if (sscanf(p, "%u%n", &vr, &n) != 1) break;
                p += n;
                if (section == 0) {
                    check("fmi2GetReal", get_real(c, &vr, 1, &x));
                    printf(" %.17g", x);
                } else {
                    check(section == 1 ? "fmi2GetInteger" : "fmi2GetBoolean",
                          (section == 1 ? get_integer : get_boolean)(c, &vr, 1, &k));
                    printf(" %d", k);
                }
            }
            printf("\n");
            break;
        }
        case 'Z': {
            double v[MAX_STATES];
            check("fmi2GetContinuousStates", get_states(c, v, nx));
            print_reals('x', v, nx);
            check("fmi2GetDerivatives", get_derivatives(c, v, nx));
            print_reals('f', v, nx);
            check("fmi2GetEventIndicators", get_indicators(c, v, nz));
            print_reals('z', v, nz);
            printf("e %d\n", events);
            break;
        }
        case 'D': {
            /* d unknown / d known with seed 1. */
            unsigned known;
            double seed = 1.0;
            sscanf(p, "%u %u", &vr, &known);
            check("fmi2GetDirectionalDerivative", derivative(c, &vr, 1, &known, 1, &seed, &x));
            printf("d %.17g\n", x);
            break;
        }
        case 'F':
            if (state) check("fmi2FreeFMUstate", free_state(c, &state));
            check("fmi2GetFMUstate", get_state(c, &state));
            saved_time = time;
            saved_events = event_info;
            break;
        case 'L':
            check("fmi2SetFMUstate", set_state(c, state));
            time = saved_time;
            event_info = saved_events;
            break;
        case 'P': {
            void *current = NULL;
            check("fmi2GetFMUstate", get_state(c, &current));
            check("fmi2SerializedFMUstateSize", serialized_size(c, current, &size));
            free(bytes);
            bytes = malloc(size);
            if (!bytes) return 2;
            check("fmi2SerializeFMUstate", serialize(c, current, bytes, size));
            check("fmi2FreeFMUstate", free_state(c, &current));
            serialized_time = time;
            serialized_events = event_info;
            printf("s %u\n", (unsigned)size);
            break;
        }
        case 'Q': {
            void *restored = NULL;
            check("fmi2DeSerializeFMUstate", deserialize(c, bytes, size, &restored));
            check("fmi2SetFMUstate", set_state(c, restored));
            check("fmi2FreeFMUstate", free_state(c, &restored));
            time = serialized_time;
            event_info = serialized_events;
            break;
        }
        default:
            break;
        }
    }
    if (state) check("fmi2FreeFMUstate", free_state(c, &state));
    free(bytes);
    check("fmi2Terminate", terminate(c));
    free_instance(c);
    return 0;
}
