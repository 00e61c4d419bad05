/* The stages of prru_dme_batch (dme_batch.c) over one floating type,
 * included once per type: REAL (double or float), WS (the workspace of that
 * type), STAGE(name) (the function's name for the type), SQRT, FABS and
 * REAL_MAX (its <math.h> functions and <float.h> maximum). Every constant
 * is an integer, exact in both types, so that the float instance does no
 * arithmetic in double; in double every operation is the scalar path's. */

/* isfinite as a comparison (vectorises everywhere; the same truth value). */
#define FINITE(x) (FABS(x) <= REAL_MAX)

/* Stage 1, three actuators: prru_jd_regular and prru_mode_status. Js =
 * J_d diag(1/L, 1/L, 1); prru_rcond3's adjugate, determinant and 1-norms;
 * J_d^-1 = diag(1/L, 1/L, 1) Js^-1 into ws->inv. pre[k] is the status
 * before the DME (unreachable, singular, other mode, or OK to go on). */
#if N == 3
PRRU_BATCH_TARGETS static void STAGE(regular3)(int n, int o, int m, const REAL *d, const REAL *Jd, REAL L,
                     REAL rcond_min, int home, WS *ws)
{
  /* prru_jd_other_mode: det J_d's sign is not home's (+-1), i.e. not
   * det J_d * home > 0 (exact: a product by +-1); never with home 0. The
   * flags are selects of doubles: GCC vectorises no selects of booleans. */
  const REAL hd = (REAL)home, other_code = home != 0 ? (REAL)PRRU_DME_OTHER_MODE : (REAL)PRRU_OK,
               other_flag = home != 0 ? 1 : 0;
  PRRU_BATCH_LOOP
  for (int k = 0; k < m; k++) {
    const long i = (long)o + k;
    const REAL J0 = Jd[i], J1 = Jd[n + i], J2 = Jd[2L * n + i], J3 = Jd[3L * n + i],
                 J4 = Jd[4L * n + i], J5 = Jd[5L * n + i], J6 = Jd[6L * n + i],
                 J7 = Jd[7L * n + i], J8 = Jd[8L * n + i];
    /* every slider finite: x * 0 is +-0 exactly when x is finite */
    const int reach = d[i] * 0 + d[n + i] * 0 + d[2L * n + i] * 0 == 0;
    const REAL a0 = J0 / L, a1 = J1 / L, a2 = J2, a3 = J3 / L, a4 = J4 / L, a5 = J5,
                 a6 = J6 / L, a7 = J7 / L, a8 = J8;
    const REAL c0 = a4 * a8 - a5 * a7, c1 = a2 * a7 - a1 * a8, c2 = a1 * a5 - a2 * a4;
    const REAL c3 = a5 * a6 - a3 * a8, c4 = a0 * a8 - a2 * a6, c5 = a2 * a3 - a0 * a5;
    const REAL c6 = a3 * a7 - a4 * a6, c7 = a1 * a6 - a0 * a7, c8 = a0 * a4 - a1 * a3;
    const REAL det = a0 * c0 + a1 * c3 + a2 * c6;
    REAL na = 0, ni = 0, s;
    s = FABS(a0) + FABS(a3) + FABS(a6);
    na = s > na ? s : na;
    s = FABS(a1) + FABS(a4) + FABS(a7);
    na = s > na ? s : na;
    s = FABS(a2) + FABS(a5) + FABS(a8);
    na = s > na ? s : na;
    s = FABS(c0) + FABS(c3) + FABS(c6);
    ni = s > ni ? s : ni;
    s = FABS(c1) + FABS(c4) + FABS(c7);
    ni = s > ni ? s : ni;
    s = FABS(c2) + FABS(c5) + FABS(c8);
    ni = s > ni ? s : ni;
    ws->inv[0][k] = c0 / det / L;
    ws->inv[1][k] = c1 / det / L;
    ws->inv[2][k] = c2 / det / L;
    ws->inv[3][k] = c3 / det / L;
    ws->inv[4][k] = c4 / det / L;
    ws->inv[5][k] = c5 / det / L;
    ws->inv[6][k] = c6 / det;
    ws->inv[7][k] = c7 / det;
    ws->inv[8][k] = c8 / det;
    REAL rc = FABS(det) / (na * ni);
    rc = det != 0 ? rc : 0;
    rc = FINITE(det) ? rc : 0;
    /* prru_jd_det_sign, on the unscaled J_d */
    const REAL dj = J0 * (J4 * J8 - J5 * J7) - J1 * (J3 * J8 - J5 * J6) + J2 * (J3 * J7 - J4 * J6);
    REAL pre = dj * hd > 0 ? (REAL)PRRU_OK : other_code;
    pre = rc > 0 ? pre : (REAL)PRRU_ESINGULAR; /* prru_jd_regular */
    pre = rc >= rcond_min ? pre : (REAL)PRRU_ESINGULAR;
    ws->pre[k] = reach ? pre : (REAL)PRRU_EUNREACHABLE;
    ws->rcond[k] = reach ? rc : 0;
    ws->other[k] = reach ? (dj * hd > 0 ? 0 : other_flag) : 0;
  }
}
#else
/* Stage 1, more actuators: prru_jd_regular with rcond_pinv's arithmetic
 * (core.c): J_d^+ = diag(1/L, 1/L, 1) Js^+ from the Householder QR of Js,
 * its early returns as a flag. With more than three actuators J_d has no
 * determinant sign: prru_jd_other_mode is home != 0 (and home, from
 * prru_assembly_mode, is 0). */
PRRU_BATCH_TARGETS static void STAGE(regular_qr)(int n, int o, int m, const REAL *d, const REAL *Jd,
                                          REAL L, REAL rcond_min, int home,
                                          WS *ws)
{
  const REAL other_code = home != 0 ? (REAL)PRRU_DME_OTHER_MODE : (REAL)PRRU_OK,
               other_flag = home != 0 ? 1 : 0;
  PRRU_BATCH_LOOP
  for (int k = 0; k < m; k++) {
    const long x = (long)o + k;
    /* every slider and every entry of Js finite: x * 0 is +-0 exactly
     * when x is finite */
    REAL dz = 0, jz = 0;
    PRRU_UNROLLED
    for (int i = 0; i < N; i++) {
      dz += d[i * (long)n + x] * 0;
      ws->W[3 * i][k] = Jd[3 * i * (long)n + x] / L;
      ws->W[3 * i + 1][k] = Jd[(3 * i + 1) * (long)n + x] / L;
      ws->W[3 * i + 2][k] = Jd[(3 * i + 2) * (long)n + x];
      jz += ws->W[3 * i][k] * 0 + ws->W[3 * i + 1][k] * 0 + ws->W[3 * i + 2][k] * 0;
    }
    const int reach = dz == 0;
    REAL ok = jz == 0 ? 1 : 0, na = 0;
    PRRU_UNROLLED
    for (int j = 0; j < 3; j++) {
      REAL s = 0;
      PRRU_UNROLLED
      for (int i = 0; i < N; i++) s += FABS(ws->W[3 * i + j][k]);
      na = s > na ? s : na;
    }
    PRRU_UNROLLED
    for (int c = 0; c < 3; c++) { /* H_c: W[c.., c] -> (alpha, 0, ...) */
      REAL sc = 0, nx = 0, vv = 0;
      PRRU_UNROLLED
      for (int i = c; i < N; i++) {
        const REAL a = FABS(ws->W[3 * i + c][k]);
        sc = a > sc ? a : sc; /* fmax: sc is never NaN */
      }
      ok = sc > 0 ? ok : 0;
      PRRU_UNROLLED
      for (int i = 0; i < N; i++) ws->V[N * c + i][k] = i < c ? 0 : ws->W[3 * i + c][k] / sc;
      PRRU_UNROLLED
      for (int i = c; i < N; i++) nx += ws->V[N * c + i][k] * ws->V[N * c + i][k];
      nx = SQRT(nx);
      const REAL alpha = ws->V[N * c + c][k] > 0 ? -nx : nx;
      ws->V[N * c + c][k] -= alpha;
      PRRU_UNROLLED
      for (int i = c; i < N; i++) vv += ws->V[N * c + i][k] * ws->V[N * c + i][k];
      ws->beta[c][k] = 2 / vv;
      PRRU_UNROLLED
      for (int j = c; j < 3; j++) {
        REAL s = 0;
        PRRU_UNROLLED
        for (int i = c; i < N; i++) s += ws->V[N * c + i][k] * ws->W[3 * i + j][k];
        s *= ws->beta[c][k];
        PRRU_UNROLLED
        for (int i = c; i < N; i++) ws->W[3 * i + j][k] -= s * ws->V[N * c + i][k];
      }
      ws->W[3 * c + c][k] = alpha * sc;
    }
    /* X = R^-1 (rows 0..2 of Q^T), column by column, into ws->inv */
    REAL nxm = 0;
    PRRU_UNROLLED
    for (int col = 0; col < N; col++) {
      PRRU_UNROLLED
      for (int i = 0; i < N; i++) ws->e[i][k] = i == col ? 1 : 0;
      PRRU_UNROLLED
      for (int c = 0; c < 3; c++) {
        REAL s = 0;
        PRRU_UNROLLED
        for (int i = c; i < N; i++) s += ws->V[N * c + i][k] * ws->e[i][k];
        s *= ws->beta[c][k];
        PRRU_UNROLLED
        for (int i = c; i < N; i++) ws->e[i][k] -= s * ws->V[N * c + i][k];
      }
      PRRU_UNROLLED
      for (int i = 2; i >= 0; i--) {
        REAL s = ws->e[i][k];
        PRRU_UNROLLED
        for (int j = i + 1; j < 3; j++) s -= ws->W[3 * i + j][k] * ws->inv[N * j + col][k];
        ws->inv[N * i + col][k] = s / ws->W[3 * i + i][k];
      }
      const REAL s = FABS(ws->inv[col][k]) + FABS(ws->inv[N + col][k]) + FABS(ws->inv[2 * N + col][k]);
      nxm = s <= nxm ? nxm : s; /* NaN propagates */
    }
    ok = FINITE(nxm) ? ok : 0;
    ok = nxm > 0 ? ok : 0;
    const REAL rc = ok != 0 ? 1 / (na * nxm) : 0;
    PRRU_UNROLLED
    for (int j = 0; j < 2 * N; j++) ws->inv[j][k] /= L;
    REAL pre = rc > 0 ? other_code : (REAL)PRRU_ESINGULAR;
    pre = rc >= rcond_min ? pre : (REAL)PRRU_ESINGULAR;
    ws->pre[k] = reach ? pre : (REAL)PRRU_EUNREACHABLE;
    ws->rcond[k] = reach ? rc : 0;
    ws->other[k] = reach ? other_flag : 0;
  }
}
#endif

/* Mt = J^+T M J^+ (symmetrized), JtR = J_R,P J^+, JtT = J_T,P J^+: the
 * three mul3n and the symmetric product of prru_dme_from. */
PRRU_BATCH_TARGETS static void STAGE(transformed)(int n, int o, int m, const REAL *M, const REAL *JP,
                        WS *ws)
{
  PRRU_BATCH_LOOP
  for (int k = 0; k < m; k++) {
    const long x = (long)o + k;
    PRRU_UNROLLED
    for (int i = 0; i < 3; i++) {
      const REAL m0 = M[3 * i * (long)n + x], m1 = M[(3 * i + 1) * (long)n + x],
                   m2 = M[(3 * i + 2) * (long)n + x];
      const REAL r0 = JP[3 * i * (long)n + x], r1 = JP[(3 * i + 1) * (long)n + x],
                   r2 = JP[(3 * i + 2) * (long)n + x];
      const REAL t0 = JP[(9 + 3 * i) * (long)n + x], t1 = JP[(10 + 3 * i) * (long)n + x],
                   t2 = JP[(11 + 3 * i) * (long)n + x];
      PRRU_UNROLLED
      for (int j = 0; j < N; j++) {
        const REAL v0 = ws->inv[j][k], v1 = ws->inv[N + j][k], v2 = ws->inv[2 * N + j][k];
        ws->tmp[N * i + j][k] = m0 * v0 + m1 * v1 + m2 * v2;
        ws->JtR[N * i + j][k] = r0 * v0 + r1 * v1 + r2 * v2;
        ws->JtT[N * i + j][k] = t0 * v0 + t1 * v1 + t2 * v2;
      }
    }
  }
  PRRU_BATCH_LOOP
  for (int k = 0; k < m; k++) {
    PRRU_UNROLLED
    for (int i = 0; i < N; i++) {
      PRRU_UNROLLED
      for (int j = i; j < N; j++) {
        const REAL s = ws->inv[i][k] * ws->tmp[j][k] + ws->inv[N + i][k] * ws->tmp[N + j][k] +
                         ws->inv[2 * N + i][k] * ws->tmp[2 * N + j][k];
        const REAL s2 = ws->inv[j][k] * ws->tmp[i][k] + ws->inv[N + j][k] * ws->tmp[N + i][k] +
                          ws->inv[2 * N + j][k] * ws->tmp[2 * N + i][k];
        ws->Mt[N * i + j][k] = ws->Mt[N * j + i][k] = (s + s2) / 2;
      }
    }
  }
}

/* prru_dme_from's basis (q0, q1) of range(J_R,P) and C = Q^T JtR (rows c0,
 * c1): the column of largest squared norm (the first of equal ones), then
 * the largest remainder of the others in column order. ok[k] is 0 where
 * either norm is not positive. */
PRRU_BATCH_TARGETS static void STAGE(range_basis)(int n, int o, int m, const REAL *JP, WS *ws)
{
  PRRU_BATCH_LOOP
  for (int k = 0; k < m; k++) {
    const long x = (long)o + k;
    /* column j of J_R,P is (a_j, b_j, c_j) */
    const REAL a0 = JP[x], a1 = JP[n + x], a2 = JP[2L * n + x];
    const REAL b0 = JP[3L * n + x], b1 = JP[4L * n + x], b2 = JP[5L * n + x];
    const REAL c0 = JP[6L * n + x], c1 = JP[7L * n + x], c2 = JP[8L * n + x];
    const REAL nn0 = a0 * a0 + b0 * b0 + c0 * c0, nn1 = a1 * a1 + b1 * b1 + c1 * c1,
                 nn2 = a2 * a2 + b2 * b2 + c2 * c2;
    const int t1 = nn1 > nn0;
    const REAL nk1 = t1 ? nn1 : nn0, k01 = t1 ? 1 : 0;
    const REAL ka1 = t1 ? a1 : a0, kb1 = t1 ? b1 : b0, kc1 = t1 ? c1 : c0;
    const int t2 = nn2 > nk1;
    const REAL nk = t2 ? nn2 : nk1, k0 = t2 ? 2 : k01; /* k0: the column's index */
    const REAL ka = t2 ? a2 : ka1, kb = t2 ? b2 : kb1, kc = t2 ? c2 : kc1;
    const REAL n0 = SQRT(nk);
    const REAL q0a = ka / n0, q0b = kb / n0, q0c = kc / n0;
    REAL best = -1, q1a = 0, q1b = 0, q1c = 0;
#define REMAINDER(j, ca, cb, cc)                                                      \
  do {                                                                              \
    const REAL cq = (ca) * q0a + (cb) * q0b + (cc) * q0c;                         \
    const REAL ra = (ca) - cq * q0a, rb = (cb) - cq * q0b, rc = (cc) - cq * q0c; \
    const REAL nr = ra * ra + rb * rb + rc * rc;                                  \
    const REAL cand = k0 != (j) ? nr : NAN; /* NaN > best is false */            \
    q1a = cand > best ? ra : q1a;                                                   \
    q1b = cand > best ? rb : q1b;                                                   \
    q1c = cand > best ? rc : q1c;                                                   \
    best = cand > best ? cand : best;                                               \
  } while (0)
    REMAINDER(0, a0, b0, c0);
    REMAINDER(1, a1, b1, c1);
    REMAINDER(2, a2, b2, c2);
#undef REMAINDER
    best = SQRT(best);
    ws->ok[k] = n0 > 0 ? (best > 0 ? 1 : 0) : 0;
    q1a /= best;
    q1b /= best;
    q1c /= best;
    PRRU_UNROLLED
    for (int j = 0; j < N; j++) {
      const REAL r0 = ws->JtR[j][k], r1 = ws->JtR[N + j][k], r2 = ws->JtR[2 * N + j][k];
      ws->c0[j][k] = q0a * r0 + q0b * r1 + q0c * r2;
      ws->c1[j][k] = q1a * r0 + q1b * r1 + q1c * r2;
    }
  }
}

/* The rest of prru_dme_from: S = C C^T, G = Mt C^T S^-1, the one-sided
 * Jacobi rotation, the singular values sa >= sb, w_R = sa / sb; then
 * sigma_T's squares f2, mf2, whose tests decide the status too. */
PRRU_BATCH_TARGETS static void STAGE(singular_values)(int m, WS *ws)
{
  PRRU_BATCH_LOOP
  for (int k = 0; k < m; k++) {
    REAL s00 = ws->c0[0][k] * ws->c0[0][k], s01 = ws->c0[0][k] * ws->c1[0][k],
           s11 = ws->c1[0][k] * ws->c1[0][k];
    PRRU_UNROLLED
    for (int j = 1; j < N; j++) {
      s00 += ws->c0[j][k] * ws->c0[j][k];
      s01 += ws->c0[j][k] * ws->c1[j][k];
      s11 += ws->c1[j][k] * ws->c1[j][k];
    }
    const REAL det = s00 * s11 - s01 * s01;
    const REAL i00 = s11 / det, i01 = -s01 / det, i11 = s00 / det;
    PRRU_UNROLLED
    for (int i = 0; i < N; i++) {
      REAL mc0 = ws->Mt[N * i][k] * ws->c0[0][k], mc1 = ws->Mt[N * i][k] * ws->c1[0][k];
      PRRU_UNROLLED
      for (int j = 1; j < N; j++) {
        mc0 += ws->Mt[N * i + j][k] * ws->c0[j][k];
        mc1 += ws->Mt[N * i + j][k] * ws->c1[j][k];
      }
      ws->g0[i][k] = mc0 * i00 + mc1 * i01;
      ws->g1[i][k] = mc0 * i01 + mc1 * i11;
    }
    REAL a = ws->g0[0][k] * ws->g0[0][k], b = ws->g1[0][k] * ws->g1[0][k],
           g = ws->g0[0][k] * ws->g1[0][k];
    PRRU_UNROLLED
    for (int i = 1; i < N; i++) {
      a += ws->g0[i][k] * ws->g0[i][k];
      b += ws->g1[i][k] * ws->g1[i][k];
      g += ws->g0[i][k] * ws->g1[i][k];
    }
    const REAL tau = (b - a) / (2 * g);
    const REAL t = (tau >= 0 ? 1 : -1) / (FABS(tau) + SQRT(1 + tau * tau));
    const REAL ct = 1 / SQRT(1 + t * t);
    const REAL cs = g != 0 ? ct : 1, sn = g != 0 ? t * ct : 0;
    REAL h0 = cs * ws->g0[0][k] - sn * ws->g1[0][k], h1 = sn * ws->g0[0][k] + cs * ws->g1[0][k];
    REAL hh0 = h0 * h0, hh1 = h1 * h1;
    PRRU_UNROLLED
    for (int i = 1; i < N; i++) {
      h0 = cs * ws->g0[i][k] - sn * ws->g1[i][k];
      h1 = sn * ws->g0[i][k] + cs * ws->g1[i][k];
      hh0 += h0 * h0;
      hh1 += h1 * h1;
    }
    const REAL ra = SQRT(hh0), rb = SQRT(hh1);
    const int swap = rb > ra;
    const REAL sa = swap ? rb : ra, sb = swap ? ra : rb;
    const REAL w = sa / sb;
    /* sigma_T = SQRT(mf2) / f2: |JtT|_F^2 by columns, |Mt JtT^T|_F^2 */
    REAL f2 = 0, mf2 = 0;
    PRRU_UNROLLED
    for (int j = 0; j < N; j++) {
      REAL cn = 0;
      PRRU_UNROLLED
      for (int i = 0; i < 3; i++) cn += ws->JtT[N * i + j][k] * ws->JtT[N * i + j][k];
      f2 += cn;
    }
    PRRU_UNROLLED
    for (int j = 0; j < 3; j++) {
      PRRU_UNROLLED
      for (int i = 0; i < N; i++) {
        REAL y = ws->Mt[N * i][k] * ws->JtT[N * j][k];
        PRRU_UNROLLED
        for (int l = 1; l < N; l++) y += ws->Mt[N * i + l][k] * ws->JtT[N * j + l][k];
        mf2 += y * y;
      }
    }
    const REAL sigma_T = SQRT(mf2) / f2;
    const int ok = (ws->ok[k] != 0) & (det > 0) & (sb > 0) & FINITE(sa) & (f2 > 0) & (mf2 > 0) &
                   FINITE(w) & FINITE(sigma_T);
    ws->ok[k] = ok ? 1 : 0;
    ws->w[k] = w;
    /* The ok tests' relative margins (det S against s00 s11, sb against
     * sa), which prru_dme_batch_f needs to trust a float OK. */
    const REAL gs = det / (s00 * s11), gw = sb / sa;
    ws->gap[k] = gs < gw ? gs : gw;
  }
}


#undef FINITE
