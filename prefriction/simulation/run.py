"""The CasADi integration loop of one :func:`prefriction.simulate` call (normalised units inside).

:class:`Run` drives the integrator calls of a run (:meth:`Run.advance`); the run's state and
its bookkeeping are in :mod:`prefriction.simulation.run_state`, the conversion of the state to
and from a call's buffers in :mod:`prefriction.simulation.state_io`, the rests decided between
calls in :mod:`prefriction.simulation.rest`; :mod:`prefriction.simulation.drive` runs it on
its path.
"""

from __future__ import annotations

import math

import numpy as np

from prefriction.simulation.compact import advance_compact
from prefriction.simulation.integrator import INTEGRATOR_FAILED, BufferedIntegrator
from prefriction.simulation.native.advance import advance_native
from prefriction.simulation.plant import Layout
from prefriction.simulation.rest import Rest
from prefriction.simulation.state_io import StateIO
from prefriction.errors import SolverError

_MIN_CALL = 1e-9  # relative length of a call below which a failed call is not made shorter (Run._shorten)


class Run(StateIO, Rest):
    """The integration loop of one :func:`prefriction.simulate` call (normalised units inside).

    ``simulate`` builds the ``plant`` (:func:`~prefriction.simulation.build.build_plant`), sets
    the initial state ``st`` and the run constants (``snap``, ``force_scale``, ``breaks``,
    ``P0``); :func:`~prefriction.simulation.drive.drive` then runs it through :meth:`advance`
    (or the dense-output loop of :mod:`prefriction.simulation.dense`); the reversals found are
    in ``rev``. The state: :class:`~prefriction.simulation.run_state.RunState`; packing of the
    call buffers: :class:`~prefriction.simulation.state_io.StateIO`; rests between calls:
    :class:`~prefriction.simulation.rest.Rest`.
    """

    # --- one call -----------------------------------------------------------------------
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

    def _count_steps(self, call: BufferedIntegrator) -> None:
        """Add the steps of the last call (interpreted integrator only; else ``steps`` = None)."""
        try:  # statistics exist for the interpreted integrator only (of this thread's buffer)
            self.steps += int(call.buf.stats()["n_steps"])
        except (RuntimeError, KeyError):
            self.steps = None

    # --- loops --------------------------------------------------------------------------
    def advance(self, t_target: float, n_target: float) -> bool:
        """Integrate to normalised time ``t_target`` or ``n_target`` reversals; True if the latter."""
        if self.native is not None:
            return advance_native(self, t_target, n_target)
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
            times = self.rev.t
            if len(times) >= 2:
                chunk = (self.spec.K + 0.6) * (times[-1] - times[-2]) * 1.25
            else:  # about one small cycle (shorter at high speed: F rises over a distance ~1),
                # doubled while no reversal comes (gross sliding)
                chunk = 2.0 * math.pi / max(1.0, abs(self.st["v"]))
            chunk = min(chunk * grow, self.max_chunk)
            t1 = min(t_target, self.st["t"] + chunk)
            t1 = min(t1, self._next_break(self.st["t"]))
            # the first call stops at the first reversal: the amplitude scales of the first
            # excursion (possibly gross sliding) do not fit the pre-sliding cycles after it
            nstop = min(len(self.rev) + (self.spec.K if self.rev else 1), n_target)
            n0 = len(self.rev)
            try:
                xf, a = self._call(self.f1, self.L, [t1], nstop)
            except SolverError:
                if not self._shorten(t1 - self.st["t"]):
                    raise
                continue
            self.max_chunk *= 2.0
            out = self._unpack(self.L, xf[:, 0], a, n0, nstop)
            if out["tmiss"] is not None:  # a reversal pair inside one step: integrate again up to
                # the least speed after it, where s v < 0 at the end of the last step
                if not out["tmiss"] > self.st["t"] and self._rest_at_noise_level():
                    continue  # inside the first step: noise of a mass at equilibrium (a hold)
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

    def _shorten(self, length: float) -> bool:
        """Limit the next calls of :meth:`advance` to 1/8 of the normalised ``length`` of a call
        that failed; False if that call was already shorter than :data:`_MIN_CALL` (the failure
        is then not the call's length).

        A call longer than the integrator's step budget (``max_num_steps``) fails: e.g. a
        growing motion of a rate-dependent model (LuGre: a bristle time constant ~ 1/|v|) over
        a call sized by the last, slower half-cycles. The state is that of the call's start,
        so the same interval is integrated again in shorter calls; the length recovers by
        doubling after each call that succeeds.
        """
        if not length > _MIN_CALL * max(1.0, abs(self.st["t"])):
            return False
        self.max_chunk = 0.125 * length
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
