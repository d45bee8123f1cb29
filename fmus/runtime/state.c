/* FMU state snapshots and their serialised form. A snapshot carries a magic number and the instance's
   interface type, joint interface and declared axes, so a foreign or corrupted state is refused with an
   error status and a log message instead of being loaded.

   Serialised layout (all integers little-endian uint32, doubles IEEE 754 little-endian):
     0  magic "FJST"            4  format version (1)     8  joint interface (0 force, 1 body)
    12  number of axes         16  declared-axes mask    20  interface type (0 ME, 1 CS)
    24  checksum: 32-bit FNV-1a of bytes 0..23 and 28..end
    28  life-cycle state (uint32), time (double), stop time defined (byte), stop time (double)
    49  the model's data (model.h: modelDataSize bytes) */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "model.h"

#define STATE_MAGIC 0x54534A46u /* "FJST" read as a little-endian uint32 */
#define FORMAT_VERSION 1u
#define HEADER_SIZE 28
#define INSTANCE_SIZE 21

typedef struct {
    uint32_t magic;
    InterfaceType type;
    ModelState state;
    double time;
    bool stopTimeDefined;
    double stopTime;
    ModelData data;
} SavedState;

/* the life-cycle states an instance of this type can be restored into */
static int restorable(InterfaceType type) {
    return Instantiated | InitializationMode | Terminated |
           (type == ModelExchange ? EventMode | ContinuousTimeMode : StepMode);
}

static unsigned countAxes(unsigned declared) {
    unsigned n = 0;
    for (; declared; declared >>= 1) n += declared & 1u;
    return n;
}

static size_t serializedSize(ModelInstance *inst) { return HEADER_SIZE + INSTANCE_SIZE + modelDataSize(inst); }

static uint32_t fnv1a(uint32_t h, const unsigned char *p, size_t n) {
    size_t i;
    for (i = 0; i < n; i++) h = (h ^ p[i]) * 16777619u;
    return h;
}

static uint32_t checksum(const unsigned char *bytes, size_t size) {
    return fnv1a(fnv1a(2166136261u, bytes, 24), bytes + HEADER_SIZE, size - HEADER_SIZE);
}

void putU32(unsigned char *p, unsigned v) {
    int i;
    for (i = 0; i < 4; i++) p[i] = (unsigned char)(v >> (8 * i));
}

unsigned getU32(const unsigned char *p) {
    return (unsigned)p[0] | (unsigned)p[1] << 8 | (unsigned)p[2] << 16 | (unsigned)p[3] << 24;
}

void putF64(unsigned char *p, double v) {
    uint64_t u;
    int i;
    memcpy(&u, &v, sizeof(u));
    for (i = 0; i < 8; i++) p[i] = (unsigned char)(u >> (8 * i));
}

double getF64(const unsigned char *p) {
    uint64_t u = 0;
    double v;
    int i;
    for (i = 7; i >= 0; i--) u = u << 8 | p[i];
    memcpy(&v, &u, sizeof(v));
    return v;
}

/* Error (logged) if the model does not declare the capability `has` */
static Status capable(ModelInstance *inst, int has, const char *what) {
    if (has) return OK;
    logError(inst, "the FMU cannot %s (see its capability flags)", what);
    return Error;
}

/* a snapshot made by this FMU for an instance like `inst`, or NULL after logging why not */
static const SavedState *checkSnapshot(ModelInstance *inst, const char *function, const void *state) {
    const SavedState *s = (const SavedState *)state;
    if (!s || s->magic != STATE_MAGIC) {
        logError(inst, "%s: the FMU state is %s", function, s ? "not one made by this FMU" : "NULL");
        return NULL;
    }
    if (s->type != inst->type || s->data.interface != inst->data.interface ||
        s->data.declared != inst->data.declared || !(s->state & restorable(inst->type))) {
        logError(inst, "%s: the FMU state belongs to an instance with another interface or axes", function);
        return NULL;
    }
    return s;
}

Status getFMUState(ModelInstance *inst, void **state) {
    SavedState *s;
    if (capable(inst, CAN_GET_AND_SET_FMU_STATE, "get and set its state") > Warning) return Error;
    if (checkArray(inst, "get FMU state", "FMU state pointer", state, 1) > Warning) return Error;
    if (*state && !checkSnapshot(inst, "get FMU state", *state)) return Error;
    s = *state ? (SavedState *)*state : malloc(sizeof(SavedState));
    if (!s) {
        logError(inst, "get FMU state: out of memory");
        return Error;
    }
    if (!(inst->state & restorable(inst->type))) {
        logError(inst, "get FMU state: the instance is in a state (%d) that cannot be restored", (int)inst->state);
        if (!*state) free(s);
        return Error;
    }
    memset(s, 0, sizeof(*s));
    s->magic = STATE_MAGIC;
    s->type = inst->type;
    s->state = inst->state;
    s->time = inst->time;
    s->stopTimeDefined = inst->stopTimeDefined;
    s->stopTime = inst->stopTime;
    s->data = inst->data;
    *state = s;
    return OK;
}

Status setFMUState(ModelInstance *inst, const void *state) {
    const SavedState *s;
    if (capable(inst, CAN_GET_AND_SET_FMU_STATE, "get and set its state") > Warning) return Error;
    if (!(s = checkSnapshot(inst, "set FMU state", state))) return Error;
    inst->state = s->state;
    inst->time = s->time;
    inst->stopTimeDefined = s->stopTimeDefined;
    inst->stopTime = s->stopTime;
    inst->data = s->data;
    return OK;
}

Status freeFMUState(ModelInstance *inst, void **state) {
    if (!state || !*state) return OK;
    if (!checkSnapshot(inst, "free FMU state", *state)) return Error;
    free(*state);
    *state = NULL;
    return OK;
}

Status serializedStateSize(ModelInstance *inst, const void *state, size_t *size) {
    if (checkArray(inst, "serialized FMU state size", "size", size, 1) > Warning ||
        !checkSnapshot(inst, "serialized FMU state size", state))
        return Error;
    *size = serializedSize(inst);
    return OK;
}

Status serializeState(ModelInstance *inst, const void *state, unsigned char bytes[], size_t size) {
    const SavedState *s;
    size_t n = serializedSize(inst);
    if (capable(inst, CAN_SERIALIZE_FMU_STATE, "serialize its state") > Warning) return Error;
    if (!(s = checkSnapshot(inst, "serialize FMU state", state)) || checkArray(inst, "serialize FMU state", "bytes", bytes, 1) > Warning) return Error;
    if (size < n) {
        logError(inst, "serialize FMU state: %zu bytes is too small for the state (%zu)", size, n);
        return Error;
    }
    putU32(bytes, STATE_MAGIC);
    putU32(bytes + 4, FORMAT_VERSION);
    putU32(bytes + 8, (uint32_t)s->data.interface);
    putU32(bytes + 12, countAxes(s->data.declared));
    putU32(bytes + 16, s->data.declared);
    putU32(bytes + 20, (uint32_t)s->type);
    putU32(bytes + HEADER_SIZE, (uint32_t)s->state);
    putF64(bytes + HEADER_SIZE + 4, s->time);
    bytes[HEADER_SIZE + 12] = s->stopTimeDefined ? 1 : 0;
    putF64(bytes + HEADER_SIZE + 13, s->stopTime);
    writeModelData(inst, &s->data, bytes + HEADER_SIZE + INSTANCE_SIZE);
    putU32(bytes + 24, checksum(bytes, n));
    return OK;
}

/* the header of serialised bytes matches this FMU, this instance and the checksum; logs if not */
static Status checkHeader(ModelInstance *inst, const unsigned char bytes[], size_t size) {
    const char *problem = NULL;
    if (!bytes || size < HEADER_SIZE) problem = "too short for a FlexJoint FMU state";
    else if (getU32(bytes) != STATE_MAGIC) problem = "not a FlexJoint FMU state (wrong magic number)";
    else if (getU32(bytes + 4) != FORMAT_VERSION) problem = "a state of another format version";
    else if (getU32(bytes + 8) != (uint32_t)inst->data.interface || getU32(bytes + 20) != (uint32_t)inst->type)
        problem = "a state of another interface";
    else if (getU32(bytes + 16) != inst->data.declared || getU32(bytes + 12) != countAxes(inst->data.declared))
        problem = "a state of other axes";
    else if (size != serializedSize(inst)) problem = "of the wrong size for this FMU's state";
    else if (getU32(bytes + 24) != checksum(bytes, size)) problem = "corrupted (checksum mismatch)";
    if (!problem) return OK;
    logError(inst, "deserialize FMU state: the %zu bytes are %s", size, problem);
    return Error;
}

Status deserializeState(ModelInstance *inst, const unsigned char bytes[], size_t size, void **state) {
    SavedState s;
    const unsigned char *p = bytes + HEADER_SIZE;
    if (capable(inst, CAN_SERIALIZE_FMU_STATE, "serialize its state") > Warning) return Error;
    if (checkArray(inst, "deserialize FMU state", "FMU state pointer", state, 1) > Warning ||
        checkHeader(inst, bytes, size) > Warning)
        return Error;
    memset(&s, 0, sizeof(s));
    s.magic = STATE_MAGIC;
    s.type = inst->type;
    s.state = (ModelState)getU32(p);
    s.time = getF64(p + 4);
    s.stopTimeDefined = p[12] != 0;
    s.stopTime = getF64(p + 13);
    if (!(s.state & restorable(inst->type)) || (s.state & (s.state - 1)) || !isfinite(s.time) || p[12] > 1 ||
        (s.stopTimeDefined && !isfinite(s.stopTime))) {
        logError(inst, "deserialize FMU state: invalid life-cycle state, time or stop time");
        return Error;
    }
    s.data = inst->data;
    if (readModelData(inst, p + INSTANCE_SIZE, &s.data) > Warning) return Error;
    if (*state && !checkSnapshot(inst, "deserialize FMU state", *state)) return Error;
    if (!*state && !(*state = malloc(sizeof(SavedState)))) {
        logError(inst, "deserialize FMU state: out of memory");
        return Error;
    }
    memcpy(*state, &s, sizeof(s));
    return OK;
}
