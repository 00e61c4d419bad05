/* prru runtime: the dynamics of the 3-PRRU over the generated kernels and
 * GSL. This header includes the runtime's core topics:
 *   prru_dynamics.h  models (built in or loaded), kinematics, forward and
 *                    inverse dynamics, joint reactions, limits;
 *   prru_sim.h       loads as functions of time, simulation, scenarios;
 *   prru_io.h        CSV tables, number parsing, text for model files.
 * The others are included on their own: prru_dme.h (manipulability and
 * maps), prru_design.h, prru_traj.h, prru_control.h, prru_ident.h,
 * prru_measure.h, prru_model_file.h. */
#ifndef PRRU_H
#define PRRU_H

#include "prru_dynamics.h"
#include "prru_io.h"
#include "prru_sim.h"

#endif /* PRRU_H */
