/* Every gnuplot script of the `prru` tool and the one place that runs
 * gnuplot (see plot.h). Scripts are written from the mechanism descriptor
 * (joints, actuators, reaction labels), never for a fixed limb count. */
#define _POSIX_C_SOURCE 200809L /* fork, waitpid, nanosleep, open_memstream */
#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "commands.h"
#include "plot.h"
#include "prru.h"

/* s as a gnuplot string expression of single-quoted pieces; escape_enhanced:
 * for titles and labels (enhanced text), not file names. Single quotes
 * take every byte as it is but the quote itself, so a quote and the
 * control characters are joined in as double-quoted octal escapes
 * ('it'."\047".'s'): a file name keeps every byte. Never a quote
 * character: gnuplot 5.4 misreads the doubled quote '' next to another
 * one, and its macro expansion takes the quote in "'" for the end of the
 * single-quoted string, so that @name later in the text would be replaced
 * by the variable name's value. In enhanced text a backslash starts an
 * escape (\101 is A) and _ ^ { } @ & ~ are markup: each gets a backslash
 * before it so that it prints as itself; a newline breaks the label, other
 * control characters are dropped. */
static void put_string_width(FILE *g, const char *s, int escape_enhanced, int width)
{
  int col = 0;
  fputc('\'', g);
  for (const char *c = s; *c; c++, col++) {
    unsigned char u = (unsigned char)*c;
    if (escape_enhanced && (*c == '\n' || (*c == ' ' && col >= width))) {
      fputs("'.\"\\n\".'", g);
      col = -1;
    } else if (*c == '\'')
      fputs("'.\"\\047\".'", g);
    else if (escape_enhanced && strchr("\\_^{}@&~", *c))
      fprintf(g, "\\%c", *c);
    else if (u >= 0x20 && u != 0x7f)
      fputc(*c, g);
    else if (!escape_enhanced)
      fprintf(g, "'.\"\\%03o\".'", u);
  }
  fputc('\'', g);
}

/* Labels break at the first space after LABEL_WIDTH characters (a title
 * made of a file's comment lines would run off a 1000-pixel image); the
 * footer, in smaller type, after FOOTER_WIDTH. */
enum { LABEL_WIDTH = 110, FOOTER_WIDTH = 150 };

static void put_string(FILE *g, const char *s, int escape_enhanced)
{
  put_string_width(g, s, escape_enhanced, LABEL_WIDTH);
}

/* The number of lines put_string_width breaks s into. */
static int count_lines(const char *s, int width)
{
  int lines = 1, col = 0;
  for (const char *c = s; *c; c++, col++)
    if (*c == '\n' || (*c == ' ' && col >= width)) {
      lines++;
      col = -1;
    }
  return lines;
}

void prru_plot_string(FILE *g, const char *s) { put_string(g, s, 0); }

void prru_plot_label(FILE *g, const char *s) { put_string(g, s, 1); }

void prru_plot_model_var(FILE *g)
{
  fputs("model = ", g);
  prru_plot_label(g, prru_cli_model()->mech->name);
  fputc('\n', g);
}

/* ---- what every figure shares ---- */

/* Viridis (perceptually uniform, readable in greyscale and by colour-blind
 * readers), for every map: 9 stops of matplotlib's table. */
static const char viridis_palette[] =
    "set palette defined (0 '#440154', 0.125 '#472d7b', 0.25 '#3b528b', 0.375 '#2c728e', "
    "0.5 '#21918c', 0.625 '#28ae80', 0.75 '#5ec962', 0.875 '#addc30', 1 '#fde725')\n";

/* Line types told apart without colour: each has its own dash pattern and
 * a colour (Okabe-Ito) of its own lightness, so that a greyscale print
 * still separates q_1 from q_2 or f_{d1} from f_{d3}. */
static const char line_styles[] =
    "set linetype 1 lc rgb '#0072b2' lw 2 dt solid pt 7\n"
    "set linetype 2 lc rgb '#d55e00' lw 2 dt (8,4) pt 5\n"
    "set linetype 3 lc rgb '#009e73' lw 2 dt (2,3) pt 9\n"
    "set linetype 4 lc rgb '#000000' lw 2 dt (12,4,2,4) pt 11\n"
    "set linetype 5 lc rgb '#cc79a7' lw 2 dt (4,4) pt 13\n"
    "set linetype 6 lc rgb '#56b4e9' lw 2 dt (12,4,2,4,2,4) pt 3\n"
    "set linetype cycle 6\n";

/* The layout of a figure of rows panels, px pixels high: every panel has
 * the same left and right edges (fixed margins, so that the time axes line
 * up whatever the width of the tick labels), the key to the right, the
 * title two lines high, room at the bottom for the last x label and the
 * footer. title: a gnuplot string expression. */
/* Lines of the footer the script being written draws (prru_plot_footer
 * sets it; the figures are made one at a time). */
static int footer_lines = 1;

static void put_layout(FILE *g, int rows, int px, const char *title)
{
  /* 78 px hold the x label and a footer of two lines; each further line
   * of 8-point type takes 12 px more, so the label never meets it. */
  double bottom = (78.0 + 12.0 * (footer_lines > 2 ? footer_lines - 2 : 0)) / px, top = 1.0 - 62.0 / px,
         spacing = 34.0 / px;
  fprintf(g, "set multiplot layout %d,1 margins screen 0.11, 0.83, %.4f, %.4f spacing screen 0, %.4f "
             "title %s\n", rows, bottom, top, spacing, title);
}

/* After the first panel: the footer is drawn once. */
static void put_footer_done(FILE *g) { fputs("unset label 1000\n", g); }

/* Text for a figure: every number of more than 6 significant digits (a
 * CSV's comment lines keep %.17g: 0.29999999999999999) as %.4g, a SHA-256
 * after "sha256 " cut to its first 12 hex digits. */
void prru_plot_shorten(const char *in, char *out, size_t len)
{
  size_t n = 0;
  const char *c = in;
  while (*c && n + 1 < len) {
    if (strncmp(c, "sha256 ", 7) == 0 && strspn(c + 7, "0123456789abcdef") == 64) {
      n += (size_t)snprintf(out + n, len - n, "sha256 %.12s...", c + 7);
      c += 7 + 64;
      if (n >= len) n = len - 1;
      continue;
    }
    int starts = (*c >= '0' && *c <= '9') || ((*c == '-' || *c == '.') && c[1] >= '0' && c[1] <= '9');
    int after_word = c > in && (isalnum((unsigned char)c[-1]) || c[-1] == '_' || c[-1] == '.');
    if (starts && !after_word) {
      char *end;
      double v = strtod(c, &end);
      int digits = 0;
      for (const char *d = c; d < end && !(*d == 'e' || *d == 'E'); d++) digits += *d >= '0' && *d <= '9';
      if (digits > 6 && isfinite(v) && !isalnum((unsigned char)*end) && *end != '_') {
        n += (size_t)snprintf(out + n, len - n, "%.4g", v);
        if (n >= len) n = len - 1;
        c = end;
        continue;
      }
      /* Copied whole, so that its tail is not taken for a number. */
      while (c < end && n + 1 < len) out[n++] = *c++;
      continue;
    }
    out[n++] = *c++;
  }
  out[n] = '\0';
}

void prru_plot_provenance(char *buf, size_t len, const char *cmd)
{
  char id[1200];
  snprintf(id, sizeof id, "prru %s %s; model %s", PRRU_VERSION, cmd, prru_cli_model_id());
  prru_plot_shorten(id, buf, len);
}

/* The footer's label (of the variable footer). */
static const char footer_label[] = "set label 1000 footer at screen 0.005, screen 0 offset 0, character footer_up left font ',8' tc rgb '#505050' front\n";

/* The footer: provenance in small grey type at the bottom left, where no
 * panel reaches (the figures keep their bottom 3 % free). A screen label
 * is drawn by every plot: multiplot figures unset it after their first. */
void prru_plot_footer(FILE *g, const char *text)
{
  fputs("footer = ", g);
  put_string_width(g, text, 1, FOOTER_WIDTH);
  /* The label's position is its first line's: lines go up from the edge
   * (in characters of the 11-point font: a line of 8 points is 3/4 of one). */
  footer_lines = count_lines(text, FOOTER_WIDTH);
  fprintf(g, "\nfooter_up = %.2f\n", 0.5 + 0.75 * (footer_lines - 1));
  fputs(footer_label, g);
}

static int cmp_double(const void *a, const void *b)
{
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

double prru_plot_percentile(const double *v, size_t n, double p)
{
  if (n == 0) return NAN;
  double *s = malloc(n * sizeof *s);
  if (!s) return NAN;
  memcpy(s, v, n * sizeof *s);
  qsort(s, n, sizeof *s, cmp_double);
  double x = p / 100.0 * (double)(n - 1);
  size_t i = (size_t)x;
  double r = i + 1 < n ? s[i] + (x - (double)i) * (s[i + 1] - s[i]) : s[n - 1];
  free(s);
  return r;
}

int prru_plot_parse_clip(const char *cmd, const char *text, double *clip)
{
  *clip = NAN;
  if (!text) return 0;
  char *end;
  errno = 0;
  double v = strtod(text, &end);
  if (!*text || *end || errno || !isfinite(v) || !(v > 1.0)) {
    prru_cli_error(cmd, "--clip '%s': must be a number above 1 (w_R >= 1; colours and the surface "
                   "stop at it)", text);
    return 2;
  }
  *clip = v;
  return 0;
}

double prru_plot_clip_value(double clip, const double *ok_w, size_t n, double w_max)
{
  if (isnan(clip)) clip = prru_plot_percentile(ok_w, n, PRRU_PLOT_CLIP_PERCENTILE);
  if (!isfinite(clip)) clip = w_max;
  if (!(clip > 1.001)) clip = 1.001; /* a range for the colour box */
  return clip;
}

void prru_plot_clip_label(FILE *g, double clip, int automatic, double w_max)
{
  if (w_max > clip)
    fprintf(g, "set cblabel sprintf(\"w_R (-), colours clipped at %%.4g\\n(%s); max %%.4g\", %.17g, %.17g)\n",
            automatic ? "the " PRRU_PLOT_CLIP_PERCENTILE_TEXT " percentile, --clip W sets it" : "--clip",
            clip, w_max);
  else
    fputs("set cblabel 'w_R (-)'\n", g);
}

/* The end of gnuplot's messages (the error is last) on stderr. */
static void show_messages(const char *log)
{
  FILE *f = fopen(log, "r");
  if (!f) return;
  char buf[2048];
  fseek(f, 0, SEEK_END);
  long size = ftell(f);
  fseek(f, size > (long)sizeof buf - 1 ? size - (long)sizeof buf + 1 : 0, SEEK_SET);
  size_t n = fread(buf, 1, sizeof buf - 1, f);
  buf[n] = '\0';
  fclose(f);
  if (n) fprintf(stderr, "gnuplot said:\n%s%s", buf, buf[n - 1] == '\n' ? "" : "\n");
}

static int wait_gnuplot(const char *cmd, pid_t pid, const char *shown);
static int check_outputs(const char *cmd, const char *dir, const char *shown_dir, const char *script);

/* Writes script to path; 0 or 1 after a message naming shown. */
static int write_script(const char *cmd, const char *path, const char *shown, const char *script)
{
  FILE *f = fopen(path, "w");
  if (!f) {
    prru_cli_error(cmd, "%s: cannot open for writing: %s", shown, strerror(errno));
    return 1;
  }
  errno = 0;
  int bad = fputs(script, f) < 0 || fflush(f) != 0;
  int e = errno;
  if (fclose(f) != 0 && !bad) {
    bad = 1;
    e = errno;
  }
  if (bad) {
    prru_cli_error(cmd, "%s: write error: %s", shown, e ? strerror(e) : "output lost");
    return 1;
  }
  return 0;
}

int prru_plot_run(const char *cmd, const char *dir, const char *shown_dir,
                  const char *script_name, const char *script)
{
  char path[4200], shown[4200];
  snprintf(path, sizeof path, "%s/%s", dir, script_name);
  snprintf(shown, sizeof shown, "%s/%s", shown_dir, script_name);
  if (write_script(cmd, path, shown, script)) return 1;
  /* gnuplot's messages go to a file, shown only when it fails: a run that
   * works says nothing ("50 frames in animation sequence" and the like). */
  char log[4200];
  snprintf(log, sizeof log, "%s/.gnuplot-messages", dir);
  int logfd = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0600);
  fflush(NULL); /* nothing buffered is written twice by the child */
  pid_t pid = fork();
  if (pid < 0) {
    prru_cli_error(cmd, "cannot start gnuplot: %s", strerror(errno));
    if (logfd >= 0) {
      close(logfd);
      unlink(log);
    }
    return 1;
  }
  if (pid == 0) {
    /* The caught signals return to their defaults at exec. */
    if (chdir(dir) != 0) _exit(126);
    if (logfd >= 0) dup2(logfd, STDERR_FILENO);
    execlp("gnuplot", "gnuplot", script_name, (char *)NULL);
    _exit(errno == ENOENT ? 127 : 126);
  }
  if (logfd >= 0) close(logfd);
  int rc = wait_gnuplot(cmd, pid, shown);
  if (rc == 1) show_messages(log);
  unlink(log);
  /* gnuplot's status alone does not say that a picture is whole. */
  return rc == 0 ? check_outputs(cmd, dir, shown_dir, script) : rc;
}

/* ---- the pictures gnuplot wrote ---- */

/* The file name of a gnuplot string expression as put_string writes it
 * (pieces '...' and "..." joined by '.') at *p, up to the end of the line,
 * into name; 0, or -1 when the text is not such an expression. */
static int parse_string(const char *p, char *name, size_t len)
{
  size_t n = 0;
  for (;;) {
    char q = *p++;
    if (q != '\'' && q != '"') return -1;
    while (*p && *p != q && *p != '\n') {
      char c = *p++;
      if (q == '"' && c == '\\') { /* only what put_string writes: \ooo */
        if (!(p[0] >= '0' && p[0] <= '7' && p[1] >= '0' && p[1] <= '7' && p[2] >= '0' && p[2] <= '7'))
          return -1;
        c = (char)((p[0] - '0') * 64 + (p[1] - '0') * 8 + (p[2] - '0'));
        p += 3;
      }
      if (n + 1 >= len) return -1;
      name[n++] = c;
    }
    if (*p++ != q) return -1;
    if (*p != '.') break;
    p++;
  }
  name[n] = '\0';
  return *p == '\n' || *p == '\0' ? 0 : -1;
}

/* Whether the file at path ends as a complete picture of its kind must:
 * a PNG with its signature and its last chunk IEND (length 0, CRC
 * AE426082), a GIF with its signature and the trailer 0x3B. gnuplot
 * exits 0 when its writes fail (a full disk): a file cut short at any
 * point lacks its ending. Another kind of file: not empty. NULL or why not. */
static const char *picture_problem(const char *path)
{
  static const unsigned char png_sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  static const unsigned char png_end[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xae, 0x42, 0x60, 0x82};
  FILE *f = fopen(path, "rb");
  if (!f) return strerror(errno);
  unsigned char head[8] = {0}, tail[12] = {0};
  size_t nh = fread(head, 1, sizeof head, f);
  long size = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
  size_t nt = size >= 12 && fseek(f, -12, SEEK_END) == 0 ? fread(tail, 1, sizeof tail, f) : 0;
  fclose(f);
  size_t n = strlen(path);
  int png = n >= 4 && strcmp(path + n - 4, ".png") == 0;
  int gif = n >= 4 && strcmp(path + n - 4, ".gif") == 0;
  if (size <= 0) return "empty";
  if (png && (nh < 8 || memcmp(head, png_sig, 8) != 0)) return "not a PNG";
  if (png && (nt < 12 || memcmp(tail, png_end, 12) != 0)) return "a PNG cut short (no IEND chunk at its end)";
  if (gif && (nh < 6 || memcmp(head, "GIF8", 4) != 0)) return "not a GIF";
  if (gif && (nt < 12 || tail[11] != 0x3b)) return "a GIF cut short (no trailer 0x3B at its end)";
  return NULL;
}

/* Checks every file the script's `set output` lines name (relative to
 * dir: every script of plot.c writes its pictures there); 0, or 1 after a
 * message naming shown_dir/file. */
static int check_outputs(const char *cmd, const char *dir, const char *shown_dir, const char *script)
{
  static const char key[] = "set output ";
  for (const char *line = script; line && *line; line = strchr(line, '\n'), line = line ? line + 1 : NULL) {
    while (*line == ' ') line++;
    if (strncmp(line, key, sizeof key - 1) != 0) continue;
    char name[PRRU_PLOT_PATH], path[2 * PRRU_PLOT_PATH + 2];
    if (parse_string(line + sizeof key - 1, name, sizeof name) != 0) {
      prru_cli_error(cmd, "internal error: a gnuplot script names its output in a way prru cannot check");
      return 1;
    }
    snprintf(path, sizeof path, "%s/%s", dir, name);
    const char *why = picture_problem(path);
    if (why) {
      prru_cli_error(cmd, "%s/%s: gnuplot exited 0 but the file is not complete: %s (disk full?)",
                     shown_dir, name, why);
      return 1;
    }
  }
  return 0;
}

/* Waits for gnuplot; the exit status as prru_plot_run returns it. */
static int wait_gnuplot(const char *cmd, pid_t pid, const char *shown)
{
  /* Poll rather than block, so that a signal to prru alone (kill) stops
   * gnuplot too. */
  int status = 0, killed = 0;
  for (;;) {
    pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == pid) break;
    if (r < 0 && errno != EINTR) {
      prru_cli_error(cmd, "waiting for gnuplot: %s", strerror(errno));
      return 1;
    }
    if (prru_cli_interrupted && !killed) {
      kill(pid, SIGTERM);
      killed = 1;
    }
    struct timespec ts = {0, 20 * 1000 * 1000};
    nanosleep(&ts, NULL);
  }
  if (prru_cli_interrupted) return prru_cli_exit_interrupted();
  if (WIFEXITED(status) && WEXITSTATUS(status) == 127) return PRRU_PLOT_NO_GNUPLOT;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    prru_cli_error(cmd, "gnuplot failed on %s", shown);
    return 1;
  }
  return 0;
}

/* ---- simulation figures ---- */

/* "C1" -> "C_1" (letters, then the rest as a subscript) for gnuplot labels. */
static void put_subscripted(FILE *g, const char *name)
{
  const char *c = name;
  while (*c && !(*c >= '0' && *c <= '9')) fputc(*c++, g);
  if (*c) fprintf(g, "_{%s}", c);
}

/* One plot command of joint j's reaction components whose name (after the
 * '_') starts with kind ('f' forces, 'm' moments): line types 1, 2, 3 by
 * the component (x, y, z), so that a component keeps its style in every
 * panel. */
static void plot_components(FILE *g, int j, char kind)
{
  const prru_joint_info *jt = &prru_cli_model()->mech->joint[j];
  int first = 1;
  for (int k = 0; k < jt->lambda_count; k++) {
    const char *label = prru_cli_model()->mech->lambda_labels[jt->lambda_offset + k];
    const char *comp = strchr(label, '_');
    comp = comp ? comp + 1 : label;
    if (comp[0] != kind) continue;
    char axis = comp[0] ? comp[1] : '\0';
    int lt = axis == 'x' ? 1 : axis == 'y' ? 2 : axis == 'z' ? 3 : 4;
    fprintf(g, "%s'%s' with lines lt %d title '%c_%s'", first ? "plot f using 't':" : ", '' using 't':",
            label, lt, comp[0], comp[0] ? comp + 1 : "");
    first = 0;
  }
  fputs(first ? "plot 0 notitle\n" : "\n", g);
}

/* A figure of one panel per joint of the type ('U', 'P') with its
 * reactions of kind ('f' forces, 'm' moments); title: a gnuplot string
 * expression. */
static void joint_figure(FILE *g, char type, char kind, const char *png, const char *title,
                         const char *unit)
{
  const int njoint = prru_cli_model()->mech->njoint;
  int n = 0;
  for (int j = 0; j < njoint; j++) n += prru_cli_model()->mech->joint[j].type == type;
  const int px = 130 + 210 * (n ? n : 1);
  fprintf(g, "set output '%s'\nset terminal pngcairo size 1000,%d enhanced font 'Sans,11'\n", png, px);
  fputs(footer_label, g);
  fputs("unset xlabel\n", g);
  put_layout(g, n ? n : 1, px, title);
  for (int j = 0, p = 0; j < njoint; j++) {
    if (prru_cli_model()->mech->joint[j].type != type) continue;
    if (++p == n) fputs("set xlabel 'time t (s)'\n", g);
    fputs("set ylabel '", g);
    put_subscripted(g, prru_cli_model()->mech->joint[j].name);
    fprintf(g, " %s'\n", unit);
    plot_components(g, j, kind);
    if (p == 1) put_footer_done(g);
  }
  if (!n) fputs("plot 0 notitle\n", g);
  fputs("unset multiplot\n", g);
}

/* Closes the memory stream g over *buf: the script's text (malloc'ed),
 * or NULL when out of memory. *buf is only final after fclose. */
static char *close_script(FILE *g, char **buf)
{
  if (fclose(g) != 0) {
    free(*buf);
    return NULL;
  }
  return *buf;
}

char *prru_plot_paper_sim_script(const char *csv)
{
  char *buf = NULL;
  size_t len = 0;
  FILE *g = open_memstream(&buf, &len);
  if (!g) return NULL;
  char footer[1200];
  prru_plot_provenance(footer, sizeof footer, "paper");
  prru_plot_model_var(g);
  fputs("set encoding utf8\nset datafile separator ','\n"
        "set terminal pngcairo size 1000,700 enhanced font 'Sans,11'\n"
        "set grid\nset key outside right top\nset autoscale xfix\n"
        "set offsets 0, 0, graph 0.05, graph 0.05\n", g);
  fputs(line_styles, g);
  prru_plot_footer(g, footer);
  fputs("f = ", g);
  prru_plot_string(g, csv);
  fputs("\nset output 'fig_q.png'\n", g);
  put_layout(g, 2, 700, "\"Generalized coordinates in the paper's study (section 4.3; not one of its figures), model \".model");
  fputs("set ylabel 'rotation (rad)'\n"
        "plot f using 't':'q1' with lines lt 1 title 'q_1', '' using 't':'q2' with lines lt 2 title 'q_2'\n", g);
  put_footer_done(g);
  fputs("set xlabel 'time t (s)'\n"
        "set ylabel 'height (m)'\n"
        "plot f using 't':'q3' with lines lt 1 title 'q_3'\n"
        "unset multiplot\n"
        "set output 'fig_d.png'\n", g);
  fputs(footer_label, g);
  put_layout(g, 1, 700, "\"Slider heights in the paper's study (section 4.3; not one of its figures), model \".model");
  fputs("set xlabel 'time t (s)'\nset ylabel 'slider height d_i (m)'\nplot ", g);
  for (int i = 1; i <= prru_cli_model()->mech->nact; i++)
    fprintf(g, "%s't':'d%d' with lines lt %d title 'd_%d'", i == 1 ? "f using " : ", '' using ", i, i, i);
  fputs("\nunset multiplot\n", g);
  joint_figure(g, 'U', 'f', "fig4_u_joint_forces.png",
               "\"U-joint reaction forces, paper fig. 4 (lower link on platform, frame S), model \".model",
               "force (N)");
  joint_figure(g, 'P', 'f', "fig5_p_joint_forces.png",
               "\"Prismatic-joint reaction forces, paper fig. 5 (rail on slider, frame S), model \".model."
               "\"\\nf_z is not shown: z is the drive axis, along which the actuator force f_d acts\"",
               "force (N)");
  joint_figure(g, 'P', 'm', "fig6_p_joint_moments.png",
               "\"Prismatic-joint reaction moments, paper fig. 6 (rail on slider, frame S), model \".model",
               "moment (N m)");
  return close_script(g, &buf);
}

/* ---- fig. 7 ---- */

/* The surface and the contour map of w_R, and the ellipses of fig. 7a. Run
 * in the output directory; the caller defines model, footer, NCONF (fig.
 * 7a poses), cond (the singularity tolerance as a condition number), CLIP
 * and the colour key. Undefined w_R (singular, unreachable, other
 * assembly mode) is NaN in the grid, so those cells are left out rather
 * than drawn as huge values. */
static const char fig7_script[] =
    "# Written by prru paper (cli/plot.c); run in the output directory.\n"
    "set terminal pngcairo size 1100,800 enhanced font 'Sans,11'\n"
    "grid = 'fig7_grid.dat'\n"
    "sing = 'fig7_singular.dat'\n"
    "stats grid using 3 nooutput\n"
    "# Next to the singular band w_R climbs steeply. The surface stops at\n"
    "# CLIP: pm3d cuts every cell smoothly at the z range (clip z), so that\n"
    "# no flat plateau at CLIP and no wall down from it are drawn, and no\n"
    "# jagged edge of whole cells left out.\n"
    "set xlabel 'q_1 (rad)'\n"
    "set ylabel 'q_2 (rad)'\n"
    "set xrange [-pi/6:pi/6]\n"
    "set yrange [-pi/4:pi/6]\n"
    "set output 'fig7_surface.png'\n"
    "set title sprintf(\"Paper fig. 7: w_R over the workspace, q_3 = 0 m, model %s\\n"
    "surface shown up to w_R = %.4g (w_R reaches %.4g next to the singular band); base plane: red J_d singular, grey other assembly mode\", model, CLIP, STATS_max)\n"
    "set zlabel 'w_R (-)' rotate by 90\n"
    "set zrange [1:CLIP]\n"
    "set cbrange [1:CLIP]\n"
    "set xyplane at 1\n"
    "set view 55, 35\n"
    "set pm3d depthorder clip z\n"
    "set key at screen 0.03, screen 0.88 left top Left reverse box opaque\n"
    "set colorbox user origin screen 0.85, screen 0.3 size screen 0.025, screen 0.45\n"
    "set grid\n"
    "splot grid using 1:2:3 with pm3d title 'w_R(q_1, q_2)', \\\n"
    "      sing using 1:2:($3 == 1 ? 1 : NaN) with points pt 5 ps 0.3 lc rgb '#a0a0a0' title 'other assembly mode', \\\n"
    "      sing using 1:2:($3 == 0 ? 1 : NaN) with points pt 7 ps 0.5 lc rgb 'red' title 'J_d singular'\n"
    "unset label 1000\n"
    "# Contour map: contour lines via a table; colours clipped at CLIP (the\n"
    "# colour key says so).\n"
    "set output 'fig7_contour.png'\n"
    "set terminal pngcairo size 1000,850 enhanced font 'Sans,11'\n"
    "set label 1000 footer at screen 0.005, screen 0 offset 0, character footer_up left font ',8' tc rgb '#505050' front\n"
    "set contour base\n"
    "set cntrparam levels discrete 1.1, 1.2, 1.3, 1.4, 1.5, 1.6, 1.7, 1.8, 1.9, 2.0, 2.1, 2.5, 3, 5, 10\n"
    "unset surface\n"
    "set zrange [*:*]\n"
    "set table 'fig7_contours.dat'\n"
    "splot grid using 1:2:3 with lines notitle\n"
    "unset table\n"
    "unset contour\n"
    "set surface\n"
    "set cbrange [1:CLIP]\n"
    "set cbtics auto\n"
    "set title \"Paper fig. 7: w_R over the workspace, q_3 = 0 m, model \".model.\"\\ncontours 1.1 to 2.1 by 0.1, then 2.5, 3, 5, 10; red: J_d singular (cond_1 > \".cond.\"), grey: other assembly mode\"\n"
    "set size ratio -1\n"
    "set key inside left top textcolor rgb 'white' noopaque nobox\n"
    "set grid front\n"
    "plot grid using 1:2:(($3 > CLIP) ? CLIP : $3) with image notitle, \\\n"
    "     'fig7_contours.dat' using 1:2 with lines lc rgb 'white' lw 1 title 'w_R contours', \\\n"
    "     sing using 1:($3 == 1 ? $2 : NaN) with points pt 5 ps 0.45 lc rgb '#a0a0a0' title 'other assembly mode (not ok)', \\\n"
    "     sing using 1:($3 == 0 ? $2 : NaN) with points pt 7 ps 0.35 lc rgb 'red' title 'J_d singular'\n"
    "unset label 1000\n"
    "# Fig. 7a: ellipse outlines in (a.e1, a.v) and segment half-lengths.\n"
    "set output 'fig7a_ellipses.png'\n"
    "set terminal pngcairo size 1300,650 enhanced font 'Sans,11'\n"
    "set label 1000 footer at screen 0.005, screen 0 offset 0, character footer_up left font ',8' tc rgb '#505050' front\n"
    "set key default\n"
    "unset colorbox\n"
    "unset logscale\n"
    "set size noratio\n"
    "set key at screen 0.28, screen 0.5 left center vertical Left reverse\n"
    "set multiplot layout 1,2 margins screen 0.07, 0.97, 0.14, 0.86 spacing screen 0.08, 0 title 'Paper fig. 7a: dynamic manipulability ellipses, q_3 = 0 m (accelerations reachable with 1 N), model '.model\n"
    "set title 'Rotational DME (in the plane of e_1 and v)'\n"
    "set xlabel 'angular acceleration along e_1 (rad s^{-2} per N)'\n"
    "set ylabel 'angular acceleration along v (rad s^{-2} per N)'\n"
    "set size ratio -1\n"
    "set xrange [-1:1]\n"
    "set yrange [-2:2]\n"
    "set xtics 0.5\n"
    "plot for [i=0:NCONF-1] 'fig7a_ellipses.dat' index i using 1:2 with lines lt i+1 title columnheader(1)\n"
    "unset label 1000\n"
    "set size noratio\n"
    "set title 'Translational DME (a segment along z)'\n"
    "set xlabel 'pose (q_1, q_2) (rad)'\n"
    "set ylabel 'linear acceleration along z (m s^{-2} per N)'\n"
    "set xrange [-0.5:NCONF-0.5]\n"
    "set yrange [*:*]\n"
    "set xtics 1\n"
    "set key off\n"
    "plot 'fig7a_segments.dat' using 1:(-$2):(0):(2*$2):($1+1):xtic(3) with vectors nohead lw 8 lc variable\n"
    "unset multiplot\n";

char *prru_plot_fig7_script(int nposes, double rcond_min, double clip, int clip_auto, double w_max)
{
  char *buf = NULL;
  size_t len = 0;
  FILE *g = open_memstream(&buf, &len);
  if (!g) return NULL;
  char footer[1200];
  prru_plot_provenance(footer, sizeof footer, "paper");
  fputs("set encoding utf8\n", g);
  prru_plot_model_var(g);
  prru_plot_footer(g, footer);
  fputs(line_styles, g);
  fputs(viridis_palette, g);
  prru_plot_clip_label(g, clip, clip_auto, w_max);
  fprintf(g, "NCONF = %d\ncond = '%.4g'\nCLIP = %.17g\n%s", nposes, 1.0 / rcond_min, clip, fig7_script);
  return close_script(g, &buf);
}

/* ---- prru plot ---- */

/* Opens a memory stream for a script; NULL when out of memory. */
static FILE *open_script(char **buf, size_t *len)
{
  *buf = NULL;
  return open_memstream(buf, len);
}

/* A round contour step for levels from 1 up to clip: about a dozen lines. */
static double contour_step(double clip)
{
  static const double steps[] = {0.01, 0.02, 0.05, 0.1, 0.2, 0.25, 0.5, 1, 2, 5, 10, 20, 50, 100};
  const int n = (int)(sizeof steps / sizeof steps[0]);
  for (int i = 0; i < n; i++)
    if ((clip - 1.0) / steps[i] <= 12.0) return steps[i];
  return steps[n - 1];
}

char *prru_plot_map_script(const char *dat, const char *png, const char *model, const char *footer,
                           const prru_plot_map_info *m)
{
  char *buf;
  size_t len;
  FILE *g = open_script(&buf, &len);
  if (!g) return NULL;
  const double step = contour_step(m->clip);
  fputs("set encoding utf8\nset terminal pngcairo size 1000,850 enhanced font 'Sans,11'\nset output ", g);
  prru_plot_string(g, png);
  fputs("\ngrid = ", g);
  prru_plot_string(g, dat);
  fputs("\nmodel = ", g);
  prru_plot_label(g, model);
  fprintf(g, "\nCLIP = %.17g\nSTEP = %.17g\n", m->clip, step);
  prru_plot_footer(g, footer);
  fputs(viridis_palette, g);
  fputs("stats grid using 1 nooutput\nX0 = STATS_min\nX1 = STATS_max\n"
        "stats grid using 2 nooutput\nY0 = STATS_min\nY1 = STATS_max\n"
        "set xrange [X0:X1]\nset yrange [Y0:Y1]\n"
        "set xlabel 'q_1 (rad)'\nset ylabel 'q_2 (rad)'\n"
        "set contour base\nset cntrparam levels incremental 1 + STEP, STEP, CLIP\nunset surface\n"
        "set table 'contours.dat'\nsplot grid using 1:2:($4 == 0 ? $3 : NaN) with lines notitle\nunset table\n"
        "unset contour\nset surface\nset cbrange [1:CLIP]\n", g);
  prru_plot_clip_label(g, m->clip, m->clip_auto, m->w_max);
  fprintf(g, "set title sprintf(\"w_R over (q_1, q_2), q_3 = %%.4g m, model %%s\\n%ld \xc3\x97 %ld grid, "
             "white contours every %%g\", %.17g, model, STEP)\n", m->n1, m->n2, m->q3);
  /* Colour only is clipped (an image has no height). */
  /* The key above the footer; the white contours are named in the title. */
  fputs("set size ratio -1\nset key at screen 0.45, screen 0.05 center center horizontal\nset grid front\n"
        "set bmargin 7\n"
        "plot grid using 1:2:($4 == 0 ? ($3 > CLIP ? CLIP : $3) : NaN) with image notitle, \\\n"
        "     'contours.dat' using 1:2 with lines lc rgb 'white' lw 1 notitle", g);
  if (m->n_other)
    fputs(", \\\n     grid using 1:($4 == 2 ? $2 : NaN) with points pt 5 ps 0.45 lc rgb '#a0a0a0' "
          "title 'other assembly mode'", g);
  if (m->n_sing)
    fputs(", \\\n     grid using 1:($4 == 1 ? $2 : NaN) with points pt 7 ps 0.35 lc rgb 'red' "
          "title 'singular or unreachable'", g);
  fputc('\n', g);
  return close_script(g, &buf);
}

/* The start of a time series figure: the CSV f, the PNG of height px,
 * line styles, the model's name for the title (model), the footer. */
static void put_series_figure(FILE *g, const char *csv, const char *png, int px, const char *model,
                              const char *footer)
{
  fprintf(g, "set encoding utf8\nset datafile separator ','\n"
             "set terminal pngcairo size 1000,%d enhanced font 'Sans,11'\nset output ", px);
  prru_plot_string(g, png);
  fputs("\nf = ", g);
  prru_plot_string(g, csv);
  fputs("\nmodel = ", g);
  prru_plot_label(g, model);
  fputc('\n', g);
  fputs(line_styles, g);
  prru_plot_footer(g, footer);
  /* The time axis is the run's span, not the next round number. */
  /* Short key samples: the key's column (right of the panels) then holds
   * "limit +-100 N" without running into the panel. */
  fputs("set grid\nset key outside right top samplen 2\nset autoscale xfix\nset offsets 0, 0, graph 0.05, graph 0.05\n"
        "set ytics format '%g'\n", g);
}

/* "plot f using 't':'<col>1' with lines title '<pre>1<post>', ..." for
 * the n columns col1..coln (line types 1..n), without the line end. */
static void put_series(FILE *g, const char *col, const char *pre, const char *post, int n)
{
  fputs("plot ", g);
  for (int i = 1; i <= n; i++)
    fprintf(g, "%s't':'%s%d' with lines lt %d title '%s%d%s'", i == 1 ? "f using " : ", '' using ",
            col, i, i, pre, i, post);
}

/* The panels q1 and q2 (rad), then q3 (m), then the slider heights d (m). */
static void put_coordinate_panels(FILE *g, int nact)
{
  fputs("set ylabel 'rotation (rad)'\n"
        "plot f using 't':'q1' with lines lt 1 title 'q_1', '' using 't':'q2' with lines lt 2 title 'q_2'\n", g);
  put_footer_done(g);
  fputs("set ylabel 'height (m)'\n"
        "plot f using 't':'q3' with lines lt 1 title 'q_3'\n"
        "set ylabel 'slider height (m)'\n", g);
  put_series(g, "d", "d_", "", nact);
  fputc('\n', g);
}

char *prru_plot_series_script(const char *csv, const char *png, const char *model, const char *footer,
                              int nact, int energies)
{
  char *buf;
  size_t len;
  FILE *g = open_script(&buf, &len);
  if (!g) return NULL;
  int panels = 3 + (energies != 0), px = 120 + 220 * panels;
  put_series_figure(g, csv, png, px, model, footer);
  put_layout(g, panels, px, "'Simulation, model '.model");
  put_coordinate_panels(g, nact);
  if (energies)
    fputs("set xlabel 'time t (s)'\nset ylabel 'energy (J)'\n"
          "plot f using 't':'T' with lines lt 1 title 'T', '' using 't':'V' with lines lt 2 title 'V', "
          "'' using 't':(column('T') + column('V')) with lines lt 4 title 'T + V'\n", g);
  fputs("unset multiplot\n", g);
  return close_script(g, &buf);
}

/* ---- prru track, and prru plot of the CSVs of track, traj, excite, id ---- */

/* The force limits as lines at +-f_max[i] (finite ones), each with a key
 * entry saying its value, grey, dash-dotted: "...", without the line end. */
/* The +-limit lines of a panel (unit in the key: "N", "m/s"), one key
 * entry for equal limits; a non-finite limit draws nothing. */
static void put_limits_unit(FILE *g, int nact, const double *lim, const char *unit)
{
  for (int i = 0; i < nact; i++) {
    if (!isfinite(lim[i])) continue;
    int same = 0;
    for (int k = 0; k < i; k++) same |= lim[k] == lim[i];
    fprintf(g, ", %.17g with lines lc rgb '#707070' lw 1.5 dt (6,3,1,3) ", lim[i]);
    if (same)
      fputs("notitle", g);
    else
      fprintf(g, "title sprintf('limit \xc2\xb1%%.4g %s', %.17g)", unit, lim[i]);
    fprintf(g, ", %.17g with lines lc rgb '#707070' lw 1.5 dt (6,3,1,3) notitle", -lim[i]);
  }
}

static void put_limits(FILE *g, int nact, const double *f_max) { put_limits_unit(g, nact, f_max, "N"); }

char *prru_plot_track_script(const char *csv, const char *png, const char *model, const char *footer,
                             int nact, const double *f_max)
{
  char *buf;
  size_t len;
  FILE *g = open_script(&buf, &len);
  if (!g) return NULL;
  const int px = 1300;
  put_series_figure(g, csv, png, px, model, footer);
  put_layout(g, 5, px, "'Computed-torque tracking, model '.model");
  /* The reference thin and black over the motion, so that both show. */
  fputs("set ylabel 'rotation (rad)'\n"
        "plot f using 't':'q1' with lines lt 1 title 'q_1', '' using 't':'q2' with lines lt 2 title 'q_2', "
        "'' using 't':'qr1' with lines lc rgb 'black' lw 1 dt (3,3) title 'reference', "
        "'' using 't':'qr2' with lines lc rgb 'black' lw 1 dt (3,3) notitle\n", g);
  put_footer_done(g);
  fputs("set ylabel 'height (m)'\n"
        "plot f using 't':'q3' with lines lt 1 title 'q_3', "
        "'' using 't':'qr3' with lines lc rgb 'black' lw 1 dt (3,3) title 'reference'\n"
        "set ylabel 'rotation error (rad)'\n"
        "plot f using 't':'e1' with lines lt 1 title 'e_1 = q_{r1} - q_1', "
        "'' using 't':'e2' with lines lt 2 title 'e_2'\n"
        "set ylabel 'height error (m)'\n"
        "plot f using 't':'e3' with lines lt 1 title 'e_3 = q_{r3} - q_3'\n"
        "set xlabel 'time t (s)'\nset ylabel 'actuator force (N)'\n", g);
  put_series(g, "fd", "f_{d", "}", nact);
  put_limits(g, nact, f_max);
  fputs("\nunset multiplot\n", g);
  return close_script(g, &buf);
}

char *prru_plot_motion_script(const char *csv, const char *png, const char *model, const char *footer,
                              int nact, int forces)
{
  char *buf;
  size_t len;
  FILE *g = open_script(&buf, &len);
  if (!g) return NULL;
  const int px = 120 + 220 * 4;
  put_series_figure(g, csv, png, px, model, footer);
  put_layout(g, 4, px, forces ? "'Excitation trajectory, model '.model" : "'Trajectory, model '.model");
  put_coordinate_panels(g, nact);
  if (forces) {
    fputs("set xlabel 'time t (s)'\nset ylabel 'actuator force (N)'\n", g);
    put_series(g, "fd", "f_{d", "}", nact);
  } else {
    fputs("set xlabel 'time t (s)'\nset ylabel 'slider velocity (m/s)'\n", g);
    put_series(g, "dd", "v_{d", "}", nact);
  }
  fputs("\nunset multiplot\n", g);
  return close_script(g, &buf);
}

char *prru_plot_forces_script(const char *csv, const char *png, const char *model, const char *footer,
                              int nact)
{
  char *buf;
  size_t len;
  FILE *g = open_script(&buf, &len);
  if (!g) return NULL;
  const int px = 600;
  put_series_figure(g, csv, png, px, model, footer);
  put_layout(g, 1, px, "'Inverse dynamics: actuator forces, model '.model");
  fputs("set xlabel 'time t (s)'\nset ylabel 'actuator force (N)'\n", g);
  put_series(g, "fd", "f_{d", "}", nact);
  fputs("\nunset multiplot\n", g);
  return close_script(g, &buf);
}

char *prru_plot_ident_script(const char *dat, const char *png, const char *model, const char *footer, long n)
{
  char *buf;
  size_t len;
  FILE *g = open_script(&buf, &len);
  if (!g) return NULL;
  /* Wide enough for one readable tick label per base parameter. */
  const long px = n * 26 + 260 > 1000 ? n * 26 + 260 : 1000;
  fprintf(g, "set encoding utf8\nset terminal pngcairo size %ld,650 enhanced font 'Sans,11'\nset output ", px);
  prru_plot_string(g, png);
  fputs("\nrep = ", g);
  prru_plot_string(g, dat);
  fputs("\nmodel = ", g);
  prru_plot_label(g, model);
  fputc('\n', g);
  prru_plot_footer(g, footer);
  /* Black estimates with bars and open vermilion squares for the model:
   * apart by shape in greyscale. The prior is the dashed zero line. */
  fprintf(g, "set title 'Identified base parameters against the prior, model '.model\n"
             "set xrange [0.3:%ld.7]\nset xtics 1 rotate by 60 right noenhanced font ',9'\n"
             "set ylabel '(value - prior) / max(|prior|, resolution)'\nset xlabel 'base parameter' offset 0,0.5\n"
             "set grid ytics\nset key outside top right\nset bmargin 11\nset rmargin 22\n"
             "set offsets 0, 0, graph 0.05, graph 0.05\nset ytics format '%%g'\n"
             "plot 0 with lines lc rgb '#000000' dt (6,4) lw 1.5 title 'prior', \\\n"
             "     rep using 1:2:3:xticlabels(5) with yerrorbars pt 7 ps 0.9 lc rgb '#000000' lw 1.5 "
             "title 'estimate {/Symbol \\261} 3 se', \\\n"
             "     rep using 1:4 with points pt 4 ps 1.6 lw 2 lc rgb '#d55e00' title 'written model'\n",
          n);
  return close_script(g, &buf);
}

char *prru_plot_topp_script(const char *csv, const char *png, const char *model, const char *footer, int nact,
                            const double *f_max, const double *v_max)
{
  char *buf;
  size_t len;
  FILE *g = open_script(&buf, &len);
  if (!g) return NULL;
  const int px = 120 + 220 * 4;
  put_series_figure(g, csv, png, px, model, footer);
  put_layout(g, 4, px, "'Time-optimal trajectory, model '.model");
  fputs("set ylabel 'rotation (rad)'\n"
        "plot f using 't':'q1' with lines lt 1 title 'q_1', '' using 't':'q2' with lines lt 2 title 'q_2'\n", g);
  put_footer_done(g);
  fputs("set ylabel 'height (m)'\nplot f using 't':'q3' with lines lt 1 title 'q_3'\n"
        "set ylabel 'slider velocity (m/s)'\n", g);
  put_series(g, "dd", "v_{d", "}", nact);
  put_limits_unit(g, nact, v_max, "m/s");
  fputs("\nset xlabel 'time t (s)'\nset ylabel 'actuator force (N)'\n", g);
  put_series(g, "fd", "f_{d", "}", nact);
  put_limits_unit(g, nact, f_max, "N");
  fputs("\nunset multiplot\n", g);
  return close_script(g, &buf);
}

/* ---- prru animate ---- */

char *prru_plot_animation_script(const char *dat, const char *gif, const char *title, long n,
                                 const double *times, long fps, const double lo[3],
                                 const double hi[3])
{
  char *buf;
  size_t len;
  FILE *g = open_script(&buf, &len);
  if (!g) return NULL;
  /* gif's delay is in 1/100 s. */
  fprintf(g, "set terminal gif animate delay %ld loop 0 optimize size 800,700 font 'Sans,10'\nset output ",
          (100 + fps / 2) / fps);
  prru_plot_string(g, gif);
  fputs("\nf = ", g);
  prru_plot_string(g, dat);
  fputs("\nmodel = ", g);
  prru_plot_label(g, title);
  char footer[1200];
  prru_plot_provenance(footer, sizeof footer, "animate");
  fputs("\nset encoding utf8\n", g);
  prru_plot_footer(g, footer);
  /* Colours told apart by lightness too (rails light, sliders black). */
  fputs("set linetype 1 lc rgb '#b0b0b0'\nset linetype 2 lc rgb '#000000'\n"
        "set linetype 3 lc rgb '#0072b2'\nset linetype 4 lc rgb '#e69f00'\n"
        "set linetype 5 lc rgb '#009e73'\n", g);
  /* One scale on x and y, the box a little larger than the mechanism; z
   * on its own scale (a long run's fall would shrink the mechanism to a
   * speck in a cube). */
  double c[3], half = 0.0;
  for (int k = 0; k < 2; k++) {
    c[k] = 0.5 * (lo[k] + hi[k]);
    if (0.5 * (hi[k] - lo[k]) > half) half = 0.5 * (hi[k] - lo[k]);
  }
  half *= 1.05;
  fprintf(g, "set xrange [%.6g:%.6g]\nset yrange [%.6g:%.6g]\nset zrange [%.6g:%.6g]\n", c[0] - half,
          c[0] + half, c[1] - half, c[1] + half, lo[2] - 0.01 * (hi[2] - lo[2]),
          hi[2] + 0.01 * (hi[2] - lo[2])); /* a vector touching the range's end is dropped whole */
  /* Depth: the floor at the rails' foot, each segment's shadow on it. */
  fprintf(g, "ZF = %.9g\nset view equal xy\nset view 65, 35\nset xyplane at ZF\n", lo[2]);
  fputs("set xlabel 'x (m)'\nset ylabel 'y (m)'\nset zlabel 'z (m)'\nset grid\nunset key\n"
        "set tics font ',8'\n", g);
  fprintf(g, "array T[%ld] = [", n);
  for (long i = 0; i < n; i++) fprintf(g, "%s%.9g", i ? ", " : "", times[i]);
  fputs("]\n", g);
  fprintf(g, "do for [i = 0:%ld] {\n"
             "  set title sprintf(\"model %%s, t = %%.3f s\\nrails grey, sliders black, upper links blue, "
             "lower links orange, platform green\", model, T[i + 1])\n"
             "  splot f index i using 1:2:(ZF):4:5:(0) with vectors nohead lc rgb '#b8b8b8' lw 3 notitle, \\\n"
             "        f index i using 1:2:($7 == 5 ? NaN : $3):4:5:6:7 with vectors nohead lc variable lw 3 "
             "notitle, \\\n"
             "        f index i using 1:2:($7 == 5 ? $3 : NaN):4:5:6 with vectors nohead lt 5 lw 5 notitle\n"
             "}\n", n - 1);
  return close_script(g, &buf);
}

/* ---- prru optimize and prru sensitivity ---- */

char *prru_plot_sensitivity_script(const char *dat, const char *png)
{
  char *buf = NULL;
  size_t len = 0;
  FILE *g = open_memstream(&buf, &len);
  if (!g) return NULL;
  prru_plot_model_var(g);
  fputs("set terminal pngcairo size 1200,650 enhanced font 'Sans,11'\nset output ", g);
  prru_plot_string(g, png);
  fputs("\ndat = ", g);
  prru_plot_string(g, dat);
  fputs("\n"
        "set title \"Sensitivity of the objective to the design parameters, model \".model.\"\\n"
        "d(objective)/d(p) x scale of p (the parameter's magnitude; body inertia, length or slider mass where p may be 0), largest 30\\n"
        "*: a grid point changed status between p - h and p + h (the difference includes a jump)\"\n"
        "set style fill solid 0.8 border -1\n"
        "set boxwidth 0.7\n"
        "set xtics rotate by -60 noenhanced\n"
        "set ylabel 'change of the objective per scale of p'\n"
        "set grid ytics\n"
        "set key off\n"
        "set xzeroaxis lt -1\n"
        "plot dat using 1:3:($3 < 0 ? 0x3b528b : 0xd95f02):xtic(2) with boxes lc rgb variable\n",
        g);
  return close_script(g, &buf);
}

char *prru_plot_optimize_script(const prru_map_grid *grid, double rcond_min, double index_before,
                                double index_after, double sing_before, double sing_after,
                                const char *name, double clip, int clip_auto, double w_max)
{
  char *buf = NULL;
  size_t len = 0;
  FILE *g = open_memstream(&buf, &len);
  if (!g) return NULL;
  char footer[1200];
  prru_plot_provenance(footer, sizeof footer, "optimize");
  fputs("set encoding utf8\n", g);
  prru_plot_model_var(g);
  prru_plot_footer(g, footer);
  fputs("opt = ", g);
  prru_plot_label(g, name);
  fprintf(g, "\nq1lo = %.17g\nq1hi = %.17g\nq2lo = %.17g\nq2hi = %.17g\nq3 = %.17g\n", grid->q1_lo,
          grid->q1_hi, grid->q2_lo, grid->q2_hi, grid->q3);
  fprintf(g, "cond = %.17g\nib = %.17g\nia = %.17g\nsb = %.17g\nsa = %.17g\nCLIP = %.17g\n", 1.0 / rcond_min,
          index_before, index_after, 100 * sing_before, 100 * sing_after, clip);
  fputs(viridis_palette, g);
  prru_plot_clip_label(g, clip, clip_auto, w_max);
  fputs("set terminal pngcairo size 1400,640 enhanced font 'Sans,11'\n"
        "set output 'optimize_maps.png'\n"
        "set multiplot layout 1,2 margins screen 0.06, 0.86, 0.12, 0.84 spacing screen 0.07, 0 "
        "title sprintf(\"w_R before and after prru optimize, q_3 = %.4g m\\n"
        "white: J_d singular (cond_1 > %.4g), other assembly mode or unreachable; one colour scale\", q3, cond)\n"
        "set xlabel 'q_1 (rad)'\n"
        "set ylabel 'q_2 (rad)'\n"
        "set cbrange [1:CLIP]\n"
        "set xrange [q1lo:q1hi]\n"
        "set yrange [q2lo:q2hi]\n"
        "set size ratio -1\n"
        "unset key\n"
        "unset colorbox\n"
        "set title sprintf(\"before: %s\\nglobal index %.4g, %.4g %% not ok\", model, ib, sb)\n"
        "plot 'before.dat' using 1:2:($3 > CLIP ? CLIP : $3) with image\n"
        "unset label 1000\n"
        "set colorbox user origin screen 0.8, screen 0.12 size screen 0.02, screen 0.72\n"
        "set title sprintf(\"after: %s\\nglobal index %.4g, %.4g %% not ok\", opt, ia, sa)\n"
        "plot 'after.dat' using 1:2:($3 > CLIP ? CLIP : $3) with image\n"
        "unset multiplot\n",
        g);
  return close_script(g, &buf);
}
