/* FlexJoint: the model's one declaration of its identity, capabilities and variable layout.
   The generic FMI layers (runtime/) take the capabilities from here and supply defaults for what a
   model leaves out (runtime/instance.h); designer/export/layout.py reads this file to write the
   modelDescription.xml, so the layout and capabilities exist nowhere else. Keep the #define and enum
   lines in these simple forms: Python parses them. */
#ifndef FLEXJOINT_CONFIG_H
#define FLEXJOINT_CONFIG_H

#include <stdbool.h>

#define MODEL_IDENTIFIER "FlexJoint"

/* ---- capabilities (1 = yes, 0 = no) */
#define HAS_EVENT_MODE 0
#define PROVIDES_DIRECTIONAL_DERIVATIVES 1
#define PROVIDES_ADJOINT_DERIVATIVES 1
#define CAN_GET_AND_SET_FMU_STATE 1
#define CAN_SERIALIZE_FMU_STATE 1
#define NEEDS_COMPLETED_INTEGRATOR_STEP 0
#define CAN_HANDLE_VARIABLE_COMMUNICATION_STEP_SIZE 1
#define N_EVENT_INDICATORS 0

/* ---- variables: value reference = VR_AXIS_STRIDE * (axis index + 1) + field; time is VR_TIME */
#define N_AXES 6
#define AXIS_NAMES {"x", "y", "z", "theta", "phi", "psi"}
#define FIELD_NAMES {"m", "c", "k", "offset", "enabled", "s", "v", "f", "a"}
#define VR_TIME 0
#define VR_AXIS_STRIDE 100
enum { F_M, F_C, F_K, F_OFFSET, F_ENABLED, F_S, F_V, F_F, F_A, N_FIELDS };

typedef enum { ForceElement, Body } JointInterface;

typedef struct {
    double m, c, k, offset; /* tunable parameters, SI */
    bool enabled;
    double s, v, f;         /* displacement or angle, its rate, force or torque */
    /* exact zero-order-hold step: x(t+h) = phi x(t) + gamma f, x = (s - offset, v), cached for step h */
    bool cached;
    double h, phi[4], gamma[2];
} Axis;

typedef struct {
    JointInterface interface;
    unsigned declared; /* bit i set: axis i is in the modelDescription */
    Axis axis[N_AXES];
} ModelData;

#endif
