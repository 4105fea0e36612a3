"""The integration loop of one :func:`prefriction.simulate` call (normalised units inside).

:class:`Run` holds the run's state and drives the integrator calls; :func:`drive` runs it on
its path (sampled controller, forced native driver, dense output or reversals only) once
:func:`check_ramps` has held the input's ramps against the run's error level. The conversion
of the state to and from a call's buffers is in :mod:`prefriction.simulation.state_io`, the
rests decided between calls in :mod:`prefriction.simulation.rest`.
"""

from __future__ import annotations

import math
from typing import Optional, Union

import numpy as np

from prefriction.simulation.compact import advance_compact
from prefriction.simulation.dense import SampleBuffer, dense_loop
from prefriction.simulation.build import BuiltPlant
from prefriction.simulation.integrator import INTEGRATOR_FAILED, BufferedIntegrator
from prefriction.simulation.feedback import LinearFeedback
from prefriction.simulation.native.advance import advance_native
from prefriction.simulation.native.forced import linear_pieces, run_forced
from prefriction.simulation.plant import Layout, PlantSpec
from prefriction.simulation.rest import Rest
from prefriction.simulation.reversal_log import ReversalLog
from prefriction.simulation.state_io import StateIO
from prefriction.errors import SolverError
from prefriction.models import Oscillator
from prefriction.units import Scales

_DIED_OUT = 1e-20  # normalised speed below which an unforced motion has died out (no reversal comes)
RAMP_ROUNDOFF = 0.3
"""Largest force error from the round-off of the time in a ramp of the input force, in units of
the run's error level ``eps`` times the force scale (:func:`prefriction.simulate` refuses
steeper ramps: they started spurious reversal pairs at a rest, or NaN in CasADi's event
transition)."""
_MIN_CALL = 1e-9  # relative length of a call below which a failed call is not made shorter (Run._shorten)


class Run(StateIO, Rest):
    """The integration loop of one :func:`prefriction.simulate` call (normalised units inside).

    ``simulate`` builds the ``plant`` (:func:`~prefriction.simulation.build.build_plant`), sets
    the initial state ``st``, the run constants (``snap``,
    ``force_scale``, ``breaks``, signal kinds, ``P0``) and then :func:`drive` runs it through
    :meth:`advance` (or :func:`prefriction.simulation.dense.dense`) and :meth:`sample`; the
    reversals found are in ``rev``. Packing of the call buffers:
    :class:`~prefriction.simulation.state_io.StateIO`; rests between calls:
    :class:`~prefriction.simulation.rest.Rest`.
    """

    def __init__(self, system: Oscillator, spec: PlantSpec, fb: Optional[LinearFeedback],
                 eps: float, plant: BuiltPlant, sc: Optional[Scales] = None) -> None:
        self.system, self.spec, self.fb = system, spec, fb
        self.sc = Scales.of(system) if sc is None else sc  # (simulate has them already)
        self.model = system.friction
        self.q = self.model.runtime_params_for(self.sc)  # may depend on the mass (units)
        self.eps = eps  # run-time tolerance: states are scaled by amplitude * eps
        self.eps_native = eps  # the same for the native drivers' norm over the active states (simulate sets it)
        # a sampled controller on a plant without a hold control: its force joins the input piece
        self.hold_in_piece = fb is not None and fb.sampled and spec.fb == "none"
        self.L, self.f1, self.native, self.native_forced = plant.L, plant.f1, plant.native, plant.native_forced
        self.setup_time, self.mode = plant.setup_time, plant.mode
        self.calls = 0
        self.steps: Optional[int] = 0
        self.max_chunk = math.inf  # longest next call of advance (finite after a failed call)
        self.rev = ReversalLog()  # (t~, x~, F~, W~) per reversal
        self.rev_events: list[int] = []  # model events of the half-cycle ending at each reversal
        self.st: dict = {}  # current state, normalised (set by simulate)
        self.snap = 0.0  # reversal-event coincidence tolerance (e.g. Dahl saturation)
        self.force_scale = 0.0  # size of the applied force / Fc
        self.A_max = 0.0  # largest amplitude seen (forced)
        self.breaks = np.zeros(0)  # sample times of sampled signals (normalised)
        self.S = np.ones(spec.n_c)  # controller state scales (times eps)
        self.P0 = np.zeros(self.L.np)  # parameters fixed during the run
        self.note = ""  # a change of method during the run, for the result's message

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

    def _failure(self, why: str) -> SolverError:
        """The SolverError of a failed call: time, state, reversals so far and what to try."""
        sc, st = self.sc, self.st
        if not self.spec.forced and abs(st["v"]) < _DIED_OUT and abs(st["F"]) < _DIED_OUT ** 0.5:
            n = len(self.rev)
            return SolverError(
                f"simulate stopped at t = {st['t'] * sc.t:.9g} s: the motion has died out after {n} "
                f"reversal{'' if n == 1 else 's'} (v = {st['v'] * sc.v:.3g} m/s, F = {st['F'] * sc.F:.3g} N, "
                f"x = {st['x'] * sc.x:.6g} m), so it will not reverse again and the requested reversals cannot "
                f"come ({why}). Give t_end to simulate up to a time instead, or ask for at most {n} "
                f"reversal{'' if n == 1 else 's'}."
            )
        return SolverError(
            f"simulate failed after t = {st['t'] * sc.t:.9g} s (state there: x = {st['x'] * sc.x:.6g} m, "
            f"v = {st['v'] * sc.v:.6g} m/s, F = {st['F'] * sc.F:.6g} N, direction {int(st['s']):+d}, "
            f"{len(self.rev)} reversals so far): {why}. Try a looser rtol, a shorter t_end or fewer "
            f"reversals" + (", or a smoother input force (samples closer together)." if self.spec.forced else ".")
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

    def sample(self) -> tuple:
        """Current state as a sample (t~, x~, v~, F~, E_f~, xc)."""
        st = self.st
        return (st["t"], st["x"], st["v"], st["F"], st["Ef"], np.array(st["xc"], dtype=float))


def drive(run: Run, t_end: float, n_target: float, times: Optional[np.ndarray], want_dense: bool,
          xc0: np.ndarray) -> tuple[Union[SampleBuffer, list], list]:
    """Run ``run`` from its initial state to the normalised time ``t_end`` or ``n_target``
    reversals on its path: a sampled controller's loop (:func:`sampled_loop`), the forced native
    driver, dense output at the normalised ``times`` (all of them if None:
    :func:`~prefriction.simulation.dense.dense_loop`) or :meth:`Run.advance`. Returns the samples
    (empty without dense output or a sampled controller) and a sampled controller's applied
    forces [N]."""
    if run.fb is not None and run.fb.sampled:
        return sampled_loop(run, xc0, t_end, n_target)
    if run.native_forced is not None:
        samples = SampleBuffer(len(xc0), len(times) if times is not None else 1024) if want_dense else []
        run_forced(run, t_end, n_target, times, samples if want_dense else None)
        return samples, []
    if want_dense:
        return dense_loop(run, times, t_end, n_target), []
    run.advance(t_end, n_target)
    return [], []


def sampled_loop(run: Run, xc0: np.ndarray, t_end: float, n_target: float) -> tuple[SampleBuffer, list]:
    """Closed loop with a sampled controller: hold its output over each period ``Ts`` up to the
    normalised time ``t_end`` or ``n_target`` reversals; returns the samples at ``k Ts`` and the
    total applied force there [N]."""
    system, feedback, sc = run.system, run.fb, run.sc
    samples = SampleBuffer(len(xc0))
    u_hist: list = []
    Ts = feedback.Ts / sc.t
    xc = xc0.copy()
    k = 0
    while True:
        tk = min(k * Ts, t_end)
        t_si = tk * sc.t
        e = float(feedback.reference(t_si)) - run.st["x"] * sc.x
        uk = float(feedback.C[0] @ xc + feedback.D[0, 0] * e)
        run.st["uhold"] = uk
        run.st["xc"] = xc.copy()
        samples.append(run.sample())
        u_hist.append(uk + (float(system.u(t_si)) if system.forced else 0.0))
        if tk >= t_end * (1 - 1e-12):
            break
        xc = feedback.A @ xc + feedback.B[:, 0] * e
        if run.advance(min((k + 1) * Ts, t_end), n_target):
            break
        k += 1
    return samples, u_hist


def check_ramps(run: Run, t_end: float, rtol: float) -> None:
    """ValueError if a piece of a piecewise-linear input force is so steep that the round-off of
    its time makes a force error above :data:`RAMP_ROUNDOFF` of the run's error level.

    The plant evaluates a piece as ``a + b (t - t_k)`` from the normalised time ``t``, which
    carries a round-off of about ``2^-53 t``; a slope ``b`` turns it into a force error
    ``2^-53 |b| t``. Near a rest the net force is compared with the error level ``eps`` times the
    force scale (:data:`prefriction.simulation.plant.EPS_REST`): a larger error started the mass
    backwards (a spurious reversal pair), or made CasADi's event transition return NaN.
    """
    sig, sc = run.spec.u_sig, run.sc
    if sig is None or sig.key != ("PiecewiseLinear",):
        return
    level = run.eps * max(run.force_scale, 1e-300)  # error level of the net force (normalised)
    t = np.concatenate(([0.0], run.breaks[run.breaks < t_end], [t_end]))
    _, slopes = linear_pieces(sig, t[:-1] * sc.t, t[1:] * sc.t)  # vectorised: one pass over the pieces
    slopes = np.abs(slopes) * (sc.t / sc.F)  # normalised
    errs = slopes * t[1:] * 2.0 ** -53
    for k in np.flatnonzero(errs > RAMP_ROUNDOFF * level)[:1]:
        ta, tb, slope, err = float(t[k]), float(t[k + 1]), float(slopes[k]), float(errs[k])
        if err > RAMP_ROUNDOFF * level:
            rise = abs(slope) * (tb - ta) * sc.F
            shortest = rise / sc.F * tb * 2.0 ** -53 / (RAMP_ROUNDOFF * level) * sc.t
            raise ValueError(
                f"system.u ramps by {rise:.3g} N over {(tb - ta) * sc.t:.3g} s (from t = {ta * sc.t:.12g} s): at rtol = "
                f"{rtol:g} that is too steep to simulate, because the round-off of the time there (2^-53 t) makes a "
                f"force error of {err * sc.F:.3g} N, more than RAMP_ROUNDOFF = {RAMP_ROUNDOFF:g} times the error "
                f"level of the net force ({level * sc.F:.3g} N) at which a resting mass starts to move. Spread the "
                f"ramp over at least {shortest:.3g} s, loosen rtol, or drop one of its two samples (a jump)"
            )
