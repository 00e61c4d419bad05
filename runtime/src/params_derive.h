/* The runtime's conversion of the public prru_params (arrays of the
 * maxima, prru_descriptor.h) to the build's topology's own type, derived
 * for its parameter kernels (prru_param_derive). Internal to the build:
 * the runtime, its tests and its benchmarks (which call the parameter
 * kernels directly) share this one declaration. */
#ifndef PRRU_PARAMS_DERIVE_H
#define PRRU_PARAMS_DERIVE_H
#include "prru_descriptor.h"
#include "prru_param_kernels.h"

void prru_params_derive(const prru_params *p, prru_param_derived *d);

#endif
