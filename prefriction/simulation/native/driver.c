/* The native driver of prefriction.simulate for unforced runs: the normalised oscillator
 *
 *   x' = v,  v' = -F(z, m, v, s),  z' = rate(z, m, v, s)                  (docs/simulator.md#native)
 *
 * from reversal to reversal with the adaptive Runge-Kutta 5(4) of CasADi's "erk" integrator (the
 * same 7-stage FSAL Dormand-Prince tableau, dense output, RMS error norm and PI step control),
 * every reversal (s v = 0) and model event (an indicator of pf_ind turning negative) located on
 * the step's dense output to 1e-15 of the step, and the model's transitions applied there.
 *
 * This file is appended to the model's generated code (model_code.py), which defines the sizes
 * PF_NZ, PF_NM, PF_NQ, PF_NE, PF_POT, PF_NORM_X, PF_RATE_INDEPENDENT, PF_NOISE (plant.EPS_DIED), the work sizes and the
 * Functions pf_rhs, pf_ind, pf_event, pf_reverse, pf_force and pf_pot. No static mutable data:
 * calls from several threads at once are safe (each has its own stack).
 *
 * Run state st[] (normalised units), read at the start of pf_run and written at its end:
 *   st[0] t, st[1] x, st[2] v, st[3] s, st[4] model events since the last reversal,
 *   st[5] time of the last reversal, st[6] of the one before (NaN if none), st[7] growth of the
 *   chunk length since the last reversal, st[8..8+PF_NZ) z, then PF_NM flags m.
 */
#include <math.h>
#include <string.h>

#define PF_NY (2 + PF_NZ)
#define PF_HEAD 8
#define PF_NMA (PF_NM > 0 ? PF_NM : 1)
#define PF_NEA (PF_NE > 0 ? PF_NE : 1)
#define PF_BRANCH_STEPS 1000000L /* steps without a reversal before a run is stopped */
#define PF_STIFF_STEPS 20000L    /* steps on a branch before a stiff one is handed to the implicit method */

enum { PF_REVERSALS = 0, PF_T_END = 1, PF_DIED_OUT = 2, PF_NONFINITE = 3, PF_TOO_MANY_STEPS = 4,
       PF_STEP_UNDERFLOW = 5, PF_STIFF = 6 };

static const double pf_A[7][6] = {
  {0., 0., 0., 0., 0., 0.},
  {2.2222222222222221e-01, 0., 0., 0., 0., 0.},
  {9.2773437500000000e-02, 2.1972656250000000e-01, 0., 0., 0., 0.},
  {7.4468624999999999e-01, -3.4916062499999998e+00, 3.5719200000000000e+00, 0., 0., 0.},
  {2.6613681355177952e+00, -1.3023809523809524e+01, 1.1682017166138619e+01, -3.6719482546593879e-01, 0., 0.},
  {2.8667876712328768e+00, -1.3844280821917808e+01, 1.2283823308650417e+01, -2.3202113342347097e-01,
   -7.4309024542014393e-02, 0.},
  {9.5303030303030306e-02, 0., 4.6607057529349077e-01, 6.1575078671044026e-01, -4.9314170832427734e-01,
   3.1601731601731603e-01}};
static const double pf_E[7] = {9.0337155371128346e-04, 0., -3.1482216823608199e-03, 2.3533727668404270e-02,
                               -6.0004801270238307e-02, 5.0463353980116470e-02, -1.1747430249632892e-02};
/* dense output: y(t0 + th h) = y0 + sum_j (sum_q D[q][j] th^(q+1)) U_j, U_j = h f_j */
static const double pf_D[4][7] = {
  {1., 0., 0., 0., 0., 0., 0.},
  {-2.7845454545454547e+00, 0., 4.0198587119063580e+00, -4.1563178102954712e+00, 5.2132123451423604e+00,
   -3.7922077922077921e+00, 1.5000000000000000e+00},
  {2.9503030303030302e+00, 0., -6.1754351226387527e+00, 1.0775638767432705e+01, -1.2398991523581831e+01,
   8.8484848484848477e+00, -4.},
  {-1.0704545454545455e+00, 0., 2.6216469860258855e+00, -6.0035701704267925e+00, 6.6926374701151925e+00,
   -4.7402597402597406e+00, 2.5000000000000000e+00}};

typedef struct {
  const double* q;
  double s, snap, k;
  double m[PF_NMA];
  const casadi_real* arg[PF_SZ_ARG + 6];
  casadi_real* res[PF_SZ_RES + 4];
  casadi_int iw[PF_SZ_IW];
  casadi_real w[PF_SZ_W];
} pf_ctx;

static void pf_args(pf_ctx* c, const double* y) {
  c->arg[0] = y;
  c->arg[1] = c->m;
  c->arg[2] = &c->s;
  c->arg[3] = c->q;
}

static void pf_f(pf_ctx* c, const double* y, double* dy) {
  pf_args(c, y);
  c->res[0] = dy;
  pf_rhs(c->arg, c->res, c->iw, c->w, 0);
}

static double pf_F(pf_ctx* c, const double* y) {
  double F;
  pf_args(c, y);
  c->res[0] = &F;
  pf_force(c->arg, c->res, c->iw, c->w, 0);
  return F;
}

static void pf_g(pf_ctx* c, const double* y, double* g) {
#if PF_NE > 0
  pf_args(c, y);
  c->res[0] = g;
  pf_ind(c->arg, c->res, c->iw, c->w, 0);
#else
  (void)c; (void)y; (void)g;
#endif
}

static double pf_potential(pf_ctx* c, const double* y) {
  double P = 0.0;
#if PF_POT
  pf_args(c, y);
  c->res[0] = &P;
  pf_pot(c->arg, c->res, c->iw, c->w, 0);
#else
  (void)c; (void)y;
#endif
  return P;
}

/* the state at th in [0, 1] of the step from y0 with the stage increments U */
static void pf_dense(const double U[7][PF_NY], const double* y0, double th, double* y) {
  int i, j;
  for (i = 0; i < PF_NY; ++i) y[i] = y0[i];
  for (j = 0; j < 7; ++j) {
    double wj = th * (pf_D[0][j] + th * (pf_D[1][j] + th * (pf_D[2][j] + th * pf_D[3][j])));
    if (wj == 0.0) continue;
    for (i = 0; i < PF_NY; ++i) y[i] += wj * U[j][i];
  }
}

/* indicator k of the step at th: k < 0 is the reversal (s v), else the model's indicator k */
static double pf_indicator(pf_ctx* c, const double U[7][PF_NY], const double* y0, double th, int k) {
  double y[PF_NY], g[PF_NEA];
  pf_dense(U, y0, th, y);
  if (k < 0) return c->s * y[1];
  pf_g(c, y, g);
  return g[k];
}

/* The first th in (0, 1] where indicator k is <= 0 (to 1e-15), from ga > 0 at 0 and gb <= 0 at 1:
 * regula falsi with the Illinois modification, bisection when a secant leaves the bracket. */
static double pf_locate(pf_ctx* c, const double U[7][PF_NY], const double* y0, int k, double ga, double gb) {
  double a = 0.0, b = 1.0, th, gc;
  int side = 0, it;
  for (it = 0; it < 200 && b - a > 1e-15; ++it) {
    th = (a * gb - b * ga) / (gb - ga);
    if (!(th > a && th < b)) th = 0.5 * (a + b);
    gc = pf_indicator(c, U, y0, th, k);
    if (gc <= 0.0) {
      b = th;
      gb = gc;
      if (side == -1) ga *= 0.5;
      side = -1;
    } else {
      a = th;
      ga = gc;
      if (side == 1) gb *= 0.5;
      side = 1;
    }
  }
  return b;
}

typedef struct {
  double sc[PF_NY]; /* error scale of each component (amplitude times eps) */
  double Eb;        /* v^2/2 + potential of the branch (speed at model events) */
  double Fmax;      /* the largest |F| on the branch so far (at the ends of its steps) */
  double chunk_end, grow;
} pf_scales;

static double pf_norm(const pf_scales* S, const double* e) {
  double acc = 0.0;
  int i;
  for (i = PF_NORM_X ? 0 : 1; i < PF_NY; ++i) acc += (e[i] / S->sc[i]) * (e[i] / S->sc[i]);
  return sqrt(acc / (PF_NY - (PF_NORM_X ? 0 : 1)));
}

/* error scales from the amplitude A = hypot(v, F) of the state y (as the compact CasADi model) */
static void pf_scale(pf_scales* S, const double* y, double F, double eps) {
  double A = fmax(hypot(y[1], F), 1e-300);
  int i;
  S->sc[0] = fmax(fmax(A, 0.5 * A * A), fmin(fabs(y[0]), 1.0)) * eps;
  S->sc[1] = A * eps;
  /* a state that carries the travel (models that track the position: Dahl's log-gap L, gamma >= 1,
   * grows like v^2/2 in deep gross sliding while F = 1 - exp(-L) has long saturated) is held to
   * its own size, as the position would be: against eps alone, the round-off of v in its
   * increments stopped the run at |v| ~ 1.5e7 */
  for (i = 2; i < PF_NY; ++i) S->sc[i] = (PF_NORM_X ? fmin(A, 1.0) : fmax(fmin(A, 1.0), fabs(y[i]))) * eps;
}

/* the scales and the branch energy at the state y */
static void pf_rescale(pf_ctx* c, pf_scales* S, const double* y, double eps) {
  pf_scale(S, y, pf_F(c, y), eps);
  S->Eb = 0.5 * y[1] * y[1] + pf_potential(c, y);
}

/* the first step of a branch: 0.015 of the expected branch (rate-independent models), else the
 * estimate of Hairer, Norsett & Wanner (II.4) from the right-hand side at the start */
static double pf_first_step(pf_ctx* c, const pf_scales* S, const double* y, const double* f0, double dur) {
  double y1[PF_NY], f1[PF_NY], d[PF_NY], d0, d1, d2, h0, h1;
  int i;
  if (PF_RATE_INDEPENDENT) return 0.015 * dur;
  d0 = pf_norm(S, y);
  d1 = pf_norm(S, f0);
  h0 = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 * dur : 0.01 * d0 / d1;
  for (i = 0; i < PF_NY; ++i) y1[i] = y[i] + h0 * f0[i];
  pf_f(c, y1, f1);
  for (i = 0; i < PF_NY; ++i) d[i] = (f1[i] - f0[i]) / h0;
  d2 = pf_norm(S, d);
  h1 = fmax(d1, d2) <= 1e-15 ? fmax(1e-6 * dur, 1e-3 * h0) : pow(0.01 / fmax(d1, d2), 0.2);
  return fmin(fmin(100.0 * h0, h1), dur);
}

#if PF_VSCALE
/* A step near a narrow curve of the force in the speed (Stribeck velocity vs): within PF_CURVE_K vs
 * of v = 0 the speed changes by at most PF_CURVE_C vs per step (at the rate a = v'), and a step
 * from outside ends at most PF_CURVE_C vs inside that band, so that stages sample the curve and
 * the error estimate sees it (docs/simulator.md#narrow-stribeck). */
#define PF_CURVE_K 3.0
#define PF_CURVE_C 0.5
static double pf_curve_bound(double vs, double v, double a) {
  return (fmax(fabs(v) - PF_CURVE_K * vs, 0.0) + PF_CURVE_C * vs) / fmax(fabs(a), 1e-300);
}
#endif

/* Stiffness test of Hairer & Wanner (dopri5, II.IV.2): the stages 6 and 7 are both at the step's
 * end, so h |lambda| ~ |h f7 - h f6| / |y7 - y6| (scaled norms); above 3.25 the step size is held
 * by the explicit method's stability, not by its accuracy. */
static int pf_stiff_step(const pf_scales* S, const double U[7][PF_NY], const double* y7, const double* y6) {
  double num = 0.0, den = 0.0, a, b;
  int i;
  for (i = 0; i < PF_NY; ++i) {
    a = (U[6][i] - U[5][i]) / S->sc[i];
    b = (y7[i] - y6[i]) / S->sc[i];
    num += a * a;
    den += b * b;
  }
  return den > 0.0 && num > 3.25 * 3.25 * den;
}

/* One run from the state st[] until n_max reversals, the time t_end or a failure (the codes
 * above). Each reversal writes its time, position, force (after the model's reset) and the model
 * events of the half-cycle it ends. eps: the run's tolerance; snap: the coincidence tolerance of
 * the model's reverse. *n_done: reversals written; *steps: accepted steps (added to). */
int pf_run(const double* q, double eps, double snap, double* st, double t_end, long n_max,
           double* t_out, double* x_out, double* F_out, double* ev_out, long* n_done, long* steps) {
  pf_ctx c;
  pf_scales S;
  double y[PF_NY], y0[PF_NY], ys[PF_NY], y6[PF_NY], f0[PF_NY], e[PF_NY], U[7][PF_NY], g0[PF_NEA], g1[PF_NEA];
  double t = st[0], ne = st[4], t_last = st[5], t_prev = st[6], h, err, err_prev = 1.0, fac, dur, vs = 0.0;
  long n = 0, branch_steps = 0, stiff = 0, nonstiff = 0;
  int i, j, rejected = 0, fsal = 0, nonfinite = 0, code = PF_T_END;
  memset(&c, 0, sizeof c);
  c.q = q;
  c.snap = snap;
  c.s = st[3];
  S.grow = st[7];
  y[0] = st[1];
  y[1] = st[2];
  for (i = 0; i < PF_NZ; ++i) y[2 + i] = st[PF_HEAD + i];
  for (i = 0; i < PF_NM; ++i) c.m[i] = st[PF_HEAD + PF_NZ + i];
#if PF_VSCALE
  pf_args(&c, y); /* the model's velocity scale from its numbers q */
  c.res[0] = &vs;
  pf_vscale(c.arg, c.res, c.iw, c.w, 0);
#else
  (void)vs;
#endif
#define PF_DURATION() ((isfinite(t_prev) ? 2.0 * (t_last - t_prev) : 2.0 * M_PI / fmax(1.0, fabs(y[1]))) * S.grow)
#define PF_BRANCH()                                \
  do {                                             \
    dur = PF_DURATION();                           \
    pf_rescale(&c, &S, y, eps);                    \
    S.chunk_end = t + dur;                         \
    pf_f(&c, y, f0);                               \
    S.Fmax = fabs(f0[1]);                          \
    fsal = 1;                                      \
    h = pf_first_step(&c, &S, y, f0, dur);         \
    pf_g(&c, y, g0);                               \
    err_prev = 1.0;                                \
    rejected = 0;                                  \
  } while (0)
  PF_BRANCH();
  while (1) {
    int k_ev = -2, last = 0;
    double th_ev = 2.0, sv;
    if (n >= n_max) { code = PF_REVERSALS; break; }
    if (!(t < t_end)) { code = PF_T_END; break; }
    if (S.sc[1] < 1e-250 * eps) { /* the motion has decayed below the double range: at rest */
      if (isfinite(t_end)) { t = t_end; y[1] = 0.0; code = PF_T_END; }
      else code = PF_DIED_OUT;
      break;
    }
    if (++branch_steps > PF_BRANCH_STEPS) { code = PF_TOO_MANY_STEPS; break; }
#if PF_VSCALE
    if (!fsal) { pf_f(&c, y, f0); fsal = 1; }
    h = fmin(h, pf_curve_bound(vs, y[1], f0[1]));
#endif
    if (t + h >= t_end) { h = t_end - t; last = 1; }
    if (!(h > 1e-15 * fmax(fabs(t), 1e-300))) { code = nonfinite ? PF_NONFINITE : PF_STEP_UNDERFLOW; break; }
    if (!fsal) { pf_f(&c, y, f0); fsal = 1; }
    for (i = 0; i < PF_NY; ++i) { y0[i] = y[i]; U[0][i] = h * f0[i]; }
    for (j = 1; j < 7; ++j) {
      int l;
      for (i = 0; i < PF_NY; ++i) {
        double acc = y0[i];
        for (l = 0; l < j; ++l) acc += pf_A[j][l] * U[l][i];
        ys[i] = acc;
      }
      if (j == 5) memcpy(y6, ys, sizeof ys);
      pf_f(&c, ys, U[j]);
      for (i = 0; i < PF_NY; ++i) U[j][i] *= h;
    }
    for (i = 0; i < PF_NY; ++i) {
      double acc = 0.0;
      for (j = 0; j < 7; ++j) acc += pf_E[j] * U[j][i];
      e[i] = acc;
    }
    err = pf_norm(&S, e);
    if (!(err <= 1.0)) {
      nonfinite = !isfinite(err); /* a step that overflowed (shrinks) or a NaN the model returns (stays) */
      fac = nonfinite ? 0.25 : fmax(0.2, 0.9 * pow(err, -0.2));
      h *= fac;
      rejected = 1;
      continue;
    }
    ++*steps;
    nonfinite = 0;
    if (pf_stiff_step(&S, U, ys, y6)) { /* 15 stiff steps (no 6 non-stiff ones between) on a long branch */
      nonstiff = 0;
      if (++stiff >= 15 && branch_steps > PF_STIFF_STEPS) { code = PF_STIFF; break; }
    } else if (++nonstiff >= 6) stiff = 0;
    /* events of the step: the reversal (s v < 0 at its end) and the model's indicators */
    sv = c.s * ys[1];
    if (sv < 0.0) { k_ev = -1; th_ev = pf_locate(&c, U, y0, -1, c.s * y0[1], sv); }
#if PF_NE > 0
    pf_g(&c, ys, g1);
    for (i = 0; i < PF_NE; ++i) {
      if (g0[i] > 0.0 && g1[i] <= 0.0) {
        double th = pf_locate(&c, U, y0, i, g0[i], g1[i]);
        if (th < th_ev) { th_ev = th; k_ev = i; }
      }
    }
#endif
    if (k_ev == -1) { /* a reversal: record it, start the branch of direction -s */
      double out[PF_NZ + PF_NMA + 1], *zn = out, *mn = out + PF_NZ, F;
      pf_dense(U, y0, th_ev, y);
      t += th_ev * h;
      pf_args(&c, y);
      c.arg[4] = &c.snap;
      c.res[0] = zn;
      c.res[1] = mn;
      c.res[2] = &F;
      pf_reverse(c.arg, c.res, c.iw, c.w, 0);
      if (!(fabs(F) > PF_NOISE * eps * S.Fmax)) { /* a reversal at the level of the integration error */
        if (isfinite(t_end)) { t = t_end; y[1] = 0.0; code = PF_T_END; } /* the mass has come to rest */
        else code = PF_DIED_OUT;
        break;
      }
      for (i = 0; i < PF_NZ; ++i) y[2 + i] = zn[i];
      for (i = 0; i < PF_NM; ++i) c.m[i] = mn[i];
      y[1] = 0.0;
      c.s = -c.s;
      t_out[n] = t;
      x_out[n] = y[0];
      F_out[n] = F;
      ev_out[n] = ne;
      ++n;
      ne = 0.0;
      t_prev = t_last;
      t_last = t;
      S.grow = 1.0;
      branch_steps = 0;
      PF_BRANCH();
      continue;
    }
    if (k_ev >= 0) { /* a model event: its transition; the speed from the branch's energy */
      double zn[PF_NZ + 1], mn[PF_NMA], changed = 0.0;
      pf_dense(U, y0, th_ev, y);
      t += th_ev * h;
      c.k = (double)k_ev;
      pf_args(&c, y);
      c.arg[4] = &c.k;
      c.res[0] = zn;
      c.res[1] = mn;
      pf_event(c.arg, c.res, c.iw, c.w, 0);
      for (i = 0; i < PF_NZ; ++i) y[2 + i] = zn[i];
      if (PF_POT) {
        double kinetic = S.Eb - pf_potential(&c, y); /* potential on the new z, flags before */
        y[1] = c.s * sqrt(fmax(2.0 * kinetic, 0.0));
      }
      for (i = 0; i < PF_NM; ++i) {
        changed += fabs(mn[i] - c.m[i]) > 0.5 ? 1.0 : 0.0;
        c.m[i] = mn[i];
      }
      ne += fmax(changed, 1.0);
      fsal = 0;
      pf_g(&c, y, g0);
      continue;
    }
    /* no event: take the step, choose the next */
    for (i = 0; i < PF_NY; ++i) { y[i] = ys[i]; f0[i] = U[6][i] / h; }
    S.Fmax = fmax(S.Fmax, fabs(f0[1])); /* v' = -F */
    /* rate-dependent models decay within a branch (damping): their errors are held to the
     * amplitude at the start of each step, so that a reversal force far below the branch's
     * starting amplitude keeps its relative accuracy */
    if (!PF_RATE_INDEPENDENT) pf_scale(&S, y, -f0[1], eps);
    for (i = 0; i < PF_NE; ++i) g0[i] = g1[i];
    t = last ? t_end : t + h;
    err = fmax(err, 1e-10);
    fac = fmin(6.0, fmax(0.2, 0.9 * pow(err, -0.14) * pow(err_prev, 0.08)));
    if (rejected) fac = fmin(fac, 1.0);
    rejected = 0;
    err_prev = fmax(err, 1e-4);
    h *= fac;
    if (t >= S.chunk_end) { /* no reversal within the expected branch: new scales, longer chunks */
      S.grow *= 4.0;
      dur = PF_DURATION();
      pf_rescale(&c, &S, y, eps);
      S.chunk_end = t + dur;
    }
  }
#undef PF_BRANCH
#undef PF_DURATION
  st[0] = t;
  st[1] = y[0];
  st[2] = y[1];
  st[3] = c.s;
  st[4] = ne;
  st[5] = t_last;
  st[6] = t_prev;
  st[7] = S.grow;
  for (i = 0; i < PF_NZ; ++i) st[PF_HEAD + i] = y[2 + i];
  for (i = 0; i < PF_NM; ++i) st[PF_HEAD + PF_NZ + i] = c.m[i];
  *n_done = n;
  return code;
}
