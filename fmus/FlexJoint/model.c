/* FlexJoint: per axis m a = f - k (s - offset) - c v (body) or f = -(k (s - offset) + c v) (force element). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model.h"

static const char *AXIS_NAME[N_AXES] = AXIS_NAMES;
static const char *FIELD_NAME[N_FIELDS] = FIELD_NAMES;
/* the Float64 fields of an axis kept in a serialised state, in this order, then `enabled` as one byte */
static const int SAVED_FIELDS[] = {F_M, F_C, F_K, F_OFFSET, F_S, F_V, F_F};
#define N_SAVED (sizeof(SAVED_FIELDS) / sizeof(SAVED_FIELDS[0]))

/* relative difference of step sizes under which the cached discretisation is reused */
#define STEP_RTOL 1e-10

static Axis *lookup(ModelInstance *inst, unsigned vr, int *field) {
    unsigned i = vr / VR_AXIS_STRIDE;
    *field = (int)(vr % VR_AXIS_STRIDE);
    if (i < 1 || i > N_AXES || *field >= N_FIELDS || !(inst->data.declared & (1u << (i - 1)))) {
        logError(inst, "unknown value reference %u", vr);
        return NULL;
    }
    if (inst->data.interface == ForceElement && *field == F_A) {
        logError(inst, "%s.a does not exist in the force-element interface", AXIS_NAME[i - 1]);
        return NULL;
    }
    return &inst->data.axis[i - 1];
}

static const char *axisName(ModelInstance *inst, const Axis *a) {
    return AXIS_NAME[a - inst->data.axis];
}

static double jointForce(const Axis *a) {
    return a->enabled ? -(a->k * (a->s - a->offset) + a->c * a->v) : 0.0;
}

static double acceleration(const Axis *a) {
    return (a->f + jointForce(a)) / a->m;
}

static Status checkAxis(ModelInstance *inst, JointInterface interface, const char *n, const Axis *a) {
    double values[] = {a->m, a->c, a->k, a->offset, a->s, a->v, a->f};
    const int fields[] = {F_M, F_C, F_K, F_OFFSET, F_S, F_V, F_F};
    size_t i;
    for (i = 0; i < sizeof(values) / sizeof(values[0]); i++) {
        if (!isfinite(values[i])) {
            logError(inst, "%s.%s = %g is not a finite number", n, FIELD_NAME[fields[i]], values[i]);
            return Error;
        }
    }
    if (a->k < 0 || a->c < 0 || a->m < 0) {
        logError(inst, "%s: m, c and k must not be negative (m = %g, c = %g, k = %g)", n, a->m, a->c, a->k);
        return Error;
    }
    if (interface == Body && a->m <= 0) {
        logError(inst, "%s.m = %g: the body interface needs a positive mass or inertia", n, a->m);
        return Error;
    }
    return OK;
}

Status checkModel(ModelInstance *inst, const ModelData *data) {
    int i;
    if (!data->declared) {
        logError(inst, "the start values declare no axis");
        return Error;
    }
    for (i = 0; i < N_AXES; i++) {
        if ((data->declared & (1u << i)) && checkAxis(inst, data->interface, AXIS_NAME[i], &data->axis[i]) > Warning)
            return Error;
    }
    return OK;
}

Status applyStart(ModelInstance *inst, const char *name, const char *value) {
    char *end;
    int i, field;
    double number;
    if (strcmp(name, "interface") == 0) {
        if (strcmp(value, "force") == 0) inst->data.interface = ForceElement;
        else if (strcmp(value, "body") == 0) inst->data.interface = Body;
        else return Error;
        return OK;
    }
    if (strcmp(name, "axis") == 0) {
        for (i = 0; i < N_AXES; i++) {
            if (strcmp(value, AXIS_NAME[i]) == 0) {
                inst->data.declared |= 1u << i;
                inst->data.axis[i].enabled = true;
                return OK;
            }
        }
        return Error;
    }
    for (i = 0; i < N_AXES; i++) {
        size_t n = strlen(AXIS_NAME[i]);
        if (strncmp(name, AXIS_NAME[i], n) != 0 || name[n] != '.') continue;
        for (field = 0; field < N_FIELDS; field++) {
            if (strcmp(name + n + 1, FIELD_NAME[field]) != 0) continue;
            if (field == F_ENABLED) {
                if (strcmp(value, "true") != 0 && strcmp(value, "false") != 0) return Error;
                inst->data.axis[i].enabled = strcmp(value, "true") == 0;
                return OK;
            }
            number = strtod(value, &end);
            if (end == value || *end != '\0' || field == F_A) return Error;
            return setFloat64(inst, (unsigned)((i + 1) * VR_AXIS_STRIDE + field), number);
        }
    }
    return Error;
}

Status getFloat64(ModelInstance *inst, unsigned vr, double *value) {
    int field;
    Axis *a;
    if (vr == VR_TIME && inst->fmiVersion == 3) { /* FMI 2 leaves time implicit: no variable 0 */
        *value = inst->time;
        return OK;
    }
    if (!(a = lookup(inst, vr, &field))) return Error;
    switch (field) {
        case F_M: *value = a->m; return OK;
        case F_C: *value = a->c; return OK;
        case F_K: *value = a->k; return OK;
        case F_OFFSET: *value = a->offset; return OK;
        case F_S: *value = a->s; return OK;
        case F_V: *value = a->v; return OK;
        case F_F: *value = inst->data.interface == Body ? a->f : jointForce(a); return OK;
        case F_A: *value = acceleration(a); return OK;
        default:
            logError(inst, "%s.%s is not a Float64 variable", axisName(inst, a), FIELD_NAME[field]);
            return Error;
    }
}

Status setFloat64(ModelInstance *inst, unsigned vr, double value) {
    int field;
    Axis *a;
    Axis changed;
    bool body = inst->data.interface == Body;
    if (!(a = lookup(inst, vr, &field))) return Error;
    const char *n = axisName(inst, a);
    if (field == F_A || field == F_ENABLED || (field == F_F && !body)) {
        logError(inst, "%s.%s cannot be set with a Float64 value", n, FIELD_NAME[field]);
        return Error;
    }
    /* a continuous state may be set before initialization ends and, in Model Exchange, in Event and
       Continuous-Time Mode; a co-simulation instance owns its states once it steps */
    if (body && (field == F_S || field == F_V) &&
        !(inst->state & (StartAndEnd | Instantiated | InitializationMode | EventMode | ContinuousTimeMode))) {
        logError(inst, "the state %s.%s cannot be set while the co-simulation steps", n, FIELD_NAME[field]);
        return Error;
    }
    if (!isfinite(value)) {
        logError(inst, "%s.%s = %g is not a finite number", n, FIELD_NAME[field], value);
        return Error;
    }
    changed = *a;
    switch (field) {
        case F_M: changed.m = value; break;
        case F_C: changed.c = value; break;
        case F_K: changed.k = value; break;
        case F_OFFSET: changed.offset = value; break;
        case F_S: changed.s = value; break;
        case F_V: changed.v = value; break;
        default: changed.f = value; break;
    }
    /* masses are checked once all start values are in, so that a start file may set m after k */
    if (inst->state != StartAndEnd && checkAxis(inst, inst->data.interface, n, &changed) > Warning) return Error;
    if (field <= F_K) changed.cached = false;
    *a = changed;
    return OK;
}

Status getBoolean(ModelInstance *inst, unsigned vr, bool *value) {
    int field;
    Axis *a = lookup(inst, vr, &field);
    if (!a || field != F_ENABLED) {
        if (a) logError(inst, "value reference %u is not a Boolean variable", vr);
        return Error;
    }
    *value = a->enabled;
    return OK;
}

Status setBoolean(ModelInstance *inst, unsigned vr, bool value) {
    int field;
    Axis *a = lookup(inst, vr, &field);
    if (!a || field != F_ENABLED) {
        if (a) logError(inst, "value reference %u is not a Boolean variable", vr);
        return Error;
    }
    a->enabled = value;
    a->cached = false;
    return OK;
}

/* d force / d known (force element) on one axis, y = s - offset */
static double forcePartial(const Axis *a, int known) {
    double e = a->enabled ? 1.0 : 0.0;
    switch (known) {
        case F_S: return -e * a->k;
        case F_V: return -e * a->c;
        case F_K: return -e * (a->s - a->offset);
        case F_C: return -e * a->v;
        case F_OFFSET: return e * a->k;
        default: return 0.0;
    }
}

Status getPartial(ModelInstance *inst, unsigned unknown, unsigned known, double *value) {
    int fu, fk;
    Axis *a = lookup(inst, unknown, &fu), *b;
    *value = 0.0;
    if (!a) return Error;
    if (known == VR_TIME && inst->fmiVersion == 3) return OK; /* nothing depends on time explicitly */
    if (!(b = lookup(inst, known, &fk))) return Error;
    if (fu == F_ENABLED || fk == F_ENABLED) {
        logError(inst, "partial derivatives: %s.enabled is Boolean and has none", AXIS_NAME[(fu == F_ENABLED ? a : b) - inst->data.axis]);
        return Error;
    }
    if (a != b) return OK;
    if (fu == fk && (fu == F_S || fu == F_V)) {
        *value = 1.0; /* a state as output, or der(s) = v */
    } else if (fu == F_F && inst->data.interface == ForceElement) {
        *value = forcePartial(a, fk);
    } else if (fu == F_A) {
        /* a = (f + force) / m */
        *value = fk == F_F ? 1.0 / a->m : fk == F_M ? -acceleration(a) / a->m : forcePartial(a, fk) / a->m;
    }
    return OK;
}

size_t numberOfStates(ModelInstance *inst) {
    size_t n = 0;
    int i;
    if (inst->data.interface != Body) return 0;
    for (i = 0; i < N_AXES; i++) n += (inst->data.declared >> i) & 1u;
    return 2 * n;
}

void getStates(ModelInstance *inst, double x[]) {
    int i;
    if (inst->data.interface != Body) return;
    for (i = 0; i < N_AXES; i++) {
        if (!(inst->data.declared & (1u << i))) continue;
        *x++ = inst->data.axis[i].s;
        *x++ = inst->data.axis[i].v;
    }
}

void setStates(ModelInstance *inst, const double x[]) {
    int i;
    if (inst->data.interface != Body) return;
    for (i = 0; i < N_AXES; i++) {
        if (!(inst->data.declared & (1u << i))) continue;
        inst->data.axis[i].s = *x++;
        inst->data.axis[i].v = *x++;
    }
}

void getDerivatives(ModelInstance *inst, double dx[]) {
    int i;
    if (inst->data.interface != Body) return;
    for (i = 0; i < N_AXES; i++) {
        if (!(inst->data.declared & (1u << i))) continue;
        *dx++ = inst->data.axis[i].v;
        *dx++ = acceleration(&inst->data.axis[i]);
    }
}

/* ---- exact zero-order hold: exp([[A, B], [0, 0]] h) by Pade 13 with scaling and squaring (Higham 2005) */

typedef double Mat[3][3];

static void matmul(Mat a, Mat b, Mat out) {
    Mat r;
    int i, j, k;
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++) {
            r[i][j] = 0;
            for (k = 0; k < 3; k++) r[i][j] += a[i][k] * b[k][j];
        }
    memcpy(out, r, sizeof(Mat));
}

/* solve q x = p for x (3x3, partial pivoting), result in p */
static void solve(Mat q, Mat p) {
    int i, j, k, piv;
    for (k = 0; k < 3; k++) {
        piv = k;
        for (i = k + 1; i < 3; i++)
            if (fabs(q[i][k]) > fabs(q[piv][k])) piv = i;
        for (j = 0; j < 3; j++) {
            double t = q[k][j]; q[k][j] = q[piv][j]; q[piv][j] = t;
            t = p[k][j]; p[k][j] = p[piv][j]; p[piv][j] = t;
        }
        for (i = k + 1; i < 3; i++) {
            double l = q[i][k] / q[k][k];
            for (j = 0; j < 3; j++) {
                q[i][j] -= l * q[k][j];
                p[i][j] -= l * p[k][j];
            }
        }
    }
    for (k = 2; k >= 0; k--)
        for (j = 0; j < 3; j++) {
            for (i = k + 1; i < 3; i++) p[k][j] -= q[k][i] * p[i][j];
            p[k][j] /= q[k][k];
        }
}

static void expm3(Mat a, Mat out) {
    static const double b[14] = {64764752532480000.0, 32382376266240000.0, 7771770303897600.0,
                                 1187353796428800.0,  129060195264000.0,   10559470521600.0,
                                 670442572800.0,      33522128640.0,       1323241920.0,
                                 40840800.0,          960960.0,            16380.0,
                                 182.0,               1.0};
    Mat x, a2, a4, a6, u, v, t;
    double norm = 0;
    int i, j, s = 0;
    for (j = 0; j < 3; j++) {
        double col = fabs(a[0][j]) + fabs(a[1][j]) + fabs(a[2][j]);
        if (col > norm) norm = col;
    }
    if (norm > 5.371920351148152) s = (int)ceil(log2(norm / 5.371920351148152));
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++) x[i][j] = ldexp(a[i][j], -s);
    matmul(x, x, a2);
    matmul(a2, a2, a4);
    matmul(a4, a2, a6);
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++) {
            double id = i == j ? 1.0 : 0.0;
            t[i][j] = b[13] * a6[i][j] + b[11] * a4[i][j] + b[9] * a2[i][j];
            u[i][j] = b[7] * a6[i][j] + b[5] * a4[i][j] + b[3] * a2[i][j] + b[1] * id;
            v[i][j] = b[12] * a6[i][j] + b[10] * a4[i][j] + b[8] * a2[i][j];
            out[i][j] = b[6] * a6[i][j] + b[4] * a4[i][j] + b[2] * a2[i][j] + b[0] * id;
        }
    matmul(a6, t, t);
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++) t[i][j] += u[i][j];
    matmul(x, t, u);      /* U */
    matmul(a6, v, v);
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++) {
            v[i][j] += out[i][j]; /* V */
            t[i][j] = v[i][j] - u[i][j];
            out[i][j] = v[i][j] + u[i][j];
        }
    solve(t, out);
    for (; s > 0; s--) matmul(out, out, out);
}

static void discretise(Axis *a, double h) {
    double k = a->enabled ? a->k : 0.0, c = a->enabled ? a->c : 0.0;
    Mat m = {{0, h, 0}, {-k / a->m * h, -c / a->m * h, h / a->m}, {0, 0, 0}}, e;
    expm3(m, e);
    a->phi[0] = e[0][0]; a->phi[1] = e[0][1];
    a->phi[2] = e[1][0]; a->phi[3] = e[1][1];
    a->gamma[0] = e[0][2]; a->gamma[1] = e[1][2];
    a->h = h;
    a->cached = true;
}

Status doStep(ModelInstance *inst, double h) {
    int i;
    if (inst->data.interface != Body) return OK;
    for (i = 0; i < N_AXES; i++) {
        Axis *a = &inst->data.axis[i];
        double y, s, v;
        if (!(inst->data.declared & (1u << i))) continue;
        if (!a->cached || fabs(h - a->h) > STEP_RTOL * h) discretise(a, h);
        y = a->s - a->offset;
        s = a->phi[0] * y + a->phi[1] * a->v + a->gamma[0] * a->f + a->offset;
        v = a->phi[2] * y + a->phi[3] * a->v + a->gamma[1] * a->f;
        if (!isfinite(s) || !isfinite(v)) {
            logError(inst, "%s: the step of %g s gave a non-finite state", AXIS_NAME[i], h);
            return Error;
        }
        a->s = s;
        a->v = v;
    }
    return OK;
}

/* ---- the model's part of a serialised FMU state: per declared axis the saved Float64 fields, then enabled */

size_t modelDataSize(ModelInstance *inst) {
    size_t n = 0;
    int i;
    for (i = 0; i < N_AXES; i++) n += (inst->data.declared >> i) & 1u;
    return n * (8 * N_SAVED + 1);
}

static double *field(Axis *a, int f) {
    switch (f) {
        case F_M: return &a->m;
        case F_C: return &a->c;
        case F_K: return &a->k;
        case F_OFFSET: return &a->offset;
        case F_S: return &a->s;
        case F_V: return &a->v;
        default: return &a->f;
    }
}

void writeModelData(ModelInstance *inst, const ModelData *data, unsigned char bytes[]) {
    int i;
    size_t j;
    for (i = 0; i < N_AXES; i++) {
        Axis a = data->axis[i];
        if (!(inst->data.declared & (1u << i))) continue;
        for (j = 0; j < N_SAVED; j++, bytes += 8) putF64(bytes, *field(&a, SAVED_FIELDS[j]));
        *bytes++ = a.enabled ? 1 : 0;
    }
}

Status readModelData(ModelInstance *inst, const unsigned char bytes[], ModelData *data) {
    int i;
    size_t j;
    for (i = 0; i < N_AXES; i++) {
        Axis *a = &data->axis[i];
        if (!(inst->data.declared & (1u << i))) continue;
        for (j = 0; j < N_SAVED; j++, bytes += 8) *field(a, SAVED_FIELDS[j]) = getF64(bytes);
        if (*bytes > 1) {
            logError(inst, "deserialize FMU state: %s.enabled is neither true nor false", AXIS_NAME[i]);
            return Error;
        }
        a->enabled = *bytes++ == 1;
        a->cached = false;
    }
    return checkModel(inst, data);
}
