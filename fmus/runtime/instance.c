/* Generic instance handling shared by the FMI 2 and FMI 3 layers. */
#include "instance.h"

#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef _WIN32
#define WIN32_LEAN_AND_MEAN
#include <windows.h>
#endif

#include "model.h"

#define START_FILE "start_values.txt"
#define MAX_MESSAGE 1024
#define MAX_LINE 512

static char *copyString(const char *s) {
    size_t n = strlen(s) + 1;
    char *c = malloc(n);
    if (c) memcpy(c, s, n);
    return c;
}

static void vlog(ModelInstance *inst, Status status, const char *category, const char *fmt, va_list args) {
    char message[MAX_MESSAGE];
    if (!inst || !inst->log) return;
    vsnprintf(message, sizeof(message), fmt, args);
    inst->log(inst, status, category, message);
}

void logEvent(ModelInstance *inst, const char *fmt, ...) {
    va_list args;
    if (!inst || !inst->logEvents) return;
    va_start(args, fmt);
    vlog(inst, OK, "logEvents", fmt, args);
    va_end(args);
}

void logError(ModelInstance *inst, const char *fmt, ...) {
    va_list args;
    if (!inst || !inst->logErrors) return;
    va_start(args, fmt);
    vlog(inst, Error, "logStatusError", fmt, args);
    va_end(args);
}

void logDiscard(ModelInstance *inst, const char *fmt, ...) {
    va_list args;
    if (!inst || !inst->logDiscards) return;
    va_start(args, fmt);
    vlog(inst, Discard, "logStatusDiscard", fmt, args);
    va_end(args);
}

bool setLogCategory(ModelInstance *inst, const char *category, bool on) {
    bool all = category == NULL;
    bool known = all;
    if (all || strcmp(category, "logEvents") == 0) inst->logEvents = on, known = true;
    if (all || strcmp(category, "logStatusError") == 0) inst->logErrors = on, known = true;
    if (all || strcmp(category, "logStatusDiscard") == 0) inst->logDiscards = on, known = true;
    return known;
}

static int hexValue(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

/* The folder of the resource location: FMI 2 passes a file URI (FMI 2.0.4 section 2.1.5, RFC 8089:
   file:///C:/a%20b/, file:/C:/a/, file://localhost/C:/a/, file://host/share/a/ for a network share),
   FMI 3 a native path (/a b/, C:\a b\). Percent-escapes are decoded; the result is UTF-8. On Windows a
   drive letter loses the URI's leading slash, a host becomes \\host\share, and '/' becomes '\'. */
static char *pathFromLocation(const char *location) {
    const char *p = location;
    char *path, *out;
    bool uri = strncmp(p, "file:", 5) == 0, share = false;
    if (uri) {
        p += 5;
        if (strncmp(p, "//", 2) == 0) {
            p += 2;
            if (strncmp(p, "localhost/", 10) == 0) p += 9;
            else share = *p != '/'; /* file://host/...: a network share */
        }
    }
    path = malloc(strlen(p) + 3);
    if (!path) return NULL;
    out = path;
    if (share) *out++ = '/', *out++ = '/';
    for (; *p; p++) {
        if (uri && *p == '%' && hexValue(p[1]) >= 0 && hexValue(p[2]) >= 0) {
            *out++ = (char)(hexValue(p[1]) * 16 + hexValue(p[2]));
            p += 2;
        } else {
            *out++ = *p;
        }
    }
    *out = '\0';
#ifdef _WIN32
    if (path[0] == '/' && isalpha((unsigned char)path[1]) && (path[2] == ':' || path[2] == '|')) {
        memmove(path, path + 1, strlen(path));
        path[1] = ':'; /* file:///C|/ is the legacy form of file:///C:/ */
    }
    for (out = path; *out; out++)
        if (*out == '/') *out = '\\';
#endif
    return path;
}

static bool isSeparator(char c) {
#ifdef _WIN32
    if (c == '\\') return true;
#endif
    return c == '/';
}

static char *startFilePath(const char *resourceDir) {
    char *dir = pathFromLocation(resourceDir);
    char *file;
    size_t n;
    if (!dir) return NULL;
    n = strlen(dir);
    file = malloc(n + sizeof(START_FILE) + 1);
    if (file) {
        memcpy(file, dir, n);
#ifdef _WIN32
        if (n == 0 || !isSeparator(dir[n - 1])) file[n++] = '\\';
#else
        if (n == 0 || !isSeparator(dir[n - 1])) file[n++] = '/';
#endif
        memcpy(file + n, START_FILE, sizeof(START_FILE));
    }
    free(dir);
    return file;
}

/* open a UTF-8 path for reading: Windows' fopen takes the ANSI code page, so convert to UTF-16 */
static FILE *openForReading(const char *path) {
#ifdef _WIN32
    FILE *file = NULL;
    wchar_t *wide;
    int n = MultiByteToWideChar(CP_UTF8, MB_ERR_INVALID_CHARS, path, -1, NULL, 0);
    if (n <= 0 || !(wide = malloc((size_t)n * sizeof(wchar_t)))) return NULL;
    if (MultiByteToWideChar(CP_UTF8, MB_ERR_INVALID_CHARS, path, -1, wide, n) == n) file = _wfopen(wide, L"r");
    free(wide);
    return file;
#else
    return fopen(path, "r");
#endif
}

static char *trim(char *s) {
    char *end;
    while (isspace((unsigned char)*s)) s++;
    end = s + strlen(s);
    while (end > s && isspace((unsigned char)end[-1])) *--end = '\0';
    return s;
}

/* zero the model data and apply the start-value file from the FMU's resources */
static Status loadStartValues(ModelInstance *inst) {
    char line[MAX_LINE];
    FILE *file = openForReading(inst->startFile);
    bool tokenSeen = false;
    Status status = OK;
    int number = 0;
    if (!file) {
        logError(inst, "cannot open %s: the FMU's resources folder is missing its start values", inst->startFile);
        return Error;
    }
    memset(&inst->data, 0, sizeof(inst->data));
    inst->state = StartAndEnd; /* start values go in unchecked, checkModel sees them all at the end */
    while (status <= Warning && fgets(line, sizeof(line), file)) {
        char *name = trim(line), *value;
        number++;
        if (*name == '\0' || *name == '#') continue;
        value = name;
        while (*value && !isspace((unsigned char)*value)) value++;
        if (*value) *value++ = '\0';
        value = trim(value);
        if (strcmp(name, "token") == 0) {
            tokenSeen = true;
            if (strcmp(value, inst->token) != 0) {
                logError(inst, "instantiation token %s does not match %s in the resources", inst->token, value);
                status = Error;
            }
        } else {
            status = applyStart(inst, name, value);
            if (status > Warning) logError(inst, "%s line %d: cannot apply '%s %s'", START_FILE, number, name, value);
        }
    }
    fclose(file);
    inst->state = Instantiated;
    if (status <= Warning && !tokenSeen) {
        logError(inst, "%s has no token line", inst->startFile);
        status = Error;
    }
    return status <= Warning ? checkModel(inst, &inst->data) : status;
}

ModelInstance *createInstance(const char *name, const char *token, const char *resourceDir, InterfaceType type,
                              int fmiVersion, bool loggingOn, LogFunction log, void *logger, void *environment) {
    ModelInstance *inst;
    if (!name || !token || !resourceDir) return NULL;
    inst = calloc(1, sizeof(ModelInstance));
    if (!inst) return NULL;
    inst->type = type;
    inst->fmiVersion = fmiVersion;
    inst->state = Instantiated;
    setLogCategory(inst, NULL, loggingOn);
    inst->log = log;
    inst->logger = logger;
    inst->environment = environment;
    inst->name = copyString(name);
    inst->token = copyString(token);
    inst->startFile = startFilePath(resourceDir);
    if (!inst->name || !inst->token || !inst->startFile || loadStartValues(inst) > Warning) {
        freeInstance(inst);
        return NULL;
    }
    logEvent(inst, "instantiated %s from %s", name, inst->startFile);
    return inst;
}

void freeInstance(ModelInstance *inst) {
    if (!inst) return;
    free(inst->name);
    free(inst->token);
    free(inst->startFile);
    free(inst);
}

Status resetInstance(ModelInstance *inst) {
    Status status = loadStartValues(inst);
    inst->time = 0;
    inst->stopTimeDefined = false;
    inst->state = status <= Warning ? Instantiated : ErrorState;
    return status;
}

bool allowedIn(ModelInstance *inst, const char *function, int mask) {
    if ((mask & ME_ONLY) && inst->type != ModelExchange) {
        logError(inst, "%s is a Model Exchange function; this instance is co-simulation", function);
    } else if ((mask & CS_ONLY) && inst->type != CoSimulation) {
        logError(inst, "%s is a co-simulation function; this instance is Model Exchange", function);
    } else if (inst->state & mask) {
        return true;
    } else {
        logError(inst, "%s must not be called in the current state (%d)", function, (int)inst->state);
    }
    if (inst->state != FatalState) inst->state = ErrorState;
    return false;
}

Status escalate(ModelInstance *inst, Status status) {
    if (status == Error) inst->state = ErrorState;
    if (status == Fatal) inst->state = FatalState;
    return status;
}

Status checkArray(ModelInstance *inst, const char *function, const char *name, const void *p, size_t n) {
    if (n == 0 || p) return OK;
    logError(inst, "%s: %s is NULL but %zu elements were passed", function, name, n);
    return Error;
}

Status getFloat64s(ModelInstance *inst, const unsigned vr[], size_t n, double value[]) {
    size_t i;
    if (checkArray(inst, "get Float64", "value references", vr, n) > Warning ||
        checkArray(inst, "get Float64", "values", value, n) > Warning)
        return Error;
    for (i = 0; i < n; i++)
        if (getFloat64(inst, vr[i], &value[i]) > Warning) return Error;
    return OK;
}

Status setFloat64s(ModelInstance *inst, const unsigned vr[], size_t n, const double value[]) {
    size_t i;
    if (checkArray(inst, "set Float64", "value references", vr, n) > Warning ||
        checkArray(inst, "set Float64", "values", value, n) > Warning)
        return Error;
    for (i = 0; i < n; i++)
        if (setFloat64(inst, vr[i], value[i]) > Warning) return Error;
    return OK;
}

Status getBooleans(ModelInstance *inst, const unsigned vr[], size_t n, bool value[]) {
    size_t i;
    if (checkArray(inst, "get Boolean", "value references", vr, n) > Warning ||
        checkArray(inst, "get Boolean", "values", value, n) > Warning)
        return Error;
    for (i = 0; i < n; i++)
        if (getBoolean(inst, vr[i], &value[i]) > Warning) return Error;
    return OK;
}

Status setBooleans(ModelInstance *inst, const unsigned vr[], size_t n, const bool value[]) {
    size_t i;
    if (checkArray(inst, "set Boolean", "value references", vr, n) > Warning ||
        checkArray(inst, "set Boolean", "values", value, n) > Warning)
        return Error;
    for (i = 0; i < n; i++)
        if (setBoolean(inst, vr[i], value[i]) > Warning) return Error;
    return OK;
}

Status noVariables(ModelInstance *inst, const char *type, size_t n) {
    if (n == 0) return OK;
    logError(inst, "the model has no %s variables", type);
    return Error;
}

Status partialDerivatives(ModelInstance *inst, bool adjoint, const unsigned unknown[], size_t nUnknown,
                          const unsigned known[], size_t nKnown, const double seed[], double sensitivity[]) {
    size_t i, j;
    double d;
    size_t nSeed = adjoint ? nUnknown : nKnown, nSensitivity = adjoint ? nKnown : nUnknown;
    const char *f = adjoint ? "adjoint derivative" : "directional derivative";
    if (adjoint ? !PROVIDES_ADJOINT_DERIVATIVES : !PROVIDES_DIRECTIONAL_DERIVATIVES) {
        logError(inst, "the FMU does not provide the %s", f);
        return Error;
    }
    if (checkArray(inst, f, "unknowns", unknown, nUnknown) > Warning ||
        checkArray(inst, f, "knowns", known, nKnown) > Warning || checkArray(inst, f, "seed", seed, nSeed) > Warning ||
        checkArray(inst, f, "sensitivity", sensitivity, nSensitivity) > Warning)
        return Error;
    for (i = 0; i < nSensitivity; i++) sensitivity[i] = 0;
    for (i = 0; i < nUnknown; i++) {
        for (j = 0; j < nKnown; j++) {
            if (getPartial(inst, unknown[i], known[j], &d) > Warning) return Error;
            if (adjoint) sensitivity[j] += d * seed[i];
            else sensitivity[i] += d * seed[j];
        }
    }
    return OK;
}

Status checkStateCount(ModelInstance *inst, const char *function, size_t nx) {
    if (nx == numberOfStates(inst)) return OK;
    logError(inst, "%s: %zu states passed but the model has %zu", function, nx, numberOfStates(inst));
    return Error;
}

Status getContinuousStates(ModelInstance *inst, const char *function, double x[], size_t nx) {
    if (checkArray(inst, function, "states", x, nx) > Warning || checkStateCount(inst, function, nx) > Warning)
        return Error;
    getStates(inst, x);
    return OK;
}

Status setContinuousStates(ModelInstance *inst, const double x[], size_t nx) {
    size_t i;
    const char *f = "set continuous states";
    if (checkArray(inst, f, "states", x, nx) > Warning || checkStateCount(inst, f, nx) > Warning) return Error;
    for (i = 0; i < nx; i++) {
        if (!isfinite(x[i])) {
            logError(inst, "%s: x[%zu] = %g is not a finite number", f, i, x[i]);
            return Error;
        }
    }
    setStates(inst, x);
    return OK;
}

Status getStateDerivatives(ModelInstance *inst, const char *function, double dx[], size_t nx) {
    if (checkArray(inst, function, "derivatives", dx, nx) > Warning || checkStateCount(inst, function, nx) > Warning)
        return Error;
    getDerivatives(inst, dx);
    return OK;
}

Status getNominals(ModelInstance *inst, const char *function, double nominals[], size_t nx) {
    size_t i;
    if (checkArray(inst, function, "nominals", nominals, nx) > Warning ||
        checkStateCount(inst, function, nx) > Warning)
        return Error;
    for (i = 0; i < nx; i++) nominals[i] = 1.0;
    return OK;
}

/* ---- time */

/* tolerance on time comparisons: communication points computed as n h or by summing steps agree to it */
static double timeTolerance(double t) { return 1e-9 * fmax(1.0, fabs(t)); }

Status setupExperiment(ModelInstance *inst, double startTime, bool stopTimeDefined, double stopTime) {
    if (!isfinite(startTime) || (stopTimeDefined && (!isfinite(stopTime) || stopTime < startTime))) {
        logError(inst, "the start time (%g) must be finite and the stop time (%g), if defined, finite and not "
                       "before it", startTime, stopTime);
        return Error;
    }
    inst->time = startTime;
    inst->stopTimeDefined = stopTimeDefined;
    inst->stopTime = stopTime;
    return OK;
}

static Status checkStopTime(ModelInstance *inst, const char *what, double t) {
    if (!inst->stopTimeDefined || t <= inst->stopTime + timeTolerance(inst->stopTime)) return OK;
    logError(inst, "%s: t = %.17g is past the stop time %.17g set for the experiment", what, t, inst->stopTime);
    return Error;
}

Status setTime(ModelInstance *inst, double time) {
    if (!isfinite(time)) {
        logError(inst, "set time: t = %g is not a finite number", time);
        return Error;
    }
    inst->time = time;
    return OK;
}

Status stepInstance(ModelInstance *inst, double currentTime, double h) {
    if (!(h > 0) || !isfinite(h) || !isfinite(currentTime)) {
        logError(inst, "do step: the step size must be positive and finite (got %g at t = %g)", h, currentTime);
        return Error;
    }
    if (fabs(currentTime - inst->time) > timeTolerance(inst->time)) {
        logError(inst, "do step: the current communication point %.17g is not the instance's time %.17g",
                 currentTime, inst->time);
        return Error;
    }
    if (checkStopTime(inst, "do step", currentTime + h) > Warning) return Error;
    if (doStep(inst, h) > Warning) return Error;
    inst->time = currentTime + h;
    return OK;
}
