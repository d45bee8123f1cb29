/* FlexJoint: up to six independent spring-damper axis channels; its data and value references. */
#ifndef FLEXJOINT_CONFIG_H
#define FLEXJOINT_CONFIG_H

#include <stdbool.h>

#define MODEL_IDENTIFIER "FlexJoint"
#define N_AXES 6

/* value reference of a variable: 100 * (axis index + 1) + field, time is 0 */
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
