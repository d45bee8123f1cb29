/* Random FMI 2 and FMI 3 call sequences against the FlexJoint runtime, linked in directly (both FMI
   layers in one executable), for AddressSanitizer + UBSan and valgrind. Arguments: random, NaN, Inf,
   huge and negative numbers, NULL arrays, wrong value references, calls out of order, corrupted and
   foreign serialized states, many instances. The FMI 2 logger formats the message as printf would
   (as libcosim does) and aborts on a conversion that is not "%%".
   Usage: fmi_fuzz SEED CALLS RESOURCES2_FORCE TOKEN RESOURCES2_BODY TOKEN RESOURCES3_FORCE TOKEN
                   RESOURCES3_BODY TOKEN      (FMI 2 resources as file: URIs, FMI 3 as paths) */
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "fmi3Functions.h"

#define SLOTS 12
#define BUF 16
#define POOL 8

typedef struct {
    void *c;
    int version, me;
    double t; /* the instance's time as the fuzzer believes it, to make valid steps too */
    void *states[2];
} Slot;

static uint64_t rng = 88172645463325252ull;
static unsigned long long calls = 0, logs = 0;
static Slot slots[SLOTS];
static unsigned char *pool[POOL];
static size_t poolSize[POOL];
static const char *res[4], *tok[4];

static uint64_t next(void) {
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return rng;
}
static unsigned pick(unsigned n) { return (unsigned)(next() % n); }
static int chance(unsigned percent) { return pick(100) < percent; }

static double number(void) {
    static const double special[] = {0.0, -0.0, 1e-3, -1e-3, 1.0, -1.0, 1e308, -1e308, 5e-324, 2.744, 0.8, 1e-9};
    switch (pick(6)) {
        case 0: return NAN;
        case 1: return chance(50) ? INFINITY : -INFINITY;
        case 2: return special[pick(sizeof(special) / sizeof(special[0]))];
        case 3: return ldexp((double)(next() >> 11), (int)pick(2100) - 1074 - 53);
        default: return ((double)(next() >> 11) / 9007199254740992.0 - 0.5) * 20.0;
    }
}

/* the exported joint declares the axes x (value references 100..108) and theta (400..408) */
static unsigned vref(void) {
    switch (pick(6)) {
        case 0: return (unsigned)next();
        case 1: return pick(4) == 0 ? 0 : pick(1000);
        case 2: return 100 * (1 + pick(6)) + pick(10);
        default: return (chance(50) ? 100 : 400) + pick(9);
    }
}

static double stepSize(void) {
    static const double h[] = {1e-3, 1e-4, 0.37, 1e-9};
    return chance(80) ? h[pick(4)] : number();
}

/* nx: the model's 4 states half of the time */
static size_t states(size_t n) { return chance(50) ? 4 : n; }

static size_t count(void) { return chance(10) ? pick(BUF + 1) : pick(4); }

static void *maybeNull(void *p) { return chance(8) ? NULL : p; }

/* the FMI 2 logger formats `message` as printf would: only "%%" may appear */
static void logger2(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                    fmi2String message, ...) {
    char out[4096];
    const char *p;
    va_list args;
    (void)env;
    (void)status;
    if (!name || !category || !message) abort();
    for (p = strchr(message, '%'); p; p = strchr(p + 2, '%'))
        if (p[1] != '%') {
            fprintf(stderr, "unescaped %% in an FMI 2 log message: %s\n", message);
            abort();
        }
    va_start(args, message);
    vsnprintf(out, sizeof(out), message, args);
    va_end(args);
    logs++;
}

static void logger3(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message) {
    (void)env;
    (void)status;
    if (!category || !message || strlen(message) > 100000) abort();
    logs++;
}

static const fmi2CallbackFunctions callbacks = {logger2, calloc, free, NULL, NULL};

static const char *instanceName(void) {
    static const char *names[] = {"joint", "joint%s%s%s%s", "%n%n%n", "", "100%"};
    return names[pick(5)];
}

static void instantiate(Slot *s) {
    int which = (int)pick(4), version = which < 2 ? 2 : 3, me = chance(50);
    const char *token = chance(5) ? "{wrong}" : tok[chance(5) ? (int)pick(4) : which];
    const char *resources = chance(3) ? NULL : res[which];
    bool logging = chance(70);
    calls++;
    if (version == 2) {
        s->c = fmi2Instantiate(instanceName(), me ? fmi2ModelExchange : fmi2CoSimulation, token, resources,
                               chance(3) ? NULL : &callbacks, fmi2False, logging);
    } else if (me) {
        s->c = fmi3InstantiateModelExchange(instanceName(), token, resources, false, logging, NULL, logger3);
    } else {
        s->c = fmi3InstantiateCoSimulation(instanceName(), token, resources, false, logging, chance(10), false, NULL,
                                           0, NULL, chance(3) ? NULL : logger3, NULL);
    }
    s->version = version;
    s->me = me;
    s->t = 0;
}

static void freeSlot(Slot *s) {
    int i;
    for (i = 0; i < 2; i++) {
        if (!s->states[i]) continue;
        if (s->version == 2) fmi2FreeFMUstate(s->c, &s->states[i]);
        else fmi3FreeFMUState(s->c, &s->states[i]);
        if (s->states[i]) free(s->states[i]); /* refused (wrong state of a dead instance): ours to free */
        s->states[i] = NULL;
    }
    if (s->version == 2) fmi2FreeInstance(s->c);
    else fmi3FreeInstance(s->c);
    s->c = NULL;
    calls++;
}

/* corrupt, truncate or keep a pooled serialized state */
static const unsigned char *pooled(size_t *size) {
    static unsigned char scratch[4096];
    int i = (int)pick(POOL);
    size_t n = poolSize[i];
    if (!pool[i]) {
        *size = pick(200);
        for (n = 0; n < *size; n++) scratch[n] = (unsigned char)next();
        return chance(10) ? NULL : scratch;
    }
    memcpy(scratch, pool[i], n);
    if (chance(50)) scratch[pick((unsigned)n)] ^= (unsigned char)(1u << pick(8));
    if (chance(10)) n = pick((unsigned)n + 8) ;
    if (n > sizeof(scratch)) n = sizeof(scratch);
    *size = n;
    return scratch;
}

static void keep(const unsigned char *bytes, size_t size) {
    int i = (int)pick(POOL);
    free(pool[i]);
    pool[i] = malloc(size);
    memcpy(pool[i], bytes, size);
    poolSize[i] = size;
}

static void callFmi2(Slot *s) {
    fmi2Component c = chance(2) ? NULL : s->c;
    fmi2ValueReference vr[BUF], vk[BUF];
    fmi2Real x[BUF], y[BUF];
    fmi2Boolean b[BUF];
    fmi2Integer in[BUF];
    fmi2String str[BUF] = {"logEvents", "logStatusError", "logStatusDiscard", "bogus"};
    fmi2FMUstate *st = &s->states[pick(2)];
    fmi2EventInfo info;
    fmi2Status status;
    size_t n = count(), i, size;
    unsigned char bytes[4096];
    for (i = 0; i < BUF; i++)
        vr[i] = vref(), vk[i] = vref(), x[i] = number(), y[i] = number(), b[i] = (fmi2Boolean)pick(3), in[i] = (int)pick(4);
    switch (pick(36)) {
        case 0: fmi2SetDebugLogging(c, chance(50), n > 4 ? 4 : n, maybeNull(str)); break;
        case 1: {
            double t0 = number();
            if (fmi2SetupExperiment(c, chance(50), number(), t0, chance(50), number()) == fmi2OK) s->t = t0;
            break;
        }
        case 2: case 3:
            if (fmi2SetupExperiment(c, 0, 0, 0, chance(30), 1.0) == fmi2OK) s->t = 0;
            fmi2EnterInitializationMode(c);
            break;
        case 4: case 5: fmi2ExitInitializationMode(c); break;
        case 6: fmi2Terminate(c); break;
        case 7: if (fmi2Reset(c) == fmi2OK) s->t = 0; break;
        case 8: case 9: fmi2GetReal(c, maybeNull(vr), n, maybeNull(x)); break;
        case 10: case 11: fmi2SetReal(c, maybeNull(vr), n, maybeNull(x)); break;
        case 12: fmi2GetBoolean(c, maybeNull(vr), n, maybeNull(b)); break;
        case 13: fmi2SetBoolean(c, maybeNull(vr), n, maybeNull(b)); break;
        case 14: fmi2GetInteger(c, maybeNull(vr), n, maybeNull(in)); fmi2SetString(c, vr, n, NULL); break;
        case 15: fmi2GetFMUstate(c, chance(5) ? NULL : st); break;
        case 16: fmi2SetFMUstate(c, *st); break;
        case 17: fmi2FreeFMUstate(c, st); break;
        case 18:
            if (fmi2SerializedFMUstateSize(c, *st, &size) == fmi2OK && size <= sizeof(bytes) &&
                fmi2SerializeFMUstate(c, *st, (fmi2Byte *)bytes, chance(10) ? pick((unsigned)size) : size) == fmi2OK)
                keep(bytes, size);
            break;
        case 19: case 20: {
            const unsigned char *p = pooled(&size);
            if (*st) fmi2FreeFMUstate(c, st);
            if (!*st) fmi2DeSerializeFMUstate(c, (const fmi2Byte *)p, size, st);
            break;
        }
        case 21: fmi2GetDirectionalDerivative(c, maybeNull(vr), n, maybeNull(vk), count(), maybeNull(x), maybeNull(y)); break;
        case 22: fmi2EnterEventMode(c); break;
        case 23: fmi2NewDiscreteStates(c, maybeNull(&info)); break;
        case 24: fmi2EnterContinuousTimeMode(c); break;
        case 25: fmi2CompletedIntegratorStep(c, 1, maybeNull(b), maybeNull(b + 1)); break;
        case 26: fmi2SetTime(c, chance(50) ? number() : 1e-3 * pick(100)); break;
        case 27: fmi2SetContinuousStates(c, maybeNull(x), states(n)); break;
        case 28: fmi2GetDerivatives(c, maybeNull(x), states(n)); break;
        case 29: fmi2GetContinuousStates(c, maybeNull(x), states(n)); fmi2GetEventIndicators(c, x, n); break;
        case 30: fmi2GetNominalsOfContinuousStates(c, maybeNull(x), states(n)); break;
        case 31: case 32: {
            double h = stepSize();
            if (chance(80)) {
                if (fmi2DoStep(c, s->t, h, 1) == fmi2OK) s->t += h;
            } else {
                fmi2DoStep(c, number(), h, 1);
            }
            break;
        }
        case 33: fmi2SetRealInputDerivatives(c, vr, n, in, x); fmi2GetRealOutputDerivatives(c, vr, n, in, x); fmi2CancelStep(c); break;
        case 34: fmi2GetStatus(c, (fmi2StatusKind)pick(5), maybeNull(&status)); fmi2GetRealStatus(c, (fmi2StatusKind)pick(5), maybeNull(x)); break;
        default: fmi2GetIntegerStatus(c, (fmi2StatusKind)pick(5), in); fmi2GetBooleanStatus(c, (fmi2StatusKind)pick(5), maybeNull(b)); break;
    }
    calls++;
}

static void callFmi3(Slot *s) {
    fmi3Instance c = chance(2) ? NULL : s->c;
    fmi3ValueReference vr[BUF], vk[BUF];
    fmi3Float64 x[BUF], y[BUF];
    fmi3Boolean b[BUF];
    fmi3Int32 in[BUF];
    fmi3String str[BUF] = {"logEvents", "logStatusError", "logStatusDiscard", "bogus"};
    fmi3FMUState *st = &s->states[pick(2)];
    size_t n = count(), m = chance(80) ? n : count(), i, size, nd;
    unsigned char bytes[4096];
    bool f[6];
    for (i = 0; i < BUF; i++)
        vr[i] = vref(), vk[i] = vref(), x[i] = number(), y[i] = number(), b[i] = chance(50), in[i] = (int)pick(4);
    switch (pick(40)) {
        case 0: fmi3SetDebugLogging(c, chance(50), n > 4 ? 4 : n, maybeNull(str)); break;
        case 1: {
            double t0 = number();
            if (fmi3EnterInitializationMode(c, chance(50), number(), t0, chance(50), number()) == fmi3OK) s->t = t0;
            break;
        }
        case 2: case 3: if (fmi3EnterInitializationMode(c, false, 0, 0, chance(30), 1.0) == fmi3OK) s->t = 0; break;
        case 4: case 5: fmi3ExitInitializationMode(c); break;
        case 6: fmi3Terminate(c); break;
        case 7: if (fmi3Reset(c) == fmi3OK) s->t = 0; break;
        case 8: case 9: fmi3GetFloat64(c, maybeNull(vr), n, maybeNull(x), m); break;
        case 10: case 11: fmi3SetFloat64(c, maybeNull(vr), n, maybeNull(x), m); break;
        case 12: fmi3GetBoolean(c, maybeNull(vr), n, maybeNull(b), m); break;
        case 13: fmi3SetBoolean(c, maybeNull(vr), n, maybeNull(b), m); break;
        case 14: fmi3GetInt32(c, maybeNull(vr), n, maybeNull(in), m); fmi3SetString(c, vr, n, NULL, m); break;
        case 15: fmi3GetFMUState(c, chance(5) ? NULL : st); break;
        case 16: fmi3SetFMUState(c, *st); break;
        case 17: fmi3FreeFMUState(c, st); break;
        case 18:
            if (fmi3SerializedFMUStateSize(c, *st, &size) == fmi3OK && size <= sizeof(bytes) &&
                fmi3SerializeFMUState(c, *st, bytes, chance(10) ? pick((unsigned)size) : size) == fmi3OK)
                keep(bytes, size);
            break;
        case 19: case 20: {
            const unsigned char *p = pooled(&size);
            if (*st) fmi3FreeFMUState(c, st);
            if (!*st) fmi3DeserializeFMUState(c, p, size, st);
            break;
        }
        case 21: nd = count(); fmi3GetDirectionalDerivative(c, maybeNull(vr), n, maybeNull(vk), nd, maybeNull(x), chance(80) ? nd : count(), maybeNull(y), chance(80) ? n : count()); break;
        case 22: nd = count(); fmi3GetAdjointDerivative(c, maybeNull(vr), n, maybeNull(vk), nd, maybeNull(x), chance(80) ? n : count(), maybeNull(y), chance(80) ? nd : count()); break;
        case 23: fmi3EnterEventMode(c); break;
        case 24: fmi3UpdateDiscreteStates(c, maybeNull(f), maybeNull(f + 1), maybeNull(f + 2), maybeNull(f + 3), maybeNull(f + 4), maybeNull(x)); break;
        case 25: fmi3EnterContinuousTimeMode(c); break;
        case 26: fmi3CompletedIntegratorStep(c, true, maybeNull(f), maybeNull(f + 1)); break;
        case 27: fmi3SetTime(c, chance(50) ? number() : 1e-3 * pick(100)); break;
        case 28: fmi3SetContinuousStates(c, maybeNull(x), states(n)); break;
        case 29: fmi3GetContinuousStateDerivatives(c, maybeNull(x), states(n)); break;
        case 30: fmi3GetContinuousStates(c, maybeNull(x), states(n)); fmi3GetEventIndicators(c, maybeNull(x), n); break;
        case 31: fmi3GetNominalsOfContinuousStates(c, maybeNull(x), states(n)); break;
        case 32: fmi3GetNumberOfContinuousStates(c, maybeNull(&size)); fmi3GetNumberOfEventIndicators(c, maybeNull(&size)); break;
        case 33: case 34: {
            double h = stepSize(), t = chance(80) ? s->t : number();
            if (fmi3DoStep(c, t, h, true, maybeNull(f), maybeNull(f + 1), maybeNull(f + 2), maybeNull(x)) == fmi3OK)
                s->t = t + h;
            break;
        }
        case 35: fmi3EnterStepMode(c); fmi3EvaluateDiscreteStates(c); break;
        case 36: fmi3GetOutputDerivatives(c, vr, n, in, x, m); fmi3EnterConfigurationMode(c); break;
        case 37: fmi3GetNumberOfVariableDependencies(c, vref(), maybeNull(&size)); fmi3GetClock(c, vr, n, b); break;
        case 38: fmi3GetIntervalDecimal(c, vr, n, x, NULL); fmi3ActivateModelPartition(c, vref(), number()); break;
        default: fmi3GetBinary(c, vr, n, NULL, NULL, m); fmi3GetUInt64(c, maybeNull(vr), n, NULL, m); break;
    }
    calls++;
}

int main(int argc, char **argv) {
    unsigned long long limit;
    int i;
    if (argc != 11) {
        fprintf(stderr, "usage: fmi_fuzz SEED CALLS (RESOURCES TOKEN) x 4\n");
        return 2;
    }
    rng ^= strtoull(argv[1], NULL, 10) * 0x9E3779B97F4A7C15ull;
    limit = strtoull(argv[2], NULL, 10);
    for (i = 0; i < 4; i++) res[i] = argv[3 + 2 * i], tok[i] = argv[4 + 2 * i];
    while (calls < limit) {
        Slot *s = &slots[pick(SLOTS)];
        if (!s->c) instantiate(s);
        else if (chance(1)) freeSlot(s);
        else if (s->version == 2) callFmi2(s);
        else callFmi3(s);
    }
    for (i = 0; i < SLOTS; i++)
        if (slots[i].c) freeSlot(&slots[i]);
    for (i = 0; i < POOL; i++) free(pool[i]);
    printf("%llu calls, %llu log messages\n", calls, logs);
    return 0;
}
