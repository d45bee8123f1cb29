/* The kernel's systems: get outputs into a row, set inputs from a row, step; each returns the FMI
 * status (0 OK, 1 Warning, 2 Discard, 3 Error, 4 Fatal); the robot's step returns 2 or more when
 * MuJoCo reset a diverged state. */
#include <mujoco/mujoco.h>

#include "fmi2FunctionTypes.h"
#include "fmi3FunctionTypes.h"
#include "kernel.h"

/* Outputs in Robot.outputs order: deflections, their rates, joint angles, motor angles. */
static void robot_get(const ks_robot *r, double *out) {
    const mjData *d = (const mjData *)r->data;
    int32_t n = r->n_joints;
    for (int32_t j = 0; j < n; j++) {
        double q = d->qpos[r->qposadr[j]];
        out[j] = q - r->motor_q[j];
        out[n + j] = d->qvel[r->dofadr[j]] - r->motor_v[j];
        out[2 * n + j] = q;
        out[3 * n + j] = r->motor_q[j];
    }
}

/* One physics step, then the motors at the new time; MuJoCo's bad-acceleration warning (it reset the
 * state) is the robot's divergence, as in Robot.do_step. */
static int32_t robot_step(ks_robot *r, double h) {
    mjData *d = (mjData *)r->data;
    for (int32_t i = 0; i < r->n_engine; i++) {
        const double *law = r->engine_law + 3 * i;
        int32_t j = r->engine_joint[i];
        d->ctrl[r->engine_actuator[i]] = law[0] * (r->motor_q[j] + law[2]) + law[1] * r->motor_v[j];
    }
    mj_step((const mjModel *)r->model, d);
    if (d->warning[mjWARN_BADQACC].number) return KS_ROBOT_DIVERGED;
    r->steps++;
    r->time = (double)r->steps * h;
    ks_robot_motors(r, r->time);
    return 0;
}

/* HubServo.set: the chirp at steps * h, then the servo's law on the specimen's s and v. */
static void servo_set(ks_servo *r, double s, double v) {
    double q, dq;
    ks_reference_eval(&r->chirp, (double)r->steps * r->h, &q, &dq);
    r->out[0] = r->stiffness * (q - s) + r->damping * (dq - v);
    r->out[1] = q;
}

int32_t ks_get(ks_system *s, double *row) {
    double *out = row + s->out_offset;
    switch (s->kind) {
    case KS_ROBOT: robot_get((const ks_robot *)s->instance, out); return 0;
    case KS_SERVO:
        out[0] = ((const ks_servo *)s->instance)->out[0];
        out[1] = ((const ks_servo *)s->instance)->out[1];
        return 0;
    case KS_FMI2:
        return ((fmi2GetRealTYPE *)s->get_fn)(s->instance, s->out_vr, (size_t)s->n_out, out);
    default:
        return ((fmi3GetFloat64TYPE *)s->get_fn)(s->instance, s->out_vr, (size_t)s->n_out, out,
                                                  (size_t)s->n_out);
    }
}

int32_t ks_set(ks_system *s, const double *row) {
    if (s->kind == KS_ROBOT) {
        const ks_robot *r = (const ks_robot *)s->instance;
        double *qfrc = ((mjData *)r->data)->qfrc_applied;
        for (int32_t k = 0; k < s->n_in; k++) qfrc[r->input_dof[k]] = row[s->src[k]];
        return 0;
    }
    if (s->kind == KS_SERVO) {
        servo_set((ks_servo *)s->instance, row[s->src[0]], row[s->src[1]]);
        return 0;
    }
    for (int32_t k = 0; k < s->n_in; k++) s->in_buf[k] = row[s->src[k]];
    if (s->kind == KS_FMI2)
        return ((fmi2SetRealTYPE *)s->set_fn)(s->instance, s->in_vr, (size_t)s->n_in, s->in_buf);
    return ((fmi3SetFloat64TYPE *)s->set_fn)(s->instance, s->in_vr, (size_t)s->n_in, s->in_buf,
                                              (size_t)s->n_in);
}

/* Model Exchange without states: time advances to (n + 1) h; the FMU may ask for an event or stop. */
static int32_t exchange_step(ks_system *s, double h) {
    int32_t status;
    int ask_event, ask_stop;
    s->steps++;
    s->failed = KS_CALL_TIME;
    if (s->kind == KS_FMI2) {
        fmi2Boolean event = fmi2False, stop = fmi2False;
        status = ((fmi2SetTimeTYPE *)s->time_fn)(s->instance, (double)s->steps * h);
        if (status > 1 || !s->completed_fn) return status;
        s->failed = KS_CALL_COMPLETED;
        status = ((fmi2CompletedIntegratorStepTYPE *)s->completed_fn)(s->instance, fmi2True, &event, &stop);
        ask_event = event, ask_stop = stop;
    } else {
        fmi3Boolean event = fmi3False, stop = fmi3False;
        status = ((fmi3SetTimeTYPE *)s->time_fn)(s->instance, (double)s->steps * h);
        if (status > 1 || !s->completed_fn) return status;
        s->failed = KS_CALL_COMPLETED;
        status = ((fmi3CompletedIntegratorStepTYPE *)s->completed_fn)(s->instance, fmi3True, &event, &stop);
        ask_event = event, ask_stop = stop;
    }
    s->asked = (ask_event ? KS_ASKED_EVENT : 0) | (ask_stop ? KS_ASKED_TERMINATE : 0);
    return status;
}

int32_t ks_step(ks_system *s, double h) {
    int32_t status;
    double t = (double)s->steps * h;
    if (s->kind == KS_ROBOT) return robot_step((ks_robot *)s->instance, h);
    if (s->kind == KS_SERVO) {
        ((ks_servo *)s->instance)->h = h;
        ((ks_servo *)s->instance)->steps++;
        return 0;
    }
    if (!s->step_fn) return exchange_step(s, h);
    if (s->kind == KS_FMI2) {
        status = ((fmi2DoStepTYPE *)s->step_fn)(s->instance, t, h, fmi2True);
    } else {
        fmi3Boolean event = fmi3False, terminate = fmi3False, early = fmi3False;
        fmi3Float64 last = 0.0;
        status = ((fmi3DoStepTYPE *)s->step_fn)(s->instance, t, h, fmi3True, &event, &terminate, &early,
                                                &last);
    }
    s->steps++;
    return status;
}
