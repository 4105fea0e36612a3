/* Plain-C reference of prefriction bench: the unforced Dahl oscillator (gamma >= 1), reversal to
 * reversal, with the adaptive Runge-Kutta 5(4) of CasADi 3.8's "erk" integrator: the same
 * 7-stage FSAL tableau, dense output, error norm (RMS of the scaled local errors) and PI step
 * control (safety 0.9, factors in [0.2, 6], first step 0.015 of a call) as the code CasADi
 * generates for prefriction.simulate's compact model, on the same states and scaling:
 *
 *   v' = -F,  L' = s v exp(-(gamma - 1) L),  F = s (1 - exp(-L))   (normalised units)
 *
 * the log-gap L = -ln(1 - s F) and the velocity v, errors relative to A eps (v) and
 * min(A, 1) eps (L) with A = hypot(v, F) at the start of each branch. A reversal is located by
 * Newton's method on the step's dense output of v (to 1e-15 of the step), where simulate uses
 * CasADi's event iteration on the same dense output. Positions follow from the branch distance
 * p(L) = (exp((gamma - 1) L) - 1) / (gamma - 1) (p = L for gamma = 1): x = x_b + s (p - p_b).
 *
 * Compiled at run time by prefriction.cli.bench.plain_c (gcc -O2 -shared -fPIC). */
#include <math.h>

static const double A[7][7] = {
  {0., 0., 0., 0., 0., 0., 0.},
  {2.2222222222222221e-01, 0., 0., 0., 0., 0., 0.},
  {9.2773437500000000e-02, 2.1972656250000000e-01, 0., 0., 0., 0., 0.},
  {7.4468624999999999e-01, -3.4916062499999998e+00, 3.5719200000000000e+00, 0., 0., 0., 0.},
  {2.6613681355177952e+00, -1.3023809523809524e+01, 1.1682017166138619e+01, -3.6719482546593879e-01, 0., 0., 0.},
  {2.8667876712328768e+00, -1.3844280821917808e+01, 1.2283823308650417e+01, -2.3202113342347097e-01,
   -7.4309024542014393e-02, 0., 0.},
  {9.5303030303030306e-02, 0., 4.6607057529349077e-01, 6.1575078671044026e-01, -4.9314170832427734e-01,
   3.1601731601731603e-01, 0.}};
/* the nodes c are not needed: the system is autonomous */
static const double E[7] = {9.0337155371128346e-04, 0., -3.1482216823608199e-03, 2.3533727668404270e-02,
                            -6.0004801270238307e-02, 5.0463353980116470e-02, -1.1747430249632892e-02};
/* dense output: y(t0 + theta h) = y0 + sum_j sum_q D[q][j] theta^(q+1) U_j (U_j = h f_j) */
static const double D[4][7] = {
  {1., 0., 0., 0., 0., 0., 0.},
  {-2.7845454545454547e+00, 0., 4.0198587119063580e+00, -4.1563178102954712e+00, 5.2132123451423604e+00,
   -3.7922077922077921e+00, 1.5000000000000000e+00},
  {2.9503030303030302e+00, 0., -6.1754351226387527e+00, 1.0775638767432705e+01, -1.2398991523581831e+01,
   8.8484848484848477e+00, -4.},
  {-1.0704545454545455e+00, 0., 2.6216469860258855e+00, -6.0035701704267925e+00, 6.6926374701151925e+00,
   -4.7402597402597406e+00, 2.5000000000000000e+00}};

static double branch_distance(double L, double g1) {
  return g1 == 0.0 ? L : expm1(g1 * L) / g1;
}

/* dense output of component k at theta, and its derivative in theta */
static void dense(const double U[7][2], double y0, int k, double th, double* y, double* dy) {
  double w, dw;
  int j;
  *y = y0;
  *dy = 0.0;
  for (j = 0; j < 7; ++j) {
    w = th * (D[0][j] + th * (D[1][j] + th * (D[2][j] + th * D[3][j])));
    dw = D[0][j] + th * (2.0 * D[1][j] + th * (3.0 * D[2][j] + th * 4.0 * D[3][j]));
    *y += w * U[j][k];
    *dy += dw * U[j][k];
  }
}

/* The first n reversals from (v0, F0) at normalised time 0, position 0: times t, positions x and
 * forces F (normalised units). eps: the tolerance (simulate's eps = 0.1 rtol); gamma >= 1.
 * Returns the number of accepted steps, or -1 if a branch does not reverse within 1e6 steps. */
long dahl_reversals(double gamma, double v0, double F0, double eps, int n, double* t_out, double* x_out,
                    double* F_out) {
  const double g1 = gamma - 1.0;
  double s = v0 > 0 ? 1.0 : (v0 < 0 ? -1.0 : -copysign(1.0, F0));
  double v = v0, L = -log1p(-s * F0), t = 0.0, x = 0.0, last = 0.0, prev = 0.0;
  double U[7][2], f0[2], y0[2], y[2], ys[2], e[2];
  long steps = 0;
  int k, i, j, it;
  for (k = 0; k < n; ++k) {
    double F = -s * expm1(-L);
    double Amp = fmax(hypot(v, F), 1e-300);
    double sv = 1.0 / (Amp * eps), sL = 1.0 / (fmin(Amp, 1.0) * eps);
    double dur = k >= 2 ? 2.0 * (last - prev) : 2.0 * M_PI / fmax(1.0, fabs(v));
    double h = 0.015 * dur, err_prev = 1.0, pb = branch_distance(L, g1);
    int rejected = 0, found = 0;
    long branch_steps = 0;
    f0[0] = -F;
    f0[1] = s * v * exp(-g1 * L);
    while (!found) {
      double err, fac, th, f, df, vv, LL;
      if (++branch_steps > 1000000) return -1;
      y0[0] = v;
      y0[1] = L;
      U[0][0] = h * f0[0]; /* FSAL: f at the step's start, from the last stage of the step before */
      U[0][1] = h * f0[1];
      for (i = 1; i < 7; ++i) {
        ys[0] = y0[0];
        ys[1] = y0[1];
        for (j = 0; j < i; ++j) {
          ys[0] += A[i][j] * U[j][0];
          ys[1] += A[i][j] * U[j][1];
        }
        U[i][0] = -h * (-s * expm1(-ys[1]));
        U[i][1] = h * s * ys[0] * exp(-g1 * ys[1]); /* as the model: the exp also for gamma = 1 */
      }
      y[0] = ys[0];  /* FSAL: the last stage's argument is the new state */
      y[1] = ys[1];
      e[0] = e[1] = 0.0;
      for (j = 0; j < 7; ++j) {
        e[0] += E[j] * U[j][0];
        e[1] += E[j] * U[j][1];
      }
      err = sqrt(0.5 * ((e[0] * sv) * (e[0] * sv) + (e[1] * sL) * (e[1] * sL)));
      if (!(err <= 1.0)) {
        fac = isfinite(err) ? fmax(0.2, 0.9 * pow(err, -0.2)) : 0.25;
        h *= fac;
        rejected = 1;
        continue;
      }
      ++steps;
      if (s * y[0] < 0.0) { /* the reversal inside this step: Newton on the dense output of v */
        th = y0[0] / (y0[0] - y[0]);
        for (it = 0; it < 50; ++it) {
          dense(U, y0[0], 0, th, &f, &df);
          if (df == 0.0) break;
          double d = f / df;
          th -= d;
          if (th < 0.0) th = 0.0;
          if (th > 1.0) th = 1.0;
          if (fabs(d) <= 1e-15) break;
        }
        dense(U, y0[1], 1, th, &LL, &vv);
        t = t + th * h;
        L = LL;
        x = x + s * (branch_distance(L, g1) - pb);
        t_out[k] = t;
        x_out[k] = x;
        F_out[k] = -s * expm1(-L); /* the force at the reversal, on the old branch */
        /* the new branch: direction -s, the same force */
        s = -s;
        L = -log1p(-s * F_out[k]);
        v = 0.0;
        prev = last;
        last = t;
        found = 1;
        break;
      }
      v = y[0];
      L = y[1];
      t += h;
      f0[0] = U[6][0] / h;
      f0[1] = U[6][1] / h;
      err = fmax(err, 1e-10);
      fac = 0.9 * pow(err, -0.14) * pow(err_prev, 0.08);
      fac = fmin(6.0, fmax(0.2, fac));
      if (rejected) fac = fmin(fac, 1.0);
      rejected = 0;
      err_prev = fmax(err, 1e-4);
      h *= fac;
    }
  }
  return steps;
}
