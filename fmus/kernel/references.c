/* Motor references, the same arithmetic as designer/cosim/references.py, operation for operation,
 * so a run gives the same bits as the Python master (built with -ffp-contract=off and without the
 * sin/cos builtins, so every call goes to the C library that Python's math module and numpy's
 * scalar loops use). */
#include <math.h>

#include "kernel.h"

static const double PI = 3.141592653589793;

static void step_ref(const double *p, double t, double *q, double *v) {
    *q = t >= p[1] ? p[2] + p[0] : p[2];
    *v = 0.0;
}

static void sine_ref(const double *p, double t, double *q, double *v) {
    double w = 2.0 * PI * p[1];
    *q = p[2] + p[0] * sin(w * t + p[3]);
    *v = p[0] * w * cos(w * t + p[3]);
}

/* designer.chirp.Chirp.motion on a 0-d array: numpy squares t**2 as t * t */
static void chirp_ref(const double *p, double t, double *q, double *v) {
    double rate = (p[2] - p[1]) / p[3];
    double phase = 2.0 * PI * (p[1] * t + rate * (t * t) / 2.0);
    double omega = 2.0 * PI * (p[1] + rate * t);
    *q = p[0] * sin(phase);
    *v = p[0] * omega * cos(phase);
}

/* Linear between samples, held outside; the interval is the last i with t[i] <= t (numpy's
 * searchsorted(side="right") - 1), found from the previous one since time only grows. */
static void table_ref(ks_reference *r, double t, double *q, double *v) {
    int64_t i = r->cursor;
    if (i >= r->n || (i >= 0 && r->t[i] > t)) i = -1;
    while (i + 1 < r->n && r->t[i + 1] <= t) i++;
    r->cursor = i;
    if (i < 0) {
        *q = r->q[0];
        *v = 0.0;
    } else if (i >= r->n - 1) {
        *q = r->q[r->n - 1];
        *v = 0.0;
    } else {
        double rate = (r->q[i + 1] - r->q[i]) / (r->t[i + 1] - r->t[i]);
        *q = r->q[i] + rate * (t - r->t[i]);
        *v = rate;
    }
}

void ks_reference_eval(ks_reference *ref, double t, double *q, double *v) {
    switch (ref->kind) {
    case KS_REF_STEP: step_ref(ref->p, t, q, v); break;
    case KS_REF_SINE: sine_ref(ref->p, t, q, v); break;
    case KS_REF_CHIRP: chirp_ref(ref->p, t, q, v); break;
    default: table_ref(ref, t, q, v); break;
    }
}

void ks_robot_motors(ks_robot *robot, double t) {
    for (int32_t j = 0; j < robot->n_joints; j++)
        ks_reference_eval(&robot->refs[j], t, &robot->motor_q[j], &robot->motor_v[j]);
}
