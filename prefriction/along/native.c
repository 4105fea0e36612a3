/* friction_along in one C pass: the motion's intervals and the model's interval step over every
 * sample, writing into the caller's arrays (docs/along.md). The step is generated from
 * prefriction.along.step.counted_interval_function twice (prefriction.along.native): pf_step_in
 * with the reversal at the interval's start, pf_plain_in without (the intervals that keep their
 * direction, most of them). Needs PF_NX (states and flags) and PF_NQ (run-time numbers).
 *
 * The motion (docs/along.md#motion, as prefriction.along.motion.Motion): interval k, samples k to
 * k + 1, has the velocity (x[k+1] - x[k]) / (t[k+1] - t[k]) and the direction of its displacement;
 * an interval without displacement keeps the previous direction (the first moving interval's, s0,
 * before it); the velocity at a sample, for the rate-dependent part of the force, is the velocity
 * of the interval that ends there (of the first interval at the first sample) or the user's
 * samples vu. */

/* the direction of the first interval with a displacement (+1 if none moves) */
double pf_first_direction(const double* x, long n) {
  long k;
  for (k = 0; k + 1 < n; ++k)
    if (x[k + 1] != x[k]) return x[k + 1] > x[k] ? 1.0 : -1.0;
  return 1.0;
}

/* 1 if t, x and vu (or NULL) are finite and t strictly increases, else 0 (the caller then finds
 * the first bad entry and names it); t and x copied into tc and xc on the way (the result's own) */
int pf_check(const double* t, const double* x, const double* vu, long n, double* tc, double* xc) {
  long k;
  int ok = 1;
  for (k = 0; k < n; ++k) {
    double tk = t[k], xk = x[k];
    ok &= isfinite(tk) && isfinite(xk) && (k == 0 || tk > t[k - 1]);
    tc[k] = tk;
    xc[k] = xk;
  }
  if (vu)
    for (k = 0; k < n; ++k) ok &= isfinite(vu[k]) != 0;
  return ok;
}

/* n samples t, x (and vu, or NULL) from the state X0[0..PF_NX), direction s0 before the first
 * moving interval. Writes the force at every sample after the first into F (F[0] is the caller's),
 * the reversal samples into rv (their count returned), the number of model events along the motion
 * into out[0] and into out[1] a sum that is NaN if a force is not finite (0 otherwise). The states
 * X (n x PF_NX, row 0 the caller's) and the event counts ev (ev[0] the caller's) are written only
 * if given (not NULL); without X the state is kept in two local rows and the pass writes only F.
 * iv, it, ix: 1 / velocity, time and length unit; uF: the force unit. The step takes the normalised
 * displacement dxn and duration dtn of the interval (its velocity is dxn / dtn, symbolically: a
 * rate-independent step sees the displacement alone, with no division). */
long pf_along(const double* t, const double* x, const double* vu, const double* q, long n, double s0, double iv,
              double it, double ix, double uF, const double* X0, double* X, double* F, long long* ev,
              long long* rv, double* out) {
  double xs[PF_NX], xn[PF_NX], qs[PF_NQ + 1]; /* local copies: held in registers across the samples */
  double dxn, dtn, ve, Fk, ek, s = s0, sp = s0, vi, events = 0.0, nonfinite = 0.0;
  long k, nr = 0;
  PF_COPY_X(xs, X0);
  PF_COPY_Q(qs, q);
  for (k = 0; k + 1 < n; ++k) {
    double dt = t[k + 1] - t[k], dx = x[k + 1] - x[k];
    vi = dx / dt;
    sp = s;
    if (dx != 0.0) s = dx > 0.0 ? 1.0 : -1.0;
    if (k == 0) sp = s;
    dxn = dx * ix;
    dtn = dt * it;
    ve = (vu ? vu[k + 1] : vi) * iv;
    if (s != sp) {
      rv[nr++] = k;
      pf_step_in(xs, dxn, dtn, sp, s, ve, qs, xn, &Fk, &ek);
    } else {
      pf_plain_in(xs, dxn, dtn, sp, s, ve, qs, xn, &Fk, &ek);
    }
    PF_COPY_X(xs, xn);
    if (X) PF_COPY_X(X + (k + 1) * PF_NX, xn);
    F[k + 1] = uF * Fk;
    nonfinite += Fk - Fk;
    events += ek;
    if (ev) ev[k + 1] = (long long)(ek + 0.5);
  }
  out[0] = events;
  out[1] = nonfinite;
  return nr;
}
