/* prru_identify_model: the steps of an identification in the order the
 * CLI and the Python binding need them, so that neither holds the
 * procedure (which prior, which options, when a model may be written). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ident_internal.h"
#include "internal.h"
#include "prru_control.h"
#include "prru_ident.h"

void prru_consistent_worst(const prru_base *b, const prru_consistent_result *c, int k, char *buf, int len)
{
  int used[PRRU_MAX_REG] = {0};
  size_t at = 0;
  if (len <= 0) return;
  buf[0] = 0;
  for (int n = 0; n < k && n < b->nbase && at < (size_t)len; n++) {
    int w = -1;
    for (int i = 0; i < b->nbase; i++)
      if (!used[i] && (w < 0 || fabs(c->t[i]) > fabs(c->t[w]))) w = i;
    used[w] = 1;
    at += (size_t)snprintf(buf + at, (size_t)len - at, "%s#%d %s at %.3g se", n ? ", " : "", w + 1,
                           prru_base_param_name(b, b->col[w]), c->t[w]);
  }
}

static int fit_failed(const prru_base *b, int n, int st, prru_identification *out)
{
  char *msg = out->msg;
  const int len = (int)sizeof out->msg;
  if (out->bad >= 0) return prru_fail(msg, len, st, "sample %d: %s", out->bad + 1, prru_strerror(st));
  if (st == PRRU_EINPUT)
    return prru_fail(msg, len, st, "%d samples give %d independent rows, fewer than the %d base parameters need",
                     n, 3 * n, b->nbase + 1);
  if (st == PRRU_ESINGULAR)
    return prru_fail(msg, len, st, "the motion does not excite every base parameter (condition number %.3g of "
                     "the column-scaled regressor); use an excitation from prru excite", out->fit.cond);
  return prru_fail(msg, len, st, "%s", prru_strerror(st));
}

static int consistent_failed(int st, prru_identification *out)
{
  const int len = (int)sizeof out->msg;
  if (st == PRRU_EINPUT)
    return prru_fail(out->msg, len, st, "the model's own parameters (the prior) are not physical (a body's "
                     "pseudo-inertia not positive definite or a negative drive coefficient): no prior to start from");
  if (st == PRRU_ENOCONV) return prru_fail(out->msg, len, st, "the physically consistent fit did not converge");
  return prru_fail(out->msg, len, st, "%s", prru_strerror(st));
}

static int contradicts_physics(const prru_base *b, prru_identification *out)
{
  char worst[512];
  const prru_consistent_result *c = &out->consistent;
  prru_consistent_worst(b, c, 5, worst, (int)sizeof worst);
  return prru_fail(out->msg, (int)sizeof out->msg, PRRU_ESINGULAR,
                   "the data contradict physics: no physically consistent robot has base parameters within the "
                   "estimate's covariance (Mahalanobis distance^2 %.4g, above the chi^2 quantile %.4g of %d "
                   "degrees of freedom at 1 - %g); furthest from the estimate: %s; check the signs and directions "
                   "of the forces, the gear ratios and the units of fd",
                   c->d2, c->d2_max, b->nbase, out->options.alpha, worst);
}

int prru_identify_model(const prru_model *m, const prru_base *b, int n, const double *q, const double *qd,
                        const double *qdd, const double *fd, const char *name, const char *description,
                        prru_identification *out)
{
  out->stage = PRRU_IDENTIFY_FIT;
  out->bad = -1;
  out->text = NULL;
  out->msg[0] = 0;
  if (!prru_base_fits(m, b))
    return prru_fail(out->msg, (int)sizeof out->msg, PRRU_EINPUT, "the base parameters were computed for a model "
                     "of %d bodies and %d actuators, not this one's %d and %d", b->nbody, b->nact, m->mech->nbody,
                     m->mech->nact);
  int st = prru_identify(m, b, n, q, qd, qdd, fd, &out->fit, &out->bad);
  if (st != PRRU_OK) return fit_failed(b, n, st, out);
  out->stage = PRRU_IDENTIFY_CONSISTENT;
  prru_ident_standard(m->mech, out->pi0);
  prru_base_params(b, out->pi0, out->prior);
  prru_consistent_options_default(&out->options);
  st = prru_ident_consistent(m, b, &out->fit, out->pi0, &out->options, out->pi, &out->consistent);
  /* PRRU_ESINGULAR comes with the nearest consistent set: a report shows it. */
  if (st != PRRU_OK && st != PRRU_ESINGULAR) return consistent_failed(st, out);
  out->stage = PRRU_IDENTIFY_PHYSICS;
  if (st == PRRU_ESINGULAR) return contradicts_physics(b, out);
  out->stage = PRRU_IDENTIFY_MODEL;
  prru_params p;
  char why[300] = "";
  if (prru_ident_model_params(m, b, out->pi, &p, why, (int)sizeof why) != PRRU_OK)
    return prru_fail(out->msg, (int)sizeof out->msg, PRRU_EINPUT,
                     "internal error: the consistent parameters are not physical: %s", why);
  st = prru_model_file_text(m, &p, name, description, &out->text, why, (int)sizeof why);
  if (st != PRRU_OK) return prru_fail(out->msg, (int)sizeof out->msg, st, "internal error: %s", why);
  out->stage = PRRU_IDENTIFY_DONE;
  return PRRU_OK;
}
