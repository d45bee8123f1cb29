/* What a model provides to the generic FMI layers: its variables (by value reference) and its equations. */
#ifndef FLEXJOINT_MODEL_H
#define FLEXJOINT_MODEL_H

#include "instance.h"

/* one entry of the start-value file: `name value` (the file's `token` line is handled by the runtime) */
Status applyStart(ModelInstance *inst, const char *name, const char *value);
/* the start values are in place: check them before the instance is handed out */
Status checkModel(ModelInstance *inst);

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

/* advance the co-simulation by h, inputs held constant over the step */
Status doStep(ModelInstance *inst, double h);

#endif
