/* The generic FMI 3.0 layer: calling-sequence checks with per-function state masks, the importer's logger,
   status escalation; everything model-specific is delegated to model.h, the model's capabilities come from
   its config.h. Scheduled Execution, clocks,
   structural parameters and variable types other than Float64 and Boolean are not part of the model. */
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"
#include "model.h"

#define ANY_LIVE (Instantiated | InitializationMode | EventMode | ContinuousTimeMode | StepMode | Terminated)
#define MASK_fmi3SetDebugLogging (ANY_LIVE | ErrorState)
#define MASK_fmi3EnterInitializationMode Instantiated
#define MASK_fmi3ExitInitializationMode InitializationMode
#define MASK_fmi3EnterEventMode (HAS_EVENT_MODE ? ContinuousTimeMode | StepMode : ME_ONLY | ContinuousTimeMode)
#define MASK_fmi3Terminate (EventMode | ContinuousTimeMode | StepMode)
#define MASK_fmi3Reset (ANY_LIVE | ErrorState)
#define MASK_fmi3Get (ANY_LIVE | ErrorState)
#define MASK_fmi3Set (Instantiated | InitializationMode | EventMode | ContinuousTimeMode | StepMode)
#define MASK_fmi3Unsupported (ANY_LIVE | ErrorState)
#define MASK_fmi3FMUState (ANY_LIVE | ErrorState)
#define MASK_fmi3Partials (InitializationMode | EventMode | ContinuousTimeMode | StepMode | Terminated | ErrorState)
#define MASK_fmi3EvaluateDiscreteStates (InitializationMode | EventMode | StepMode)
#define MASK_fmi3UpdateDiscreteStates EventMode
#define MASK_fmi3EnterContinuousTimeMode (ME_ONLY | EventMode)
#define MASK_fmi3CompletedIntegratorStep (ME_ONLY | ContinuousTimeMode)
#define MASK_fmi3SetTime (ME_ONLY | EventMode | ContinuousTimeMode)
#define MASK_fmi3SetContinuousStates (ME_ONLY | ContinuousTimeMode)
#define MASK_fmi3GetStates (ME_ONLY | InitializationMode | EventMode | ContinuousTimeMode | Terminated | ErrorState)
#define MASK_fmi3GetNominals (MASK_fmi3GetStates | Instantiated)
#define MASK_fmi3GetNumbers (ME_ONLY | ANY_LIVE | ErrorState)
#define MASK_fmi3OutputDerivatives (CS_ONLY | StepMode | Terminated | ErrorState)
#define MASK_fmi3DoStep (CS_ONLY | StepMode)
#define MASK_fmi3EnterStepMode (CS_ONLY | EventMode)

#define BEGIN(f)                                                          \
    ModelInstance *inst = (ModelInstance *)instance;                      \
    if (!inst || !allowedIn(inst, #f, MASK_##f)) return fmi3Error

#define RETURN(status) return (fmi3Status)escalate(inst, (status))

#define CHECK_ARRAY(f, p, n) \
    if (checkArray(inst, #f, #p, (p), (n)) > Warning) RETURN(Error)

static void logFmi3(ModelInstance *inst, Status status, const char *category, const char *message) {
    fmi3LogMessageCallback logMessage = (fmi3LogMessageCallback)(size_t)inst->logger;
    if (logMessage) logMessage(inst->environment, (fmi3Status)status, category, message);
}

/* an error for a feature the model does not have */
static Status unsupported(ModelInstance *inst, const char *what) {
    logError(inst, "%s is not supported by this FMU", what);
    return Error;
}

/* scalar variables only: one value per value reference */
static Status checkValues(ModelInstance *inst, size_t nValueReferences, size_t nValues) {
    if (nValues == nValueReferences) return OK;
    logError(inst, "%zu values for %zu value references: the model has no arrays", nValues, nValueReferences);
    return Error;
}

const char *fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[]) {
    size_t i;
    BEGIN(fmi3SetDebugLogging);
    CHECK_ARRAY(fmi3SetDebugLogging, categories, nCategories);
    if (nCategories == 0) setLogCategory(inst, NULL, loggingOn);
    for (i = 0; i < nCategories; i++) {
        if (!categories[i] || !setLogCategory(inst, categories[i], loggingOn)) {
            logError(inst, "fmi3SetDebugLogging: unknown log category %s", categories[i] ? categories[i] : "(NULL)");
            RETURN(Error);
        }
    }
    return fmi3OK;
}

static fmi3Instance instantiate(fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath,
                                InterfaceType type, fmi3Boolean loggingOn, fmi3InstanceEnvironment environment,
                                fmi3LogMessageCallback logMessage) {
    if (!instanceName || !instantiationToken || !resourcePath) {
        if (logMessage && loggingOn)
            logMessage(environment, fmi3Error, "logStatusError",
                       "instanceName, instantiationToken and resourcePath are required");
        return NULL;
    }
    return createInstance(instanceName, instantiationToken, resourcePath, type, 3, loggingOn, logFmi3,
                          (void *)(size_t)logMessage, environment);
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage) {
    (void)visible;
    return instantiate(instanceName, instantiationToken, resourcePath, ModelExchange, loggingOn,
                       instanceEnvironment, logMessage);
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                         fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
                                         const fmi3ValueReference requiredIntermediateVariables[],
                                         size_t nRequiredIntermediateVariables,
                                         fmi3InstanceEnvironment instanceEnvironment,
                                         fmi3LogMessageCallback logMessage,
                                         fmi3IntermediateUpdateCallback intermediateUpdate) {
    (void)visible;
    (void)earlyReturnAllowed;
    (void)requiredIntermediateVariables;
    (void)nRequiredIntermediateVariables;
    (void)intermediateUpdate;
    if (eventModeUsed && !HAS_EVENT_MODE) {
        if (logMessage && loggingOn)
            logMessage(instanceEnvironment, fmi3Error, "logStatusError",
                       "eventModeUsed = true, but the FMU has no event mode (hasEventMode = false)");
        return NULL;
    }
    return instantiate(instanceName, instantiationToken, resourcePath, CoSimulation, loggingOn,
                       instanceEnvironment, logMessage);
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String instanceName, fmi3String instantiationToken,
                                               fmi3String resourcePath, fmi3Boolean visible,
                                               fmi3Boolean loggingOn, fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3LogMessageCallback logMessage,
                                               fmi3ClockUpdateCallback clockUpdate,
                                               fmi3LockPreemptionCallback lockPreemption,
                                               fmi3UnlockPreemptionCallback unlockPreemption) {
    (void)instantiationToken;
    (void)resourcePath;
    (void)visible;
    (void)clockUpdate;
    (void)lockPreemption;
    (void)unlockPreemption;
    if (logMessage && loggingOn)
        logMessage(instanceEnvironment, fmi3Error, "logStatusError",
                   instanceName ? "Scheduled Execution is not supported by this FMU" : "instanceName is NULL");
    return NULL;
}

void fmi3FreeInstance(fmi3Instance instance) { freeInstance((ModelInstance *)instance); }

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    (void)toleranceDefined;
    (void)tolerance;
    BEGIN(fmi3EnterInitializationMode);
    if (setupExperiment(inst, startTime, stopTimeDefined, stopTime) > Warning) RETURN(Error);
    inst->state = InitializationMode;
    return fmi3OK;
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    BEGIN(fmi3ExitInitializationMode);
    if (checkModel(inst, &inst->data) > Warning) RETURN(Error);
    inst->state = inst->type == ModelExchange ? EventMode : StepMode;
    return fmi3OK;
}

fmi3Status fmi3EnterEventMode(fmi3Instance instance) {
    BEGIN(fmi3EnterEventMode);
    inst->state = EventMode;
    return fmi3OK;
}

fmi3Status fmi3Terminate(fmi3Instance instance) {
    BEGIN(fmi3Terminate);
    inst->state = Terminated;
    return fmi3OK;
}

fmi3Status fmi3Reset(fmi3Instance instance) {
    BEGIN(fmi3Reset);
    return (fmi3Status)resetInstance(inst);
}

/* ---- getting and setting variable values */

fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                          size_t nValueReferences, fmi3Float64 values[], size_t nValues) {
    BEGIN(fmi3Get);
    if (checkValues(inst, nValueReferences, nValues) > Warning) RETURN(Error);
    RETURN(getFloat64s(inst, valueReferences, nValueReferences, values));
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                          size_t nValueReferences, const fmi3Float64 values[], size_t nValues) {
    BEGIN(fmi3Set);
    if (checkValues(inst, nValueReferences, nValues) > Warning) RETURN(Error);
    RETURN(setFloat64s(inst, valueReferences, nValueReferences, values));
}

fmi3Status fmi3GetBoolean(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                          size_t nValueReferences, fmi3Boolean values[], size_t nValues) {
    BEGIN(fmi3Get);
    if (checkValues(inst, nValueReferences, nValues) > Warning) RETURN(Error);
    RETURN(getBooleans(inst, valueReferences, nValueReferences, values));
}

fmi3Status fmi3SetBoolean(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                          size_t nValueReferences, const fmi3Boolean values[], size_t nValues) {
    BEGIN(fmi3Set);
    if (checkValues(inst, nValueReferences, nValues) > Warning) RETURN(Error);
    RETURN(setBooleans(inst, valueReferences, nValueReferences, values));
}

/* accessors of the types the model does not have: any value reference is unknown */
#define NO_VARIABLES(T, CT)                                                                              \
    fmi3Status fmi3Get##T(fmi3Instance instance, const fmi3ValueReference valueReferences[],             \
                          size_t nValueReferences, CT values[], size_t nValues) {                        \
        (void)valueReferences;                                                                           \
        (void)values;                                                                                    \
        (void)nValues;                                                                                   \
        BEGIN(fmi3Get);                                                                                  \
        RETURN(noVariables(inst, #T, nValueReferences));                                                 \
    }                                                                                                    \
    fmi3Status fmi3Set##T(fmi3Instance instance, const fmi3ValueReference valueReferences[],             \
                          size_t nValueReferences, const CT values[], size_t nValues) {                  \
        (void)valueReferences;                                                                           \
        (void)values;                                                                                    \
        (void)nValues;                                                                                   \
        BEGIN(fmi3Set);                                                                                  \
        RETURN(noVariables(inst, #T, nValueReferences));                                                 \
    }

NO_VARIABLES(Float32, fmi3Float32)
NO_VARIABLES(Int8, fmi3Int8)
NO_VARIABLES(UInt8, fmi3UInt8)
NO_VARIABLES(Int16, fmi3Int16)
NO_VARIABLES(UInt16, fmi3UInt16)
NO_VARIABLES(Int32, fmi3Int32)
NO_VARIABLES(UInt32, fmi3UInt32)
NO_VARIABLES(Int64, fmi3Int64)
NO_VARIABLES(UInt64, fmi3UInt64)
NO_VARIABLES(String, fmi3String)

fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                         size_t nValueReferences, size_t valueSizes[], fmi3Binary values[], size_t nValues) {
    (void)valueReferences;
    (void)valueSizes;
    (void)values;
    (void)nValues;
    BEGIN(fmi3Get);
    RETURN(noVariables(inst, "Binary", nValueReferences));
}

fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                         size_t nValueReferences, const size_t valueSizes[], const fmi3Binary values[],
                         size_t nValues) {
    (void)valueReferences;
    (void)valueSizes;
    (void)values;
    (void)nValues;
    BEGIN(fmi3Set);
    RETURN(noVariables(inst, "Binary", nValueReferences));
}

fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                        size_t nValueReferences, fmi3Clock values[]) {
    (void)valueReferences;
    (void)values;
    BEGIN(fmi3Get);
    RETURN(noVariables(inst, "Clock", nValueReferences));
}

fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                        size_t nValueReferences, const fmi3Clock values[]) {
    (void)valueReferences;
    (void)values;
    BEGIN(fmi3Set);
    RETURN(noVariables(inst, "Clock", nValueReferences));
}

/* ---- variable dependencies: declared in modelDescription.xml, not queried at run time */

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance, fmi3ValueReference valueReference,
                                               size_t *nDependencies) {
    (void)valueReference;
    (void)nDependencies;
    BEGIN(fmi3Unsupported);
    RETURN(unsupported(inst, "fmi3GetNumberOfVariableDependencies (see ModelStructure)"));
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[], fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[], fmi3DependencyKind dependencyKinds[],
                                       size_t nDependencies) {
    (void)dependent;
    (void)elementIndicesOfDependent;
    (void)independents;
    (void)elementIndicesOfIndependents;
    (void)dependencyKinds;
    (void)nDependencies;
    BEGIN(fmi3Unsupported);
    RETURN(unsupported(inst, "fmi3GetVariableDependencies (see ModelStructure)"));
}

/* ---- FMU state */

fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *FMUState) {
    BEGIN(fmi3FMUState);
    RETURN(getFMUState(inst, FMUState));
}

fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState FMUState) {
    BEGIN(fmi3FMUState);
    RETURN(setFMUState(inst, FMUState));
}

fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *FMUState) {
    BEGIN(fmi3FMUState);
    RETURN(freeFMUState(inst, FMUState));
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState FMUState, size_t *size) {
    BEGIN(fmi3FMUState);
    RETURN(serializedStateSize(inst, FMUState, size));
}

fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState FMUState, fmi3Byte serializedState[],
                                 size_t size) {
    BEGIN(fmi3FMUState);
    RETURN(serializeState(inst, FMUState, serializedState, size));
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte serializedState[], size_t size,
                                   fmi3FMUState *FMUState) {
    BEGIN(fmi3FMUState);
    RETURN(deserializeState(inst, serializedState, size, FMUState));
}

/* ---- partial derivatives (the model is linear: exact) */

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[],
                                        size_t nUnknowns, const fmi3ValueReference knowns[], size_t nKnowns,
                                        const fmi3Float64 seed[], size_t nSeed, fmi3Float64 sensitivity[],
                                        size_t nSensitivity) {
    BEGIN(fmi3Partials);
    if (nSeed != nKnowns || nSensitivity != nUnknowns) RETURN(unsupported(inst, "array-valued partials"));
    RETURN(partialDerivatives(inst, false, unknowns, nUnknowns, knowns, nKnowns, seed, sensitivity));
}

fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                    const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                    size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity) {
    BEGIN(fmi3Partials);
    if (nSeed != nUnknowns || nSensitivity != nKnowns) RETURN(unsupported(inst, "array-valued partials"));
    RETURN(partialDerivatives(inst, true, unknowns, nUnknowns, knowns, nKnowns, seed, sensitivity));
}

/* ---- configuration mode and clocks: the model has no structural parameters and no clocks */

fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance) {
    BEGIN(fmi3Unsupported);
    RETURN(unsupported(inst, "configuration mode (no structural parameters)"));
}

fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance) {
    BEGIN(fmi3Unsupported);
    RETURN(unsupported(inst, "configuration mode (no structural parameters)"));
}

#define NO_CLOCKS(f, ...)                                                                                \
    fmi3Status f(fmi3Instance instance, const fmi3ValueReference valueReferences[],                      \
                 size_t nValueReferences, __VA_ARGS__) {                                                 \
        (void)valueReferences;                                                                           \
        (void)nValueReferences;                                                                          \
        BEGIN(fmi3Unsupported);                                                                          \
        RETURN(unsupported(inst, #f " (no clocks)"));                                                    \
    }

NO_CLOCKS(fmi3GetIntervalDecimal, fmi3Float64 intervals[], fmi3IntervalQualifier qualifiers[])
NO_CLOCKS(fmi3GetIntervalFraction, fmi3UInt64 counters[], fmi3UInt64 resolutions[],
          fmi3IntervalQualifier qualifiers[])
NO_CLOCKS(fmi3GetShiftDecimal, fmi3Float64 shifts[])
NO_CLOCKS(fmi3GetShiftFraction, fmi3UInt64 counters[], fmi3UInt64 resolutions[])
NO_CLOCKS(fmi3SetIntervalDecimal, const fmi3Float64 intervals[])
NO_CLOCKS(fmi3SetIntervalFraction, const fmi3UInt64 counters[], const fmi3UInt64 resolutions[])
NO_CLOCKS(fmi3SetShiftDecimal, const fmi3Float64 shifts[])
NO_CLOCKS(fmi3SetShiftFraction, const fmi3UInt64 counters[], const fmi3UInt64 resolutions[])

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clockReference,
                                      fmi3Float64 activationTime) {
    (void)clockReference;
    (void)activationTime;
    BEGIN(fmi3Unsupported);
    RETURN(unsupported(inst, "Scheduled Execution"));
}

/* ---- discrete states: a linear model without events */

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance) {
    BEGIN(fmi3EvaluateDiscreteStates);
    return fmi3OK;
}

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *discreteStatesNeedUpdate,
                                    fmi3Boolean *terminateSimulation, fmi3Boolean *nominalsOfContinuousStatesChanged,
                                    fmi3Boolean *valuesOfContinuousStatesChanged, fmi3Boolean *nextEventTimeDefined,
                                    fmi3Float64 *nextEventTime) {
    BEGIN(fmi3UpdateDiscreteStates);
    if (discreteStatesNeedUpdate) *discreteStatesNeedUpdate = false;
    if (terminateSimulation) *terminateSimulation = false;
    if (nominalsOfContinuousStatesChanged) *nominalsOfContinuousStatesChanged = false;
    if (valuesOfContinuousStatesChanged) *valuesOfContinuousStatesChanged = false;
    if (nextEventTimeDefined) *nextEventTimeDefined = false;
    if (nextEventTime) *nextEventTime = 0;
    return fmi3OK;
}

/* ---- Model Exchange */

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) {
    BEGIN(fmi3EnterContinuousTimeMode);
    inst->state = ContinuousTimeMode;
    return fmi3OK;
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation) {
    (void)noSetFMUStatePriorToCurrentPoint;
    BEGIN(fmi3CompletedIntegratorStep);
    CHECK_ARRAY(fmi3CompletedIntegratorStep, enterEventMode, 1);
    CHECK_ARRAY(fmi3CompletedIntegratorStep, terminateSimulation, 1);
    *enterEventMode = false;
    *terminateSimulation = false;
    return fmi3OK;
}

fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time) {
    BEGIN(fmi3SetTime);
    RETURN(setTime(inst, time));
}

fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 continuousStates[],
                                   size_t nContinuousStates) {
    BEGIN(fmi3SetContinuousStates);
    RETURN(setContinuousStates(inst, continuousStates, nContinuousStates));
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 derivatives[],
                                             size_t nContinuousStates) {
    BEGIN(fmi3GetStates);
    RETURN(getStateDerivatives(inst, "fmi3GetContinuousStateDerivatives", derivatives, nContinuousStates));
}

fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 eventIndicators[], size_t nEventIndicators) {
    (void)eventIndicators;
    BEGIN(fmi3GetStates);
    RETURN(noVariables(inst, "event indicator", nEventIndicators));
}

fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 continuousStates[],
                                   size_t nContinuousStates) {
    BEGIN(fmi3GetStates);
    RETURN(getContinuousStates(inst, "fmi3GetContinuousStates", continuousStates, nContinuousStates));
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 nominals[],
                                             size_t nContinuousStates) {
    BEGIN(fmi3GetNominals);
    RETURN(getNominals(inst, "fmi3GetNominalsOfContinuousStates", nominals, nContinuousStates));
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *nEventIndicators) {
    BEGIN(fmi3GetNumbers);
    CHECK_ARRAY(fmi3GetNumberOfEventIndicators, nEventIndicators, 1);
    *nEventIndicators = N_EVENT_INDICATORS;
    return fmi3OK;
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *nContinuousStates) {
    BEGIN(fmi3GetNumbers);
    CHECK_ARRAY(fmi3GetNumberOfContinuousStates, nContinuousStates, 1);
    *nContinuousStates = numberOfStates(inst);
    return fmi3OK;
}

/* ---- Co-Simulation */

fmi3Status fmi3EnterStepMode(fmi3Instance instance) {
    BEGIN(fmi3EnterStepMode);
    inst->state = StepMode;
    return fmi3OK;
}

fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, const fmi3Int32 orders[], fmi3Float64 values[],
                                    size_t nValues) {
    (void)valueReferences;
    (void)orders;
    (void)values;
    (void)nValues;
    BEGIN(fmi3OutputDerivatives);
    if (nValueReferences == 0) return fmi3OK;
    RETURN(unsupported(inst, "output derivatives (maxOutputDerivativeOrder is 0)"));
}

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint,
                      fmi3Float64 communicationStepSize, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                      fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn,
                      fmi3Float64 *lastSuccessfulTime) {
    Status status;
    (void)noSetFMUStatePriorToCurrentPoint;
    BEGIN(fmi3DoStep);
    status = stepInstance(inst, currentCommunicationPoint, communicationStepSize);
    if (eventHandlingNeeded) *eventHandlingNeeded = false;
    if (terminateSimulation) *terminateSimulation = false;
    if (earlyReturn) *earlyReturn = false;
    if (lastSuccessfulTime) *lastSuccessfulTime = inst->time;
    RETURN(status);
}
