"""The exported plant's C body: the simulator's own native driver, its numbers as constants.

:func:`plant_body` writes the source of ``<name>_reset`` and ``<name>_step`` for
:func:`prefriction.export.plant_source`: the model's generated Functions, the native driver
(``simulation/native/driver.c``, ``forced.c``, ``loop.c``: the sampled loop of
``docs/controllers.md#compiled-loop`` with the controller off) and a small interface around
``pf_loop``. One period is one ``pf_loop`` call on the loop state ``w`` with the held force as its
input; the run state (the step size carried from period to period) lives in the state struct.
Every symbol of the driver is renamed ``<name>_pf_...`` so that several exports link together,
and ``memset``/``memcpy`` are replaced by local loops so that the code needs ``<math.h>`` only.
"""

from __future__ import annotations

import re

import casadi as ca
import numpy as np

from prefriction.simulation.loops.native_loop import loop_source
from prefriction.simulation.native.forced import FHEAD

from .period import Period


__all__ = ["CAP", "plant_body", "run_width"]

CAP = 48
"""Reversal slots of one period (a period with more reversals stops: status 1)."""
_ROOM = 0  # pf_loop starts a period whatever the free slots: each period starts with all CAP free

_PRELUDE = """\
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define memset(p, v, n) NAME_pf_fill((void*)(p), (n))
#define memcpy(d, s, n) NAME_pf_copy((void*)(d), (const void*)(s), (n))
static void NAME_pf_fill(void* p, unsigned long n) {
  unsigned char* b = (unsigned char*)p;
  while (n--) *b++ = 0;
}
static void NAME_pf_copy(void* d, const void* s, unsigned long n) {
  unsigned char* a = (unsigned char*)d;
  const unsigned char* b = (const unsigned char*)s;
  while (n--) *a++ = *b++;
}
"""

_INTERFACE = """
/* ---- NAME: the interface around the native loop (one pf_loop call per period) ---- */
static const double NAME_pf_Q[{nq}] = {{{q}}};
static const double NAME_pf_CFG[9] = {{{cfg}}};
static const double NAME_pf_PAR[{npar}] = {{{par}}};

static void NAME_pf_outputs(NAME_state* s) {{
  const casadi_real* arg[PF_SZ_ARG + 6];
  casadi_real* res[PF_SZ_RES + 4];
  casadi_int iw[PF_SZ_IW];
  casadi_real work[PF_SZ_W];
  double F;
  arg[0] = s->w;
  arg[1] = s->w + 2 + PF_NZ;
  arg[2] = s->w + PF_LS_S;
  arg[3] = NAME_pf_Q;
  res[0] = &F;
  pf_force(arg, res, iw, work, 0);
  s->x = s->w[0] * {xu!r};
  s->v = s->w[1] * {vu!r};
  s->F = F * {Fu!r};
}}

void NAME_reset(NAME_state* s, double x0, double v0) {{
  const casadi_real* arg[PF_SZ_ARG + 6];
  casadi_real* res[PF_SZ_RES + 4];
  casadi_int iw[PF_SZ_IW];
  casadi_real work[PF_SZ_W];
  double y[3];
  int i;
  arg[0] = &x0;
  arg[1] = &v0;
  res[0] = s->w;
  res[1] = y;
  pf_initial(arg, res, iw, work, 0);
  for (i = 0; i < {nrun}; ++i) s->run[i] = 0.0;
  s->run[12] = NAN;
  s->run[13] = NAN;
  s->k = 0.0;
  s->reversals = 0.0;
  NAME_pf_outputs(s);
}}

int NAME_step(NAME_state* s, double u) {{
  double W[PF_LNW], rec[PF_LNREC], rev[5 * {cap}], w0[PF_LNS], run0[{nrun}];
  long cnt[4] = {{0, 0, 0, 0}};
  int i, code;
  for (i = 0; i < PF_LNW; ++i) W[i] = 0.0;
  for (i = 0; i < PF_LNS; ++i) w0[i] = s->w[i];
  for (i = 0; i < {nrun}; ++i) run0[i] = s->run[i];
  W[PF_LI_T0] = s->k * {Ts_n!r};
  W[PF_LI_T1] = (s->k + 1.0) * {Ts_n!r};
  W[PF_LI_ACTIVE] = 1.0;
  W[PF_LI_DA] = u;
  code = pf_loop(NAME_pf_Q, NAME_pf_CFG, NAME_pf_PAR, W, 1L, s->w, s->run, rec, rev, {cap}L, cnt);
  for (i = 0; i < PF_LNS; ++i) if (!isfinite(s->w[i])) code = 3;
  if (code != 0 && code != 6) {{ /* the integrator failed: s is unchanged */
    for (i = 0; i < PF_LNS; ++i) s->w[i] = w0[i];
    for (i = 0; i < {nrun}; ++i) s->run[i] = run0[i];
    return 2;
  }}
  if (code == 6) {{ /* more reversals than CAP: the state where the period stopped */
    s->w[0] = s->run[1];
    s->w[1] = s->run[2];
    s->w[PF_LS_S] = s->run[3];
    s->w[PF_LS_S + 1] = s->run[5];
    s->w[PF_LS_S + 2] = s->run[6];
    s->w[PF_LS_S + 3] = s->run[8];
    for (i = 0; i < PF_NZ; ++i) s->w[2 + i] = s->run[PF_FHEAD + i];
    for (i = 0; i < PF_NM; ++i) s->w[2 + PF_NZ + i] = s->run[PF_FHEAD + PF_NZ + i];
  }}
  s->k += 1.0;
  s->reversals = (double)cnt[0];
  NAME_pf_outputs(s);
  return code == 6 ? 1 : 0;
}}
"""


def run_width(per: Period) -> int:
    """Entries of the native run state (forced.c ``st[]``) of the period's model."""
    return FHEAD + per.model.n_states + per.model.n_flags


def _numbers(values: np.ndarray) -> str:
    return ", ".join(repr(float(v)) for v in np.atleast_1d(values)) or "0.0"


def plant_body(per: Period, initial: ca.Function, cfg: np.ndarray, name: str) -> str:
    """The C source (after ``#include "<name>.h"``) of the exported plant of ``per``: the native
    loop with ``initial`` (``(x0, v0) -> (w, [x, v, F])``) generated in as ``pf_initial``."""
    init = ca.Function("pf_initial", initial.sx_in(), initial.call(initial.sx_in()), initial.name_in(),
                       initial.name_out())
    src = loop_source(per.spec, (init,))
    src = src.replace("#include <string.h>\n", "")
    src = f"#define PF_LOOP_ROOM {_ROOM}L\n" + src
    q = np.asarray(per.q, dtype=float)
    sc = per.sc
    text = _PRELUDE + src + _INTERFACE.format(
        nq=max(q.size, 1), q=_numbers(q), cfg=_numbers(cfg), npar=per.LL.npar, par=_numbers(per.par),
        xu=float(sc.x), vu=float(sc.v), Fu=float(sc.F), nrun=run_width(per), cap=CAP,
        Ts_n=float(per.Ts / sc.t))
    text = re.sub(r"\bpf_", f"{name}_pf_", text)
    return text.replace("NAME_", f"{name}_")
