"""The sampled-data loop as one compiled CasADi Function: many samples per call.

One sample period ``[t_k, t_{k+1}]`` of the loop (docs/controllers.md#compiled-loop):

1. the measurement ``y_k`` [m]: the position ``x(t_{k-d})`` of ``d`` samples ago (``d <=
   MAX_DELAY``) plus a noise sample, rounded to the encoder step ``q`` (``q = 0``: no rounding);
   the error ``e_k = r_k - y_k`` [m], the controller output ``v_k = C xc_k + D e_k`` [N], the
   compensation force ``c_k`` of the compensator's step (its state, ``[y_k, u_{k-1}]``, the
   reference samples ``[r_k, r_{k+1}, r'_k, r'_{k+1}]`` and its numbers) and the applied force
   ``u_k = clip(v_k + c_k, -u_max, u_max)``, held over the period (zero-order hold);
2. the controller update ``xc_{k+1} = A xc_k + B e_k + Ts k_aw (u_k - v_k - c_k)`` (back-calculation
   anti-windup; ``k_aw = 0`` and ``u_max = 1e300`` give the linear law);
3. a mass at rest whose net force ``u_k + d(t_k) - F`` leaves the rest threshold starts to move
   (a reversal at ``t_k`` if it leaves backwards), exactly as
   :meth:`prefriction.simulation.run.Run._leave_rest`;
4. the plant of :func:`prefriction.simulation.plant.build_integrator` (the forced register
   model with a piecewise-linear input, the held force added to its piece) integrated over the
   period, every reversal located inside it, unless the mass rests and stays at rest (the
   integrator is then skipped: ``casadi.Function.conditional`` evaluates only the branch taken).

:func:`loop_function` repeats this with ``Function.mapaccum`` over ``block`` samples. Every
number is a run-time input: the controller matrices, ``u_max``, ``k_aw``, ``Ts``, the reference
samples, the compensator's numbers, the encoder step, the delay, the model's numbers and the
tolerance; the structure is the plant's, the controller order, the compensator's structure and
the block length.
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca

from prefriction.simulation.plant import EPS_REST, Layout, PlantSpec, build_integrator

__all__ = ["MAX_DELAY", "LoopLayout", "LoopSpec", "NoCompensation", "control_law", "loop_function"]

MAX_DELAY = 8
"""Most samples of measurement delay (a run-time number up to this structural limit)."""

NSTOP = 2.0
"""Reversals after which the plant stops within one period (its register length ``K``): a
period with more reversals is finished by the Python loop (:mod:`.runner`)."""


@dataclass(frozen=True)
class NoCompensation:
    """The structure of a loop without compensator: no state, no numbers, zero force.

    A compensator structure is hashable (equal structures share one compiled loop) and gives
    ``n_state``, ``n_param`` and :meth:`function`, its step ``(state, meas, ref, par) ->
    (state_next, force)`` with ``meas = [y_k, u_{k-1}]`` [m, N] and ``ref = [r_k, r_{k+1}, r'_k,
    r'_{k+1}]`` [m, m/s] (SI)."""

    n_state: int = 0
    n_param: int = 0

    def function(self) -> ca.Function:
        """The step ``(state, meas, ref, par) -> (state_next, force)``: zero force."""
        c, me, r, p = ca.SX.sym("c", 0), ca.SX.sym("meas", 2), ca.SX.sym("ref", 4), ca.SX.sym("par", 0)
        return ca.Function("no_compensation", [c, me, r, p], [c, ca.SX.zeros(1, 1)])


@dataclass(frozen=True)
class LoopSpec:
    """Structure of a compiled loop: the plant's structure, the controller order, the block
    length and the compensator's structure."""

    plant: PlantSpec
    n_c: int
    block: int
    comp: object = NoCompensation()


class LoopLayout:
    """Index map of the loop state ``S``, the per-sample inputs ``w``, the parameters and the records."""

    def __init__(self, spec: LoopSpec) -> None:
        L = Layout(spec.plant)
        self.plant = L
        nz, nm, n = L.nz, L.nm, spec.n_c
        names = ["x", "v"] + [f"z{i}" for i in range(nz)] + [f"m{i}" for i in range(nm)]
        names += ["s", "rest", "W", "Amax"] + [f"xc{i}" for i in range(n)]
        self.n_comp = spec.comp.n_state
        names += [f"c{i}" for i in range(self.n_comp)] + [f"y{i}" for i in range(MAX_DELAY)] + ["uprev"]
        self.state = {k: i for i, k in enumerate(names)}
        self.nS = len(names)
        inputs = ["t0", "t1", "r", "active", "tl", "da", "db", "rn", "vr", "vrn", "noise"]
        self.inp = {k: i for i, k in enumerate(inputs)}
        self.nw = len(self.inp)
        self.p_plant = slice(0, L.np)
        o = L.np
        self.p_A = slice(o, o + n * n)
        self.p_B = slice(self.p_A.stop, self.p_A.stop + n)
        self.p_C = slice(self.p_B.stop, self.p_B.stop + n)
        self.p_kaw = slice(self.p_C.stop, self.p_C.stop + n)
        rest = ["D", "umax", "Ts", "force_scale", "quant"]
        self.param = {k: self.p_kaw.stop + i for i, k in enumerate(rest)}
        o = self.p_kaw.stop + len(rest)
        self.p_delay = slice(o, o + MAX_DELAY + 1)  # one-hot: which sample of the measurement is used
        self.p_comp = slice(self.p_delay.stop, self.p_delay.stop + spec.comp.n_param)
        self.npar = self.p_comp.stop
        K = spec.plant.K
        rec = ["F", "u", "moved", "lr", "lr_t", "lr_x", "lr_F", "lr_W", "n_new", "y", "comp"]
        self.rec = {k: self.nS + i for i, k in enumerate(rec)}
        self.reg = self.nS + len(rec)
        self.nrec = self.reg + 4 * K


def control_law(spec: LoopSpec, LL: LoopLayout, S: ca.SX, w: ca.SX, par: ca.SX) -> dict:
    """The sample instant ``t_k`` of the loop (module notes, step 1 and 2) on the symbols of the
    loop state ``S``, the sample's inputs ``w`` and the parameters ``par``: the friction force
    ``F``, the measurement (``y_now``, ``past``, ``y_meas``), the compensator (``cs``, ``cs_next``,
    ``comp``), the applied force ``u`` (and ``u_total`` with the oscillator's own input) and the
    controller's next state ``xc_next`` (the native loop compiles the same law, loops/native_loop.py)."""
    L, model, n = LL.plant, spec.plant.model, spec.n_c
    st = {k: S[i] for k, i in LL.state.items()}
    wi = {k: w[i] for k, i in LL.inp.items()}
    pp = {k: par[i] for k, i in LL.param.items()}
    P0 = par[LL.p_plant]
    pl = {k: P0[i] for k, i in L.param.items()}
    z = [st[f"z{i}"] for i in range(L.nz)]
    m = [st[f"m{i}"] for i in range(L.nm)]
    xc = ca.vertcat(*[st[f"xc{i}"] for i in range(n)]) if n else ca.SX(0, 1)
    F = model.force(z, m, st["v"], st["s"], P0[L.q])
    active = wi["active"] > 0.5
    # measurement (SI): noise, encoder rounding, delay of whole samples
    y_now = st["x"] * pl["xunit"] + wi["noise"]
    qs = pp["quant"]
    y_now = ca.if_else(qs > 0.0, qs * ca.floor(y_now / ca.fmax(qs, 1e-300) + 0.5), y_now)
    past = [st[f"y{i}"] for i in range(MAX_DELAY)]
    y_meas = ca.dot(par[LL.p_delay], ca.vertcat(y_now, *past))
    # compensator and controller (SI): error, raw output, clipped force, update with back-calculation
    cs = ca.vertcat(*[st[f"c{i}"] for i in range(LL.n_comp)]) if LL.n_comp else ca.SX(0, 1)
    cs_next, comp = spec.comp.function()(cs, ca.vertcat(y_meas, st["uprev"]),
                                         ca.vertcat(wi["r"], wi["rn"], wi["vr"], wi["vrn"]), par[LL.p_comp])
    e = wi["r"] - y_meas
    raw = (ca.dot(par[LL.p_C], xc) if n else 0.0) + pp["D"] * e + comp
    u = ca.fmin(ca.fmax(raw, -pp["umax"]), pp["umax"])
    t_si = wi["t0"] * pl["tunit"]
    u_total = u + wi["da"] + wi["db"] * (t_si - wi["tl"])  # with the oscillator's own input
    xc_next = xc
    if n:
        A = ca.reshape(par[LL.p_A], n, n)
        xc_next = ca.mtimes(A, xc) + par[LL.p_B] * e + pp["Ts"] * par[LL.p_kaw] * (u - raw)
        xc_next = ca.if_else(active, xc_next, xc)
    return {"F": F, "y_now": y_now, "past": past, "y_meas": y_meas, "cs": cs, "cs_next": cs_next, "comp": comp,
            "u": u, "u_total": u_total, "xc_next": xc_next, "active": active}


def _step(spec: LoopSpec, LL: LoopLayout) -> ca.Function:
    """One sample period: ``(S, w, par) -> (S_next, record)`` (record: the state at ``t_k``, the
    friction force, the applied force, a reversal at ``t_k`` and the plant's register)."""
    L, model, n = LL.plant, spec.plant.model, spec.n_c
    S, w, par = ca.SX.sym("S", LL.nS), ca.SX.sym("w", LL.nw), ca.SX.sym("par", LL.npar)
    st = {k: S[i] for k, i in LL.state.items()}
    wi = {k: w[i] for k, i in LL.inp.items()}
    pp = {k: par[i] for k, i in LL.param.items()}
    P0 = par[LL.p_plant]
    pl = {k: P0[i] for k, i in L.param.items()}
    q = P0[L.q]
    x, v, s, W = st["x"], st["v"], st["s"], st["W"]
    z = [st[f"z{i}"] for i in range(L.nz)]
    m = [st[f"m{i}"] for i in range(L.nm)]
    law = control_law(spec, LL, S, w, par)
    F, y_now, past, y_meas = law["F"], law["y_now"], law["past"], law["y_meas"]
    cs, cs_next, comp, u, u_total = law["cs"], law["cs_next"], law["comp"], law["u"], law["u_total"]
    xc_next, active = law["xc_next"], law["active"]
    # amplitude scales of the period (Run._scales, forced), first with the state at t_k
    A0 = ca.hypot(v, F)
    Amax = ca.fmax(st["Amax"], A0)
    A_rest = ca.fmax(ca.fmax(ca.fmax(A0, pp["force_scale"]), 0.1 * Amax), 1e-150)
    # leaving rest at t_k (Run._leave_rest): the net force left the rest threshold
    acc = u_total / pl["Fc"] - F
    leaving = ca.logic_and(st["rest"] > 0.5, ca.fabs(acc) > EPS_REST * pl["eps"] * A_rest)
    new_s = ca.if_else(acc > 0, 1.0, -1.0)
    back = ca.logic_and(leaving, new_s != s)
    zr, mr = model.reverse(z, m, new_s, q, pl["snap"])
    z1 = [ca.if_else(back, zr[i], z[i]) for i in range(L.nz)]
    m1 = [ca.if_else(back, mr[i], m[i]) for i in range(L.nm)]
    s1 = ca.if_else(back, new_s, s)
    W1 = ca.if_else(back, 0.0, W)
    rest1 = ca.if_else(leaving, 0.0, st["rest"])
    F1 = model.force(z1, m1, v, s1, q)
    A1 = ca.hypot(v, F1)
    Amax = ca.fmax(Amax, A1)
    A = ca.fmax(ca.fmax(ca.fmax(A1, pp["force_scale"]), 0.1 * Amax), 1e-150)
    eps = pl["eps"]
    Ax = ca.fmax(ca.fmax(A, 0.5 * A * A), ca.fmin(ca.fabs(x), 1.0)) * eps
    Av, AF, AE = A * eps, ca.fmin(A, 1.0) * eps, A * A * eps
    # the plant's arguments (Run._pack, Run._params, Run._controls)
    X0 = ca.SX.zeros(L.nx)
    ix = L.state
    X0[ix["vh"]] = v / Av
    for i in range(L.nz):
        X0[ix[f"z{i}"]] = z1[i] / AF
    for i in range(L.nm):
        X0[ix[f"m{i}"]] = m1[i]
    X0[ix["s"]] = s1
    X0[ix["rest"]] = rest1
    X0[ix["Wh"]] = W1 / AE
    P = ca.SX(P0)
    for k, val in (("Ax", Ax), ("Av", Av), ("AF", AF), ("AE", AE), ("xref", x), ("Efref", 0.0), ("nstop", NSTOP)):
        P[L.param[k]] = val
    U = ca.SX.zeros(L.nu)
    U[L.control["dur"]] = wi["t1"] - wi["t0"]
    U[L.control["t0"]] = wi["t0"]
    U[L.uc.start] = wi["tl"]
    U[L.uc.start + 1] = wi["da"] + u
    U[L.uc.start + 2] = wi["db"]
    # skip the integrator: padding, the last sample, or a mass that rests and stays at rest
    skip = ca.logic_or(ca.logic_not(active),
                       ca.logic_and(rest1 > 0.5, wi["db"] == 0.0))
    pre = ca.Function("pre", [S, w, par], [X0, P, U, skip])
    # the state after the period, from the plant's state at its end (Run._unpack)
    Xe = ca.SX.sym("Xe", L.nx)
    ze = [AF * Xe[ix[f"z{i}"]] for i in range(L.nz)]
    me = [Xe[ix[f"m{i}"]] for i in range(L.nm)]
    moved = ca.logic_not(skip)
    nxt = {"x": x + Ax * Xe[ix["xh"]], "v": Av * Xe[ix["vh"]], "s": Xe[ix["s"]], "rest": Xe[ix["rest"]],
           "W": AE * Xe[ix["Wh"]]}
    nxt.update({f"z{i}": ze[i] for i in range(L.nz)})
    nxt.update({f"m{i}": me[i] for i in range(L.nm)})
    kept = {"x": x, "v": v, "s": s1, "rest": rest1, "W": W1}
    kept.update({f"z{i}": z1[i] for i in range(L.nz)})
    kept.update({f"m{i}": m1[i] for i in range(L.nm)})
    S_next = ca.SX.zeros(LL.nS)
    for k, val in nxt.items():
        S_next[LL.state[k]] = ca.if_else(moved, val, kept[k])
    S_next[LL.state["Amax"]] = Amax
    for i in range(n):
        S_next[LL.state[f"xc{i}"]] = xc_next[i]
    for i in range(LL.n_comp):
        S_next[LL.state[f"c{i}"]] = ca.if_else(active, cs_next[i], cs[i])
    for i, yi in enumerate([y_now] + past[:-1]):
        S_next[LL.state[f"y{i}"]] = yi
    S_next[LL.state["uprev"]] = u
    rec = ca.SX.zeros(LL.nrec)
    rec[: LL.nS] = S
    r = LL.rec
    rec[r["F"]], rec[r["u"]], rec[r["moved"]] = F, u_total, moved
    rec[r["y"]], rec[r["comp"]] = y_meas, comp
    rec[r["lr"]], rec[r["lr_t"]], rec[r["lr_x"]], rec[r["lr_F"]], rec[r["lr_W"]] = back, wi["t0"], x, F, W
    rec[r["n_new"]] = ca.if_else(moved, Xe[ix["n"]], 0.0)
    rec[LL.reg:] = Xe[L.reg:]
    post = ca.Function("post", [S, w, par, Xe], [ca.densify(S_next), ca.densify(rec)])
    # glue (MX): the plant runs only in the branch that integrates
    plant = build_integrator(spec.plant)
    Xs, Us, Ps = ca.MX.sym("X", L.nx), ca.MX.sym("U", L.nu), ca.MX.sym("P", L.np)
    run = ca.Function("run", [Xs, Ps, Us], [plant(x0=Xs, p=Ps, u=Us)["xf"]])
    hold = ca.Function("hold", [Xs, Ps, Us], [Xs])
    cond = ca.Function.conditional("period", [run], hold)
    Sm, wm, pm = ca.MX.sym("S", LL.nS), ca.MX.sym("w", LL.nw), ca.MX.sym("par", LL.npar)
    X0m, Pm, Um, skipm = pre(Sm, wm, pm)
    Xem = cond(skipm, X0m, Pm, Um)
    S1, recm = post(Sm, wm, pm, Xem)
    return ca.Function("loop_step", [Sm, wm, pm], [S1, recm])


def loop_function(spec: LoopSpec) -> ca.Function:
    """``(S0, W, par) -> (S, R)``: ``spec.block`` sample periods; ``W`` holds one column of
    per-sample inputs per period, ``R`` one record per period, ``S`` the state after each."""
    LL = LoopLayout(spec)
    step = _step(spec, LL)
    name = f"{type(spec.plant.model).__name__.lower()}_loop{spec.n_c}_{spec.block}"
    if spec.comp.n_state or spec.comp.n_param:
        name += "_" + spec.comp.function().name()
    return step.mapaccum(name, spec.block, 1)
