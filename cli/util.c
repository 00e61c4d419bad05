/* Argument parsing, messages and JSON output shared by the sub-commands. */
#define _POSIX_C_SOURCE 200809L /* sigaction */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "commands.h"
#include "prru.h"

volatile sig_atomic_t prru_cli_interrupted = 0;
volatile sig_atomic_t prru_cli_signal_count = 0;

/* Only records the signal: the loops poll it and stop at a row boundary. */
static void on_signal(int sig)
{
  prru_cli_interrupted = sig;
  /* The three signals are blocked while this runs (sa_mask): no race. */
  prru_cli_signal_count = prru_cli_signal_count + 1;
}

void prru_cli_catch_signals(void)
{
  static const int sigs[] = {SIGINT, SIGTERM, SIGHUP};
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  for (int i = 0; i < 3; i++) sigaddset(&sa.sa_mask, sigs[i]);
  /* SA_RESTART: blocking calls (stdio on stdout and stderr, pthread_join,
   * write) resume instead of failing with EINTR; nothing needs EINTR to
   * notice the flag, every wait polls it. No SA_RESETHAND: the handler
   * stays for a second signal. */
  sa.sa_flags = SA_RESTART;
  for (int i = 0; i < 3; i++) {
    struct sigaction old;
    /* A signal ignored by the parent (nohup, `trap '' INT`) stays ignored. */
    if (sigaction(sigs[i], NULL, &old) == 0 && old.sa_handler == SIG_IGN) continue;
    sigaction(sigs[i], &sa, NULL);
  }
}

int prru_cli_exit_interrupted(void)
{
  int sig = prru_cli_interrupted;
  return 128 + (sig > 0 && sig < 64 ? sig : SIGINT);
}

const char *prru_cli_signal_name(void)
{
  switch (prru_cli_interrupted) {
  case SIGINT: return "SIGINT";
  case SIGTERM: return "SIGTERM";
  case SIGHUP: return "SIGHUP";
  default: return "a signal";
  }
}

int prru_cli_close_stdout(const char *cmd)
{
  errno = 0;
  int bad = fflush(stdout) != 0;
  int e = errno;
  bad |= ferror(stdout) != 0;
  errno = 0;
  if (fclose(stdout) != 0 && !bad) {
    bad = 1;
    e = errno;
  }
  if (!bad) return 0;
  prru_cli_error(cmd, "stdout: write error: %s", e ? strerror(e) : "output lost");
  return 1;
}

void prru_cli_error(const char *cmd, const char *fmt, ...)
{
  va_list ap;
  fprintf(stderr, "prru %s: ", cmd);
  va_start(ap, fmt);
  vfprintf(stderr, fmt, ap);
  va_end(ap);
  fputc('\n', stderr);
}

int prru_cli_exit_for(int status)
{
  return status == PRRU_EINTERRUPTED ? prru_cli_exit_interrupted() : 1;
}

static int usage_error(const char *cmd, const char *what, const char *arg)
{
  prru_cli_error(cmd, "%s '%s' (see 'prru %s --help')", what, arg, cmd);
  return 2;
}

/* The options, and when file is not NULL one positional argument. */
static int parse_args(const char *cmd, int argc, char **argv, const prru_cli_option *opts, int nopts,
                      const char **file)
{
  for (int i = 0; i < argc; i++) {
    const char *a = argv[i];
    if (strncmp(a, "--", 2) != 0 || a[2] == '\0') {
      if (file && !*file) {
        *file = a;
        continue;
      }
      return usage_error(cmd, "unexpected argument", a);
    }
    const char *name = a + 2, *eq = strchr(name, '=');
    size_t len = eq ? (size_t)(eq - name) : strlen(name);
    const prru_cli_option *o = NULL;
    for (int k = 0; k < nopts; k++)
      if (strlen(opts[k].name) == len && strncmp(opts[k].name, name, len) == 0) o = &opts[k];
    if (!o) return usage_error(cmd, "unknown option", a);
    if (o->takes_value) {
      const char *v = eq ? eq + 1 : (i + 1 < argc ? argv[++i] : NULL);
      if (!v) return usage_error(cmd, "missing value for option", a);
      if (*o->value) return usage_error(cmd, "option given twice:", a);
      *o->value = v;
    } else {
      if (eq) return usage_error(cmd, "option takes no value:", a);
      *o->flag = 1;
    }
  }
  return 0;
}

int prru_cli_parse(const char *cmd, int argc, char **argv, const prru_cli_option *opts,
                   int nopts)
{
  return parse_args(cmd, argc, argv, opts, nopts, NULL);
}

int prru_cli_parse_file(const char *cmd, int argc, char **argv, const prru_cli_option *opts,
                        int nopts, const char **file)
{
  *file = NULL;
  return parse_args(cmd, argc, argv, opts, nopts, file);
}

int prru_cli_units(const char *cmd, const char *units, int *motor, int *current)
{
  const prru_model *m = prru_cli_model();
  *motor = *current = 0;
  if (!units || strcmp(units, "rail") == 0) return 0;
  if (strcmp(units, "motor") != 0) {
    prru_cli_error(cmd, "--units '%s': one of rail, motor", units);
    return 2;
  }
  if (!prru_model_has_lead(m)) {
    prru_cli_error(cmd, "--units motor: model %s has no screw lead (actuators.lead in its model file, "
                   "spec 13): rail forces cannot be converted to motor torques", m->mech->name);
    return 2;
  }
  *motor = 1;
  *current = 1;
  for (int i = 0; i < m->mech->nact; i++) *current &= m->mech->torque_constant[i] > 0;
  return 0;
}

int prru_cli_limits(const char *cmd, const char *alias_name, const prru_cli_limit_args *a, prru_limits *out)
{
  if (a->force_max && a->alias) {
    prru_cli_error(cmd, "--force-max and --%s are the same limit: give one", alias_name);
    return 2;
  }
  const prru_limit_args la = {a->none, a->force_max ? a->force_max : a->alias, a->speed_max, a->stroke};
  char msg[600];
  if (prru_limits_for_run(prru_cli_model(), &la, out, msg, sizeof msg) == PRRU_OK) return 0;
  /* the library names --force-max; the user may have typed the alias */
  if (a->alias && strncmp(msg, "--force-max", 11) == 0)
    prru_cli_error(cmd, "--%s%s", alias_name, msg + 11);
  else
    prru_cli_error(cmd, "%s", msg);
  return 2;
}

int prru_cli_numbers(const char *cmd, const char *name, const char *text, double *out, int n)
{
  if (prru_parse_values(text, out, n) == PRRU_OK) return 0;
  if (n == 1)
    prru_cli_error(cmd, "--%s: '%s' is not a finite number (decimal, or a multiple of pi such as "
                   "-pi/6)", name, text);
  else
    prru_cli_error(cmd, "--%s: '%s' is not %d comma-separated finite numbers (decimal, or multiples "
                   "of pi such as -pi/6)", name, text, n);
  return 2;
}

int prru_cli_number(const char *cmd, const char *name, const char *text, double *out)
{
  return prru_cli_numbers(cmd, name, text, out, 1);
}

void prru_cli_json_number(FILE *f, double v)
{
  if (isfinite(v))
    fprintf(f, "%.17g", v);
  else
    fputs("null", f);
}

void prru_cli_json_array(FILE *f, const double *v, int n)
{
  fputc('[', f);
  for (int i = 0; i < n; i++) {
    if (i) fputs(", ", f);
    prru_cli_json_number(f, v[i]);
  }
  fputc(']', f);
}

const char *prru_cli_names(char *buf, size_t len, const char *prefix, int n, const char *sep)
{
  size_t used = 0;
  buf[0] = '\0';
  for (int i = 0; i < n && used < len; i++) {
    int w = snprintf(buf + used, len - used, "%s%s%d", i ? sep : "", prefix, i + 1);
    if (w < 0) break;
    used += (size_t)w;
  }
  return buf;
}

void prru_cli_json_string(FILE *f, const char *s)
{
  /* A byte that is not well-formed UTF-8 (a --model path holds any
   * bytes) as U+FFFD: JSON text is UTF-8. */
  fputc('"', f);
  while (*s) {
    const unsigned char c = (unsigned char)*s;
    const size_t n = prru_utf8_char(s);
    if (c == '"' || c == '\\')
      fprintf(f, "\\%c", c);
    else if (c < 0x20 || c == 0x7f)
      fprintf(f, "\\u%04x", c);
    else if (n == 0)
      fputs("\\ufffd", f);
    else
      fwrite(s, 1, n, f);
    s += n ? n : 1;
  }
  fputc('"', f);
}

/* s with control characters replaced, so that it stays on one line. */
static void put_plain(char *out, size_t len, size_t *used, const char *s)
{
  for (const unsigned char *c = (const unsigned char *)s; *c && *used + 1 < len; c++)
    out[(*used)++] = (char)(*c < 0x20 || *c == 0x7f ? '?' : *c);
  out[*used] = '\0';
}

/* The model every command computes with: the built-in one until main
 * loads --model's (prru_cli_load_model), then that one until exit. */
static prru_model cli_model;
static int cli_model_set;
static char *cli_model_id;

const prru_model *prru_cli_model(void)
{
  if (!cli_model_set) {
    prru_model_default(&cli_model);
    cli_model_set = 1;
  }
  return &cli_model;
}

int prru_cli_load_model(const char *path)
{
  char msg[1024];
  prru_model m;
  prru_model_default(&m);
  int st = prru_model_load(&m, path, msg, sizeof msg);
  if (st != PRRU_OK) {
    /* The library's message names the file, the key and the reason; the
     * path may hold any bytes. */
    char plain[sizeof msg];
    size_t used = 0;
    put_plain(plain, sizeof plain, &used, msg[0] ? msg : prru_strerror(st));
    fprintf(stderr, "prru: %s\n", plain);
    return st == PRRU_ENOMEM ? 1 : 2;
  }
  prru_cli_free_model();
  cli_model = m;
  cli_model_set = 1;
  return 0;
}

void prru_cli_free_model(void)
{
  if (cli_model_set) prru_model_free(&cli_model);
  free(cli_model_id);
  cli_model_id = NULL;
}

const char *prru_cli_model_id(void)
{
  if (cli_model_id) return cli_model_id;
  const prru_model *m = prru_cli_model();
  /* prru_model_identity's text without its leading "model ", control
   * characters replaced so that it stays on one line. */
  const size_t len = strlen(m->mech->name) + strlen(m->mech->model_file) + strlen(m->mech->sha256) +
                     strlen(m->kernels->path) + 64;
  char *raw = malloc(len), *id = malloc(len);
  if (!raw || !id) {
    free(raw), free(id);
    return "(out of memory)";
  }
  prru_model_identity(m, raw, len);
  size_t used = 0;
  put_plain(id, len, &used, strncmp(raw, "model ", 6) == 0 ? raw + 6 : raw);
  free(raw);
  cli_model_id = id;
  return id;
}

int prru_cli_npreload(const prru_model *m) { return m->mech->nact - 3; }

int prru_cli_nreaction_null(const prru_model *m) { return m->mech->nlambda - (6 * m->mech->nbody - 3); }

const char *prru_cli_paper_fd_text(void)
{
  static char text[32 * PRRU_MAX_ACT];
  prru_scenario s;
  /* The paper's forces for every actuator a model may have (a fourth gets limb 3's). */
  prru_scenario_paper(&s);
  size_t used = 0;
  for (int i = 0; i < prru_cli_model()->mech->nact && used < sizeof text; i++)
    used += (size_t)snprintf(text + used, sizeof text - used, "%s%g", i ? ", " : "", s.loads.base.fd[i]);
  prru_scenario_free(&s);
  return text;
}

int prru_cli_is_paper_model(void) { return strcmp(prru_cli_model()->mech->sha256, PRRU_PAPER_SHA256) == 0; }

void prru_cli_print_version(FILE *f)
{
  const prru_model *m = prru_cli_model();
  char plain[4096];
  size_t used = 0;
  put_plain(plain, sizeof plain, &used, m->mech->model_file);
  fprintf(f, "prru %s\n", PRRU_VERSION);
  fprintf(f, "model: %s\n", m->mech->name);
  fprintf(f, "model file: %s\n", plain);
  fprintf(f, "model format: %d\n", m->mech->format);
  fprintf(f, "model actuators: %d\n", m->mech->nact);
  fprintf(f, "model sha256: %s\n", m->mech->sha256);
  fprintf(f, "model kernels: %s\n", m->kernels->path);
}

void prru_cli_json_model(FILE *f)
{
  const prru_model *m = prru_cli_model();
  fputs("\"model\": {\"name\": ", f);
  prru_cli_json_string(f, m->mech->name);
  fputs(", \"file\": ", f);
  prru_cli_json_string(f, m->mech->model_file);
  fputs(", \"sha256\": ", f);
  prru_cli_json_string(f, m->mech->sha256);
  fputs(", \"kernels\": ", f);
  prru_cli_json_string(f, m->kernels->path);
  fputc('}', f);
}

void prru_cli_csv_comment(FILE *f)
{
  fprintf(f, "# prru %s model %s\n", PRRU_VERSION, prru_cli_model_id());
}

void prru_cli_json_matrix(FILE *f, const double *v, int rows, int cols)
{
  fputc('[', f);
  for (int r = 0; r < rows; r++) {
    if (r) fputs(", ", f);
    prru_cli_json_array(f, v + (size_t)r * (size_t)cols, cols);
  }
  fputc(']', f);
}

int prru_cli_out_motion_row(prru_cli_out *o, double t, const double q[3], const double qd[3],
                            const double qdd[3], const double d[], const double v[])
{
  const int nact = prru_cli_model()->mech->nact;
  prru_cli_out_printf(o, "%.17g", t);
  prru_cli_out_numbers(o, q, 3);
  prru_cli_out_numbers(o, qd, 3);
  prru_cli_out_numbers(o, qdd, 3);
  prru_cli_out_numbers(o, d, nact);
  prru_cli_out_numbers(o, v, nact);
  prru_cli_out_printf(o, "\n");
  return prru_cli_out_row(o);
}

int prru_cli_same_file(const char *a, const char *b)
{
  struct stat sa, sb;
  if (!a || !b || strcmp(a, "-") == 0 || strcmp(b, "-") == 0) return 0;
  /* A file that does not exist yet is no input's file. */
  if (stat(a, &sa) != 0 || stat(b, &sb) != 0) return 0;
  return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

int prru_cli_refuse_same_file(const char *cmd, const char *in_opt, const char *in,
                              const char *out_opt, const char *out)
{
  if (!prru_cli_same_file(in, out)) return 0;
  prru_cli_error(cmd, "--%s %s and --%s %s are the same file: writing it would replace what is "
                 "read (give another --%s)", in_opt, in, out_opt, out, out_opt);
  return 2;
}

int prru_cli_read_interrupted(const char *cmd, const char *opt, const char *path)
{
  if (!prru_cli_interrupted) return 0;
  prru_cli_error(cmd, "interrupted (%s) while reading --%s %s; nothing written", prru_cli_signal_name(),
                 opt, path);
  return prru_cli_exit_interrupted();
}

const char *prru_cli_vec(char *buf, size_t len, const double *v, int n)
{
  size_t used = 0;
  buf[0] = '\0';
  for (int i = 0; i < n && used + 1 < len; i++) {
    /* The fewest significant digits that read back as v[i] (0.2, not
     * 0.20000000000000001): exact, and as the user typed it. */
    char num[32];
    for (int p = 1; p <= 17; p++) {
      snprintf(num, sizeof num, "%.*g", p, v[i]);
      if (strtod(num, NULL) == v[i] || v[i] != v[i]) break;
    }
    used += (size_t)snprintf(buf + used, len - used, "%s%s%s", i ? ", " : "(", num, i == n - 1 ? ")" : "");
  }
  return buf;
}
