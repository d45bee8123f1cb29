/* The FMI-version-independent part of an FMU instance: life-cycle state, logging, status escalation,
   start values read from the FMU's resources. The FMI 2 and FMI 3 layers translate their calls into
   these; the model (model.h) only knows its variables and equations. */
#ifndef FLEXJOINT_INSTANCE_H
#define FLEXJOINT_INSTANCE_H

#include <stdbool.h>
#include <stddef.h>

#include "config.h"

/* same numbering as fmi2Status and fmi3Status */
typedef enum { OK, Warning, Discard, Error, Fatal } Status;

typedef enum { ModelExchange, CoSimulation } InterfaceType;

/* life-cycle states, one bit each so that every function can list where it may be called */
typedef enum {
    StartAndEnd        = 1 << 0,
    Instantiated       = 1 << 1,
    InitializationMode = 1 << 2,
    EventMode          = 1 << 3,
    ContinuousTimeMode = 1 << 4,
    StepMode           = 1 << 5,
    Terminated         = 1 << 6,
    ErrorState         = 1 << 7,
    FatalState         = 1 << 8
} ModelState;

struct ModelInstance;
typedef void (*LogFunction)(struct ModelInstance *inst, Status status, const char *category, const char *message);

typedef struct ModelInstance {
    char *name;
    char *token;
    char *startFile;
    InterfaceType type;
    ModelState state;
    double time;
    bool logEvents;
    bool logErrors;
    LogFunction log;
    void *environment;  /* the importer's instance environment, passed back to its logger */
    void *logger;       /* the importer's logger callback, called by `log` */
    ModelData data;
} ModelInstance;

ModelInstance *createInstance(const char *name, const char *token, const char *resourceDir, InterfaceType type,
                              bool loggingOn, LogFunction log, void *logger, void *environment);
void freeInstance(ModelInstance *inst);
Status resetInstance(ModelInstance *inst);

void logEvent(ModelInstance *inst, const char *fmt, ...);
void logError(ModelInstance *inst, const char *fmt, ...);

/* FMU state snapshots (get/set/serialize FMU state): life-cycle state, time and model data */
typedef struct {
    unsigned size; /* sizeof(SavedState), checked when deserializing */
    ModelState state;
    double time;
    ModelData data;
} SavedState;
void saveState(ModelInstance *inst, SavedState *saved);
void restoreState(ModelInstance *inst, const SavedState *saved);

/* shared implementations of the FMI calls; they log what went wrong and return the status */
Status getFloat64s(ModelInstance *inst, const unsigned vr[], size_t n, double value[]);
Status setFloat64s(ModelInstance *inst, const unsigned vr[], size_t n, const double value[]);
Status noVariables(ModelInstance *inst, const char *type, size_t n);
/* sensitivity = J seed (directional) or J^T seed (adjoint), J = d unknown / d known */
Status partialDerivatives(ModelInstance *inst, bool adjoint, const unsigned unknown[], size_t nUnknown,
                          const unsigned known[], size_t nKnown, const double seed[], double sensitivity[]);
Status checkStateCount(ModelInstance *inst, const char *function, size_t nx);
Status setContinuousStates(ModelInstance *inst, const double x[], size_t nx);
Status stepInstance(ModelInstance *inst, double currentTime, double h);
Status newSavedState(ModelInstance *inst, void **saved);
Status deserializeState(ModelInstance *inst, const unsigned char bytes[], size_t size, void **saved);

/* check that `function` may be called in the instance's current state; logs and returns false if not */
bool allowedIn(ModelInstance *inst, const char *function, int mask);

/* after a call: an Error or Fatal status moves the instance into the matching terminal state */
Status escalate(ModelInstance *inst, Status status);

#endif
