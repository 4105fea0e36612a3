/* friction_along in one C pass: the model's interval step (pf_step, generated from
 * prefriction.along.step.counted_interval_function) over every interval of the motion, reading
 * the motion's arrays (SI, converted to normalised units here) and writing the states, forces and
 * event counts into the caller's arrays (docs/along.md). Needs PF_NX (states and flags). */

/* n intervals from the state X[0..PF_NX) (row 0 of X, (n + 1) x PF_NX); F[0] and ev[0] are the
 * caller's. v, dt, s_prev, s: per interval; v_at: per sample (n + 1). iv, it: 1 / velocity and
 * 1 / time unit; uF: the force unit. */
void pf_along(const double* v, const double* dt, const double* s_prev, const double* s, const double* v_at,
              const double* q, long n, double iv, double it, double uF, double* X, double* F, long long* ev) {
  const casadi_real* arg[PF_SZ_ARG + 1];
  casadi_real* res[PF_SZ_RES + 1];
  casadi_int iw[PF_SZ_IW];
  casadi_real w[PF_SZ_W];
  double vn, dtn, ve, Fk, ek;
  long k;
  arg[1] = &vn; arg[2] = &dtn; arg[3] = 0; arg[4] = 0; arg[5] = &ve; arg[6] = q;
  res[1] = &Fk; res[2] = &ek;
  for (k = 0; k < n; ++k) {
    vn = v[k] * iv;
    dtn = dt[k] * it;
    ve = v_at[k + 1] * iv;
    arg[0] = X + k * PF_NX;
    arg[3] = s_prev + k;
    arg[4] = s + k;
    res[0] = X + (k + 1) * PF_NX;
    pf_step(arg, res, iw, w, 0);
    F[k + 1] = uF * Fk;
    ev[k + 1] = (long long)(ek + 0.5);
  }
}
