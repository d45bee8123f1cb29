/* The FMI-version-independent part of an FMU instance: life-cycle state, logging, status escalation,
   start values read from the FMU's resources, time checks and FMU state (de)serialisation. The FMI 2
   and FMI 3 layers translate their calls into these; the model (model.h) only knows its variables and
   equations, and declares its capabilities in its config.h (defaults below). */
#ifndef FLEXJOINT_INSTANCE_H
#define FLEXJOINT_INSTANCE_H

#include <stdbool.h>
#include <stddef.h>

#include "config.h"
#include "names.h"

/* ---- defaults for the capabilities a model's config.h does not declare */
#ifndef HAS_EVENT_MODE
#define HAS_EVENT_MODE 0
#endif
#ifndef PROVIDES_DIRECTIONAL_DERIVATIVES
#define PROVIDES_DIRECTIONAL_DERIVATIVES 0
#endif
#ifndef PROVIDES_ADJOINT_DERIVATIVES
#define PROVIDES_ADJOINT_DERIVATIVES 0
#endif
#ifndef CAN_GET_AND_SET_FMU_STATE
#define CAN_GET_AND_SET_FMU_STATE 0
#endif
#ifndef CAN_SERIALIZE_FMU_STATE
#define CAN_SERIALIZE_FMU_STATE 0
#endif
#ifndef NEEDS_COMPLETED_INTEGRATOR_STEP
#define NEEDS_COMPLETED_INTEGRATOR_STEP 1
#endif
#ifndef N_EVENT_INDICATORS
#define N_EVENT_INDICATORS 0
#endif

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

/* added to a function's state mask: it belongs to one interface only */
#define ME_ONLY (1 << 9)
#define CS_ONLY (1 << 10)

struct ModelInstance;
typedef void (*LogFunction)(struct ModelInstance *inst, Status status, const char *category, const char *message);

typedef struct ModelInstance {
    char *name;
    char *token;
    char *startFile;
    InterfaceType type;
    int fmiVersion;     /* 2 or 3: FMI 2 declares no time variable */
    ModelState state;
    double time;
    bool stopTimeDefined;
    double stopTime;
    bool logEvents;     /* log categories, all off when the importer turns logging off */
    bool logErrors;
    bool logDiscards;
    LogFunction log;
    void *environment;  /* the importer's instance environment, passed back to its logger */
    void *logger;       /* the importer's logger callback, called by `log` */
    ModelData data;
} ModelInstance;

ModelInstance *createInstance(const char *name, const char *token, const char *resourceDir, InterfaceType type,
                              int fmiVersion, bool loggingOn, LogFunction log, void *logger, void *environment);
void freeInstance(ModelInstance *inst);
Status resetInstance(ModelInstance *inst);

void logEvent(ModelInstance *inst, const char *fmt, ...);
void logError(ModelInstance *inst, const char *fmt, ...);
void logDiscard(ModelInstance *inst, const char *fmt, ...);
/* turn the log categories on or off (NULL category: all of them); false if the category is unknown */
bool setLogCategory(ModelInstance *inst, const char *category, bool on);

/* shared implementations of the FMI calls; they log what went wrong and return the status */
Status getFloat64s(ModelInstance *inst, const unsigned vr[], size_t n, double value[]);
Status setFloat64s(ModelInstance *inst, const unsigned vr[], size_t n, const double value[]);
Status getBooleans(ModelInstance *inst, const unsigned vr[], size_t n, bool value[]);
Status setBooleans(ModelInstance *inst, const unsigned vr[], size_t n, const bool value[]);
Status noVariables(ModelInstance *inst, const char *type, size_t n);
/* logs and returns Error if an array of n > 0 elements is NULL */
Status checkArray(ModelInstance *inst, const char *function, const char *name, const void *p, size_t n);
/* sensitivity = J seed (directional) or J^T seed (adjoint), J = d unknown / d known */
Status partialDerivatives(ModelInstance *inst, bool adjoint, const unsigned unknown[], size_t nUnknown,
                          const unsigned known[], size_t nKnown, const double seed[], double sensitivity[]);
Status checkStateCount(ModelInstance *inst, const char *function, size_t nx);
Status getContinuousStates(ModelInstance *inst, const char *function, double x[], size_t nx);
Status setContinuousStates(ModelInstance *inst, const double x[], size_t nx);
Status getStateDerivatives(ModelInstance *inst, const char *function, double dx[], size_t nx);
Status getNominals(ModelInstance *inst, const char *function, double nominals[], size_t nx);

/* time: start (and stop) of the experiment, Model Exchange time, one co-simulation step */
Status setupExperiment(ModelInstance *inst, double startTime, bool stopTimeDefined, double stopTime);
Status setTime(ModelInstance *inst, double time);
Status stepInstance(ModelInstance *inst, double currentTime, double h);

/* FMU state: snapshots in memory and their serialised form (magic, version, interface, axes, checksum) */
Status getFMUState(ModelInstance *inst, void **state);
Status setFMUState(ModelInstance *inst, const void *state);
Status freeFMUState(ModelInstance *inst, void **state);
Status serializedStateSize(ModelInstance *inst, const void *state, size_t *size);
Status serializeState(ModelInstance *inst, const void *state, unsigned char bytes[], size_t size);
Status deserializeState(ModelInstance *inst, const unsigned char bytes[], size_t size, void **state);

/* portable little-endian byte encoding of serialised states */
void putU32(unsigned char *p, unsigned v);
unsigned getU32(const unsigned char *p);
void putF64(unsigned char *p, double v);
double getF64(const unsigned char *p);

/* check that `function` may be called in the instance's current state (and by its interface type);
   logs, moves the instance to the error state and returns false if not */
bool allowedIn(ModelInstance *inst, const char *function, int mask);

/* after a call: an Error or Fatal status moves the instance into the matching terminal state */
Status escalate(ModelInstance *inst, Status status);

#endif
