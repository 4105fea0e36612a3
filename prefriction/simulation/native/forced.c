/* The native driver of forced and dense runs: the normalised oscillator with an input force
 *
 *   x' = v,  v' = u(t) - F(z, m, v, s),  z' = rate(z, m, v, s),  W' = u v,  E_f' = F v
 *                                                                           (docs/simulator.md#native)
 *
 * with the Runge-Kutta 5(4) of driver.c (the tableau of CasADi's "erk", its dense output, RMS
 * error norm and PI step control), the step size carried over from step to step, call to call.
 * The events are those of the CasADi plant (plant.py, module notes): the zero of s v (a reversal
 * if the net force a = u - F opposes s by more than EPS_TOUCH times the error level, a touch if it
 * pushes along s, else a rest), the model's own events, the end of a rest (|a| above EPS_REST times
 * the error level) and a reversal pair inside one step (the least speed s v of the step's dense
 * output below zero: the first zero before it is the reversal).
 *
 * The input u: the generated pf_input(t_si, theta, piece) of the signal's structure (every
 * prefriction.signals kind: analytic kinds as their expression, piecewise-linear kinds, Samples
 * and ZeroOrderHold as a table of pieces read per interval between the break times). The
 * integration is broken at every break time. Dense output: the states at the requested times,
 * from the step's dense output, written into arrays.
 *
 * A continuous controller (PF_NC > 0 states, pf_forced_fb, native/closed.py): its states join the
 * integrated state after E_f, its force is added to the input, the reference is pf_ref (PF_NRPC
 * per-interval numbers, rows as the input's); at rest the plant's rates are zero and the controller
 * integrates on, the end of the rest and the force limit's switches are events of the steps.
 * pf_forced_stiff stops with PF_F_STIFF where the step is held by stability (the test of
 * driver.c), for stiff_forced.py to go on with Radau.
 *
 * This file follows driver.c (pf_ctx, the tableau, the model's Functions) and needs PF_FORCED
 * (1: an input signal, with pf_input, PF_NPC per-interval numbers; 0: unforced dense runs).
 *
 * Run state st[] (normalised units), read at the start of pf_forced and written at its end:
 *   0 t, 1 x, 2 v, 3 s, 4 model events since the last reversal, 5 rest (0/1), 6 W (input work
 *   since the last reversal), 7 E_f (friction work since t = 0), 8 largest amplitude so far,
 *   9 the step size to try next (0: none yet), 10 index of the current piece, 11 branch energy
 *   v^2/2 + potential - W, 12 time of the last reversal, 13 of the one before (NaN if none),
 *   14.. z, then m (with a controller: then xc and the force limit's mode 0, +-1).
 * cfg[]: 0 eps (error control), 1 eps of the thresholds, 2 snap, 3 time unit [s], 4 1/Fc [1/N],
 *   5 force scale, 6 dense (E_f error-controlled), 7 piecewise-linear input (1/0), 8 energy
 *   correction at model events (1/0), 9 (with a controller) 1 / the position unit [1/m].
 */

#ifndef PF_NC
#define PF_NC 0 /* continuous controller states (0: no feedback) */
#endif
#ifndef PF_NRPC
#define PF_NRPC 0
#endif
#define PF_NF (PF_NY + 2 + PF_NC)
#define PF_IW PF_NY
#define PF_IE (PF_NY + 1)
#define PF_IC (PF_NY + 2)
#define PF_NCA (PF_NC > 0 ? PF_NC : 1)
#define PF_NRPCA (PF_NRPC > 0 ? PF_NRPC : 1)
#define PF_FHEAD 14
#define PF_NPCA (PF_NPC > 0 ? PF_NPC : 1)
#define PF_EPS_TOUCH 1.0
#define PF_EPS_REST 3.0
#define PF_EPS_START 1e-13

enum { PF_F_REVERSALS = 0, PF_F_T_END = 1, PF_F_DIED_OUT = 2, PF_F_NONFINITE = 3, PF_F_STEP_UNDERFLOW = 5,
       PF_F_STIFF = 6 };

typedef struct {
  pf_ctx c;
  const double* th;  /* the signal's run-time numbers */
  const double* brk; /* break times (normalised), increasing */
  const double* pcs; /* per-interval numbers, row k for [brk[k-1], brk[k]) */
  long nbrk, kb;
  double tunit, invFc;
  double F_last; /* the friction force of the last pf_ff */
  const double* line; /* an added line (t_l, a, b) [s, N, N/s]: a + b (t - t_l) (a sampled loop's held force), or 0 */
#if PF_NC
  /* the controller (normalised units, as plant.py): An (row-major), Bn, Cn, Dn, umax, kaw, then
   * the error scales 1/|Cn_i| (1 where Cn_i = 0); the reference's numbers and pieces */
  const double *An, *Bn, *Cn, *kaw, *xs, *thr, *pcr;
  double Dn, umax, invx, sat, w_last;
#endif
  int rest; /* at rest (with a controller: the plant frozen, the controller integrating) */
} pf_fctx;

static double pf_u(pf_fctx* f, double t) {
#if PF_FORCED
  double tsi = t * f->tunit, u;
  pf_ctx* c = &f->c;
  c->arg[0] = &tsi;
  c->arg[1] = f->th;
  c->arg[2] = f->pcs + f->kb * PF_NPCA;
  c->res[0] = &u;
  pf_input(c->arg, c->res, c->iw, c->w, 0);
  if (f->line) u += f->line[1] + f->line[2] * (tsi - f->line[0]);
  return u * f->invFc;
#else
  (void)f; (void)t;
  return 0.0;
#endif
}

#if PF_NC
/* the position reference r(t) [normalised] (pf_ref of the reference's structure) */
static double pf_r(pf_fctx* f, double t) {
  double tsi = t * f->tunit, r;
  pf_ctx* c = &f->c;
  c->arg[0] = &tsi;
  c->arg[1] = f->thr;
  c->arg[2] = f->pcr + f->kb * PF_NRPCA;
  c->res[0] = &r;
  pf_ref(c->arg, c->res, c->iw, c->w, 0);
  return r * f->invx;
}

/* the controller's force at (t, Y), its unclipped output in f->w_last and, if dxc, the rates of
 * its states: w = Cn xc + Dn e, u = w (inside) or sat umax, xc' = An xc + Bn e + kaw (u - w) */
static double pf_ufb(pf_fctx* f, double t, const double* Y, double* dxc) {
  const double* xc = Y + PF_IC;
  double e = pf_r(f, t) - Y[0], w = f->Dn * e, u;
  int i, j;
  for (i = 0; i < PF_NC; ++i) w += f->Cn[i] * xc[i];
  u = f->sat == 0.0 ? w : f->sat * f->umax;
  f->w_last = w;
  if (dxc)
    for (i = 0; i < PF_NC; ++i) {
      double acc = f->Bn[i] * e + f->kaw[i] * (u - w);
      for (j = 0; j < PF_NC; ++j) acc += f->An[i * PF_NC + j] * xc[j];
      dxc[i] = acc;
    }
  return u;
}
#endif

/* the right-hand side at (t, Y); returns the friction force */
static double pf_ff(pf_fctx* f, double t, const double* Y, double* dY) {
  double F, u;
  pf_f(&f->c, Y, dY);
  F = -dY[1];
  f->F_last = F;
  u = pf_u(f, t);
#if PF_NC
  u += pf_ufb(f, t, Y, dY + PF_IC);
  if (f->rest) { /* at rest: only the controller moves */
    int i;
    for (i = 0; i < PF_NY; ++i) dY[i] = 0.0;
    dY[PF_IW] = dY[PF_IE] = 0.0;
    f->F_last = F;
    return F;
  }
#endif
  dY[1] += u;
  dY[PF_IW] = u * Y[1];
  dY[PF_IE] = F * Y[1];
  return F;
}

/* the total applied force (input and controller) at (t, Y) */
static double pf_utot(pf_fctx* f, double t, const double* Y) {
#if PF_NC
  return pf_u(f, t) + pf_ufb(f, t, Y, 0);
#else
  (void)Y;
  return pf_u(f, t);
#endif
}

/* sample j of nd: x, v, F, E_f and the controller states */
static void pf_put(double* out, long nd, long j, const double* y, double v, double F) {
  out[j] = y[0]; out[nd + j] = v; out[2 * nd + j] = F; out[3 * nd + j] = y[PF_IE];
#if PF_NC
  {
    int i;
    for (i = 0; i < PF_NC; ++i) out[(4 + i) * nd + j] = y[PF_IC + i];
  }
#endif
}

static void pf_fdense(const double U[7][PF_NF], const double* y0, double th, double* y) {
  int i, j;
  for (i = 0; i < PF_NF; ++i) y[i] = y0[i];
  for (j = 0; j < 7; ++j) {
    double wj = th * (pf_D[0][j] + th * (pf_D[1][j] + th * (pf_D[2][j] + th * pf_D[3][j])));
    if (wj == 0.0) continue;
    for (i = 0; i < PF_NF; ++i) y[i] += wj * U[j][i];
  }
}

/* component i of the step's dense output at th, and its derivative d/dth */
static double pf_fdense1(const double U[7][PF_NF], const double* y0, double th, int i, int deriv) {
  double y = deriv ? 0.0 : y0[i];
  int j;
  for (j = 0; j < 7; ++j) {
    double wj = deriv ? pf_D[0][j] + th * (2.0 * pf_D[1][j] + th * (3.0 * pf_D[2][j] + th * 4.0 * pf_D[3][j]))
                      : th * (pf_D[0][j] + th * (pf_D[1][j] + th * (pf_D[2][j] + th * pf_D[3][j])));
    y += wj * U[j][i];
  }
  return y;
}

typedef struct {
  const double (*U)[PF_NF];
  const double* y0;
  double off; /* the offset of the reversal indicator (EPS_START times the amplitude) */
  double t0, h; /* the step's start and size */
  double thr, F; /* at rest: the exit threshold and the (frozen) friction force */
} pf_step;

#if PF_NC
/* the feedback's indicators at the state y, time t: -4 the end of a rest (thr - |u - F|), -5 and -6
 * the clip's upper and lower switch (relative to umax; 1 where the switch cannot come) */
static double pf_fbind(pf_fctx* f, const pf_step* P, double t, const double* y, int k) {
  double u = pf_u(f, t) + pf_ufb(f, t, y, 0), w = f->w_last / f->umax;
  if (k == -4) return P->thr - fabs(u - P->F);
  if (k == -5) return f->sat == 0.0 ? 1.0 - w : (f->sat > 0.0 ? w - 1.0 : 1.0);
  return f->sat == 0.0 ? 1.0 + w : (f->sat < 0.0 ? -1.0 - w : 1.0);
}
#endif

/* indicator k at th: -1 the reversal s v + off, -3 minus the slope of s v, -4 to -6 the feedback's
 * (pf_fbind), else the model's k */
static double pf_find(pf_fctx* f, const pf_step* P, double th, int k) {
  double y[PF_NF], g[PF_NEA] = {0.0};
  if (k == -1) return f->c.s * pf_fdense1(P->U, P->y0, th, 1, 0) + P->off;
  if (k == -3) return -f->c.s * pf_fdense1(P->U, P->y0, th, 1, 1);
  pf_fdense(P->U, P->y0, th, y);
#if PF_NC
  if (k <= -4) return pf_fbind(f, P, P->t0 + th * P->h, y, k);
#endif
  pf_g(&f->c, y, g);
  return g[k];
}

/* the first th in (a, b] where indicator k is <= 0 (to 1e-15), from ga > 0 at a and gb <= 0 at b */
static double pf_flocate(pf_fctx* f, const pf_step* P, int k, double a, double b, double ga, double gb) {
  double th, gc;
  int side = 0, it;
  for (it = 0; it < 200 && b - a > 1e-15; ++it) {
    th = (a * gb - b * ga) / (gb - ga);
    if (!(th > a && th < b)) th = 0.5 * (a + b);
    gc = pf_find(f, P, th, k);
    if (gc <= 0.0) {
      b = th; gb = gc;
      if (side == -1) ga *= 0.5;
      side = -1;
    } else {
      a = th; ga = gc;
      if (side == 1) gb *= 0.5;
      side = 1;
    }
  }
  return b;
}

/* error scales of x, v, z, W, E_f at the amplitude A (as StateIO._scales; E_f only if dense) */
static void pf_fscale(pf_fctx* f, double* sc, const double* Y, double A, double eps) {
  int i;
  sc[0] = fmax(fmax(A, 0.5 * A * A), fmin(fabs(Y[0]), 1.0)) * eps;
  sc[1] = A * eps;
  for (i = 2; i < PF_NY; ++i) sc[i] = fmin(A, 1.0) * eps;
  sc[PF_IW] = sc[PF_IE] = A * A * eps;
#if PF_NC
  for (i = 0; i < PF_NC; ++i) sc[PF_IC + i] = f->xs[i] * eps; /* a controller force error of eps */
#else
  (void)f;
#endif
}

static double pf_fnorm(const double* sc, const double* e, int n_act, int dense) {
  double acc = 0.0;
  int i;
  for (i = 0; i < PF_NY; ++i) acc += (e[i] / sc[i]) * (e[i] / sc[i]);
#if PF_FORCED
  acc += (e[PF_IW] / sc[PF_IW]) * (e[PF_IW] / sc[PF_IW]);
#endif
  if (dense) acc += (e[PF_IE] / sc[PF_IE]) * (e[PF_IE] / sc[PF_IE]);
  for (i = PF_IC; i < PF_NF; ++i) acc += (e[i] / sc[i]) * (e[i] / sc[i]);
  return sqrt(acc / n_act);
}

/* the energy of the branch after a reversal or at a start: v^2/2 + potential - W */
static double pf_branch_energy(pf_fctx* f, const double* Y) {
  return 0.5 * Y[1] * Y[1] + pf_potential(&f->c, Y) - Y[PF_IW];
}

/* One run from st[] to n_max reversals, the time t_end or a failure (the codes above). Each
 * reversal writes rev[0..4][n] = (t, x, F after the model's reset, W, model events of its
 * half-cycle); each requested time td[j] (increasing, j < nd) writes out[0..3][j] = (x, v, F, E_f).
 * cnt[0] reversals written, cnt[1] samples written, cnt[2] accepted steps (added to). */
static int pf_forced_run(const double* q, const double* th, const double* brk, long nbrk, const double* pcs,
                         const double* cfg, double* st, double t_end, long n_max, double* rev, const double* td,
                         long nd, double* out, long* cnt, const double* fbp, const double* thr, const double* pcr,
                         int stiff_ok, const double* line) {
  pf_fctx f;
  pf_step P;
  double Y[PF_NF], Y0[PF_NF], Ys[PF_NF], f0[PF_NF], e[PF_NF], U[7][PF_NF], g0[PF_NEA], g1[PF_NEA], sc[PF_NF];
  double cst[7];
  const double eps = cfg[0], eps_ev = cfg[1], fs = cfg[5];
  const int dense = cfg[6] > 0.5, linear = cfg[7] > 0.5, ecorr = cfg[8] > 0.5;
  const int n_act = PF_NY + PF_FORCED + dense + PF_NC;
  double t = st[0], ne = st[4], Amax = st[8], h = st[9], Eb = st[11], t_last = st[12], t_prev = st[13];
  double err, err_prev = 1.0, fac, F0, F_end, Fmax = 0.0, vs = 0.0;
  long n = cnt[0], jd = cnt[1], *steps = cnt + 2, branch_steps = 0, stiff = 0, nonstiff = 0;
  double y6[PF_NF];
  int i, j, rejected = 0, fsal = 0, nonfinite = 0, rest = st[5] > 0.5, leaving = 0, code = PF_F_T_END;
  memset(&f, 0, sizeof f);
  memset(&P, 0, sizeof P);
  (void)vs;
#if PF_NC
  f.An = fbp;
  f.Bn = fbp + PF_NC * PF_NC;
  f.Cn = f.Bn + PF_NC;
  f.Dn = f.Cn[PF_NC];
  f.umax = f.Cn[PF_NC + 1];
  f.kaw = f.Cn + PF_NC + 2;
  f.xs = f.kaw + PF_NC;
  f.thr = thr;
  f.pcr = pcr;
  f.invx = cfg[9];
  f.sat = st[PF_FHEAD + PF_NZ + PF_NM + PF_NC];
  for (i = 0; i < PF_NC; ++i) Y[PF_IC + i] = st[PF_FHEAD + PF_NZ + PF_NM + i];
#else
  (void)fbp; (void)thr; (void)pcr;
#endif
  f.rest = rest;
  f.line = line;
  f.c.q = q;
  f.c.snap = cfg[2];
  f.c.s = st[3];
  f.th = th;
  f.brk = brk;
  f.pcs = pcs;
  f.nbrk = nbrk;
  f.kb = (long)st[10];
  f.tunit = cfg[3];
  f.invFc = cfg[4];
  Y[0] = st[1];
  Y[1] = st[2];
  for (i = 0; i < PF_NZ; ++i) Y[2 + i] = st[PF_FHEAD + i];
  for (i = 0; i < PF_NM; ++i) f.c.m[i] = st[PF_FHEAD + PF_NZ + i];
  Y[PF_IW] = st[6];
  Y[PF_IE] = st[7];
  for (j = 0; j < 7; ++j) { /* the stage times c_j: the row sums of A (c_6 = 1) */
    double acc = 0.0;
    int l;
    for (l = 0; l < 6; ++l) acc += pf_A[j][l];
    cst[j] = acc;
  }
  while (f.kb < nbrk && brk[f.kb] <= t) ++f.kb;
#if PF_VSCALE
  pf_args(&f.c, Y); /* the model's velocity scale from its numbers q */
  f.c.res[0] = &vs;
  pf_vscale(f.c.arg, f.c.res, f.c.iw, f.c.w, 0);
#endif
  F0 = pf_ff(&f, t, Y, f0);
  fsal = 1;
  if (!(h > 0.0)) { /* the first step (Hairer, Norsett & Wanner II.4, as driver.c) */
    double A = fmax(fmax(hypot(Y[1], F0), fs), 1e-150), d0, d1, d2, h0, h1, Y1[PF_NF], f1[PF_NF], dd[PF_NF];
    double dur = 2.0 * M_PI / fmax(1.0, fabs(Y[1]));
    pf_fscale(&f, sc, Y, A, eps);
    d0 = pf_fnorm(sc, Y, n_act, dense);
    d1 = pf_fnorm(sc, f0, n_act, dense);
    h0 = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 * dur : 0.01 * d0 / d1;
    for (i = 0; i < PF_NF; ++i) Y1[i] = Y[i] + h0 * f0[i];
    pf_ff(&f, t + h0, Y1, f1);
    for (i = 0; i < PF_NF; ++i) dd[i] = (f1[i] - f0[i]) / h0;
    d2 = pf_fnorm(sc, dd, n_act, dense);
    h1 = fmax(d1, d2) <= 1e-15 ? fmax(1e-6 * dur, 1e-3 * h0) : pow(0.01 / fmax(d1, d2), 0.2);
    h = fmin(fmin(100.0 * h0, h1), dur);
  }
  if (!PF_FORCED) Fmax = fabs(F0);
  pf_g(&f.c, Y, g0);
  while (1) {
    double t_lim = t_end, hs, A, a0;
    int k_ev = -2, clipped = 0;
    double th_ev = 2.0, sv, th_min = 2.0;
    while (jd < nd && td[jd] <= t) { /* samples at the current time */
      pf_put(out, nd, jd, Y, Y[1], F0);
      ++jd;
    }
    if (n >= n_max) { code = PF_F_REVERSALS; break; }
    if (!(t < t_end)) { code = PF_F_T_END; break; }
    if (f.kb < nbrk && brk[f.kb] < t_lim) t_lim = brk[f.kb];
    A = hypot(Y[1], F0);
    if (PF_FORCED) {
      Amax = fmax(Amax, A);
      A = fmax(fmax(A, fs), 0.1 * Amax);
    }
    A = fmax(A, 1e-150);
#if PF_NC
    /* a resting mass whose net force is above the threshold at the start of a step (the
     * reference or the input jumped at a break, or the run starts so): it leaves at once */
    if (rest && !leaving && fabs(pf_utot(&f, t, Y) - F0) > PF_EPS_REST * eps_ev * A) leaving = 1;
#endif
    if (rest && (!PF_NC || leaving)) { /* at rest: the state is frozen until |u - F| exceeds the threshold
                                         * (with a controller: the exit was located on its steps) */
      double thr = PF_EPS_REST * eps_ev * A, t1, a1, ta, tb, ga, gb;
      int it, side = 0;
      a0 = pf_utot(&f, t, Y) - F0;
      if (!leaving && fabs(a0) <= thr) {
        t1 = linear ? t_lim : fmin(t_lim, t + fmin(fmax(h, 1e-6), 2.0 * M_PI / 16.0));
        a1 = pf_u(&f, t1) - F0;
        if (fabs(a1) <= thr) { /* rest through t1 */
          while (jd < nd && td[jd] <= t1) {
            pf_put(out, nd, jd, Y, 0.0, F0);
            ++jd;
          }
          t = t1;
          if (f.kb < nbrk && t >= brk[f.kb]) ++f.kb;
          continue;
        }
        /* the exit in (t, t1]: regula falsi (Illinois) on thr - |u - F| */
        ta = t; tb = t1; ga = thr - fabs(a0); gb = thr - fabs(a1);
        for (it = 0; it < 200 && tb - ta > 1e-15 * fmax(fabs(tb), 1e-300); ++it) {
          double tc = (ta * gb - tb * ga) / (gb - ga), gc;
          if (!(tc > ta && tc < tb)) tc = 0.5 * (ta + tb);
          gc = thr - fabs(pf_u(&f, tc) - F0);
          if (gc <= 0.0) { tb = tc; gb = gc; if (side == -1) ga *= 0.5; side = -1; }
          else { ta = tc; ga = gc; if (side == 1) gb *= 0.5; side = 1; }
        }
        while (jd < nd && td[jd] <= tb) {
          pf_put(out, nd, jd, Y, 0.0, F0);
          ++jd;
        }
        t = tb;
        a0 = pf_u(&f, t) - F0;
      }
      rest = f.rest = leaving = 0;
      if ((a0 > 0 ? 1.0 : -1.0) != f.c.s) { /* leaves backwards: a reversal at this instant */
        double zr[PF_NZ + PF_NMA + 1], *zn = zr, *mn = zr + PF_NZ, Fr, s_old = f.c.s;
        pf_args(&f.c, Y);
        f.c.arg[4] = &f.c.snap;
        f.c.res[0] = zn; f.c.res[1] = mn; f.c.res[2] = &Fr;
        pf_reverse(f.c.arg, f.c.res, f.c.iw, f.c.w, 0);
        f.c.s = -s_old;
        rev[n] = t; rev[n_max + n] = Y[0]; rev[2 * n_max + n] = F0; rev[3 * n_max + n] = Y[PF_IW];
        rev[4 * n_max + n] = ne;
        ++n;
        (void)Fr;
        for (i = 0; i < PF_NZ; ++i) Y[2 + i] = zn[i];
        for (i = 0; i < PF_NM; ++i) f.c.m[i] = mn[i];
        Y[PF_IW] = 0.0;
        ne = 0.0;
        t_prev = t_last; t_last = t; branch_steps = 0;
        Eb = pf_branch_energy(&f, Y);
      }
      Y[1] = 0.0;
      F0 = pf_ff(&f, t, Y, f0);
      fsal = 1;
      pf_g(&f.c, Y, g0);
      continue;
    }
    if (!fsal) { F0 = pf_ff(&f, t, Y, f0); fsal = 1; }
#if PF_VSCALE
    h = fmin(h, pf_curve_bound(vs, Y[1], f0[1])); /* a narrow Stribeck curve: driver.c */
#endif
    if (t + h >= t_lim) { hs = h; h = t_lim - t; clipped = 1; }
    else hs = h;
    if (!(h > 1e-15 * fmax(fabs(t), 1e-300))) {
      if (clipped && t_lim < t_end) { /* a break within round-off: the next piece */
        t = t_lim; ++f.kb; fsal = 0; h = hs;
        F0 = pf_ff(&f, t, Y, f0); fsal = 1;
        continue;
      }
      if (clipped) { /* the end within round-off (a break just before it): the run is there */
        t = t_lim;
        h = hs;
        continue;
      }
      code = nonfinite ? PF_F_NONFINITE : PF_F_STEP_UNDERFLOW;
      break;
    }
    if (!fsal) { F0 = pf_ff(&f, t, Y, f0); fsal = 1; }
    pf_fscale(&f, sc, Y, A, eps);
    for (i = 0; i < PF_NF; ++i) { Y0[i] = Y[i]; U[0][i] = h * f0[i]; }
    for (j = 1; j < 7; ++j) {
      int l;
      for (i = 0; i < PF_NF; ++i) {
        double acc = Y0[i];
        for (l = 0; l < j; ++l) acc += pf_A[j][l] * U[l][i];
        Ys[i] = acc;
      }
      if (j == 5) memcpy(y6, Ys, sizeof y6);
      pf_ff(&f, t + cst[j] * h, Ys, U[j]);
      for (i = 0; i < PF_NF; ++i) U[j][i] *= h;
    }
    for (i = 0; i < PF_NF; ++i) {
      double acc = 0.0;
      for (j = 0; j < 7; ++j) acc += pf_E[j] * U[j][i];
      e[i] = acc;
    }
    err = pf_fnorm(sc, e, n_act, dense);
    if (!(err <= 1.0)) {
      nonfinite = !isfinite(err);
      fac = nonfinite ? 0.25 : fmax(0.2, 0.9 * pow(err, -0.2));
      h *= fac;
      if (clipped && h > hs) h = hs;
      rejected = 1;
      continue;
    }
    F_end = f.F_last; /* the last stage is the step's end */
    ++*steps;
    ++branch_steps;
    nonfinite = 0;
    if (stiff_ok) { /* 15 stiff steps (no 6 non-stiff ones between) long after the last reversal: driver.c */
      double num = 0.0, den = 0.0;
      for (i = 0; i < PF_NY; ++i) {
        double a = (U[6][i] - U[5][i]) / sc[i], b = (Ys[i] - y6[i]) / sc[i];
        num += a * a;
        den += b * b;
      }
      if (den > 0.0 && num > 3.25 * 3.25 * den) {
        nonstiff = 0;
        if (++stiff >= 15 && branch_steps > PF_STIFF_STEPS) { code = PF_F_STIFF; break; }
      } else if (++nonstiff >= 6) stiff = 0;
    }
    P.U = (const double (*)[PF_NF])U;
    P.y0 = Y0;
    P.off = PF_FORCED ? PF_EPS_START * A : 0.0;
    P.t0 = t;
    P.h = h;
    P.F = F0;
    P.thr = PF_EPS_REST * eps_ev * A;
    /* events: the zero of s v (at the step's end, or before its least speed), the model's */
    sv = f.c.s * Ys[1] + P.off;
    if (sv <= 0.0) { k_ev = -1; th_ev = pf_flocate(&f, &P, -1, 0.0, 1.0, f.c.s * Y0[1] + P.off, sv); }
    else if (PF_FORCED && f.c.s * U[0][1] < 0.0 && f.c.s * U[6][1] > 0.0) { /* a least speed inside */
      double da = pf_find(&f, &P, 0.0, -3), db = pf_find(&f, &P, 1.0, -3);
      if (da > 0.0 && db <= 0.0) {
        th_min = pf_flocate(&f, &P, -3, 0.0, 1.0, da, db);
        double gm = pf_find(&f, &P, th_min, -1);
        if (gm <= 0.0) { k_ev = -1; th_ev = pf_flocate(&f, &P, -1, 0.0, th_min, f.c.s * Y0[1] + P.off, gm); }
      }
    }
#if PF_NE > 0
    pf_g(&f.c, Ys, g1);
    for (i = 0; i < PF_NE; ++i) {
      if (g0[i] > 0.0 && g1[i] <= 0.0) {
        double th1 = pf_flocate(&f, &P, i, 0.0, 1.0, g0[i], g1[i]);
        if (th1 < th_ev) { th_ev = th1; k_ev = i; }
      }
    }
#endif
#if PF_NC
    { /* the controller's events: the end of a rest, the clip's switches */
      int k;
      for (k = -4; k >= -6; --k) {
        double ga, gb, th1;
        if ((k == -4 && !rest) || (k < -4 && !(f.umax < 1e300))) continue;
        ga = pf_find(&f, &P, 0.0, k);
        gb = pf_find(&f, &P, 1.0, k);
        if (ga > 0.0 && gb <= 0.0) {
          th1 = pf_flocate(&f, &P, k, 0.0, 1.0, ga, gb);
          if (th1 < th_ev) { th_ev = th1; k_ev = k; }
        }
      }
    }
#endif
    { /* samples inside the step (up to its event) */
      double t_stop = k_ev == -2 ? (clipped ? t_lim : t + h) : t + th_ev * h;
      while (jd < nd && td[jd] <= t_stop) {
        double y[PF_NF];
        pf_fdense(P.U, Y0, (td[jd] - t) / h, y);
        pf_put(out, nd, jd, y, y[1], pf_F(&f.c, y));
        ++jd;
      }
    }
    if (k_ev == -1) { /* the zero of s v: a reversal, a touch or a rest */
      double ac, Fe, dY[PF_NF], thr = PF_EPS_TOUCH * eps_ev * A;
      pf_fdense(P.U, Y0, th_ev, Y);
      t += th_ev * h;
      Fe = pf_ff(&f, t, Y, dY);
      ac = f.c.s * dY[1];
      if (PF_FORCED && ac > thr) { /* a touch: the speed keeps its sign */
        Y[1] = 0.0;
      } else if (PF_FORCED && ac >= -thr) { /* the net force vanishes: the mass rests */
        Y[1] = 0.0;
        rest = f.rest = 1;
      } else { /* a reversal: record it, start the branch of direction -s */
        double zr[PF_NZ + PF_NMA + 1], *zn = zr, *mn = zr + PF_NZ, Fr;
        pf_args(&f.c, Y);
        f.c.arg[4] = &f.c.snap;
        f.c.res[0] = zn; f.c.res[1] = mn; f.c.res[2] = &Fr;
        pf_reverse(f.c.arg, f.c.res, f.c.iw, f.c.w, 0);
        if (!PF_FORCED && !(fabs(Fr) > PF_NOISE * eps * Fmax)) { /* creep to rest at the error level */
          if (isfinite(t_end)) { t = t_end; Y[1] = 0.0; code = PF_F_T_END; }
          else code = PF_F_DIED_OUT;
          while (jd < nd && td[jd] <= t) {
            pf_put(out, nd, jd, Y, 0.0, Fe);
            ++jd;
          }
          break;
        }
        rev[n] = t; rev[n_max + n] = Y[0]; rev[2 * n_max + n] = Fr; rev[3 * n_max + n] = Y[PF_IW];
        rev[4 * n_max + n] = ne;
        ++n;
        for (i = 0; i < PF_NZ; ++i) Y[2 + i] = zn[i];
        for (i = 0; i < PF_NM; ++i) f.c.m[i] = mn[i];
        Y[1] = 0.0;
        Y[PF_IW] = 0.0;
        f.c.s = -f.c.s;
        ne = 0.0;
        t_prev = t_last; t_last = t; branch_steps = 0;
        Eb = pf_branch_energy(&f, Y);
        Fmax = 0.0;
      }
      (void)Fe;
      F0 = pf_ff(&f, t, Y, f0);
      if (!PF_FORCED) Fmax = fmax(Fmax, fabs(F0));
      fsal = 1;
      pf_g(&f.c, Y, g0);
      h = hs;
      continue;
    }
    if (k_ev >= 0) { /* a model event: its transition; the speed from the branch's energy */
      double zn[PF_NZ + 1], mn[PF_NMA], changed = 0.0;
      pf_fdense(P.U, Y0, th_ev, Y);
      t += th_ev * h;
      f.c.k = (double)k_ev;
      pf_args(&f.c, Y);
      f.c.arg[4] = &f.c.k;
      f.c.res[0] = zn;
      f.c.res[1] = mn;
      pf_event(f.c.arg, f.c.res, f.c.iw, f.c.w, 0);
      for (i = 0; i < PF_NZ; ++i) Y[2 + i] = zn[i];
      if (PF_POT && ecorr) {
        double kinetic = Eb + Y[PF_IW] - pf_potential(&f.c, Y); /* potential on the new z, flags before */
        Y[1] = f.c.s * sqrt(fmax(2.0 * kinetic, 0.0));
      }
      for (i = 0; i < PF_NM; ++i) {
        changed += fabs(mn[i] - f.c.m[i]) > 0.5 ? 1.0 : 0.0;
        f.c.m[i] = mn[i];
      }
      ne += fmax(changed, 1.0);
      F0 = pf_ff(&f, t, Y, f0);
      fsal = 1;
      pf_g(&f.c, Y, g0);
      h = hs;
      continue;
    }
#if PF_NC
    if (k_ev <= -4) { /* the end of a rest (left at the top of the loop) or a switch of the clip */
      pf_fdense(P.U, Y0, th_ev, Y);
      t += th_ev * h;
      if (k_ev == -4) leaving = 1;
      else f.sat = f.sat != 0.0 ? 0.0 : (k_ev == -5 ? 1.0 : -1.0);
      F0 = pf_ff(&f, t, Y, f0);
      fsal = 1;
      pf_g(&f.c, Y, g0);
      h = hs;
      continue;
    }
#endif
    /* no event: take the step, choose the next */
    for (i = 0; i < PF_NF; ++i) { Y[i] = Ys[i]; f0[i] = U[6][i] / h; }
    F0 = F_end;
    if (!PF_FORCED) Fmax = fmax(Fmax, fabs(F0));
    for (i = 0; i < PF_NE; ++i) g0[i] = g1[i];
    err = fmax(err, 1e-10);
    fac = fmin(6.0, fmax(0.2, 0.9 * pow(err, -0.14) * pow(err_prev, 0.08)));
    if (rejected) fac = fmin(fac, 1.0);
    rejected = 0;
    err_prev = fmax(err, 1e-4);
    if (clipped) {
      t = t_lim;
      h = fmax(h * fac, hs);
      if (f.kb < nbrk && t >= brk[f.kb]) { /* a break: the next piece, the right-hand side anew (if the run goes on) */
        ++f.kb;
        if (t < t_end) F0 = pf_ff(&f, t, Y, f0);
      }
    } else {
      t += h;
      h *= fac;
    }
  }
  st[0] = t;
  st[1] = Y[0];
  st[2] = Y[1];
  st[3] = f.c.s;
  st[4] = ne;
  st[5] = rest;
  st[6] = Y[PF_IW];
  st[7] = Y[PF_IE];
  st[8] = Amax;
  st[9] = h;
  st[10] = (double)f.kb;
  st[11] = Eb;
  st[12] = t_last;
  st[13] = t_prev;
  for (i = 0; i < PF_NZ; ++i) st[PF_FHEAD + i] = Y[2 + i];
  for (i = 0; i < PF_NM; ++i) st[PF_FHEAD + PF_NZ + i] = f.c.m[i];
#if PF_NC
  for (i = 0; i < PF_NC; ++i) st[PF_FHEAD + PF_NZ + PF_NM + i] = Y[PF_IC + i];
  st[PF_FHEAD + PF_NZ + PF_NM + PF_NC] = f.sat;
#endif
  cnt[0] = n;
  cnt[1] = jd;
  return code;
}

int pf_forced(const double* q, const double* th, const double* brk, long nbrk, const double* pcs,
              const double* cfg, double* st, double t_end, long n_max, double* rev, const double* td, long nd,
              double* out, long* cnt) {
  return pf_forced_run(q, th, brk, nbrk, pcs, cfg, st, t_end, n_max, rev, td, nd, out, cnt, 0, 0, 0, 0, 0);
}

/* pf_forced that stops with PF_F_STIFF on a stiff stretch (the caller continues on an implicit method) */
int pf_forced_stiff(const double* q, const double* th, const double* brk, long nbrk, const double* pcs,
                    const double* cfg, double* st, double t_end, long n_max, double* rev, const double* td, long nd,
                    double* out, long* cnt) {
  return pf_forced_run(q, th, brk, nbrk, pcs, cfg, st, t_end, n_max, rev, td, nd, out, cnt, 0, 0, 0, 1, 0);
}

#if PF_NC
/* pf_forced with the continuous controller fbp (pf_fctx) and the reference's numbers thr and
 * per-interval numbers pcr (rows as pcs); st[] holds the controller states and the clip's mode
 * after m, out[] the controller states after E_f, cfg[9] is 1 / the position unit [1/m] */
int pf_forced_fb(const double* q, const double* th, const double* brk, long nbrk, const double* pcs,
                 const double* cfg, double* st, double t_end, long n_max, double* rev, const double* td, long nd,
                 double* out, long* cnt, const double* fbp, const double* thr, const double* pcr) {
  return pf_forced_run(q, th, brk, nbrk, pcs, cfg, st, t_end, n_max, rev, td, nd, out, cnt, fbp, thr, pcr, 0, 0);
}
#endif
