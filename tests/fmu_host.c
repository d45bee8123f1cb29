/* A minimal FMI 2 / FMI 3 importer for the tests: loads an FMU binary, instantiates it for co-simulation
   or model exchange and follows a script read from stdin (UTF-8, tab-separated, so paths may hold any
   character), printing each value asked for with 17 digits. Built natively, for Windows (run under
   Wine) and for aarch64 Linux (run under qemu-user) by tests/test_fmu_prebuilt.py, so the three runs
   of the same script can be compared.

   dll <path> | fmi <2|3> | kind <cs|me> | token <token> | resources <location> | nx <states>
   init <start time> | set <vr> <value> | step <h> | get <vr>
   (dll .. nx before init; model exchange integrates with explicit Euler at the step size) */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "fmi3Functions.h"

#ifdef _WIN32
#include <windows.h>
static void *load(const char *path) {
    wchar_t wide[4096];
    if (!MultiByteToWideChar(CP_UTF8, 0, path, -1, wide, 4096)) return NULL;
    return (void *)LoadLibraryW(wide);
}
#define SYMBOL(h, n) ((void *)GetProcAddress((HMODULE)(h), (n)))
#else
#include <dlfcn.h>
static void *load(const char *path) { return dlopen(path, RTLD_NOW | RTLD_LOCAL); }
#define SYMBOL(h, n) dlsym((h), (n))
#endif

#define MAX_STATES 64

static void *lib;
static void *get(const char *name) {
    void *f = SYMBOL(lib, name);
    if (!f) {
        printf("error: no symbol %s\n", name);
        exit(1);
    }
    return f;
}
#define F(type, name) ((type)get(#name))
#define CHECK(call)                                  \
    do {                                             \
        if ((int)(call) > 1) {                       \
            printf("error: %s failed\n", #call);     \
            exit(1);                                 \
        }                                            \
    } while (0)

static void logFmi2(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                 fmi2String message, ...) {
    (void)env, (void)name;
    fprintf(stderr, "[%d %s] %s\n", (int)status, category, message);
}
static void logFmi3(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message) {
    (void)env;
    fprintf(stderr, "[%d %s] %s\n", (int)status, category, message);
}

int main(void) {
    char line[8192], dll[4096] = "", token[256] = "", resources[4096] = "", kind[8] = "cs";
    int fmi = 2, nx = 0, me;
    void *c = NULL;
    double t = 0, x[MAX_STATES], dx[MAX_STATES];
    fmi2CallbackFunctions callbacks = {logFmi2, calloc, free, NULL, NULL};
    while (fgets(line, sizeof line, stdin)) {
        char *key = strtok(line, "\t\r\n"), *a = strtok(NULL, "\t\r\n"), *b = strtok(NULL, "\t\r\n");
        if (!key) continue;
        if (!strcmp(key, "dll")) snprintf(dll, sizeof dll, "%s", a);
        else if (!strcmp(key, "fmi")) fmi = atoi(a);
        else if (!strcmp(key, "kind")) snprintf(kind, sizeof kind, "%s", a);
        else if (!strcmp(key, "token")) snprintf(token, sizeof token, "%s", a);
        else if (!strcmp(key, "resources")) snprintf(resources, sizeof resources, "%s", a);
        else if (!strcmp(key, "nx")) nx = atoi(a);
        else if (!strcmp(key, "init")) {
            t = atof(a);
            me = !strcmp(kind, "me");
            if (nx > MAX_STATES || !(lib = load(dll))) {
                printf("error: cannot load %s\n", dll);
                return 1;
            }
            if (fmi == 2) {
                c = F(fmi2InstantiateTYPE *, fmi2Instantiate)("host", me ? fmi2ModelExchange : fmi2CoSimulation,
                                                              token, resources, &callbacks, fmi2False, fmi2False);
                if (!c) return printf("error: fmi2Instantiate returned NULL\n"), 1;
                CHECK(F(fmi2SetupExperimentTYPE *, fmi2SetupExperiment)(c, fmi2False, 0, t, fmi2False, 0));
                CHECK(F(fmi2EnterInitializationModeTYPE *, fmi2EnterInitializationMode)(c));
                CHECK(F(fmi2ExitInitializationModeTYPE *, fmi2ExitInitializationMode)(c));
                if (me) {
                    fmi2EventInfo info = {fmi2True};
                    while (info.newDiscreteStatesNeeded && !info.terminateSimulation)
                        CHECK(F(fmi2NewDiscreteStatesTYPE *, fmi2NewDiscreteStates)(c, &info));
                    CHECK(F(fmi2EnterContinuousTimeModeTYPE *, fmi2EnterContinuousTimeMode)(c));
                }
            } else {
                c = me ? F(fmi3InstantiateModelExchangeTYPE *, fmi3InstantiateModelExchange)(
                             "host", token, resources, fmi3False, fmi3False, NULL, logFmi3)
                       : F(fmi3InstantiateCoSimulationTYPE *, fmi3InstantiateCoSimulation)(
                             "host", token, resources, fmi3False, fmi3False, fmi3False, fmi3False, NULL, 0, NULL,
                             logFmi3, NULL);
                if (!c) return printf("error: fmi3Instantiate returned NULL\n"), 1;
                CHECK(F(fmi3EnterInitializationModeTYPE *, fmi3EnterInitializationMode)(c, fmi3False, 0, t,
                                                                                          fmi3False, 0));
                CHECK(F(fmi3ExitInitializationModeTYPE *, fmi3ExitInitializationMode)(c));
                if (me) {
                    fmi3Boolean update = fmi3True, stop = fmi3False, n, v, d;
                    fmi3Float64 next;
                    while (update && !stop)
                        CHECK(F(fmi3UpdateDiscreteStatesTYPE *, fmi3UpdateDiscreteStates)(c, &update, &stop, &n,
                                                                                          &v, &d, &next));
                    CHECK(F(fmi3EnterContinuousTimeModeTYPE *, fmi3EnterContinuousTimeMode)(c));
                }
            }
        } else if (!strcmp(key, "set")) {
            unsigned vr = (unsigned)strtoul(a, NULL, 10);
            double value = strtod(b, NULL);
            if (fmi == 2) CHECK(F(fmi2SetRealTYPE *, fmi2SetReal)(c, &vr, 1, &value));
            else CHECK(F(fmi3SetFloat64TYPE *, fmi3SetFloat64)(c, &vr, 1, &value, 1));
        } else if (!strcmp(key, "get")) {
            unsigned vr = (unsigned)strtoul(a, NULL, 10);
            double value;
            if (fmi == 2) CHECK(F(fmi2GetRealTYPE *, fmi2GetReal)(c, &vr, 1, &value));
            else CHECK(F(fmi3GetFloat64TYPE *, fmi3GetFloat64)(c, &vr, 1, &value, 1));
            printf("%.17g\n", value);
        } else if (!strcmp(key, "step")) {
            double h = strtod(a, NULL);
            if (!me && fmi == 2) {
                CHECK(F(fmi2DoStepTYPE *, fmi2DoStep)(c, t, h, fmi2True));
            } else if (!me) {
                fmi3Boolean event, stop, early;
                fmi3Float64 last;
                CHECK(F(fmi3DoStepTYPE *, fmi3DoStep)(c, t, h, fmi3True, &event, &stop, &early, &last));
            } else if (fmi == 2) {
                fmi2Boolean enter, stop;
                CHECK(F(fmi2GetContinuousStatesTYPE *, fmi2GetContinuousStates)(c, x, nx));
                CHECK(F(fmi2GetDerivativesTYPE *, fmi2GetDerivatives)(c, dx, nx));
                for (int i = 0; i < nx; i++) x[i] += h * dx[i];
                CHECK(F(fmi2SetTimeTYPE *, fmi2SetTime)(c, t + h));
                CHECK(F(fmi2SetContinuousStatesTYPE *, fmi2SetContinuousStates)(c, x, nx));
                CHECK(F(fmi2CompletedIntegratorStepTYPE *, fmi2CompletedIntegratorStep)(c, fmi2True, &enter, &stop));
            } else {
                fmi3Boolean enter, stop;
                CHECK(F(fmi3GetContinuousStatesTYPE *, fmi3GetContinuousStates)(c, x, nx));
                CHECK(F(fmi3GetContinuousStateDerivativesTYPE *, fmi3GetContinuousStateDerivatives)(c, dx, nx));
                for (int i = 0; i < nx; i++) x[i] += h * dx[i];
                CHECK(F(fmi3SetTimeTYPE *, fmi3SetTime)(c, t + h));
                CHECK(F(fmi3SetContinuousStatesTYPE *, fmi3SetContinuousStates)(c, x, nx));
                CHECK(F(fmi3CompletedIntegratorStepTYPE *, fmi3CompletedIntegratorStep)(c, fmi3True, &enter,
                                                                                        &stop));
            }
            t += h;
        }
    }
    if (c && fmi == 2) F(fmi2FreeInstanceTYPE *, fmi2FreeInstance)(c);
    if (c && fmi == 3) F(fmi3FreeInstanceTYPE *, fmi3FreeInstance)(c);
    return 0;
}
