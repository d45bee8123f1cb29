/* The runtime's and the model's external names, prefixed like the FMI functions when an importer
   builds the sources with FMI2_FUNCTION_PREFIX or FMI3_FUNCTION_PREFIX (FMI 2.0.4 section 2.1.1,
   FMI 3 section 2.2.1), so several FMUs built from source link into one executable. Without a
   prefix (a shared library, where only the FMI functions are exported) the names stay as written. */
#ifndef FLEXJOINT_NAMES_H
#define FLEXJOINT_NAMES_H

#if defined(FMI2_FUNCTION_PREFIX)
#define FJ_PREFIX FMI2_FUNCTION_PREFIX
#elif defined(FMI3_FUNCTION_PREFIX)
#define FJ_PREFIX FMI3_FUNCTION_PREFIX
#endif

#ifdef FJ_PREFIX
#define FJ_PASTE(a, b) a##b
#define FJ_NAME(a, b) FJ_PASTE(a, b)
#define allowedIn FJ_NAME(FJ_PREFIX, allowedIn)
#define applyStart FJ_NAME(FJ_PREFIX, applyStart)
#define checkArray FJ_NAME(FJ_PREFIX, checkArray)
#define checkModel FJ_NAME(FJ_PREFIX, checkModel)
#define checkStateCount FJ_NAME(FJ_PREFIX, checkStateCount)
#define createInstance FJ_NAME(FJ_PREFIX, createInstance)
#define deserializeState FJ_NAME(FJ_PREFIX, deserializeState)
#define doStep FJ_NAME(FJ_PREFIX, doStep)
#define escalate FJ_NAME(FJ_PREFIX, escalate)
#define freeFMUState FJ_NAME(FJ_PREFIX, freeFMUState)
#define freeInstance FJ_NAME(FJ_PREFIX, freeInstance)
#define getBoolean FJ_NAME(FJ_PREFIX, getBoolean)
#define getBooleans FJ_NAME(FJ_PREFIX, getBooleans)
#define getContinuousStates FJ_NAME(FJ_PREFIX, getContinuousStates)
#define getDerivatives FJ_NAME(FJ_PREFIX, getDerivatives)
#define getF64 FJ_NAME(FJ_PREFIX, getF64)
#define getFMUState FJ_NAME(FJ_PREFIX, getFMUState)
#define getFloat64 FJ_NAME(FJ_PREFIX, getFloat64)
#define getFloat64s FJ_NAME(FJ_PREFIX, getFloat64s)
#define getNominals FJ_NAME(FJ_PREFIX, getNominals)
#define getPartial FJ_NAME(FJ_PREFIX, getPartial)
#define getStateDerivatives FJ_NAME(FJ_PREFIX, getStateDerivatives)
#define getStates FJ_NAME(FJ_PREFIX, getStates)
#define getU32 FJ_NAME(FJ_PREFIX, getU32)
#define logDiscard FJ_NAME(FJ_PREFIX, logDiscard)
#define logError FJ_NAME(FJ_PREFIX, logError)
#define logEvent FJ_NAME(FJ_PREFIX, logEvent)
#define modelDataSize FJ_NAME(FJ_PREFIX, modelDataSize)
#define noVariables FJ_NAME(FJ_PREFIX, noVariables)
#define numberOfStates FJ_NAME(FJ_PREFIX, numberOfStates)
#define partialDerivatives FJ_NAME(FJ_PREFIX, partialDerivatives)
#define putF64 FJ_NAME(FJ_PREFIX, putF64)
#define putU32 FJ_NAME(FJ_PREFIX, putU32)
#define readModelData FJ_NAME(FJ_PREFIX, readModelData)
#define resetInstance FJ_NAME(FJ_PREFIX, resetInstance)
#define serializeState FJ_NAME(FJ_PREFIX, serializeState)
#define serializedStateSize FJ_NAME(FJ_PREFIX, serializedStateSize)
#define setBoolean FJ_NAME(FJ_PREFIX, setBoolean)
#define setBooleans FJ_NAME(FJ_PREFIX, setBooleans)
#define setContinuousStates FJ_NAME(FJ_PREFIX, setContinuousStates)
#define setFMUState FJ_NAME(FJ_PREFIX, setFMUState)
#define setFloat64 FJ_NAME(FJ_PREFIX, setFloat64)
#define setFloat64s FJ_NAME(FJ_PREFIX, setFloat64s)
#define setLogCategory FJ_NAME(FJ_PREFIX, setLogCategory)
#define setStates FJ_NAME(FJ_PREFIX, setStates)
#define setTime FJ_NAME(FJ_PREFIX, setTime)
#define setupExperiment FJ_NAME(FJ_PREFIX, setupExperiment)
#define stepInstance FJ_NAME(FJ_PREFIX, stepInstance)
#define writeModelData FJ_NAME(FJ_PREFIX, writeModelData)
#endif

#endif
