/* The largest mechanism the library's public structs hold: every array
 * in a public struct is sized by these maxima, not by the model a build
 * was generated from, so that the structs' layout (the ABI) is the same
 * for every model (3 or 4 limbs) and every build. A model's own sizes
 * are data: m->mech->nact, nbody, nlambda (prru_mechanism), and an array
 * of a public struct holds its first nact (nbody, nlambda, nreg) entries,
 * the rest unused. Matrices in a public struct are compact: an nact x 3
 * J_d is row-major with row stride 3, an nact x nact matrix has row
 * stride nact; the regressor's base matrices have row stride nreg
 * (prru_ident.h). The 4-PRRU (spec section 12) is the largest model. */
#ifndef PRRU_SIZES_H
#define PRRU_SIZES_H

#define PRRU_MAX_ACT 4     /* actuators (one per limb) */
#define PRRU_MAX_LIMB 4
#define PRRU_MAX_BODY 13   /* the platform and three bodies per limb */
#define PRRU_MAX_JOINT 16  /* four per limb */
#define PRRU_MAX_LAMBDA 76 /* reaction coordinates: 4 for a limb's U joint on the
                              platform, 5 for each of its R, R and P: 19 per limb */
/* Standard inertial parameters of identification: 10 per body, 3 per
 * actuator's drive (armature, damping, Coulomb). */
#define PRRU_MAX_REG (10 * PRRU_MAX_BODY + 3 * PRRU_MAX_ACT)

#endif /* PRRU_SIZES_H */
