/* The time a user waits for the kernels to be regenerated from the model
 * file. */
#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bench.h"

static void remove_tree_flat(const char *dir)
{
  DIR *dp = opendir(dir);
  if (dp) {
    struct dirent *e;
    char path[4096];
    while ((e = readdir(dp)) != NULL) {
      if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
      snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
      if (remove(path) != 0)
        fprintf(stderr, "prru_bench: cannot remove %s: %s\n", path, strerror(errno));
    }
    closedir(dp);
  }
  if (rmdir(dir) != 0)
    fprintf(stderr, "prru_bench: cannot remove %s: %s\n", dir, strerror(errno));
}

/* The generator's sets (gen/prru_gen.py): the default double set a
 * controller drops in, each opt-in set with it, the single-precision set,
 * and everything the library's build asks for. */
const bench_regen_set bench_regen_sets[BENCH_REGEN_NSETS] = {
    {"default", ""},
    {"derivatives", "--derivatives"},
    {"regressor", "--regressor"},
    {"float", "--precision float"},
    {"build", "--derivatives --regressor"},
};

/* Wall seconds of `python3 gen/prru_gen.py MODEL --out TMP --quiet` with
 * each set's options, the whole process including the interpreter's start,
 * as a user pays it; the sets interleaved, rep after rep. Returns 0 or -1
 * (with the reason on stderr). */
int bench_time_regeneration(int reps, bench_stats out[BENCH_REGEN_NSETS])
{
  const char *paths[] = {PRRU_BENCH_PYTHON, PRRU_BENCH_SOURCE_DIR, PRRU_BENCH_MODEL};
  for (int i = 0; i < 3; i++)
    if (strchr(paths[i], '\'')) {
      fprintf(stderr, "prru_bench: regeneration: path %s contains a quote\n", paths[i]);
      return -1;
    }
  const char *tmp = getenv("TMPDIR");
  char dir[1024];
  snprintf(dir, sizeof dir, "%s/prru_bench_gen_XXXXXX", tmp && *tmp ? tmp : "/tmp");
  if (!mkdtemp(dir)) {
    fprintf(stderr, "prru_bench: regeneration: cannot create %s: %s\n", dir, strerror(errno));
    return -1;
  }
  static double s[BENCH_REGEN_NSETS][MAXREPS];
  char cmd[8192];
  int rc = 0;
  for (int i = 0; i < reps && rc == 0; i++)
    for (int k = 0; k < BENCH_REGEN_NSETS && rc == 0; k++) {
      /* The generator's stdout goes to stderr so it cannot corrupt --json. */
      snprintf(cmd, sizeof cmd, "'%s' '%s/gen/prru_gen.py' '%s' %s --out '%s' --quiet 1>&2",
               PRRU_BENCH_PYTHON, PRRU_BENCH_SOURCE_DIR, PRRU_BENCH_MODEL,
               bench_regen_sets[k].options, dir);
      double t0 = bench_now_ns();
      rc = system(cmd);
      s[k][i] = (bench_now_ns() - t0) * 1e-9;
    }
  remove_tree_flat(dir);
  if (rc != 0) {
    fprintf(stderr, "prru_bench: regeneration failed (status %d): %s\n", rc, cmd);
    return -1;
  }
  for (int k = 0; k < BENCH_REGEN_NSETS; k++) out[k] = bench_stats_of(s[k], reps);
  return 0;
}
