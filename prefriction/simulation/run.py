"""The integration loop of one :func:`prefriction.simulate` call (normalised units inside)."""

from __future__ import annotations

import math
from typing import Optional

import numpy as np

from prefriction.simulation.compact import advance_compact
from prefriction.simulation.integrator import INTEGRATOR_FAILED, BufferedIntegrator, integrator
from prefriction.simulation.feedback import LinearFeedback
from prefriction.simulation.plant import EPS_REST, EPS_TOUCH, Layout, PlantSpec
from prefriction.errors import SolverError
from prefriction.models import Oscillator
from prefriction.units import Scales

N_DENSE = 16  # output times per call of the dense-output integrator


class Run:
    """The integration loop of one :func:`prefriction.simulate` call (normalised units inside).

    ``simulate`` sets the initial state ``st``, the run constants (``snap``, ``force_scale``,
    ``breaks``, signal kinds, ``P0``) and then drives :meth:`advance`, :meth:`dense` and
    :meth:`sample`; the reversals found are in ``rev``.
    """

    def __init__(self, system: Oscillator, spec: PlantSpec, fb: Optional[LinearFeedback],
                 eps: float, jit: bool) -> None:
        self.system, self.spec, self.fb = system, spec, fb
        self.sc = Scales.of(system)
        self.model = system.friction
        self.q = self.model.runtime_params_for(self.sc)  # may depend on the mass (units)
        self.eps = eps  # run-time tolerance: states are scaled by amplitude * eps
        self.L = Layout(spec)  # the same for any number of outputs per call
        # a sampled controller on a plant without a hold control: its force joins the input piece
        self.hold_in_piece = fb is not None and fb.sampled and spec.fb == "none"
        # one plant: a dense run makes its single-output calls on the dense plant, padded
        self.f1, self.setup_time, self.mode = integrator(spec, jit)
        self.calls = 0
        self.steps: Optional[int] = 0
        self.rev: list[tuple] = []  # (t~, x~, F~, W~)
        self.rev_events: list[int] = []  # model events of the half-cycle ending at each reversal
        self.st: dict = {}  # current state, normalised (set by simulate)
        self.snap = 0.0  # reversal-event coincidence tolerance (e.g. Dahl saturation)
        self.force_scale = 0.0  # size of the applied force / Fc
        self.A_max = 0.0  # largest amplitude seen (forced)
        self.breaks = np.zeros(0)  # sample times of sampled signals (normalised)
        self.S = np.ones(spec.n_c)  # controller state scales (times eps)
        self.P0 = np.zeros(self.L.np)  # parameters fixed during the run

    # --- state conversion -------------------------------------------------------------
    def _scales(self) -> dict:
        """Amplitude scales of the next call (normalised units): the state and, if forced, the
        force scale of the input and the largest amplitude so far (a motion can grow)."""
        v, F = self.st["v"], self.st["F"]
        A = math.hypot(v, F)
        if self.spec.forced:
            self.A_max = max(self.A_max, A)
            A = max(A, self.force_scale, 0.1 * self.A_max)
        A = max(A, 1e-150)  # AE = A^2 stays a normal double
        Ax = max(A, 0.5 * A * A, min(abs(self.st["x"]), 1.0))  # positions: relative to |x| (<= 1)
        return {"Ax": Ax, "Av": A, "AF": min(A, 1.0), "AE": A * A}

    def _constant_params(self, L: Layout) -> np.ndarray:
        """Parameter vector with the entries that stay fixed during the run."""
        sc, fb, spec = self.sc, self.fb, self.spec
        P = np.zeros(L.np)
        P[L.param["eps"]] = self.eps
        P[L.q] = self.q
        if spec.stops_at_reversal:  # the amplitudes and the direction change per call
            return P
        P[L.param["snap"]] = self.snap
        P[L.param["tunit"]] = sc.t
        P[L.param["xunit"]] = sc.x
        P[L.param["Fc"]] = sc.F
        if spec.u_sig is not None:
            P[L.up] = spec.u_sig.params()
        if spec.r_sig is not None:
            P[L.rp] = spec.r_sig.params()
        if spec.fb == "continuous":
            Ct = fb.C[0] / sc.F
            self.S = self.eps * np.where(Ct != 0, 1.0 / np.where(Ct == 0, 1.0, np.abs(Ct)), 1.0)
            P[L.p_A:L.p_B] = (fb.A * sc.t).T.ravel()  # column-major, as ca.reshape reads it
            P[L.p_B:L.p_C] = fb.B[:, 0] * sc.t * sc.x
            P[L.p_C:L.p_D] = Ct
            P[L.p_D] = fb.D[0, 0] * sc.x / sc.F
            P[L.p_S:L.p_umax] = self.S
            P[L.p_umax] = 1e300 if fb.u_max is None else fb.u_max / sc.F  # no limit: the linear law
            P[L.p_kaw:L.np] = fb.k_aw * sc.t * sc.F
        return P

    def _params(self, call: BufferedIntegrator, L: Layout, a: dict, nstop: float) -> None:
        """Write the parameters of the next call into ``call.P``."""
        P, ix = call.P, L.param
        np.copyto(P, self.P0)
        P[ix["Ax"]], P[ix["Av"]], P[ix["AF"]], P[ix["AE"]] = a["Ax"], a["Av"], a["AF"], a["AE"]
        P[ix["xref"]], P[ix["Efref"]], P[ix["nstop"]] = self.st["x"], self.st["Ef"], nstop
        if "ecorr" in ix:  # the speed at model events from the branch's energy, when it is known
            P[ix["ecorr"]] = 1.0 if "Eb" in self.st else 0.0

    def _pack(self, call: BufferedIntegrator, L: Layout, a: dict) -> None:
        """Write the scaled state into ``call.X0`` (the register is output only)."""
        st, ix, X = self.st, L.state, call.X0
        X[0] = 0.0  # xh: positions relative to xref
        X[1] = st["v"] / a["Av"]
        for i, zi in enumerate(st["z"]):
            X[2 + i] = zi / a["AF"]
        X[ix["s"]] = st["s"]
        X[ix["n"]] = len(self.rev)
        for i, mi in enumerate(st["m"]):
            X[ix[f"m{i}"]] = mi
        if "rest" in ix:
            X[ix["rest"]] = st["rest"]
            X[ix["Wh"]] = st["W"] / a["AE"]
            X[ix["armed"]], X[ix["tmiss"]] = 1.0, 0.0
        if "Eh" in ix:
            X[ix["Eh"]] = 0.0
        if "ne" in ix:
            X[ix["ne"]] = st.get("ne", 0)  # (a state set without it: none so far)
        if "Ebh" in ix:
            X[ix["Ebh"]] = st.get("Eb", 0.0) / a["AE"]
        if self.spec.fb == "continuous":
            X[L.xc] = st["xc"] / self.S
            X[ix["sat"]] = self._clip_mode()

    def _unpack(self, L: Layout, col: np.ndarray, a: dict, n_before: int, nstop: float) -> dict:
        """State of one output column; ``t`` is the stop time if the call stopped at ``nstop``."""
        ix = L.state
        c = col.tolist()  # Python floats: cheaper to index than numpy scalars
        n = int(c[ix["n"]] + 0.5)
        s = c[ix["s"]]
        z = [a["AF"] * c[2 + i] for i in range(L.nz)]
        m = [c[ix[f"m{i}"]] for i in range(L.nm)]
        v = a["Av"] * c[1]
        out = {
            "x": a["xref"] + a["Ax"] * c[0],
            "v": v,
            "z": z,
            "m": m,
            "F": float(self.model.force(z, m, v, s, self.q)),
            "s": s,
            "n": n,
            "frozen": n >= nstop,
            "rest": c[ix["rest"]] if "rest" in ix else 0.0,
            "W": a["AE"] * c[ix["Wh"]] if "Wh" in ix else 0.0,
            "Ef": a["Efref"] + a["AE"] * c[ix["Eh"]] if "Eh" in ix else 0.0,
            "xc": col[L.xc] * self.S if self.spec.fb == "continuous" else self.st["xc"],
        }
        new = n - n_before
        w, r0 = L.reg_width, L.reg
        regs, counts = [], []
        counted = "ne" in ix
        for j in range(min(new, self.spec.K) - 1, -1, -1):
            k = r0 + j * w
            regs.append((c[k], c[k + 1], c[k + 2], c[k + 3] if w == 4 else 0.0))
            counts.append(int(c[ix[f"nr{j}"]] + 0.5) if counted else 0)
        out["new"], out["new_events"] = regs, counts
        out["ne"] = int(c[ix["ne"]] + 0.5) if counted else 0
        if "Ebh" in ix and "Eb" in self.st:
            out["Eb"] = a["AE"] * c[ix["Ebh"]]
        # a skipped reversal pair stopped the call at the least speed after it (1 + t~ there)
        out["tmiss"] = c[ix["tmiss"]] - 1.0 if "tmiss" in ix and c[ix["tmiss"]] > 0.5 else None
        out["overflow"] = new > self.spec.K
        out["t"] = regs[-1][0] if out["frozen"] and regs else None
        return out

    # --- one call -----------------------------------------------------------------------
    def _controls(self, t0: float, t1: float, j: int) -> list[float]:
        """Controls of the output interval [t0, t1] (normalised times)."""
        L, sc = self.L, self.sc
        U = [0.0] * L.nu
        U[L.control["dur"]] = t1 - t0
        U[L.control["t0"]] = t0 - (t1 - t0) * j  # t~ = t0 + dur * tau, tau in [j, j + 1]
        if L.uc.stop > L.uc.start:
            U[L.uc] = self.spec.u_sig.piece(t0 * sc.t, t1 * sc.t).tolist()
            if self.hold_in_piece:  # a sampled controller's held force joins the input's piece
                U[L.uc.start + 1] += self.st["uhold"]
        if L.rc.stop > L.rc.start:
            U[L.rc] = self.spec.r_sig.piece(t0 * sc.t, t1 * sc.t).tolist()
        if "uhold" in L.control:
            U[L.control["uhold"]] = self.st["uhold"]
        return U

    def _clip_mode(self) -> float:
        """Mode of the continuous controller's force limit now: 0 inside, +-1 clipped at +-u_max."""
        fb, st = self.fb, self.st
        if fb.u_max is None:
            return 0.0
        w = float(fb.output(st["xc"], float(fb.reference(st["t"] * self.sc.t)) - st["x"] * self.sc.x))
        return 0.0 if abs(w) <= fb.u_max else math.copysign(1.0, w)

    def _net_force(self) -> float:
        """Normalised net force ``u~ - F~`` on the mass in the current state."""
        st, sc, fb = self.st, self.sc, self.fb
        t_si = st["t"] * sc.t
        u = float(self.system.u(t_si)) if self.system.forced else 0.0
        if self.spec.fb == "continuous":
            e = float(self.fb.reference(t_si)) - st["x"] * sc.x
            u += float(self.fb.force(st["xc"], e))
        elif fb is not None and fb.sampled:
            u += st["uhold"]
        return u / sc.F - st["F"]

    def _leave_rest(self) -> None:
        """End a rest at the start of a call if the net force no longer vanishes (the input or the
        held force jumped at a sample time; inside a call the rest-exit event does this)."""
        acc = self._net_force()
        if abs(acc) <= EPS_REST * self.eps * self._scales()["Av"]:
            return
        st = self.st
        new_s = 1.0 if acc > 0 else -1.0
        if new_s != st["s"]:  # leaves backwards: a reversal at this instant
            self.rev.append((st["t"], st["x"], st["F"], st["W"]))
            self.rev_events.append(st.get("ne", 0))
            st["W"], st["ne"] = 0.0, 0
            st["z"], st["m"] = self.model.reverse(st["z"], st["m"], new_s, self.q, self.snap)
            st["s"] = new_s
            if "Eb" in st:  # at rest on the new branch
                st["Eb"] = float(self.model.branch_potential(st["z"], st["m"], new_s, self.q))
        st["rest"] = 0.0

    def _call(self, call: BufferedIntegrator, L: Layout, times: list[float], nstop: float) -> tuple[np.ndarray, dict]:
        """One integrator call over the output ``times`` (normalised), stopping at ``nstop`` reversals."""
        if self.spec.forced and self.st["rest"] > 0.5:
            self._leave_rest()
        t_prev = self.st["t"]
        times = list(times)
        n_out = call.U.shape[0]
        while len(times) < n_out:  # padding outputs just after the last one, discarded
            times.append(times[-1] + 1e-3 * (times[-1] - self.st["t"]) + 1e-9)
        for j, t1 in enumerate(times):
            call.U[j] = self._controls(t_prev, t1, j)
            t_prev = t1
        eps = self.eps
        for retry in (False, True):
            a = {k: val * eps for k, val in self._scales().items()}
            a["xref"], a["Efref"] = self.st["x"], self.st["Ef"]
            self._params(call, L, a, nstop)
            call.P[L.param["eps"]] = eps
            self._pack(call, L, a)
            try:
                self._trigger(call)
                break
            except SolverError:
                if retry:
                    raise
                # CasADi's erk can fail on an event within round-off of the end of an output
                # interval (NaN in its event transition; seen once in a dense forced GMS run).
                # The same call at a tolerance 0.1 % tighter takes other steps.
                eps *= 1.0 - 2.0 ** -10
        xf = call.out.reshape(n_out, L.nx).T
        if not math.isfinite(float(call.out.sum())):
            raise self._failure("the integrator returned non-finite values")
        return xf, a  # a skipped reversal pair (tmiss) is integrated again by advance

    def _trigger(self, call: BufferedIntegrator) -> None:
        """Run ``call`` on its buffers and count the call and its steps; ``SolverError`` if it fails."""
        self.calls += 1
        try:
            call.trigger()
            failed = call.buf.ret() != 0
        except RuntimeError as exc:
            raise self._failure(str(exc).strip().splitlines()[-1]) from None
        if failed:
            raise self._failure(INTEGRATOR_FAILED)
        if self.steps is not None:
            self._count_steps(call)

    def _failure(self, why: str) -> SolverError:
        """The SolverError of a failed call: time, state, reversals so far and what to try."""
        sc, st = self.sc, self.st
        return SolverError(
            f"simulate failed after t = {st['t'] * sc.t:.9g} s (state there: x = {st['x'] * sc.x:.6g} m, "
            f"v = {st['v'] * sc.v:.6g} m/s, F = {st['F'] * sc.F:.6g} N, direction {int(st['s']):+d}, "
            f"{len(self.rev)} reversals so far): {why}. Try a looser rtol, a shorter t_end or fewer "
            f"reversals, or a smoother input force (samples closer together)."
        )

    def _record(self, out: dict) -> None:
        """Append the reversals of the unpacked state ``out`` and their half-cycles' event counts."""
        self.rev.extend(out["new"])
        self.rev_events.extend(out["new_events"])

    def _accept(self, out: dict, t: float) -> None:
        """Take the unpacked state ``out``, at normalised time ``t`` unless the call stopped early."""
        self._record(out)
        for k in ("x", "v", "F", "z", "m", "s", "rest", "W", "Ef", "xc", "ne"):
            self.st[k] = out[k]
        if "Eb" in out:
            self.st["Eb"] = out["Eb"]
        self.st["t"] = t if out["t"] is None else out["t"]

    # --- loops --------------------------------------------------------------------------
    def _count_steps(self, call: BufferedIntegrator) -> None:
        """Add the steps of the last call (interpreted integrator only; else ``steps`` = None)."""
        try:  # statistics exist for the interpreted integrator only (memory 1: the buffer's)
            self.steps += int(call.fun.stats(1)["n_steps"])
        except (RuntimeError, KeyError):
            self.steps = None

    def advance(self, t_target: float, n_target: float) -> bool:
        """Integrate to normalised time ``t_target`` or ``n_target`` reversals; True if the latter."""
        if self.spec.stops_at_reversal:
            return advance_compact(self, t_target, n_target)
        grow = 1.0
        while True:
            if len(self.rev) >= n_target:
                return True
            if self.st["t"] >= t_target * (1 - 1e-15) and t_target < math.inf:
                return False
            # call length: K half-cycles as long as the last one, with a margin. A call that
            # stops at its K-th reversal integrates a zero right-hand side to its end, which is
            # cheap but not free; one that ends early is followed by another.
            rev = self.rev
            if len(rev) >= 2:
                chunk = (self.spec.K + 0.6) * (rev[-1][0] - rev[-2][0]) * 1.25
            else:  # about one small cycle (shorter at high speed: F rises over a distance ~1),
                # doubled while no reversal comes (gross sliding)
                chunk = 2.0 * math.pi / max(1.0, abs(self.st["v"]))
            chunk *= grow
            t1 = min(t_target, self.st["t"] + chunk)
            t1 = min(t1, self._next_break(self.st["t"]))
            # the first call stops at the first reversal: the amplitude scales of the first
            # excursion (possibly gross sliding) do not fit the pre-sliding cycles after it
            nstop = min(len(self.rev) + (self.spec.K if self.rev else 1), n_target)
            n0 = len(self.rev)
            xf, a = self._call(self.f1, self.L, [t1], nstop)
            out = self._unpack(self.L, xf[:, 0], a, n0, nstop)
            if out["tmiss"] is not None:  # a reversal pair inside one step: integrate again up to
                # the least speed after it, where s v < 0 at the end of the last step
                t1 = self._retry_to(out["tmiss"])
                xf, a = self._call(self.f1, self.L, [t1], nstop)
                out = self._unpack(self.L, xf[:, 0], a, n0, nstop)
                if out["tmiss"] is not None:
                    if self._rest_at_noise_level():  # the pair was noise of a mass at equilibrium
                        continue
                    raise self._failure(f"a reversal pair inside one step at t = {out['tmiss'] * self.sc.t:.9g} s "
                                        f"was not resolved by a second pass")
            self._accept(out, t1)
            grow = 1.0 if out["frozen"] or len(self.rev) > n0 else 2.0 * grow

    def _rest_at_noise_level(self) -> bool:
        """Put the mass at rest (``v = 0``) if its speed and net force are at the error level of
        the run (:data:`EPS_TOUCH` and :data:`EPS_REST` times ``Av = eps A``); True if it did.

        A loop that settles at equilibrium without a clean zero of the velocity (its speed
        decays into the integration error) shows "reversal pairs" that are noise; such a mass
        rests, as at a zero velocity with a vanishing net force (``docs/simulator.md#events``).
        """
        st = self.st
        Av = self.eps * self._scales()["Av"]
        if abs(st["v"]) > EPS_TOUCH * Av or abs(self._net_force()) > EPS_REST * Av:
            return False
        st["v"], st["rest"] = 0.0, 1.0
        st["F"] = float(self.model.force(st["z"], st["m"], 0.0, st["s"], self.q))  # rate-dependent models
        return True

    def _retry_to(self, t_miss: float) -> float:
        """End of the second pass over a call that skipped a reversal pair: ``t_miss`` (the least
        speed after the pair, normalised), or, if that is the call's start, ``SolverError``."""
        if not t_miss > self.st["t"]:
            raise self._failure("a reversal pair inside the first step of a call could not be located")
        return t_miss

    def _next_break(self, t: float) -> float:
        """Next sample time of a sampled input or reference after normalised time ``t``."""
        b = self.breaks
        if b.size == 0:
            return math.inf
        k = np.searchsorted(b, t * (1 + 1e-15) + 1e-300, side="right")
        return float(b[k]) if k < b.size else math.inf

    def sample(self) -> tuple:
        """Current state as a sample (t~, x~, v~, F~, E_f~, xc)."""
        st = self.st
        return (st["t"], st["x"], st["v"], st["F"], st["Ef"], np.array(st["xc"], dtype=float))
