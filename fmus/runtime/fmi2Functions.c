/* The generic FMI 2.0 layer: calling-sequence checks with per-function state masks, the importer's logger,
   status escalation; everything model-specific is delegated to model.h. */
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "model.h"

#define ANY_LIVE (Instantiated | InitializationMode | EventMode | ContinuousTimeMode | StepMode | Terminated)
#define MASK_fmi2SetDebugLogging (ANY_LIVE | ErrorState)
#define MASK_fmi2SetupExperiment Instantiated
#define MASK_fmi2EnterInitializationMode Instantiated
#define MASK_fmi2ExitInitializationMode InitializationMode
#define MASK_fmi2Terminate (EventMode | ContinuousTimeMode | StepMode)
#define MASK_fmi2Reset (ANY_LIVE | ErrorState)
#define MASK_fmi2Get (ANY_LIVE | ErrorState)
#define MASK_fmi2Set (Instantiated | InitializationMode | EventMode | ContinuousTimeMode | StepMode)
#define MASK_fmi2FMUstate (ANY_LIVE | ErrorState)
#define MASK_fmi2GetDirectionalDerivative \
    (InitializationMode | EventMode | ContinuousTimeMode | StepMode | Terminated | ErrorState)
#define MASK_fmi2EnterEventMode (EventMode | ContinuousTimeMode)
#define MASK_fmi2NewDiscreteStates EventMode
#define MASK_fmi2EnterContinuousTimeMode EventMode
#define MASK_fmi2CompletedIntegratorStep ContinuousTimeMode
#define MASK_fmi2SetTime (EventMode | ContinuousTimeMode)
#define MASK_fmi2SetContinuousStates ContinuousTimeMode
#define MASK_fmi2GetStates (InitializationMode | EventMode | ContinuousTimeMode | Terminated | ErrorState)
#define MASK_fmi2InputDerivatives (Instantiated | InitializationMode | StepMode)
#define MASK_fmi2OutputDerivatives (StepMode | Terminated | ErrorState)
#define MASK_fmi2DoStep StepMode
#define MASK_fmi2Status (StepMode | Terminated | ErrorState)

/* the instance, or return fmi2Error when it is NULL or `f` may not be called in its state */
#define BEGIN(f)                                                          \
    ModelInstance *inst = (ModelInstance *)c;                             \
    if (!inst || !allowedIn(inst, #f, MASK_##f)) return fmi2Error

#define CHECK_ARRAY(f, p, n)                                              \
    if ((n) > 0 && !(p)) {                                                \
        logError(inst, "%s: %s is NULL", #f, #p);                         \
        return (fmi2Status)escalate(inst, Error);                         \
    }

static void logFmi2(ModelInstance *inst, Status status, const char *category, const char *message) {
    fmi2CallbackLogger logger = (fmi2CallbackLogger)(size_t)inst->logger;
    if (logger) logger(inst->environment, inst->name, (fmi2Status)status, category, message);
}

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }

const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[]) {
    size_t i;
    BEGIN(fmi2SetDebugLogging);
    CHECK_ARRAY(fmi2SetDebugLogging, categories, nCategories);
    if (nCategories == 0) {
        inst->logEvents = loggingOn;
        inst->logErrors = true;
    }
    for (i = 0; i < nCategories; i++) {
        if (strcmp(categories[i], "logEvents") == 0) inst->logEvents = loggingOn;
        else if (strcmp(categories[i], "logStatusError") == 0) inst->logErrors = loggingOn;
        else {
            logError(inst, "unknown log category %s", categories[i]);
            return (fmi2Status)escalate(inst, Error);
        }
    }
    return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn) {
    (void)visible;
    if (!functions || !functions->logger) return NULL;
    if (fmuType != fmi2ModelExchange && fmuType != fmi2CoSimulation) {
        functions->logger(functions->componentEnvironment, instanceName, fmi2Error, "logStatusError",
                          "unknown fmuType");
        return NULL;
    }
    if (!instanceName || !fmuGUID || !fmuResourceLocation) {
        functions->logger(functions->componentEnvironment, instanceName ? instanceName : "?", fmi2Error,
                          "logStatusError", "instanceName, fmuGUID and fmuResourceLocation are required");
        return NULL;
    }
    return createInstance(instanceName, fmuGUID, fmuResourceLocation,
                          fmuType == fmi2ModelExchange ? ModelExchange : CoSimulation, loggingOn, logFmi2,
                          (void *)(size_t)functions->logger, functions->componentEnvironment);
}

void fmi2FreeInstance(fmi2Component c) { freeInstance((ModelInstance *)c); }

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    (void)toleranceDefined;
    (void)tolerance;
    (void)stopTimeDefined;
    (void)stopTime;
    BEGIN(fmi2SetupExperiment);
    inst->time = startTime;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    BEGIN(fmi2EnterInitializationMode);
    inst->state = InitializationMode;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    BEGIN(fmi2ExitInitializationMode);
    if (checkModel(inst) > Warning) return (fmi2Status)escalate(inst, Error);
    inst->state = inst->type == ModelExchange ? EventMode : StepMode;
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component c) {
    BEGIN(fmi2Terminate);
    inst->state = Terminated;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c) {
    BEGIN(fmi2Reset);
    return (fmi2Status)resetInstance(inst);
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
    BEGIN(fmi2Get);
    return (fmi2Status)escalate(inst, getFloat64s(inst, vr, nvr, value));
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
    BEGIN(fmi2Set);
    return (fmi2Status)escalate(inst, setFloat64s(inst, vr, nvr, value));
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[]) {
    size_t i;
    bool b;
    BEGIN(fmi2Get);
    CHECK_ARRAY(fmi2GetBoolean, vr, nvr);
    CHECK_ARRAY(fmi2GetBoolean, value, nvr);
    for (i = 0; i < nvr; i++) {
        if (getBoolean(inst, vr[i], &b) > Warning) return (fmi2Status)escalate(inst, Error);
        value[i] = b ? fmi2True : fmi2False;
    }
    return fmi2OK;
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Boolean value[]) {
    size_t i;
    BEGIN(fmi2Set);
    CHECK_ARRAY(fmi2SetBoolean, vr, nvr);
    CHECK_ARRAY(fmi2SetBoolean, value, nvr);
    for (i = 0; i < nvr; i++)
        if (setBoolean(inst, vr[i], value[i] != fmi2False) > Warning) return (fmi2Status)escalate(inst, Error);
    return fmi2OK;
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[]) {
    (void)vr;
    (void)value;
    BEGIN(fmi2Get);
    return (fmi2Status)escalate(inst, noVariables(inst, "Integer", nvr));
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[]) {
    (void)vr;
    (void)value;
    BEGIN(fmi2Get);
    return (fmi2Status)escalate(inst, noVariables(inst, "String", nvr));
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Integer value[]) {
    (void)vr;
    (void)value;
    BEGIN(fmi2Set);
    return (fmi2Status)escalate(inst, noVariables(inst, "Integer", nvr));
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[]) {
    (void)vr;
    (void)value;
    BEGIN(fmi2Set);
    return (fmi2Status)escalate(inst, noVariables(inst, "String", nvr));
}

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *FMUstate) {
    BEGIN(fmi2FMUstate);
    if (newSavedState(inst, FMUstate) > Warning) return (fmi2Status)escalate(inst, Error);
    saveState(inst, (SavedState *)*FMUstate);
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate) {
    BEGIN(fmi2FMUstate);
    CHECK_ARRAY(fmi2SetFMUstate, FMUstate, 1);
    restoreState(inst, (const SavedState *)FMUstate);
    return fmi2OK;
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *FMUstate) {
    BEGIN(fmi2FMUstate);
    if (FMUstate) {
        free(*FMUstate);
        *FMUstate = NULL;
    }
    return fmi2OK;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate FMUstate, size_t *size) {
    (void)FMUstate;
    BEGIN(fmi2FMUstate);
    CHECK_ARRAY(fmi2SerializedFMUstateSize, size, 1);
    *size = sizeof(SavedState);
    return fmi2OK;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate FMUstate, fmi2Byte serializedState[],
                                 size_t size) {
    BEGIN(fmi2FMUstate);
    CHECK_ARRAY(fmi2SerializeFMUstate, FMUstate, 1);
    CHECK_ARRAY(fmi2SerializeFMUstate, serializedState, 1);
    if (size < sizeof(SavedState)) {
        logError(inst, "fmi2SerializeFMUstate: %zu bytes is too small for the state (%zu)", size,
                 sizeof(SavedState));
        return (fmi2Status)escalate(inst, Error);
    }
    memcpy(serializedState, FMUstate, sizeof(SavedState));
    return fmi2OK;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[], size_t size,
                                   fmi2FMUstate *FMUstate) {
    BEGIN(fmi2FMUstate);
    return (fmi2Status)escalate(inst, deserializeState(inst, (const unsigned char *)serializedState, size, FMUstate));
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[],
                                        size_t nUnknown, const fmi2ValueReference vKnown_ref[], size_t nKnown,
                                        const fmi2Real dvKnown[], fmi2Real dvUnknown[]) {
    BEGIN(fmi2GetDirectionalDerivative);
    return (fmi2Status)escalate(
        inst, partialDerivatives(inst, false, vUnknown_ref, nUnknown, vKnown_ref, nKnown, dvKnown, dvUnknown));
}

/* ---- Model Exchange */

fmi2Status fmi2EnterEventMode(fmi2Component c) {
    BEGIN(fmi2EnterEventMode);
    inst->state = EventMode;
    return fmi2OK;
}

fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *eventInfo) {
    BEGIN(fmi2NewDiscreteStates);
    CHECK_ARRAY(fmi2NewDiscreteStates, eventInfo, 1);
    memset(eventInfo, 0, sizeof(*eventInfo)); /* a linear model without events */
    return fmi2OK;
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) {
    BEGIN(fmi2EnterContinuousTimeMode);
    inst->state = ContinuousTimeMode;
    return fmi2OK;
}

fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi2Boolean *enterEventMode, fmi2Boolean *terminateSimulation) {
    (void)noSetFMUStatePriorToCurrentPoint;
    BEGIN(fmi2CompletedIntegratorStep);
    CHECK_ARRAY(fmi2CompletedIntegratorStep, enterEventMode, 1);
    CHECK_ARRAY(fmi2CompletedIntegratorStep, terminateSimulation, 1);
    *enterEventMode = fmi2False;
    *terminateSimulation = fmi2False;
    return fmi2OK;
}

fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time) {
    BEGIN(fmi2SetTime);
    inst->time = time;
    return fmi2OK;
}

fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t nx) {
    BEGIN(fmi2SetContinuousStates);
    return (fmi2Status)escalate(inst, setContinuousStates(inst, x, nx));
}

fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real derivatives[], size_t nx) {
    BEGIN(fmi2GetStates);
    CHECK_ARRAY(fmi2GetDerivatives, derivatives, nx);
    if (checkStateCount(inst, "fmi2GetDerivatives", nx) > Warning) return (fmi2Status)escalate(inst, Error);
    getDerivatives(inst, derivatives);
    return fmi2OK;
}

fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real eventIndicators[], size_t ni) {
    (void)eventIndicators;
    BEGIN(fmi2GetStates);
    if (ni == 0) return fmi2OK;
    logError(inst, "fmi2GetEventIndicators: the model has no event indicators, ni = %zu", ni);
    return (fmi2Status)escalate(inst, Error);
}

fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real x[], size_t nx) {
    BEGIN(fmi2GetStates);
    CHECK_ARRAY(fmi2GetContinuousStates, x, nx);
    if (checkStateCount(inst, "fmi2GetContinuousStates", nx) > Warning) return (fmi2Status)escalate(inst, Error);
    getStates(inst, x);
    return fmi2OK;
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, fmi2Real x_nominal[], size_t nx) {
    size_t i;
    BEGIN(fmi2GetStates);
    CHECK_ARRAY(fmi2GetNominalsOfContinuousStates, x_nominal, nx);
    if (checkStateCount(inst, "fmi2GetNominalsOfContinuousStates", nx) > Warning) return (fmi2Status)escalate(inst, Error);
    for (i = 0; i < nx; i++) x_nominal[i] = 1.0;
    return fmi2OK;
}

/* ---- Co-Simulation */

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    (void)vr;
    (void)order;
    (void)value;
    BEGIN(fmi2InputDerivatives);
    if (nvr == 0) return fmi2OK;
    logError(inst, "fmi2SetRealInputDerivatives: inputs are held constant over a step (canInterpolateInputs "
                   "is false)");
    return (fmi2Status)escalate(inst, Error);
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[]) {
    (void)vr;
    (void)order;
    (void)value;
    BEGIN(fmi2OutputDerivatives);
    if (nvr == 0) return fmi2OK;
    logError(inst, "fmi2GetRealOutputDerivatives: maxOutputDerivativeOrder is 0");
    return (fmi2Status)escalate(inst, Error);
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentCommunicationPoint) {
    (void)noSetFMUStatePriorToCurrentCommunicationPoint;
    BEGIN(fmi2DoStep);
    return (fmi2Status)escalate(inst, stepInstance(inst, currentCommunicationPoint, communicationStepSize));
}

fmi2Status fmi2CancelStep(fmi2Component c) {
    BEGIN(fmi2DoStep);
    logError(inst, "fmi2CancelStep: steps complete synchronously, there is nothing to cancel");
    return (fmi2Status)escalate(inst, Error);
}

/* steps never run asynchronously: the status functions answer for the last completed step */
fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) {
    (void)s;
    BEGIN(fmi2Status);
    CHECK_ARRAY(fmi2GetStatus, value, 1);
    *value = fmi2OK;
    return fmi2OK;
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value) {
    BEGIN(fmi2Status);
    CHECK_ARRAY(fmi2GetRealStatus, value, 1);
    if (s != fmi2LastSuccessfulTime) return fmi2Discard;
    *value = inst->time;
    return fmi2OK;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value) {
    (void)s;
    (void)value;
    BEGIN(fmi2Status);
    return fmi2Discard;
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value) {
    BEGIN(fmi2Status);
    CHECK_ARRAY(fmi2GetBooleanStatus, value, 1);
    if (s != fmi2Terminated) return fmi2Discard;
    *value = fmi2False;
    return fmi2OK;
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value) {
    (void)s;
    (void)value;
    BEGIN(fmi2Status);
    return fmi2Discard;
}
