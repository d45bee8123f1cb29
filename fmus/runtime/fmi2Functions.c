/* The generic FMI 2.0 layer: calling-sequence checks with per-function state masks (and the interface
   type a function belongs to), the importer's logger, status escalation; everything model-specific is
   delegated to model.h, the model's capabilities come from its config.h. */
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
#define MASK_fmi2EnterEventMode (ME_ONLY | EventMode | ContinuousTimeMode)
#define MASK_fmi2NewDiscreteStates (ME_ONLY | EventMode)
#define MASK_fmi2EnterContinuousTimeMode (ME_ONLY | EventMode)
#define MASK_fmi2CompletedIntegratorStep (ME_ONLY | ContinuousTimeMode)
#define MASK_fmi2SetTime (ME_ONLY | EventMode | ContinuousTimeMode)
#define MASK_fmi2SetContinuousStates (ME_ONLY | ContinuousTimeMode)
#define MASK_fmi2GetStates (ME_ONLY | InitializationMode | EventMode | ContinuousTimeMode | Terminated | ErrorState)
#define MASK_fmi2GetNominals (MASK_fmi2GetStates | Instantiated)
#define MASK_fmi2InputDerivatives (CS_ONLY | Instantiated | InitializationMode | StepMode)
#define MASK_fmi2OutputDerivatives (CS_ONLY | StepMode | Terminated | ErrorState)
#define MASK_fmi2DoStep (CS_ONLY | StepMode)
#define MASK_fmi2Status (CS_ONLY | StepMode | Terminated | ErrorState)

/* the instance, or return fmi2Error when it is NULL or `f` may not be called in its state */
#define BEGIN(f)                                                          \
    ModelInstance *inst = (ModelInstance *)c;                             \
    if (!inst || !allowedIn(inst, #f, MASK_##f)) return fmi2Error

#define RETURN(status) return (fmi2Status)escalate(inst, (status))

#define CHECK_ARRAY(f, p, n) \
    if (checkArray(inst, #f, #p, (p), (n)) > Warning) RETURN(Error)

/* FMI 2's logger takes `message` as a printf format: every '%' of the text is doubled, so that an
   instance name or path with '%' in it is printed as is (section 2.1.5) */
static void logFmi2(ModelInstance *inst, Status status, const char *category, const char *message) {
    fmi2CallbackLogger logger = (fmi2CallbackLogger)(size_t)inst->logger;
    char escaped[2048];
    size_t i, n = 0;
    if (!logger) return;
    for (i = 0; message[i] && n + 2 < sizeof(escaped); i++) {
        if (message[i] == '%') escaped[n++] = '%';
        escaped[n++] = message[i];
    }
    escaped[n] = '\0';
    logger(inst->environment, inst->name, (fmi2Status)status, category, escaped);
}

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }

const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[]) {
    size_t i;
    BEGIN(fmi2SetDebugLogging);
    CHECK_ARRAY(fmi2SetDebugLogging, categories, nCategories);
    if (nCategories == 0) setLogCategory(inst, NULL, loggingOn != fmi2False);
    for (i = 0; i < nCategories; i++) {
        if (!categories[i] || !setLogCategory(inst, categories[i], loggingOn != fmi2False)) {
            logError(inst, "fmi2SetDebugLogging: unknown log category %s", categories[i] ? categories[i] : "(NULL)");
            RETURN(Error);
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
        if (loggingOn)
            functions->logger(functions->componentEnvironment, instanceName ? instanceName : "?", fmi2Error,
                              "logStatusError", "unknown fmuType");
        return NULL;
    }
    if (!instanceName || !fmuGUID || !fmuResourceLocation) {
        if (loggingOn)
            functions->logger(functions->componentEnvironment, instanceName ? instanceName : "?", fmi2Error,
                              "logStatusError", "instanceName, fmuGUID and fmuResourceLocation are required");
        return NULL;
    }
    return createInstance(instanceName, fmuGUID, fmuResourceLocation,
                          fmuType == fmi2ModelExchange ? ModelExchange : CoSimulation, 2, loggingOn != fmi2False,
                          logFmi2, (void *)(size_t)functions->logger, functions->componentEnvironment);
}

void fmi2FreeInstance(fmi2Component c) { freeInstance((ModelInstance *)c); }

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    (void)toleranceDefined;
    (void)tolerance;
    BEGIN(fmi2SetupExperiment);
    RETURN(setupExperiment(inst, startTime, stopTimeDefined != fmi2False, stopTime));
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    BEGIN(fmi2EnterInitializationMode);
    inst->state = InitializationMode;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    BEGIN(fmi2ExitInitializationMode);
    if (checkModel(inst, &inst->data) > Warning) RETURN(Error);
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
    RETURN(getFloat64s(inst, vr, nvr, value));
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
    BEGIN(fmi2Set);
    RETURN(setFloat64s(inst, vr, nvr, value));
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[]) {
    size_t i;
    bool b;
    BEGIN(fmi2Get);
    CHECK_ARRAY(fmi2GetBoolean, vr, nvr);
    CHECK_ARRAY(fmi2GetBoolean, value, nvr);
    for (i = 0; i < nvr; i++) {
        if (getBoolean(inst, vr[i], &b) > Warning) RETURN(Error);
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
        if (setBoolean(inst, vr[i], value[i] != fmi2False) > Warning) RETURN(Error);
    return fmi2OK;
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[]) {
    (void)vr;
    (void)value;
    BEGIN(fmi2Get);
    RETURN(noVariables(inst, "Integer", nvr));
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[]) {
    (void)vr;
    (void)value;
    BEGIN(fmi2Get);
    RETURN(noVariables(inst, "String", nvr));
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Integer value[]) {
    (void)vr;
    (void)value;
    BEGIN(fmi2Set);
    RETURN(noVariables(inst, "Integer", nvr));
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[]) {
    (void)vr;
    (void)value;
    BEGIN(fmi2Set);
    RETURN(noVariables(inst, "String", nvr));
}

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *FMUstate) {
    BEGIN(fmi2FMUstate);
    RETURN(getFMUState(inst, FMUstate));
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate) {
    BEGIN(fmi2FMUstate);
    RETURN(setFMUState(inst, FMUstate));
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *FMUstate) {
    BEGIN(fmi2FMUstate);
    RETURN(freeFMUState(inst, FMUstate));
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate FMUstate, size_t *size) {
    BEGIN(fmi2FMUstate);
    RETURN(serializedStateSize(inst, FMUstate, size));
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate FMUstate, fmi2Byte serializedState[],
                                 size_t size) {
    BEGIN(fmi2FMUstate);
    RETURN(serializeState(inst, FMUstate, (unsigned char *)serializedState, size));
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[], size_t size,
                                   fmi2FMUstate *FMUstate) {
    BEGIN(fmi2FMUstate);
    RETURN(deserializeState(inst, (const unsigned char *)serializedState, size, FMUstate));
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[],
                                        size_t nUnknown, const fmi2ValueReference vKnown_ref[], size_t nKnown,
                                        const fmi2Real dvKnown[], fmi2Real dvUnknown[]) {
    BEGIN(fmi2GetDirectionalDerivative);
    RETURN(partialDerivatives(inst, false, vUnknown_ref, nUnknown, vKnown_ref, nKnown, dvKnown, dvUnknown));
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
    RETURN(setTime(inst, time));
}

fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t nx) {
    BEGIN(fmi2SetContinuousStates);
    RETURN(setContinuousStates(inst, x, nx));
}

fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real derivatives[], size_t nx) {
    BEGIN(fmi2GetStates);
    RETURN(getStateDerivatives(inst, "fmi2GetDerivatives", derivatives, nx));
}

fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real eventIndicators[], size_t ni) {
    (void)eventIndicators;
    BEGIN(fmi2GetStates);
    RETURN(noVariables(inst, "event indicator", ni));
}

fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real x[], size_t nx) {
    BEGIN(fmi2GetStates);
    RETURN(getContinuousStates(inst, "fmi2GetContinuousStates", x, nx));
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, fmi2Real x_nominal[], size_t nx) {
    BEGIN(fmi2GetNominals);
    RETURN(getNominals(inst, "fmi2GetNominalsOfContinuousStates", x_nominal, nx));
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
    RETURN(Error);
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[]) {
    (void)vr;
    (void)order;
    (void)value;
    BEGIN(fmi2OutputDerivatives);
    if (nvr == 0) return fmi2OK;
    logError(inst, "fmi2GetRealOutputDerivatives: maxOutputDerivativeOrder is 0");
    RETURN(Error);
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentCommunicationPoint) {
    (void)noSetFMUStatePriorToCurrentCommunicationPoint;
    BEGIN(fmi2DoStep);
    RETURN(stepInstance(inst, currentCommunicationPoint, communicationStepSize));
}

fmi2Status fmi2CancelStep(fmi2Component c) {
    BEGIN(fmi2DoStep);
    logError(inst, "fmi2CancelStep: steps complete synchronously, there is nothing to cancel");
    RETURN(Error);
}

/* steps never run asynchronously: the status functions answer for the last completed step; a status
   kind without an answer is fmi2Discard, logged in the category logStatusDiscard */
static fmi2Status noStatus(ModelInstance *inst, const char *function, int kind) {
    logDiscard(inst, "%s: no value for status kind %d (steps complete synchronously)", function, kind);
    return fmi2Discard;
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) {
    BEGIN(fmi2Status);
    CHECK_ARRAY(fmi2GetStatus, value, 1);
    if (s != fmi2DoStepStatus) return noStatus(inst, "fmi2GetStatus", (int)s);
    *value = fmi2OK;
    return fmi2OK;
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value) {
    BEGIN(fmi2Status);
    CHECK_ARRAY(fmi2GetRealStatus, value, 1);
    if (s != fmi2LastSuccessfulTime) return noStatus(inst, "fmi2GetRealStatus", (int)s);
    *value = inst->time;
    return fmi2OK;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value) {
    (void)value;
    BEGIN(fmi2Status);
    return noStatus(inst, "fmi2GetIntegerStatus", (int)s);
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value) {
    BEGIN(fmi2Status);
    CHECK_ARRAY(fmi2GetBooleanStatus, value, 1);
    if (s != fmi2Terminated) return noStatus(inst, "fmi2GetBooleanStatus", (int)s);
    *value = fmi2False;
    return fmi2OK;
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value) {
    (void)value;
    BEGIN(fmi2Status);
    return noStatus(inst, "fmi2GetStringStatus", (int)s);
}
