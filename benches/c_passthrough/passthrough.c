/*
 * A C pass-through FMU (FMI 2.0 Co-Simulation), written for this project as a bench fixture: the
 * yardstick for the cost of our Rust FMI layer (benches/parity.rs, `make bench`).
 *
 * It keeps the call semantics of the Modelica Reference-FMUs' Feedthrough, the usual hand-written C
 * FMU: one Real input u (value reference 0) and one Real output y = u (value reference 1);
 *   - every function checks the instance and its state against a bitmask of allowed states
 *     (FMI 2.0 section 4.2.4) and logs "Illegal call sequence" otherwise;
 *   - fmi2SetReal/fmi2GetReal check the arrays for NULL, dispatch on the value reference with a
 *     switch and refuse unknown ones; a set marks the outputs dirty, a get recomputes them first;
 *   - fmi2DoStep refuses a non-positive step and a communication point that is not the instance's
 *     time, then advances the time by counting fixed solver steps from the start time.
 * All other functions exist (importers resolve every symbol) and refuse what they do not support.
 *
 * Built by `make bench` with: cc -O2 -shared -fPIC -o target/c_passthrough/PassThroughC.so
 */

#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef void *fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef char fmi2Char;
typedef const fmi2Char *fmi2String;
typedef char fmi2Byte;

typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef enum { fmi2DoStepStatus, fmi2PendingStatus, fmi2LastSuccessfulTime, fmi2Terminated } fmi2StatusKind;

typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, ...);
typedef struct {
    fmi2CallbackLogger logger;
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(fmi2ComponentEnvironment, fmi2Status);
    fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

#define EXPORT __attribute__((visibility("default")))

#define GUID "{c-passthrough-bench-fixture}"
enum { VR_U = 0, VR_Y = 1 };
/* Fixed solver step of the internal clock; the step counter gives the time without drift. */
#define SOLVER_STEP 1e-3
/* Communication points match within an absolute or relative 1e-5, as the Reference-FMUs allow. */
#define TIME_EPSILON 1e-5

enum {
    Instantiated = 1 << 0,
    InitializationMode = 1 << 1,
    StepComplete = 1 << 2,
    StepFailed = 1 << 3,
    Terminated = 1 << 4,
    Error = 1 << 5,
    Fatal = 1 << 6,
};

#define ALL_BUT_FATAL (Instantiated | InitializationMode | StepComplete | StepFailed | Terminated | Error)
#define MASK_SET (Instantiated | InitializationMode | StepComplete)
#define MASK_GET (InitializationMode | StepComplete | StepFailed | Terminated | Error)
#define MASK_STATUS (StepComplete | StepFailed | Terminated)

typedef struct {
    char *name;
    fmi2CallbackLogger logger;
    fmi2ComponentEnvironment environment;
    int state;
    int dirty;
    double start_time, time;
    long long steps;
    double u, y;
} Instance;

static void log_error(Instance *inst, const char *fmt, ...) {
    char text[256];
    va_list args;
    if (!inst->logger) return;
    va_start(args, fmt);
    vsnprintf(text, sizeof text, fmt, args);
    va_end(args);
    inst->logger(inst->environment, inst->name, fmi2Error, "logStatusError", "%s", text);
}

static int allowed(fmi2Component c, int mask, const char *function) {
    Instance *inst = (Instance *)c;
    if (!inst) return 0;
    if (!(inst->state & mask)) {
        log_error(inst, "%s: Illegal call sequence.", function);
        return 0;
    }
    return 1;
}

#define CHECK(mask, name) \
    if (!allowed(c, mask, name)) return fmi2Error
#define I ((Instance *)c)

static int null_argument(Instance *inst, const char *function, const char *argument, const void *p) {
    if (p) return 0;
    log_error(inst, "%s: Invalid argument %s = NULL.", function, argument);
    return 1;
}

static int is_close(double a, double b) {
    const double d = fabs(a - b);
    return isfinite(a) && isfinite(b) && (d <= TIME_EPSILON || d <= TIME_EPSILON * fmax(fabs(a), fabs(b)));
}

static void set_start_values(Instance *inst) {
    inst->u = 0.0;
    inst->dirty = 1;
}

static void calculate_values(Instance *inst) { inst->y = inst->u; }

EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }

EXPORT fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resources,
                                     const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                                     fmi2Boolean logging_on) {
    (void)resources, (void)visible, (void)logging_on;
    fmi2CallbackLogger logger = functions ? functions->logger : NULL;
    fmi2ComponentEnvironment env = functions ? functions->componentEnvironment : NULL;
    if (!name || !*name || type != fmi2CoSimulation || !guid || strcmp(guid, GUID) != 0) {
        if (logger) logger(env, name ? name : "?", fmi2Error, "logStatusError", "fmi2Instantiate: refused");
        return NULL;
    }
    Instance *inst = calloc(1, sizeof *inst);
    if (!inst) return NULL;
    inst->name = strdup(name);
    inst->logger = logger;
    inst->environment = env;
    inst->state = Instantiated;
    set_start_values(inst);
    return inst;
}

EXPORT void fmi2FreeInstance(fmi2Component c) {
    if (!c) return;
    free(I->name);
    free(c);
}

EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String categories[]) {
    (void)on, (void)n, (void)categories;
    CHECK(ALL_BUT_FATAL, "fmi2SetDebugLogging");
    return fmi2OK;
}

EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tolerance_defined, fmi2Real tolerance,
                                      fmi2Real start, fmi2Boolean stop_defined, fmi2Real stop) {
    (void)tolerance_defined, (void)tolerance, (void)stop_defined, (void)stop;
    CHECK(Instantiated, "fmi2SetupExperiment");
    I->start_time = I->time = start;
    I->steps = 0;
    return fmi2OK;
}

EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    CHECK(Instantiated, "fmi2EnterInitializationMode");
    I->state = InitializationMode;
    return fmi2OK;
}

EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    CHECK(InitializationMode, "fmi2ExitInitializationMode");
    if (I->dirty) {
        calculate_values(I);
        I->dirty = 0;
    }
    I->state = StepComplete;
    return fmi2OK;
}

EXPORT fmi2Status fmi2Terminate(fmi2Component c) {
    CHECK(StepComplete | StepFailed, "fmi2Terminate");
    I->state = Terminated;
    return fmi2OK;
}

EXPORT fmi2Status fmi2Reset(fmi2Component c) {
    CHECK(ALL_BUT_FATAL, "fmi2Reset");
    I->state = Instantiated;
    I->start_time = I->time = 0.0;
    I->steps = 0;
    set_start_values(I);
    return fmi2OK;
}

EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
    CHECK(MASK_SET, "fmi2SetReal");
    if (nvr > 0 && (null_argument(I, "fmi2SetReal", "vr[]", vr) || null_argument(I, "fmi2SetReal", "value[]", value)))
        return fmi2Error;
    for (size_t i = 0; i < nvr; i++) {
        switch (vr[i]) {
        case VR_U:
            I->u = value[i];
            break;
        default:
            log_error(I, "fmi2SetReal: cannot set value reference %u.", vr[i]);
            return fmi2Error;
        }
    }
    if (nvr > 0) I->dirty = 1;
    return fmi2OK;
}

EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
    CHECK(MASK_GET, "fmi2GetReal");
    if (nvr > 0 && (null_argument(I, "fmi2GetReal", "vr[]", vr) || null_argument(I, "fmi2GetReal", "value[]", value)))
        return fmi2Error;
    if (nvr > 0 && I->dirty) {
        calculate_values(I);
        I->dirty = 0;
    }
    for (size_t i = 0; i < nvr; i++) {
        switch (vr[i]) {
        case VR_U:
            value[i] = I->u;
            break;
        case VR_Y:
            value[i] = I->y;
            break;
        default:
            log_error(I, "fmi2GetReal: unknown value reference %u.", vr[i]);
            return fmi2Error;
        }
    }
    return fmi2OK;
}

#define NO_VALUES(function, type, qualifier)                                                                      \
    EXPORT fmi2Status function(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, qualifier type value[]) { \
        (void)vr, (void)value;                                                                                    \
        CHECK(ALL_BUT_FATAL, #function);                                                                          \
        if (nvr == 0) return fmi2OK;                                                                              \
        log_error(I, #function ": this FMU has no such variables.");                                              \
        return fmi2Error;                                                                                         \
    }
NO_VALUES(fmi2GetInteger, fmi2Integer, )
NO_VALUES(fmi2GetBoolean, fmi2Boolean, )
NO_VALUES(fmi2GetString, fmi2String, )
NO_VALUES(fmi2SetInteger, fmi2Integer, const)
NO_VALUES(fmi2SetBoolean, fmi2Boolean, const)
NO_VALUES(fmi2SetString, fmi2String, const)

static fmi2Status unsupported(fmi2Component c, const char *function) {
    CHECK(ALL_BUT_FATAL, function);
    log_error(I, "%s: not supported.", function);
    return fmi2Error;
}

EXPORT fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)s; return unsupported(c, "fmi2GetFMUstate"); }
EXPORT fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) { (void)s; return unsupported(c, "fmi2SetFMUstate"); }
EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)s; return unsupported(c, "fmi2FreeFMUstate"); }
EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *n) {
    (void)s, (void)n;
    return unsupported(c, "fmi2SerializedFMUstateSize");
}
EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t n) {
    (void)s, (void)b, (void)n;
    return unsupported(c, "fmi2SerializeFMUstate");
}
EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t n, fmi2FMUstate *s) {
    (void)s, (void)b, (void)n;
    return unsupported(c, "fmi2DeSerializeFMUstate");
}
EXPORT fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                               const fmi2ValueReference k[], size_t nk, const fmi2Real dk[],
                                               fmi2Real du[]) {
    (void)u, (void)nu, (void)k, (void)nk, (void)dk, (void)du;
    return unsupported(c, "fmi2GetDirectionalDerivative");
}
EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                              const fmi2Integer order[], const fmi2Real value[]) {
    (void)vr, (void)nvr, (void)order, (void)value;
    return unsupported(c, "fmi2SetRealInputDerivatives");
}
EXPORT fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                               const fmi2Integer order[], fmi2Real value[]) {
    (void)vr, (void)nvr, (void)order, (void)value;
    return unsupported(c, "fmi2GetRealOutputDerivatives");
}
EXPORT fmi2Status fmi2CancelStep(fmi2Component c) { return unsupported(c, "fmi2CancelStep"); }

EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean no_prior_state) {
    (void)no_prior_state;
    CHECK(StepComplete, "fmi2DoStep");
    if (!(h > 0)) {
        log_error(I, "fmi2DoStep: communication step size must be > 0 but was %g.", h);
        I->state = Error;
        return fmi2Error;
    }
    if (!is_close(t, I->time)) {
        log_error(I, "fmi2DoStep: expected currentCommunicationPoint = %.16g but was %.16g.", I->time, t);
        I->state = Error;
        return fmi2Error;
    }
    /* y = u needs no integration: the solver only counts its fixed steps up to the next point. */
    const double next = t + h + TIME_EPSILON;
    while (I->start_time + (I->steps + 1) * SOLVER_STEP <= next) {
        I->steps++;
        I->time = I->start_time + I->steps * SOLVER_STEP;
    }
    return fmi2OK;
}

static fmi2Status no_status(fmi2Component c, const char *function, const void *value) {
    CHECK(MASK_STATUS, function);
    if (null_argument(I, function, "value", value)) return fmi2Error;
    return fmi2Discard;
}

EXPORT fmi2Status fmi2GetStatus(fmi2Component c, fmi2StatusKind s, fmi2Status *value) {
    (void)s;
    return no_status(c, "fmi2GetStatus", value);
}
EXPORT fmi2Status fmi2GetRealStatus(fmi2Component c, fmi2StatusKind s, fmi2Real *value) {
    fmi2Status status = no_status(c, "fmi2GetRealStatus", value);
    if (status != fmi2Discard || s != fmi2LastSuccessfulTime) return status;
    *value = I->time;
    return fmi2OK;
}
EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component c, fmi2StatusKind s, fmi2Integer *value) {
    (void)s;
    return no_status(c, "fmi2GetIntegerStatus", value);
}
EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component c, fmi2StatusKind s, fmi2Boolean *value) {
    fmi2Status status = no_status(c, "fmi2GetBooleanStatus", value);
    if (status != fmi2Discard || s != fmi2Terminated) return status;
    *value = 0;
    return fmi2OK;
}
EXPORT fmi2Status fmi2GetStringStatus(fmi2Component c, fmi2StatusKind s, fmi2String *value) {
    (void)s;
    return no_status(c, "fmi2GetStringStatus", value);
}
