/* The checks of tests/test_topology_kernels.c that do not need the build's
 * own topology, written once for either set of topology kernels: included
 * twice, with TT_N defined as 3 (prru_p3_*, prru_p3_derived) and as 4
 * (prru_p4_*, prru_p4_derived). Needs tt_states, tt_compare and the TOL_*
 * constants of the including file. */
#define TT_CAT_(a, b) a##b
#define TT_CAT(a, b) TT_CAT_(a, b)
#define TT_K(name) TT_CAT(TT_CAT(prru_p, TT_N), TT_CAT(_, name))     /* prru_p3_name */
#define TT_M(name) TT_CAT(TT_CAT(PRRU_P, TT_N), TT_CAT(_, name))     /* PRRU_P3_NAME */
#define TT_F(name) TT_CAT(name, TT_N)                                /* name3 */
#define TT_T TT_CAT(TT_CAT(prru_p, TT_N), _derived)                  /* prru_p3_derived */
#define TT_NA TT_M(NACT)
#define TT_NB TT_M(NBODY)

/* testref.h's ref_margin through the topology kernels' poses: the smallest
 * |sin| of an upper link's angle and cos(phi) of limb 3's U joint, in (0, 1];
 * -1 where q is out of reach. */
static double TT_F(margin)(const TT_T *p, const double q[3])
{
  double R[9 * TT_NB], pos[3 * TT_NB];
  TT_K(poses)(p, q, R, pos);
  if (isnan(R[0])) return -1;
  double m = 1.0;
  for (int i = 0; i < TT_NA; i++) {
    const double *Ru = R + 9 * (1 + TT_NA + i);
    m = fmin(m, fabs(i < 2 ? Ru[7] : Ru[2]));
  }
  const double sp = sin(q[0]) * cos(q[1]);
  return fmin(m, sqrt(1.0 - sp * sp));
}

/* n states over a box larger than design p's workspace (q1, q2 within a
 * half turn, q3 within twice the longest limb): compared[k] where the
 * margin is at least MARGIN; a NaN and an infinite q among them. */
static void TT_F(draw)(const TT_T *p, tt_states *s, int n)
{
  double L = 0;
  for (int i = 0; i < TT_NA; i++) L = fmax(L, p->params.l1[i] + p->params.l2[i]);
  for (int k = 0; k < n; k++) {
    s->q[k][0] = tu_uniform(-1.57, 1.57);
    s->q[k][1] = tu_uniform(-1.57, 1.57);
    s->q[k][2] = tu_uniform(-2 * L, 2 * L);
    s->compared[k] = TT_F(margin)(p, s->q[k]) >= MARGIN;
    for (int i = 0; i < 3; i++) {
      s->qd[k][i] = tu_uniform(-2, 2);
      s->fp[k][i] = tu_uniform(-50, 50);
      s->mp[k][i] = tu_uniform(-5, 5);
    }
    for (int i = 0; i < TT_NA; i++) s->fd[k][i] = tu_uniform(-100, 100);
  }
  if (n > 2) {
    s->q[n / 2][0] = NAN;
    s->q[n - 1][2] = INFINITY;
    s->compared[n / 2] = s->compared[n - 1] = 0;
  }
}

/* The outputs of the batched kernels that may use vector sin, cos, tanh
 * (dynamics, eom, eom_solve), the scalar way, at state k with q replaced. */
typedef struct {
  double M[9], h[3], G[3], b[3], qdd[3], minors[3];
} TT_F(trig_outs);

static void TT_F(scalar_trig)(const TT_T *p, const tt_states *s, int k, const double q[3],
                              TT_F(trig_outs) *o)
{
  double M[9];
  TT_K(dynamics)(p, q, s->qd[k], o->M, o->h, o->G);
  TT_K(eom_solve)(p, q, s->qd[k], s->fd[k], s->fp[k], s->mp[k], M, o->b, o->qdd, o->minors);
}

/* Batched against scalar, state by state, as tests/test_batch.c does for
 * the constant kernels (its rule: the exact kernels bit for bit; the ones
 * that may call vector sin, cos, tanh within TOL_BATCH of the output's
 * largest entry plus SENS_FACTOR times its change when q1 or q2 moves by
 * PERTURB_EPS ulp, the scalar kernel's own sensitivity to the trigonometric
 * functions' error). Returns the worst difference relative to the largest
 * entry. */
static double TT_F(check_batch)(const TT_T *p, const tt_states *s, int n, int *nan_ok)
{
  static double want[6][18 * NMAX], got[6][18 * NMAX]; /* 18 >= 3 NA */
  static double sens[6][NMAX];
  const double *q = tt_soa(0, &s->q[0][0], 3, 3, n), *qd = tt_soa(1, &s->qd[0][0], 3, 3, n),
               *fd = tt_soa(2, &s->fd[0][0], 4, TT_NA, n), *fp = tt_soa(3, &s->fp[0][0], 3, 3, n),
               *mp = tt_soa(4, &s->mp[0][0], 3, 3, n);
  const char *set = TT_N == 3 ? "prru_p3_batch" : "prru_p4_batch";
  double worst = 0;
  char k[64];
#define TT_CMP(kern, name, g, w, dim, sv)                                       \
  do {                                                                          \
    snprintf(k, sizeof k, "%s_%s", set, kern);                                  \
    const double e_ = tt_compare(k, name, g, w, sv, dim, n, s->compared, nan_ok); \
    if (e_ > worst) worst = e_;                                                 \
  } while (0)
  for (int i = 0; i < n; i++) {
    TT_K(ik_jd)(p, s->q[i], want[0] + TT_NA * i, want[1] + 3 * TT_NA * i);
    TT_K(mass)(p, s->q[i], want[2] + 9 * i);
    TT_K(platform_jacobian)(p, s->q[i], want[3] + 18 * i);
  }
  TT_K(batch_ik_jd)(p, n, q, got[0], got[1]);
  TT_CMP("ik_jd", "d", got[0], want[0], TT_NA, NULL);
  TT_CMP("ik_jd", "Jd", got[1], want[1], 3 * TT_NA, NULL);
  TT_K(batch_mass)(p, n, q, got[2]);
  TT_CMP("mass", "M", got[2], want[2], 9, NULL);
  TT_K(batch_platform_jacobian)(p, n, q, got[3]);
  TT_CMP("platform_jacobian", "JP", got[3], want[3], 18, NULL);
  TT_K(batch_dme_terms)(p, n, q, got[0], got[1], got[2], got[3]);
  TT_CMP("dme_terms", "d", got[0], want[0], TT_NA, NULL);
  TT_CMP("dme_terms", "Jd", got[1], want[1], 3 * TT_NA, NULL);
  TT_CMP("dme_terms", "M", got[2], want[2], 9, NULL);
  TT_CMP("dme_terms", "JP", got[3], want[3], 18, NULL);
  /* The sensitivity of each vector-trig output per state. */
  for (int i = 0; i < n; i++) {
    for (int j = 0; j < 6; j++) sens[j][i] = 0;
    if (!s->compared[i]) continue;
    TT_F(trig_outs) o0, o1;
    TT_F(scalar_trig)(p, s, i, s->q[i], &o0);
    for (int j = 0; j < 2; j++)
      for (int sign = -1; sign <= 1; sign += 2) {
        double qq[3] = {s->q[i][0], s->q[i][1], s->q[i][2]};
        qq[j] += sign * PERTURB_EPS * DBL_EPSILON * fmax(1.0, fabs(qq[j]));
        TT_F(scalar_trig)(p, s, i, qq, &o1);
        sens[0][i] = fmax(sens[0][i], tt_maxdiff(o1.M, o0.M, 9));
        sens[1][i] = fmax(sens[1][i], tt_maxdiff(o1.h, o0.h, 3));
        sens[2][i] = fmax(sens[2][i], tt_maxdiff(o1.G, o0.G, 3));
        sens[3][i] = fmax(sens[3][i], tt_maxdiff(o1.b, o0.b, 3));
        sens[4][i] = fmax(sens[4][i], tt_maxdiff(o1.qdd, o0.qdd, 3));
        sens[5][i] = fmax(sens[5][i], tt_maxdiff(o1.minors, o0.minors, 3));
      }
  }
  for (int i = 0; i < n; i++)
    TT_K(dynamics)(p, s->q[i], s->qd[i], want[0] + 9 * i, want[1] + 3 * i, want[2] + 3 * i);
  TT_K(batch_dynamics)(p, n, q, qd, got[0], got[1], got[2]);
  TT_CMP("dynamics", "M", got[0], want[0], 9, sens[0]);
  TT_CMP("dynamics", "h", got[1], want[1], 3, sens[1]);
  TT_CMP("dynamics", "G", got[2], want[2], 3, sens[2]);
  for (int i = 0; i < n; i++)
    TT_K(eom)(p, s->q[i], s->qd[i], s->fd[i], s->fp[i], s->mp[i], want[0] + 9 * i, want[3] + 3 * i);
  TT_K(batch_eom)(p, n, q, qd, fd, fp, mp, got[0], got[3]);
  TT_CMP("eom", "M", got[0], want[0], 9, sens[0]);
  TT_CMP("eom", "b", got[3], want[3], 3, sens[3]);
  for (int i = 0; i < n; i++)
    TT_K(eom_solve)(p, s->q[i], s->qd[i], s->fd[i], s->fp[i], s->mp[i], want[0] + 9 * i,
                    want[3] + 3 * i, want[4] + 3 * i, want[5] + 3 * i);
  TT_K(batch_eom_solve)(p, n, q, qd, fd, fp, mp, got[0], got[3], got[4], got[5]);
  TT_CMP("eom_solve", "M", got[0], want[0], 9, sens[0]);
  TT_CMP("eom_solve", "b", got[3], want[3], 3, sens[3]);
  TT_CMP("eom_solve", "qdd", got[4], want[4], 3, sens[4]);
  TT_CMP("eom_solve", "minors", got[5], want[5], 3, sens[5]);
#undef TT_CMP
  return worst;
}

#undef TT_T
#undef TT_NA
#undef TT_NB
#undef TT_K
#undef TT_M
#undef TT_F
#undef TT_CAT
#undef TT_CAT_
