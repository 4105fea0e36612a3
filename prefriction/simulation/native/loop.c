/* The native sampled-data loop: the controller's law at each sample instant (the generated
 * pf_ctrl, loops/compiled_loop.control_law: measurement, quantisation, noise, delay, compensator,
 * force limit and anti-windup) and the plant over the period on the forced driver (forced.c), the
 * step size carried over from period to period (docs/controllers.md#compiled-loop). The force over
 * a period is the oscillator's own input (pf_input of its structure, generated as for a forced run:
 * its numbers th, break times brk and per-interval numbers pcs, the integration broken at every
 * break inside the period) plus the held line (t_l, a + u, b) of the sample's inputs, u the
 * controller's force.
 *
 * This file follows forced.c (compiled with PF_FORCED 1) and needs the loop layout's sizes and
 * indices (loops/native_loop.py): PF_LNS (loop state), PF_LNW (inputs per sample), PF_LNREC
 * (record), PF_LI_T0, PF_LI_T1, PF_LI_ACTIVE, PF_LI_TL, PF_LI_DA, PF_LI_DB (inputs), PF_LS_S
 * (index of s in the loop state; rest, W and Amax follow it), PF_LR_F, PF_LR_U, PF_LR_MOVED,
 * PF_LR_Y, PF_LR_COMP (record).
 */

#ifndef PF_LOOP_ROOM
#define PF_LOOP_ROOM 64L /* least free reversal slots before a period is started */
#endif

/* nblk sample periods from the loop state S (in and out) and the native run state fst (in and
 * out: carries the step size, the model events since the last reversal and the input's current
 * piece) under the input (th, brk, nbrk, pcs: as pf_forced; pcs null: none, the held line is then
 * the piece of the piecewise-linear structure). Wb: nblk rows of PF_LNW inputs; R: nblk records
 * of PF_LNREC;
 * rev: reversals (5 rows of stride cap). cnt[0] reversals written (in and out), cnt[2] accepted
 * steps (added to), cnt[3] periods done (out). Returns 0, a code of pf_forced (> 1), or 6 if a
 * period had more reversals than there was room for. */
int pf_loop_input(const double* q, const double* th, const double* brk, long nbrk, const double* pcs,
                  const double* cfg, const double* par, const double* Wb, long nblk, double* S, double* fst,
                  double* R, double* rev, long cap, long* cnt) {
  pf_ctx c;
  double Sn[PF_LNS], out[5], line[3], dummy = 0.0;
  long j;
  int i, code;
  memset(&c, 0, sizeof c);
  for (j = 0; j < nblk; ++j) {
    const double* w = Wb + j * PF_LNW;
    double* rec = R + j * PF_LNREC;
    if (cap - cnt[0] < PF_LOOP_ROOM) break; /* the caller takes the reversals, then calls again */
    c.arg[0] = S;
    c.arg[1] = w;
    c.arg[2] = par;
    c.res[0] = Sn;
    c.res[1] = out;
    pf_ctrl(c.arg, c.res, c.iw, c.w, 0);
    for (i = 0; i < PF_LNS; ++i) rec[i] = S[i];
    rec[PF_LR_F] = out[4];
    rec[PF_LR_U] = out[0];
    rec[PF_LR_Y] = out[2];
    rec[PF_LR_COMP] = out[3];
    rec[PF_LR_MOVED] = w[PF_LI_ACTIVE] > 0.5 ? 1.0 : 0.0;
    if (w[PF_LI_ACTIVE] > 0.5) {
      double t1 = w[PF_LI_T1];
      long n_before = cnt[0];
      int resting = S[PF_LS_S + 1] > 0.5;
      fst[0] = w[PF_LI_T0];
      fst[1] = S[0];
      fst[2] = S[1];
      fst[3] = S[PF_LS_S]; /* fst[4], the model events since the last reversal, carries over */
      fst[5] = S[PF_LS_S + 1];
      fst[6] = S[PF_LS_S + 2];
      fst[7] = 0.0;
      fst[8] = S[PF_LS_S + 3];
      for (i = 0; i < PF_NZ; ++i) fst[PF_FHEAD + i] = S[2 + i];
      for (i = 0; i < PF_NM; ++i) fst[PF_FHEAD + PF_NZ + i] = S[2 + PF_NZ + i];
      line[0] = w[PF_LI_TL];
      line[1] = w[PF_LI_DA] + out[1];
      line[2] = w[PF_LI_DB];
      cnt[1] = 0;
      if (!pcs) fst[10] = 0.0; /* the line is the only piece */
      code = pcs ? pf_forced_run(q, th, brk, nbrk, pcs, cfg, fst, t1, cap, rev, &dummy, 0, &dummy, cnt, 0, 0, 0, 0, line)
                 : pf_forced_run(q, &dummy, &dummy, 0, line, cfg, fst, t1, cap, rev, &dummy, 0, &dummy, cnt, 0, 0, 0, 0, 0);
      if (code > 1) { cnt[3] = j; return code; }
      if (code == 0 && fst[0] < t1) { cnt[3] = j; return 6; }
      if (resting && fst[5] > 0.5 && cnt[0] == n_before) rec[PF_LR_MOVED] = 0.0; /* rested through the period */
      Sn[0] = fst[1];
      Sn[1] = fst[2];
      Sn[PF_LS_S] = fst[3];
      Sn[PF_LS_S + 1] = fst[5];
      Sn[PF_LS_S + 2] = fst[6];
      Sn[PF_LS_S + 3] = fst[8];
      for (i = 0; i < PF_NZ; ++i) Sn[2 + i] = fst[PF_FHEAD + i];
      for (i = 0; i < PF_NM; ++i) Sn[2 + PF_NZ + i] = fst[PF_FHEAD + PF_NZ + i];
    }
    for (i = 0; i < PF_LNS; ++i) S[i] = Sn[i];
  }
  cnt[3] = j;
  return 0;
}

/* pf_loop_input without an input of its own: the held line is the input's piece (the loop of a
 * piecewise-linear input's structure, as controllers.simulate_loop and the exported plant build it) */
int pf_loop(const double* q, const double* cfg, const double* par, const double* Wb, long nblk, double* S,
            double* fst, double* R, double* rev, long cap, long* cnt) {
  return pf_loop_input(q, 0, 0, 0, 0, cfg, par, Wb, nblk, S, fst, R, rev, cap, cnt);
}
