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

/* The runtime's own conversion of a public prru_params (arrays of the
 * maxima, prru_descriptor.h) to the build's topology's type, derived for
 * its parameter kernels (runtime/src/internal.h; in the static library). */
void prru_params_derive(const prru_params *p, prru_param_derived *d);
#endif
