/* friction_along in one C pass: the motion's intervals and the model's interval step over every
 * sample, writing into the caller's arrays (docs/along.md). The step is generated from
 * prefriction.along.step.counted_interval_function twice: pf_step with the reversal at the
 * interval's start, pf_plain without (the intervals that keep their direction, most of them).
 * Needs PF_NX (states and flags).
 *
 * The motion (docs/along.md#motion, as prefriction.along.motion.Motion): interval k, samples k to
 * k + 1, has the velocity (x[k+1] - x[k]) / (t[k+1] - t[k]) and the direction of its displacement;
 * an interval without displacement keeps the previous direction (the first moving interval's, s0,
 * before it); the velocity at a sample is the velocity of the interval that ends there (of the
 * first interval at the first sample) or the user's samples vu. */

/* the direction of the first interval with a displacement (+1 if none moves) */
double pf_first_direction(const double* x, long n) {
  long k;
  for (k = 0; k + 1 < n; ++k)
    if (x[k + 1] != x[k]) return x[k + 1] > x[k] ? 1.0 : -1.0;
  return 1.0;
}

/* 1 if t, x and vu (or NULL) are finite and t strictly increases, else 0 (the caller then finds
 * the first bad entry and names it) */
int pf_check(const double* t, const double* x, const double* vu, long n) {
  long k;
  int ok = 1;
  for (k = 0; k < n; ++k) ok &= isfinite(t[k]) && isfinite(x[k]) && (k == 0 || t[k] > t[k - 1]);
  if (vu)
    for (k = 0; k < n; ++k) ok &= isfinite(vu[k]) != 0;
  return ok;
}

/* n samples t, x (and vu, or NULL) from the state X[0..PF_NX) (row 0 of X, n x PF_NX), direction s0
 * before the first moving interval; F[0] and ev[0] are the caller's. Writes X, F, ev and the
 * velocity at every sample va [m/s]; the reversal samples into rv, their count returned. iv, it:
 * 1 / velocity and 1 / time unit; uF: the force unit. */
long pf_along(const double* t, const double* x, const double* vu, const double* q, long n, double s0, double iv,
              double it, double uF, double* X, double* F, long long* ev, double* va, long long* rv) {
  const casadi_real* arg[PF_SZ_ARG + 1];
  casadi_real* res[PF_SZ_RES + 1];
  casadi_int iw[PF_SZ_IW];
  casadi_real w[PF_SZ_W];
  double vn, dtn, ve, Fk, ek, s = s0, sp = s0, vi;
  long k, nr = 0;
  arg[1] = &vn; arg[2] = &dtn; arg[3] = &sp; arg[4] = &s; arg[5] = &ve; arg[6] = q;
  res[1] = &Fk; res[2] = &ek;
  for (k = 0; k + 1 < n; ++k) {
    double dt = t[k + 1] - t[k], dx = x[k + 1] - x[k];
    vi = dx / dt;
    sp = s;
    if (dx != 0.0) s = dx > 0.0 ? 1.0 : -1.0;
    if (k == 0) {
      sp = s;
      va[0] = vu ? vu[0] : vi;
    }
    va[k + 1] = vu ? vu[k + 1] : vi;
    vn = vi * iv;
    dtn = dt * it;
    ve = va[k + 1] * iv;
    arg[0] = X + k * PF_NX;
    res[0] = X + (k + 1) * PF_NX;
    if (s != sp) {
      rv[nr++] = k;
      pf_step(arg, res, iw, w, 0);
    } else {
      pf_plain(arg, res, iw, w, 0);
    }
    F[k + 1] = uF * Fk;
    ev[k + 1] = (long long)(ek + 0.5);
  }
  return nr;
}
