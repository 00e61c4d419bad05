/* prru gen: the generator (gen/prru_gen.py, Python 3 standard library
 * only) behind the tool, so that a user with an installed prru writes the
 * kernels of a model file without a source tree. Its arguments go to the
 * generator unchanged (an argument vector, no shell: nothing to escape),
 * and its exit status is the command's. */
#define _POSIX_C_SOURCE 200809L /* readlink, access */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "commands.h"

#ifndef PRRU_GEN_SOURCE_SCRIPT
#define PRRU_GEN_SOURCE_SCRIPT ""
#endif

static int readable(const char *path) { return path[0] && access(path, R_OK) == 0; }

/* The generator: $PRRU_GENERATOR; else the one installed beside this
 * program (BIN/../share/prru/gen/prru_gen.py, the same release); else the
 * source tree's this program was built from. */
static int find_generator(char *out, size_t len)
{
  const char *env = getenv("PRRU_GENERATOR");
  if (env && env[0]) {
    if (!readable(env)) {
      prru_cli_error("gen", "PRRU_GENERATOR=%s: %s", env, strerror(errno));
      return 2;
    }
    snprintf(out, len, "%s", env);
    return 0;
  }
  char exe[4096];
  const ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
  if (n > 0) {
    exe[n] = 0;
    char *slash = strrchr(exe, '/');
    if (slash) {
      *slash = 0;
      if ((size_t)snprintf(out, len, "%s/../share/prru/gen/prru_gen.py", exe) < len && readable(out)) return 0;
    }
  }
  if (readable(PRRU_GEN_SOURCE_SCRIPT)) {
    snprintf(out, len, "%s", PRRU_GEN_SOURCE_SCRIPT);
    return 0;
  }
  prru_cli_error("gen", "the generator (prru_gen.py) is neither installed beside this program (share/prru/gen) "
                 "nor in the source tree it was built from (%s); set PRRU_GENERATOR to its path",
                 PRRU_GEN_SOURCE_SCRIPT[0] ? PRRU_GEN_SOURCE_SCRIPT : "unknown");
  return 2;
}

int prru_cmd_gen(int argc, char **argv)
{
  char script[4096 + 64];
  int rc = find_generator(script, sizeof script);
  if (rc) return rc;
  /* python3 -c RUN SCRIPT ARGS... (argv: the arguments after "gen"):
   * RUN imports SCRIPT and calls its main under the name "prru gen",
   * which its usage and messages then say. */
  static const char run[] = "import os, sys; sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[1]))); "
                            "import prru_gen; sys.exit(prru_gen.main(sys.argv[2:], prog='prru gen'))";
  char **args = calloc((size_t)argc + 5, sizeof *args);
  if (!args) {
    prru_cli_error("gen", "out of memory");
    return 1;
  }
  args[0] = "python3";
  args[1] = "-c";
  args[2] = (char *)run;
  args[3] = script;
  for (int i = 0; i < argc; i++) args[i + 4] = argv[i];
  fflush(stdout);
  execvp("python3", args);
  prru_cli_error("gen", "cannot run python3 (the generator needs Python 3): %s", strerror(errno));
  free(args);
  return 2;
}
