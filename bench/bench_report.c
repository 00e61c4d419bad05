/* prru_bench's output: the human-readable table and the JSON object
 * (bench/check_json.py reads the latter). */
#include <stdio.h>
#include <string.h>

#include "bench.h"

void bench_cpu_model(char *buf, size_t len)
{
  snprintf(buf, len, "unknown");
  FILE *f = fopen("/proc/cpuinfo", "r");
  if (!f) return;
  char line[512];
  while (fgets(line, sizeof line, f)) {
    if (strncmp(line, "model name", 10) != 0) continue;
    char *v = strchr(line, ':');
    if (!v) continue;
    v++;
    while (*v == ' ' || *v == '\t') v++;
    v[strcspn(v, "\n")] = '\0';
    snprintf(buf, len, "%s", v);
    break;
  }
  fclose(f);
}

static void json_string(const char *s)
{
  putchar('"');
  for (; *s; s++) {
    unsigned char ch = (unsigned char)*s;
    if (ch == '"' || ch == '\\') printf("\\%c", ch);
    else if (ch < 0x20) printf("\\u%04x", ch);
    else putchar(ch);
  }
  putchar('"');
}

void bench_print_json(const bench_options *op, const char *cpu, const sim_result *sim,
                      const map_result *map, int regen_ok, const bench_stats *regen)
{
  printf("{\"kernels\": {");
  for (int i = 0; i < bench_nkernels; i++) {
    const bench_kernel *k = &bench_kernels[i];
    printf("%s\"%s\": {\"generated_ns\": %.4g, \"reference_ns\": %.4g, \"ratio\": %.4g}",
           i ? ", " : "", k->name, k->gen.median, k->ref.median, k->ref.median / k->gen.median);
  }
  printf("}, \"model\": {\"name\": ");
  json_string(prru_mech.name);
  printf(", \"file\": ");
  json_string(prru_mech.model_file);
  printf(", \"sha256\": ");
  json_string(prru_mech.sha256);
  printf("}, \"cpu\": ");
  json_string(cpu);
  printf(", \"compiler\": ");
  json_string(BENCH_COMPILER);
  printf(", \"flags\": ");
  json_string(PRRU_BENCH_FLAGS);
  printf(", \"build_type\": ");
  json_string(PRRU_BENCH_BUILD_TYPE);
  printf(", \"reps\": %d, \"states\": %d, \"quick\": %s", op->reps, NSTATES,
         op->quick ? "true" : "false");
  printf(", \"spread_ns\": {");
  for (int i = 0; i < bench_nkernels; i++) {
    const bench_kernel *k = &bench_kernels[i];
    printf("%s\"%s\": {\"generated\": [%.4g, %.4g], \"reference\": [%.4g, %.4g]}", i ? ", " : "",
           k->name, k->gen.min, k->gen.max, k->ref.min, k->ref.max);
  }
  printf("}, \"max_rel_diff\": {");
  for (int i = 0; i < bench_nkernels; i++)
    printf("%s\"%s\": %.3g", i ? ", " : "", bench_kernels[i].name, bench_kernels[i].max_rel_diff);
  printf("}, \"ops\": {");
  for (int i = 0; i < bench_nkernels; i++) {
    printf("%s\"%s\": ", i ? ", " : "", bench_kernels[i].name);
    json_string(bench_kernels[i].ops);
  }
  printf("}, \"param_cost\": {");
  for (int i = 0, n = 0; i < bench_nkernels; i++) {
    const bench_kernel *k = &bench_kernels[i], *c = k->constant ? bench_kernel_named(k->constant) : NULL;
    if (!c) continue;
    printf("%s\"%s\": {\"param_ns\": %.4g, \"constant_ns\": %.4g, \"ratio\": %.4g, "
           "\"ratio_spread\": [%.4g, %.4g], \"param_arith\": %d, \"constant_arith\": %d}",
           n++ ? ", " : "", c->name, k->cost_param.median, k->cost_constant.median,
           k->cost.median, k->cost.min, k->cost.max, k->arith, k->constant_arith);
  }
  printf("}");
#ifndef PRRU_BENCH_HAVE_DME
  printf(", \"missing\": {\"w_r\": \"runtime/include/prru_dme.h not present at build time\"}");
#endif
  if (sim->ok) {
    printf(", \"simulated_second\": {\"scenario\": \"paper section 4.3\"");
    printf(", \"generated_s\": %.4g, \"reference_s\": %.4g, "
           "\"ratio\": %.4g, \"stepper\": \"rk8pd\", \"rel_tol\": %g, \"abs_tol\": %g, "
           "\"reference_steps\": %lu, \"final_q\": [%.15g, %.15g, %.15g], "
           "\"max_abs_diff_q\": %.3g, \"max_abs_diff_qd\": %.3g",
           sim->gen_s.median, sim->ref_s.median, sim->ref_s.median / sim->gen_s.median, sim->tol,
           sim->tol, sim->ref_steps, sim->q[0], sim->q[1], sim->q[2], sim->dq, sim->dqd);
    if (sim->param_ok)
      printf(", \"parameter_s\": %.4g, \"parameter_over_specialised\": {\"median\": %.4g, \"min\": %.4g, "
             "\"max\": %.4g}", sim->param_s.median, sim->param_ratio.median, sim->param_ratio.min,
             sim->param_ratio.max);
    printf("}");
  } else
    printf(", \"simulated_second\": null");
  if (map->ok) {
    double pts = (double)map->n * map->n, rpts = (double)map->n_ref * map->n_ref;
    printf(", \"map\": {\"grid\": %d, \"seconds_2_threads\": %.4g, \"seconds_1_thread\": %.4g, "
           "\"generated_points_per_s\": %.4g, \"generated_points_per_s_1_thread\": %.4g, "
           "\"reference_points_per_s\": %.4g, \"ratio_1_thread\": %.4g, \"max_rel_diff\": %.3g}",
           map->n, map->gen2_s.median, map->gen1_s.median, pts / map->gen2_s.median,
           pts / map->gen1_s.median, rpts / map->ref_s.median,
           (pts / map->gen1_s.median) / (rpts / map->ref_s.median), map->max_rel_diff);
  } else {
    printf(", \"map\": null");
  }
  if (regen_ok) {
    printf(", \"regeneration_s\": %.4g, \"regeneration_sets_s\": {", regen[0].median);
    for (int k = 0; k < BENCH_REGEN_NSETS; k++)
      printf("%s\"%s\": %.4g", k ? ", " : "", bench_regen_sets[k].name, regen[k].median);
    printf("}");
  } else
    printf(", \"regeneration_s\": null, \"regeneration_sets_s\": null");
  if (bench_modes_done) {
    bench_modes_print_json(&bench_modes_result);
    bench_peer_print_json(&bench_peer_result);
    bench_bound_print_json(&bench_bound_result);
    bench_derivs_print_json(&bench_derivs_result);
  }
  printf("}\n");
}

/* What reading the model's numbers at run time costs: each param_ row
 * against its constant-folded namesake, batches interleaved. */
static void print_param_cost(void)
{
  printf("runtime-parameter kernels (numbers derived once, prru_param_derive) against the constant-folded ones,\n"
         "batches interleaved, median [min-max] of the per-repetition time ratio:\n");
  for (int i = 0; i < bench_nkernels; i++) {
    const bench_kernel *k = &bench_kernels[i], *c = k->constant ? bench_kernel_named(k->constant) : NULL;
    if (!c) continue;
    char rs[64];
    snprintf(rs, sizeof rs, "%.2fx [%.2f-%.2f]", k->cost.median, k->cost.min, k->cost.max);
    printf("  %-17s %-20s the time of %-9s (%.1f vs %.1f ns; %d vs %d arithmetic)\n", k->name, rs,
           c->name, k->cost_param.median, k->cost_constant.median, k->arith, k->constant_arith);
  }
  printf("\n");
}

void bench_print_table(const bench_options *op, const char *cpu, const sim_result *sim,
                       const map_result *map, int regen_ok, const bench_stats *regen)
{
  printf("prru_bench: ns per call, median [min-max] of %d repetitions, %d input states\n",
         op->reps, NSTATES);
  printf("model: %s (%s, sha256 %s)\n", prru_mech.name, prru_mech.model_file, prru_mech.sha256);
  printf("cpu: %s | compiler: %s | flags: %s (%s)\n\n", cpu, BENCH_COMPILER, PRRU_BENCH_FLAGS,
         PRRU_BENCH_BUILD_TYPE);
  printf("%-17s %-26s %-32s %8s %9s  %s\n", "kernel", "generated ns", "reference ns", "ratio",
         "rel diff", "generated: operations");
  for (int i = 0; i < bench_nkernels; i++) {
    const bench_kernel *k = &bench_kernels[i];
    char gs[64], rs[64];
    snprintf(gs, sizeof gs, "%.1f [%.1f-%.1f]", k->gen.median, k->gen.min, k->gen.max);
    snprintf(rs, sizeof rs, "%.1f [%.1f-%.1f]", k->ref.median, k->ref.min, k->ref.max);
    printf("%-17s %-26s %-32s %7.1fx %9.1e  %s\n", k->name, gs, rs, k->ref.median / k->gen.median,
           k->max_rel_diff, k->ops);
  }
#ifndef PRRU_BENCH_HAVE_DME
  printf("%-17s not timed: runtime/include/prru_dme.h was not present at build time\n", "w_r");
#endif
  printf("\n");
  print_param_cost();
  if (sim->ok) {
    printf("simulated second (paper scenario, rk8pd, rel = abs tol %g, h0 %g):\n", sim->tol,
           sim->h0);
    printf("  generated  %.3f ms [%.3f-%.3f]  (prru_simulate)\n", 1e3 * sim->gen_s.median,
           1e3 * sim->gen_s.min, 1e3 * sim->gen_s.max);
    printf("  reference  %.3f ms [%.3f-%.3f]  (gsl_odeiv2 + prru_ref_forward_dynamics, %lu steps)"
           "\n", 1e3 * sim->ref_s.median, 1e3 * sim->ref_s.min, 1e3 * sim->ref_s.max,
           sim->ref_steps);
    printf("  ratio %.1fx; final q = (%.12f, %.12f, %.12f); max |diff| q %.2e, qd %.2e\n",
           sim->ref_s.median / sim->gen_s.median, sim->q[0], sim->q[1], sim->q[2], sim->dq,
           sim->dqd);
    if (sim->param_ok)
      printf("  parameter  %.3f ms: the model file loaded onto the parameter kernels, %.2fx [%.2f-%.2f] of "
             "generated\n", 1e3 * sim->param_s.median, sim->param_ratio.median, sim->param_ratio.min,
             sim->param_ratio.max);
  } else {
    printf("simulated second: failed (see above)\n");
  }
  if (map->ok) {
    double pts = (double)map->n * map->n, rpts = (double)map->n_ref * map->n_ref;
    printf("w_R map over the fig. 7 rectangle (q3 = 0):\n");
    printf("  generated  %dx%d in %.3f s [%.3f-%.3f] with 2 threads (%.3g points/s), %.3f s with 1"
           "\n", map->n, map->n, map->gen2_s.median, map->gen2_s.min, map->gen2_s.max,
           pts / map->gen2_s.median, map->gen1_s.median);
    if (bench_modes_done && !bench_modes_result.scaling_measured)
      printf("  (the second core was not free: 2 threads against 1 is no scaling figure here)\n");
    printf("  reference  %dx%d in %.3f s, 1 thread (%.3g points/s); per-thread ratio %.1fx; "
           "max rel diff %.1e\n", map->n_ref, map->n_ref, map->ref_s.median,
           rpts / map->ref_s.median, (pts / map->gen1_s.median) / (rpts / map->ref_s.median),
           map->max_rel_diff);
  } else {
    printf("w_R map: not measured\n");
  }
  if (bench_modes_done) {
    bench_modes_print_table(&bench_modes_result);
    bench_peer_print_table(&bench_peer_result);
    bench_bound_print_table(&bench_bound_result);
    bench_derivs_print_table(&bench_derivs_result);
  }
  if (regen_ok) {
    printf("regeneration from %s (wall s, the interpreter's start included):\n",
           PRRU_BENCH_MODEL);
    for (int k = 0; k < BENCH_REGEN_NSETS; k++)
      printf("  %-12s %-28s %.3f [%.3f-%.3f]%s\n", bench_regen_sets[k].name,
             *bench_regen_sets[k].options ? bench_regen_sets[k].options : "(no option)",
             regen[k].median, regen[k].min, regen[k].max,
             k == 0 ? " (target < 0.5 s, paper model)" : "");
  } else
    printf("regeneration: failed (see above)\n");
  if (strcmp(PRRU_BENCH_BUILD_TYPE, "Release") != 0)
    printf("note: build type %s, not Release: these are not the documented numbers\n",
           PRRU_BENCH_BUILD_TYPE);
}

