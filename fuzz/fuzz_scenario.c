/* libFuzzer harness: scenario files (prru_scenario_parse, the in-memory
 * body of prru_scenario_read used by `prru simulate --scenario`). base_dir
 * is NULL so a `loads` line is rejected instead of opening files.
 * Oracles: on success the initial state and loads are finite, the options
 * pass the simulator's own checks' preconditions (0 < dt <= t_end) and
 * opt.loads points at the scenario's own schedule; on failure a message
 * naming the file. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "prru.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  char msg[512] = "";
  prru_scenario s;
  prru_model m;
  prru_model_default(&m);
  int st = prru_scenario_parse(&m, &s, (const char *)data, size, "fuzz.scn", NULL, msg, sizeof msg);
  if (st != PRRU_OK) {
    if (!msg[0] || strncmp(msg, "fuzz.scn", 8) != 0) abort();
    return 0;
  }
  for (int k = 0; k < 3; k++)
    if (!isfinite(s.q0[k]) || !isfinite(s.qd0[k]) || !isfinite(s.loads.base.fd[k]) ||
        !isfinite(s.loads.base.fp[k]) || !isfinite(s.loads.base.mp[k]))
      abort();
  if (!(s.opt.dt_out > 0 && s.opt.dt_out <= s.opt.t_end && isfinite(s.opt.t_end))) abort();
  if (s.opt.loads != &s.loads) abort();
  if (s.loads.kind == PRRU_LOAD_HARMONIC && !(isfinite(s.loads.amp) && isfinite(s.loads.omega)))
    abort();
  prru_scenario_free(&s);
  return 0;
}
