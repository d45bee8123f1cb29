/* What a model provides to the generic FMI layers: its variables (by value reference) and its equations. */
#ifndef FLEXJOINT_MODEL_H
#define FLEXJOINT_MODEL_H

#include "instance.h"

/* one entry of the start-value file: `name value` (the file's `token` line is handled by the runtime) */
Status applyStart(ModelInstance *inst, const char *name, const char *value);
/* check model data (the instance's after its start values, or a state being restored); logs problems */
Status checkModel(ModelInstance *inst, const ModelData *data);

Status getFloat64(ModelInstance *inst, unsigned vr, double *value);
Status setFloat64(ModelInstance *inst, unsigned vr, double value);
Status getBoolean(ModelInstance *inst, unsigned vr, bool *value);
Status setBoolean(ModelInstance *inst, unsigned vr, bool value);
/* d unknown / d known at the current point (the model is linear, so this is exact) */
Status getPartial(ModelInstance *inst, unsigned unknown, unsigned known, double *value);

size_t numberOfStates(ModelInstance *inst);
void getStates(ModelInstance *inst, double x[]);
void setStates(ModelInstance *inst, const double x[]);
void getDerivatives(ModelInstance *inst, double dx[]);

/* the model's part of a serialised FMU state: its size, writing it, reading and checking it */
size_t modelDataSize(ModelInstance *inst);
void writeModelData(ModelInstance *inst, const ModelData *data, unsigned char bytes[]);
Status readModelData(ModelInstance *inst, const unsigned char bytes[], ModelData *data);

/* advance the co-simulation by h, inputs held constant over the step */
Status doStep(ModelInstance *inst, double h);

#endif
