"""Conversion between a run's state (normalised units) and the buffers of one plant call.

:class:`StateIO` is the part of :class:`prefriction.simulation.run.Run` that writes the
parameters, the scaled initial state and the controls of the next integrator call and reads
the state back from an output column (``docs/simulator.md``, amplitude scaling and the
arguments of one call).
"""

from __future__ import annotations

import math

import numpy as np

from prefriction.simulation.integrator import BufferedIntegrator
from prefriction.simulation.plant import Layout
from prefriction.simulation.run_state import RunState

__all__ = ["StateIO"]


class StateIO(RunState):
    """Packing and unpacking of the plant's parameter, state and control vectors of a run.

    A part of :class:`~prefriction.simulation.run.Run`; the state it converts is that of
    :class:`~prefriction.simulation.run_state.RunState`.
    """

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
        """Parameter vector with the entries that stay fixed during the run (sets the controller
        state scales ``S`` of a continuous controller)."""
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

    def _clip_mode(self) -> float:
        """Mode of the continuous controller's force limit now: 0 inside, +-1 clipped at +-u_max."""
        fb, st = self.fb, self.st
        if fb.u_max is None:
            return 0.0
        w = float(fb.output(st["xc"], float(fb.reference(st["t"] * self.sc.t)) - st["x"] * self.sc.x))
        return 0.0 if abs(w) <= fb.u_max else math.copysign(1.0, w)

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
