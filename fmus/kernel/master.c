/* The fixed-step loop of designer/cosim/master.py: per row, the exchange schedule (gets and sets in
 * the master's order), the row recorded, every system stepped, the row checked for non-finite values. */
#include <pthread.h>

#include <mujoco/mujoco.h>

#include "kernel.h"

static int32_t fail(ks_run *run, int32_t system, int32_t call, int32_t status, double t) {
    run->error_system = system;
    run->error_call = call;
    run->error_status = status;
    run->error_time = t;
    return run->systems[system].kind == KS_ROBOT ? KS_ROBOT_DIVERGED : KS_FMU_STATUS;
}

/* A status above Warning stops the run, as fmpy raises for it in the Python master. */
static int32_t exchange(ks_run *run, double *row, double t) {
    for (int32_t i = 0; i < run->n_ops; i++) {
        int32_t op = run->ops[2 * i], k = run->ops[2 * i + 1];
        ks_system *s = &run->systems[k];
        int32_t status = op == KS_GET ? ks_get(s, row) : ks_set(s, row);
        if (status > 1) return fail(run, k, op == KS_GET ? KS_CALL_GET : KS_CALL_SET, status, t);
    }
    return KS_OK;
}

/* Any NaN or infinity in the row makes the sum of value * 0 NaN: one multiply-add per column. */
static int finite_row(const double *row, int32_t n) {
    double acc = 0.0;
    for (int32_t k = 0; k < n; k++) acc += row[k] * 0.0;
    return acc == acc;
}

/* Steps every system from row i's time; an FMU's stop request ends the run, event requests are
 * collected (the Python side runs the event iterations before the next row). */
static int32_t step_all(ks_run *run, double t, int *events) {
    double h = run->step;
    for (int32_t k = 0; k < run->n_systems; k++) {
        ks_system *s = &run->systems[k];
        double at = s->kind == KS_ROBOT ? ((ks_robot *)s->instance)->time : t;
        int32_t status = ks_step(s, h);
        int me = (s->kind == KS_FMI2 || s->kind == KS_FMI3) && !s->step_fn;
        /* the times FmuSystem.do_step reports: n h for DoStep, (n + 1) h once Model Exchange moved on */
        if (status > 1)
            return fail(run, k, me ? s->failed : KS_CALL_STEP, status, me ? (double)s->steps * h : at);
        if (s->asked & KS_ASKED_TERMINATE) {
            run->error_system = k;
            run->error_time = t;
            return KS_TERMINATE;
        }
        *events |= s->asked;
    }
    return KS_OK;
}

static int32_t run_rows(ks_run *run, int64_t first, int64_t last) {
    double h = run->step;
    for (int64_t i = first; i < last; i++) {
        double *row = run->values + i * run->n_cols;
        double t = (double)i * h;
        int events = 0;
        int32_t rc = exchange(run, row, t);
        if (rc != KS_OK) return rc;
        if (i == run->n) break;
        rc = step_all(run, t, &events);
        if (rc != KS_OK) return rc;
        if (!finite_row(row, run->n_cols)) {
            run->error_time = t;
            return KS_DIVERGED;
        }
        if (events) {
            run->error_time = t;
            run->event_row = i;
            return KS_EVENT;
        }
    }
    return KS_OK;
}

/* MuJoCo's Python bindings install a clock as mjcb_time, which mj_step then reads around each of its
 * stages for its profiling timers (d->timer): about 0.7 us of a 2-link arm's step. The loops run
 * without it (no physics changes, only those timers stay still); the last loop to finish gives it
 * back, so runs in several threads at once do not lose it. */
static pthread_mutex_t clock_lock = PTHREAD_MUTEX_INITIALIZER;
static int clock_users = 0;
static mjfTime clock_saved = NULL;

int32_t ks_run_rows(ks_run *run, int64_t first, int64_t last) {
    int32_t rc;
    pthread_mutex_lock(&clock_lock);
    if (clock_users++ == 0) {
        clock_saved = mjcb_time;
        mjcb_time = NULL;
    }
    pthread_mutex_unlock(&clock_lock);
    rc = run_rows(run, first, last);
    pthread_mutex_lock(&clock_lock);
    if (--clock_users == 0) mjcb_time = clock_saved;
    pthread_mutex_unlock(&clock_lock);
    return rc;
}

void ks_sizes(int64_t sizes[3]) {
    sizes[0] = sizeof(ks_reference);
    sizes[1] = sizeof(ks_system);
    sizes[2] = sizeof(ks_run);
}

int64_t ks_struct_size(int32_t kind) {
    switch (kind) {
    case KS_ROBOT:
        return sizeof(ks_robot);
    case KS_SERVO:
        return sizeof(ks_servo);
    default:
        return 0; /* an FMU instance: no struct of ours */
    }
}
