/* The co-simulation stepping kernel: the fixed-step loop of designer/cosim/master.py in C.
 *
 * Python builds the connection graph, instantiates the FMUs (fmpy) and the MuJoCo model, then hands
 * this kernel the raw pointers: each FMU's instance and its fmi2/fmi3 Set/Get/DoStep functions, the
 * mjModel and mjData, and one exchange schedule (a list of get/set operations per system, the same
 * the Python master runs). The kernel steps rows [first, last) of a preallocated output array
 * (rows x columns, C order) and stops at the first FMU error status, MuJoCo warning, or non-finite
 * output, reporting where in `ks_run`. Every struct here is mirrored field for field by ctypes: the
 * kernel's own in designer/cosim/kernel.py and binding.py, a system's in its module (robot.py, rig.py).
 */
#ifndef DESIGNER_KERNEL_H
#define DESIGNER_KERNEL_H

#include <stdint.h>

#if defined(_WIN32)
#define KS_EXPORT __declspec(dllexport)
#else
#define KS_EXPORT __attribute__((visibility("default")))
#endif

/* kinds of system */
enum { KS_ROBOT = 0, KS_FMI2 = 1, KS_FMI3 = 2, KS_SERVO = 3 };
/* operations of the exchange schedule */
enum { KS_GET = 0, KS_SET = 1 };
/* motor references */
enum { KS_REF_STEP = 0, KS_REF_SINE = 1, KS_REF_CHIRP = 2, KS_REF_TABLE = 3 };
/* outcomes of ks_run_rows */
enum { KS_OK = 0, KS_FMU_STATUS = 1, KS_DIVERGED = 2, KS_ROBOT_DIVERGED = 3, KS_EVENT = 4, KS_TERMINATE = 5 };
/* which FMI call failed (index into the Python side's names) */
enum { KS_CALL_SET = 0, KS_CALL_GET = 1, KS_CALL_STEP = 2, KS_CALL_TIME = 3, KS_CALL_COMPLETED = 4 };
/* what a Model Exchange instance asked for in CompletedIntegratorStep */
enum { KS_ASKED_EVENT = 1, KS_ASKED_TERMINATE = 2 };

/* A motor reference: angle q(t) and rate v(t), rad and rad/s.
 * step:  p = {amplitude, at, initial}
 * sine:  p = {amplitude, frequency, offset, phase}
 * chirp: p = {amplitude, f0, f1, sweep}
 * table: t, q (n samples, t strictly increasing), linear between samples, held outside */
typedef struct {
    int32_t kind;
    int32_t n;
    double p[4];
    const double *t;
    const double *q;
    int64_t cursor; /* last interval found; time only grows during a run */
} ks_reference;

/* The robot: MuJoCo model and data, the mapped joints and their motors, the driven dofs. */
typedef struct {
    void *model; /* const mjModel* */
    void *data;  /* mjData* */
    int32_t n_joints;
    int32_t n_inputs;
    const int32_t *qposadr;   /* n_joints */
    const int32_t *dofadr;    /* n_joints */
    const int32_t *input_dof; /* n_inputs: where each input torque goes in qfrc_applied */
    ks_reference *refs;       /* n_joints */
    double *motor_q;          /* n_joints, the motors at the robot's time */
    double *motor_v;          /* n_joints */
    int64_t steps;
    double time;
    /* joints whose spring-damper MuJoCo computes (the validation reference): before each step,
     * ctrl[actuator] = k (q_motor + offset) + c q_motor' (Robot.do_step) */
    int32_t n_engine;
    int32_t pad;
    const int32_t *engine_actuator; /* n_engine */
    const int32_t *engine_joint;    /* n_engine: index into the joints */
    const double *engine_law;       /* n_engine x (k, c, offset), SI */
} ks_robot;

/* The virtual rig's hub (designer/cosim/rig.py HubServo): inputs s, v; outputs the load
 * f = K (q - s) + C (q' - v) and the hub angle q, with q(t) its chirp at the servo's time. */
typedef struct {
    ks_reference chirp;
    double stiffness; /* K, SI */
    double damping;   /* C, SI */
    double out[2];    /* f, q as last set */
    int64_t steps;
    double h;         /* the last step, 0 before the first */
} ks_servo;

/* One system of the graph: the robot (instance = ks_robot*), the hub (ks_servo*) or an FMU instance, co-simulation
 * (step: DoStep(n h, h)) or Model Exchange without states (step: SetTime((n + 1) h), then
 * CompletedIntegratorStep when the FMU needs it; an event it asks for is left to Python). */
typedef struct {
    int32_t kind;
    int32_t n_in;
    int32_t n_out;
    int32_t out_offset;  /* first column of its outputs in a row */
    const int32_t *src;  /* n_in: the column feeding each input */
    double *in_buf;      /* n_in scratch */
    void *instance;
    void *set_fn;        /* fmi2SetReal / fmi3SetFloat64 */
    void *get_fn;        /* fmi2GetReal / fmi3GetFloat64 */
    void *step_fn;       /* co-simulation: fmi2DoStep / fmi3DoStep; NULL for Model Exchange */
    void *time_fn;       /* Model Exchange: fmi2SetTime / fmi3SetTime */
    void *completed_fn;  /* Model Exchange: fmi2/fmi3CompletedIntegratorStep, NULL if not needed */
    const uint32_t *in_vr;
    const uint32_t *out_vr;
    int64_t steps;
    int32_t asked;       /* KS_ASKED_* flags from the last step */
    int32_t failed;      /* Model Exchange: KS_CALL_TIME or KS_CALL_COMPLETED, the call of the last step */
} ks_system;

/* A run: the systems, the exchange schedule, the output array and, after an error, what failed. */
typedef struct {
    int32_t n_systems;
    int32_t n_ops;
    int32_t n_cols;
    int32_t pad;
    ks_system *systems;   /* in the master's order, the order of do_step */
    const int32_t *ops;   /* n_ops pairs (KS_GET or KS_SET, system index) */
    double *values;       /* (n + 1) x n_cols */
    double step;          /* s */
    int64_t n;            /* number of steps; rows 0..n */
    int32_t error_system; /* set on error */
    int32_t error_call;
    int32_t error_status;
    int32_t pad2;
    double error_time;    /* s */
    int64_t event_row;    /* KS_EVENT: the row after whose step systems asked for an event */
} ks_run;

KS_EXPORT int32_t ks_run_rows(ks_run *run, int64_t first, int64_t last);
KS_EXPORT void ks_reference_eval(ks_reference *ref, double t, double *q, double *v);
KS_EXPORT void ks_robot_motors(ks_robot *robot, double t);
/* sizes of ks_reference, ks_system, ks_run: the ctypes mirrors in designer/cosim check them */
KS_EXPORT void ks_sizes(int64_t sizes[3]);
/* the size of a kind's own struct (ks_robot, ks_servo; 0 for FMUs): checked against the mirror a
 * system's binding() hands over */
KS_EXPORT int64_t ks_struct_size(int32_t kind);

/* systems.c */
int32_t ks_get(ks_system *s, double *row);
int32_t ks_set(ks_system *s, const double *row);
int32_t ks_step(ks_system *s, double h);

#endif
