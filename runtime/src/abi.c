/* prru_struct_size: the library's own sizeof of its public structs, for
 * bindings that mirror them (python/prru/_lib.py checks every mirror
 * against it when it loads: a header change the mirror does not follow
 * is an error there, not a silent misreading). */
#include <string.h>

#include "prru.h"
#include "prru_control.h"
#include "prru_design.h"
#include "prru_dme.h"
#include "prru_ident.h"
#include "prru_linearize.h"
#include "prru_measure.h"
#include "prru_model_file.h"
#include "prru_traj.h"

#define ENTRY(t) {#t, sizeof(t)}

static const struct {
  const char *name;
  size_t size;
} structs[] = {
  ENTRY(prru_model), ENTRY(prru_loads), ENTRY(prru_data), ENTRY(prru_limits), ENTRY(prru_mechanism),
  ENTRY(prru_joint_info), ENTRY(prru_params), ENTRY(prru_sample), ENTRY(prru_load_schedule),
  ENTRY(prru_sim_options), ENTRY(prru_scenario), ENTRY(prru_dme), ENTRY(prru_map_grid),
  ENTRY(prru_map_summary), ENTRY(prru_map_options), ENTRY(prru_linearization), ENTRY(prru_quintic),
  ENTRY(prru_topp), ENTRY(prru_path_side), ENTRY(prru_track_sample), ENTRY(prru_track_options),
  ENTRY(prru_track_summary), ENTRY(prru_base), ENTRY(prru_ident_result), ENTRY(prru_consistent_options),
  ENTRY(prru_consistent_result), ENTRY(prru_identification), ENTRY(prru_fourier),
  ENTRY(prru_excite_options), ENTRY(prru_excite_result), ENTRY(prru_design_var),
  ENTRY(prru_design_problem), ENTRY(prru_design_eval), ENTRY(prru_design_options),
  ENTRY(prru_design_result), ENTRY(prru_measure_options), ENTRY(prru_diff_options), ENTRY(prru_diff_choice),
};

size_t prru_struct_size(const char *name)
{
  if (!name) return 0;
  for (size_t i = 0; i < sizeof structs / sizeof structs[0]; i++)
    if (strcmp(structs[i].name, name) == 0) return structs[i].size;
  return 0;
}
