"""The integration loop of the compact unforced model: one compiled call per reversal.

Every reversal of an unforced run without dense output ends an integrator call (the plant's
transition sets ``vh eps = -s (1 + tau)``, see :mod:`prefriction.simulation.plant`); the next
branch starts here, in Python, through the model's :meth:`~prefriction.FrictionModel.reverse`.
The loop keeps its state in local variables and writes the call buffers through memoryviews:
it is the hot path of every unforced run (about 2 us of Python per reversal).
"""

from __future__ import annotations

import math
from typing import Any

from prefriction.simulation.integrator import INTEGRATOR_FAILED
from prefriction.simulation.plant import EPS_DIED

__all__ = ["advance_compact"]


def advance_compact(self: Any, t_target: float, n_target: float) -> bool:
    """:meth:`Run.advance` (``self``: the :class:`~prefriction.simulation.run.Run`, which imports this
    module) for the compact unforced model (``spec.stops_at_reversal``): each call
    runs to the next reversal (or ``t_target``); the new branch starts here, in Python.
    Local variables only (``self.st`` is written at the end or before an error); True if
    ``n_target`` reversals were reached."""
    call, L, model, eps = self.f1, self.L, self.model, self.eps
    q = self.q.tolist()  # floats: the model's numeric fast paths
    # memoryviews of the call's buffers: item assignment costs ~25 ns, not ~70 ns (numpy)
    X0, P, U = memoryview(call.X0), memoryview(call.P), memoryview(call.U.reshape(-1))
    out, trigger, buf = memoryview(call.out), call.trigger, call.buf
    compiled = self.mode != "interpreted"
    ix = L.state
    iv, ixh = ix["vh"], ix.get("xh")
    iz = [ix[f"z{i}"] for i in range(L.nz)]
    im = [ix[f"m{i}"] for i in range(L.nm)]
    tracks = ixh is None
    iEb = L.param.get("Eb")  # the branch's energy: the speed at model events (branch_potential)
    potential = model.branch_potential
    force, travel, reverse, snap = model.force, model.travel, model.reverse, self.snap
    P[:] = self.P0  # eps and the model's numbers q
    st, rev = self.st, self.rev
    times = rev.t
    x, v, z, m, s, t = st["x"], st["v"], st["z"], st["m"], st["s"], st["t"]
    ne = st.get("ne", 0)  # model events since the last reversal
    rev_events = self.rev_events
    grow = 1.0
    calls = 0
    t_stop = t_target * (1 - 1e-15) if t_target < math.inf else math.inf
    n = len(rev)
    # a model with closed-form branches (free_branch: e.g. Dahl gamma = 0 below saturation)
    free = model.free_branch if model.has_free_branch else None

    def reset(z: list, m: list, s: float) -> tuple:
        """The direction, state and force just after a reversal of the branch ``s``.

        The force is the one after the model's reset: an event within ``snap`` of the reversal
        is taken as coinciding with it (the reset puts its state on the switching surface)."""
        z, m = reverse(z, m, -s, q, snap)
        return -s, z, m, float(force(z, m, 0.0, -s, q))

    while n < n_target and t < t_stop:
        exact = free(z, m, v, s, q, t_target - t) if free is not None else None
        if exact is not None:  # no integration: the branch in closed form
            dt, v, z, m, dx, n_ev = exact
            x += dx
            ne += n_ev
            if dt < t_target - t:  # a reversal
                t += dt
                n += 1
                s, z, m, F = reset(z, m, s)
                rev.append((t, x, F, 0.0))
                rev_events.append(ne)
                ne = 0
            else:
                t = t_target
            continue
        F = float(force(z, m, v, s, q))
        if n >= 2:  # the next half-cycle about as long as the last one, with a margin
            chunk = 2.0 * (times[-1] - times[-2]) * grow
        else:  # F rises over a distance ~1 (time ~1/|v|): the first step must not skip it;
            # quadrupled while no reversal comes (a gross slide: the scales follow the speed)
            chunk = 2.0 * math.pi / max(1.0, abs(v)) * grow
        t1 = min(t_target, t + chunk)
        A = max(math.hypot(v, F), 1e-300)
        Fmax = abs(F) if grow == 1.0 else max(Fmax, abs(F))  # the largest force of the branch (call starts)
        Ax = max(A, 0.5 * A * A, min(abs(x), 1.0)) * eps
        # a state that carries the travel (Dahl's log-gap) is held to its own size, as the native
        # driver does (docs/simulator.md#stiff, deep gross sliding)
        AF = (max(min(A, 1.0), max(abs(zi) for zi in z)) if tracks and z else min(A, 1.0)) * eps
        Av = A * eps
        P[0], P[1], P[2], P[3] = Ax, Av, AF, s
        if iEb is not None:
            P[iEb] = 0.5 * v * v + float(potential(z, m, s, q))
        X0[iv] = v / Av
        for i, k in enumerate(iz):
            X0[k] = z[i] / AF
        for i, k in enumerate(im):
            X0[k] = m[i]
        if not tracks:
            X0[ixh] = 0.0
        U[0], U[1] = t1 - t, t
        calls += 1
        why = INTEGRATOR_FAILED
        # a failed compiled call returns before writing its result: the NaN stays (asking
        # the buffer for the return code costs ~0.6 us; the interpreted call is asked)
        out[0] = math.nan
        try:
            trigger()
            ok = compiled or buf.ret() == 0
        except RuntimeError as exc:
            ok, why = False, str(exc).strip().splitlines()[-1]
        c = out.tolist()
        if not (ok and math.isfinite(math.fsum(c))):
            self.calls += calls
            st.update(x=x, v=v, z=z, m=m, s=s, t=t, F=F, ne=ne)
            raise self._failure(why)
        if self.steps is not None:
            self._count_steps(call)
        z1 = [AF * c[k] for k in iz]
        x = x + travel(z, z1, s, q) if tracks else x + Ax * c[ixh]
        m1 = [c[k] for k in im]
        # the events of the call: the flags it set (the model's events only set flags; the
        # register model counts them in a state, plant.event_count)
        for a, b in zip(m, m1):
            if b > a + 0.5:
                ne += 1
        z, m = z1, m1
        sv = s * c[iv] * eps
        if sv > -0.5:  # no reversal: vh is the velocity
            v = Av * c[iv]
            t = t1
            grow *= 4.0
        else:  # vh eps = -s (1 + tau) at a reversal: record it, start the branch of direction -s
            t = t + (t1 - t) * (-sv - 1.0)  # t0 + dur tau, as the integrator's time
            v = 0.0
            sr, zr, mr, F = reset(z, m, s)
            if not abs(F) > EPS_DIED * eps * Fmax:  # at rest (plant.EPS_DIED)
                if t_target < math.inf:
                    t = t_target
                    break
                self.calls += calls
                st.update(x=x, v=v, z=z, m=m, s=s, t=t, F=float(force(z, m, v, s, q)), ne=ne)
                raise self._failure("its velocity crosses zero only at the level of the integration error")
            n += 1
            s, z, m = sr, zr, mr
            rev.append((t, x, F, 0.0))
            rev_events.append(ne)
            ne = 0
            grow = 1.0
    self.calls += calls
    st.update(x=x, v=v, z=z, m=m, s=s, t=t, F=float(force(z, m, v, s, q)), ne=ne)
    return n >= n_target

