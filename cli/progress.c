/* Progress on stderr: a bar on a terminal, plain lines in a log (see
 * progress.h). */
#define _POSIX_C_SOURCE 200809L /* isatty */
#include <stdio.h>
#include <unistd.h>

#include "progress.h"

void prru_cli_progress_init(prru_cli_progress *p, const char *label, const char *unit, int requested,
                            int long_run)
{
  p->label = label;
  p->unit = unit;
  p->last = -1;
  if (isatty(STDERR_FILENO))
    p->mode = requested || long_run ? PRRU_PROGRESS_BAR : PRRU_PROGRESS_OFF;
  else
    p->mode = requested ? PRRU_PROGRESS_LINES : PRRU_PROGRESS_OFF;
}

static void draw_bar(prru_cli_progress *p, int pct, double done, double total)
{
  char bar[41];
  int fill = pct * 40 / 100;
  for (int i = 0; i < 40; i++) bar[i] = i < fill ? '#' : '.';
  bar[40] = '\0';
  fprintf(stderr, "\r%s [%s] %3d%%", p->label, bar, pct);
  if (p->unit) fprintf(stderr, " (%.0f/%.0f %s)", done, total, p->unit);
  if (done >= total) fputc('\n', stderr);
  fflush(stderr);
  p->last = done >= total ? 101 : pct;
}

void prru_cli_progress_update(prru_cli_progress *p, double done, double total)
{
  if (p->mode == PRRU_PROGRESS_OFF || !(total > 0)) return;
  int pct = (int)(100.0 * done / total);
  if (pct > 100) pct = 100;
  if (p->mode == PRRU_PROGRESS_BAR) {
    if (pct != p->last) draw_bar(p, pct, done, total);
    return;
  }
  int tenth = pct / 10;
  if (tenth == p->last) return;
  fprintf(stderr, "%s: %d%%", p->label, 10 * tenth);
  if (p->unit) fprintf(stderr, " (%.0f/%.0f %s)", done, total, p->unit);
  fputc('\n', stderr);
  fflush(stderr);
  p->last = tenth;
}

void prru_cli_progress_end(prru_cli_progress *p)
{
  if (p->mode == PRRU_PROGRESS_BAR && p->last >= 0 && p->last <= 100) fputc('\n', stderr);
  p->last = 101;
}
