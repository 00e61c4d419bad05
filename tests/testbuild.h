/* The build's model for the tests of its build: the generated sizes
 * (PRRU_NACT, ...), descriptor prru_mech, parameters prru_params_model and
 * regressor names, which the library's public headers no longer carry
 * (one ABI for every model, runtime/include/prru_sizes.h). */
#ifndef PRRU_TESTBUILD_H
#define PRRU_TESTBUILD_H
#include "prru_kernels.h"
#include "prru_mechanism.h"
#include "prru_param_kernels.h"
#include "prru_regressor.h"

#include "params_derive.h" /* prru_params_derive (runtime/src) */
#endif
