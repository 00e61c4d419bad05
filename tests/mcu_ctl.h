/* The single-precision controller set (prru_f_ik_jd, prru_f_dynamics,
 * prru_f_eom_solve, prru_f_inverse_terms) on one state, as flat records of
 * floats: shared by the Cortex-M4 firmware (tests/mcu/fw_float.c, run under
 * QEMU) and the host's check of its outputs (test_float_kernels --mcu), so
 * both evaluate and lay out the outputs the same way. A record is an array
 * of floats (no padding), sent as the hex bit patterns of its words.
 * With four limbs inverse_terms gives tau (and d, J_d), not fd: fd =
 * J_d^+ tau needs the runtime's QR, which the controller set does not
 * carry. */
#ifndef MCU_CTL_H
#define MCU_CTL_H

#include "prru_f_kernels.h"

#define MCU_NA PRRU_F_NACT

typedef struct {
  float q[3], qd[3], qdd[3], fd[MCU_NA], fp[3], mp[3];
} mcu_in;

typedef struct {
  float ikjd_d[MCU_NA], ikjd_J[MCU_NA * 3];
  float dyn_M[9], dyn_h[3], dyn_G[3];
  float es_M[9], es_b[3], es_qdd[3], es_min[3];
  float it_d[MCU_NA], it_J[MCU_NA * 3];
#if MCU_NA == 3
  float it_Jinv[9], it_fd[3];
#else
  float it_tau[3];
#endif
} mcu_out;

#define MCU_IN_WORDS (sizeof(mcu_in) / sizeof(float))
#define MCU_OUT_WORDS (sizeof(mcu_out) / sizeof(float))

static inline void mcu_eval(const mcu_in *x, mcu_out *y)
{
  prru_f_ik_jd(x->q, y->ikjd_d, y->ikjd_J);
  prru_f_dynamics(x->q, x->qd, y->dyn_M, y->dyn_h, y->dyn_G);
  prru_f_eom_solve(x->q, x->qd, x->fd, x->fp, x->mp, y->es_M, y->es_b, y->es_qdd, y->es_min);
#if MCU_NA == 3
  prru_f_inverse_terms(x->q, x->qd, x->qdd, x->fp, x->mp, y->it_d, y->it_J, y->it_Jinv, y->it_fd);
#else
  prru_f_inverse_terms(x->q, x->qd, x->qdd, x->fp, x->mp, y->it_d, y->it_J, y->it_tau);
#endif
}

#endif /* MCU_CTL_H */
