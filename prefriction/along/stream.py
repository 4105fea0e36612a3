"""The friction force sample by sample, for a loop: :class:`FrictionStream`."""

from __future__ import annotations

import numpy as np

from prefriction._validation import check_count, check_finite
from prefriction.along.engine import Units, stepper
from prefriction.along.run import check_model, initial_state
from prefriction.models.base import FrictionModel

__all__ = ["FrictionStream"]


class FrictionStream:
    """Friction force of a model along a motion given one sample at a time.

    The same interval step as :func:`prefriction.friction_along` (same semantics: linear motion
    between samples, reversals on the samples, exact steps), for a control loop that knows the
    next position only when it comes. Feeding the samples of a record one by one gives the
    forces of ``friction_along`` on the whole record.

    Parameters
    ----------
    model : FrictionModel
        Any friction model.
    x0 : float
        Position [m] at the start.
    t0 : float, default 0.0
        Time [s] at the start.
    F0 : float, default 0.0
        Force [N] of the model's state at the start, on a virgin branch whose direction is that
        of the first motion (``docs/along.md#initial-state``).
    substeps : int, default 16
        Runge-Kutta sub-steps per interval for a model without an exact step (1 to 64).

    Raises
    ------
    TypeError, ValueError
        For a model that is not a FrictionModel, a non-finite ``x0``/``t0``, ``F0`` out of range
        or ``substeps`` not in [1, 64].

    Examples
    --------
    >>> import prefriction as pf
    >>> stream = pf.FrictionStream(pf.Dahl(sigma=1e5, Fc=1.0), x0=0.0)
    >>> [round(stream.step(x, t), 6) for t, x in [(1e-3, 1e-6), (2e-3, 2e-6), (3e-3, 1e-6)]]
    [0.095163, 0.181269, 0.068857]
    """

    def __init__(self, model: FrictionModel, x0: float, *, t0: float = 0.0, F0: float = 0.0,
                 substeps: int = 16) -> None:
        self.model = check_model(model)
        self.x = check_finite("x0", x0)
        self.t = check_finite("t0", t0)
        self.substeps = check_count("substeps", substeps, 1, 64)
        self.F0, _ = initial_state(model, F0, 1.0)
        self._step = stepper(model, self.substeps).buffered()
        self._step.inputs[6][:] = np.asarray(model.runtime_params(), dtype=float)
        self._units = Units.of(model)
        self._started = False  # the state is built at the first motion, when its direction is known
        self._s = 1.0
        self.F = self.F0
        """The force [N] at the last sample."""
        self.events = 0
        """Model events so far."""
        self.reversals = 0
        """Reversals so far."""

    _STATE = ("model", "x", "t", "substeps", "F0", "_started", "_s", "F", "events", "reversals")

    def __getstate__(self) -> dict:
        """What a copy or a pickle holds: the numbers and the model's state (not the compiled step)."""
        state = {k: getattr(self, k) for k in self._STATE}
        state["_w"] = self._step.inputs[0].copy()
        return state

    def __setstate__(self, state: dict) -> None:
        """Rebuild the stream from :meth:`__getstate__`: its own step buffers, the model's state copied."""
        for k in self._STATE:
            setattr(self, k, state[k])
        self._step = stepper(self.model, self.substeps).buffered()
        self._step.inputs[6][:] = np.asarray(self.model.runtime_params(), dtype=float)
        self._step.inputs[0][:] = state["_w"]
        self._units = Units.of(self.model)

    def __copy__(self) -> "FrictionStream":
        """An independent stream at the same sample (its own state: stepping one leaves the other)."""
        new = FrictionStream.__new__(FrictionStream)
        new.__setstate__(self.__getstate__())
        return new

    def __deepcopy__(self, memo: dict) -> "FrictionStream":
        import copy

        state = self.__getstate__()
        state["model"] = copy.deepcopy(self.model, memo)
        new = FrictionStream.__new__(FrictionStream)
        new.__setstate__(state)
        return new

    def __repr__(self) -> str:
        return (f"FrictionStream({type(self.model).__name__}: t = {self.t:.6g} s, x = {self.x:.6g} m, "
                f"F = {self.F:.6g} N, {self.reversals} reversals, {self.events} events)")

    def step(self, x: float, t: float, v: float | None = None) -> float:
        """Advance to the position ``x`` [m] at the time ``t`` [s] and return the force [N] there.

        Parameters
        ----------
        x : float
            Position [m] at ``t``.
        t : float
            Time [s], later than the previous sample.
        v : float, optional
            Velocity [m/s] at ``t`` for the rate-dependent part of the force; default the
            velocity of the interval just ended.

        Raises
        ------
        ValueError
            If ``x``, ``t`` or ``v`` is not finite or ``t`` is not later than the last time.
        """
        x, t = check_finite("x", x), check_finite("t", t)
        if not t > self.t:
            raise ValueError(f"t must be later than the last sample's time {self.t!r} s, got {t!r}")
        dx, dt = x - self.x, t - self.t
        vi = dx / dt
        v_end = vi if v is None else check_finite("v", v)
        s_prev = self._s
        s = s_prev if dx == 0.0 else (1.0 if dx > 0.0 else -1.0)
        if not self._started:
            if dx == 0.0:
                self.x, self.t = x, t
                return self.F
            self._step.inputs[0][:] = initial_state(self.model, self.F0, s)[1]
            self._started, s_prev = True, s
        U = self._units
        F, ev = self._step(vi / U.v, dt / U.t, s_prev, s, v_end / U.v)
        self.reversals += int(s != s_prev)
        self.events += int(ev)
        self._s, self.x, self.t = s, x, t
        self.F = U.F * F
        if not np.isfinite(self.F):
            from prefriction.errors import SolverError

            raise SolverError(f"the model's force is not finite at t = {t!r} s, x = {x!r} m; check the model's "
                              f"parameters, or give more substeps for a model without an exact step")
        return self.F
