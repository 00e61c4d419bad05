/* A model file (models/NAME.json, spec sections 3, 5, 11-13) read at run time:
 * the same validation as the generator (gen/prrugen/model.py), the same
 * messages, every number equal to float() of the generator's exact value.
 * docs/model-files.md describes the rules the two share. */
#ifndef PRRU_MODEL_FILE_H
#define PRRU_MODEL_FILE_H

#include <stddef.h>

#include "prru.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PRRU_MODEL_NAME_MAX 16                 /* [a-z][a-z0-9_]{0,15} */
#define PRRU_MODEL_DESCRIPTION_MAX 400         /* characters, UTF-8 */
#define PRRU_MODEL_FILE_MAX_BYTES (1 << 20)    /* as the generator */

typedef struct {
  double b, l1, l2, a; /* m; a = 0 for limbs 3 and 4 */
} prru_model_limb;

typedef struct {
  char name[PRRU_MODEL_NAME_MAX + 1];
  char description[4 * PRRU_MODEL_DESCRIPTION_MAX + 1];
  int format; /* 1 or 2 */
  int nlimb;  /* 3 or 4 */
  int nbody;  /* 1 + 3 nlimb, in the order P, L1..Ln, U1..Un, S1..Sn */
  double gravity[3];                      /* m/s^2 in {S} */
  prru_model_limb limb[PRRU_MAX_LIMB];
  double mass[PRRU_MAX_BODY];             /* kg */
  double com[PRRU_MAX_BODY][3];           /* m, body frame */
  double inertia[PRRU_MAX_BODY][6];       /* Ixx Iyy Izz Ixy Ixz Iyz about
                                             the centre, body axes */
  double armature[PRRU_MAX_LIMB];         /* kg, per actuator */
  double damping[PRRU_MAX_LIMB];          /* N s/m */
  double coulomb[PRRU_MAX_LIMB];          /* N */
  double coulomb_velocity;                /* m/s; 0 when no Coulomb force */
  /* Section 13, per actuator. keys: which of its keys the file gives
   * (PRRU_DRIVE_* bits; each key covers every actuator). The values as
   * written, and the limits in rail units: force_max from torque_max,
   * speed_max from motor_speed_max (docs/model-files.md gives the
   * conversions); armature above holds what rotor_inertia reflects. */
  unsigned keys;
  double lead[PRRU_MAX_LIMB];            /* m per screw revolution; 0: none */
  double gear[PRRU_MAX_LIMB];            /* motor rev per screw rev; 1 */
  double rotor_inertia[PRRU_MAX_LIMB];   /* kg m^2; 0 unless given */
  double torque_constant[PRRU_MAX_LIMB]; /* N m / A; 0: none */
  double d_min[PRRU_MAX_LIMB], d_max[PRRU_MAX_LIMB]; /* m; -inf, inf: none */
  double torque_max[PRRU_MAX_LIMB];      /* N m at the motor, as written */
  double motor_speed_max[PRRU_MAX_LIMB]; /* rev/min at the motor, as written */
  double force_max[PRRU_MAX_LIMB];       /* N on the rail; inf: none */
  double speed_max[PRRU_MAX_LIMB];       /* m/s on the rail; inf: none */
  char sha256[65];           /* of the file's bytes, as generated/ headers print it */
  char canonical_sha256[65]; /* of the parsed numbers (model.canonical_sha256) */
} prru_model_spec;

/* Reads and validates the model file at path. PRRU_OK fills *out;
 * PRRU_EIO (unreadable) or PRRU_EPARSE (refused) write the generator's
 * message "path: key: reason" into msg (msglen bytes, may be NULL/0) and
 * leave *out untouched; PRRU_ENOMEM likewise. */
PRRU_API prru_status prru_model_file_read(const char *path, prru_model_spec *out,
                                          char *msg, int msglen);

/* The same for len bytes of text; name stands for the path in messages
 * (NULL: "<model>"). */
PRRU_API prru_status prru_model_file_parse(const char *text, size_t len,
                                           const char *name, prru_model_spec *out,
                                           char *msg, int msglen);

#ifdef __cplusplus
}
#endif

#endif
