/* The mechanism as data (MuJoCo's mjModel for the 3-PRRU): sizes, body and
 * joint layout, reaction coordinates and the model's numbers. One type for
 * every model: arrays are sized by the maxima of prru_sizes.h and a model
 * uses the first nbody, nlimb, nact, njoint or nlambda entries (the rest
 * are 0 or NULL). The built-in model's descriptor is prru_mech (the
 * generator writes its numbers, `prru_gen.py --descriptor-type
 * prru_descriptor.h`); prru_model_load fills one from a model file.
 *
 * Stacking of H (6 nbody x 3), Phi, K and the body wrenches: rows 3b..3b+2
 * are body b's rotational part, rows 3 nbody + 3b.. its translational
 * part. Body order P, L1..Ln, U1..Un, S1..Sn (n = nlimb). */
#ifndef PRRU_DESCRIPTOR_H
#define PRRU_DESCRIPTOR_H

#include "prru_sizes.h"

/* One joint; the reaction the proximal body exerts on the distal one has
 * lambda_count coordinates starting at lambda_offset (spec order: the
 * platform's U joints, then every limb's B, A and P joints). */
typedef struct {
  const char *name;  /* "C1", "B2", "P3", ... */
  char type;         /* 'U' universal (on the platform), 'R' revolute, 'P' prismatic */
  int limb;          /* 0-based limb index */
  int proximal;      /* body index, -1 for the rail (ground) */
  int distal;        /* body index */
  int lambda_offset, lambda_count;
} prru_joint_info;

typedef struct {
  /* identity */
  const char *name, *description, *model_file, *sha256;
  int format;                                /* model file format, 1 or 2 */
  /* sizes: nq = 3, nact = nlimb (3 or 4), nbody = 1 + 3 nlimb, njoint =
   * 4 nlimb, nlambda = 19 nlimb */
  int nq, nact, nlimb, nbody, nlambda, njoint;
  /* bodies */
  const char *body_names[PRRU_MAX_BODY];
  int body_limb[PRRU_MAX_BODY];              /* -1 for the platform */
  int platform;                              /* body index of P */
  int lower[PRRU_MAX_LIMB], upper[PRRU_MAX_LIMB], slider[PRRU_MAX_LIMB];
  /* inertial parameters */
  double gravity[3];                         /* m/s^2 in {S} */
  double mass[PRRU_MAX_BODY], total_mass;    /* kg */
  double com[PRRU_MAX_BODY][3];              /* centre of mass in the body frame, m */
  double inertia[PRRU_MAX_BODY][9];          /* about the centre, body axes, kg m^2 */
  double inertia_inv[PRRU_MAX_BODY][9];      /* its inverse */
  /* geometry per limb, m: rail offset, upper and lower link, U-joint offset */
  double b[PRRU_MAX_LIMB], l1[PRRU_MAX_LIMB], l2[PRRU_MAX_LIMB], a[PRRU_MAX_LIMB];
  /* drives per actuator: armature kg, damping N s/m, Coulomb N; v_s m/s */
  double armature[PRRU_MAX_ACT], damping[PRRU_MAX_ACT], coulomb[PRRU_MAX_ACT];
  double coulomb_velocity;
  prru_joint_info joint[PRRU_MAX_JOINT];     /* lambda order */
  const char *lambda_labels[PRRU_MAX_LAMBDA];
  /* screw drives per actuator (spec 13): lead m of slider travel per screw
   * revolution (0: no lead given), gear motor revolutions per screw
   * revolution (1 unless given), torque constant N m / A (0: none) */
  double lead[PRRU_MAX_ACT], gear[PRRU_MAX_ACT], torque_constant[PRRU_MAX_ACT];
  /* limits per actuator in rail units (torque_max and motor_speed_max
   * converted): |f| <= force_max N, |dd| <= speed_max m/s, d_min <= d <=
   * d_max m; INFINITY (-INFINITY for d_min) when the model sets none */
  double force_max[PRRU_MAX_ACT], speed_max[PRRU_MAX_ACT];
  double d_min[PRRU_MAX_ACT], d_max[PRRU_MAX_ACT];
  /* the forms the model file gives (for writers that keep them): bit k
   * for its k-th key of lead, gear, rotor_inertia, torque_constant,
   * stroke, force_max, torque_max, speed_max, motor_speed_max; and those
   * values as written (0 where not given): kg m^2, N m, rev/min */
  unsigned int drive_keys;
  double rotor_inertia[PRRU_MAX_ACT], torque_max[PRRU_MAX_ACT], motor_speed_max[PRRU_MAX_ACT];
} prru_mechanism;

/* A design: every number of a model that the parameter kernels read
 * (prru_model_params gives a model's; the design optimiser, the tracking
 * plant and the identification write them). The layout of the 4-limb
 * topology kernels' prru_params4, whose arrays are the maxima; a model
 * uses the first nlimb, nbody and nact entries. */
typedef struct {
  /* geometry per limb, m: rail offset b, upper link l1, lower link l2,
     U-joint offset a (limbs 1 and 2 only; the others' are ignored) */
  double b[PRRU_MAX_LIMB], l1[PRRU_MAX_LIMB], l2[PRRU_MAX_LIMB], a[PRRU_MAX_LIMB];
  double gravity[3]; /* m/s^2 in {S} */
  /* per body, in body order: mass (kg), centre of mass in the body frame
     (m), inertia Ixx Iyy Izz Ixy Ixz Iyz about it in body axes (kg m^2) */
  double mass[PRRU_MAX_BODY], com[PRRU_MAX_BODY][3], inertia[PRRU_MAX_BODY][6];
  /* drives per actuator: armature (kg), viscous damping (N s/m), Coulomb
     force (N); the Coulomb smoothing velocity v_s (m/s, > 0) */
  double armature[PRRU_MAX_ACT], damping[PRRU_MAX_ACT], coulomb[PRRU_MAX_ACT], coulomb_velocity;
} prru_params;

#endif /* PRRU_DESCRIPTOR_H */
