"""Friction blocks as python-control describing-function nonlinearities.

python-control's :class:`control.DescribingFunctionNonlinearity` has a describing function of
the amplitude alone. A rate-dependent block (LuGre, and any mass with friction) has one of the
amplitude and the frequency: these classes hold the frequency ``omega`` as a fixed attribute,
:meth:`at` gives the same block at another frequency, and
:func:`prefriction.describing.predict_limit_cycle` iterates on the frequency
(``docs/describing.md#rate-dependent``). Values are cached per ``(A, omega)``: every one is a
simulation.
"""

from __future__ import annotations

from typing import Any, Optional

import control

from prefriction._validation import check_positive
from prefriction.describing.cycle import friction_describing_function, plant_describing_function
from prefriction.describing.dahl import dahl_describing_function
from prefriction.models import Dahl, Oscillator, check_oscillator

__all__ = ["BLOCK_OPTIONS", "FrictionDescribingFunction", "PlantDescribingFunction"]

BLOCK_OPTIONS = {"rtol": 1e-8, "tol": 1e-6}
"""Defaults of the settled-cycle integration inside a block (``N`` to about 1e-5, far inside the
describing function's own approximation; 5-10 times faster than the function's defaults)."""


class _Block(control.DescribingFunctionNonlinearity):
    """Common part: the system, the frequency, the cache, ``at`` and ``__call__``."""

    rate_independent = False

    def __init__(self, system: Oscillator, omega: Optional[float], options: dict) -> None:
        super().__init__()
        check_oscillator(system, type(self).__name__)
        self.system = system
        self.omega = None if omega is None else check_positive("omega", omega)
        self._options = options
        self._cache: dict = {}

    def at(self, omega: float) -> "_Block":
        """The same block at the angular frequency ``omega`` [rad/s] (sharing the cache)."""
        other = type(self)(self.system, omega, **self._options)
        other._cache = self._cache
        return other

    def __call__(self, x: Any) -> float:
        raise NotImplementedError(
            f"{type(self).__name__} has memory and is evaluated on whole settled cycles; "
            "use describing_function(A) (control.describing_function uses it by default)"
        )

    def describing_function(self, A: float) -> complex:
        """``N(A)`` at :attr:`omega` (cached)."""
        A = check_positive("A", A)
        key = (A, None if self.rate_independent else self._need_omega())
        if key not in self._cache:
            self._cache[key] = self._evaluate(A)
        return self._cache[key]

    def _need_omega(self) -> float:
        if self.omega is None:
            raise ValueError(
                f"{type(self).__name__} of a rate-dependent block needs a frequency: pass omega [rad/s] "
                "or use .at(omega)"
            )
        return self.omega

    def __repr__(self) -> str:
        w = "any" if self.rate_independent else self.omega
        return f"{type(self).__name__}({type(self.system.friction).__name__}, mass={self.system.mass!r} kg, omega={w})"


class FrictionDescribingFunction(_Block):
    """Friction model alone, displacement in [m], force out [N]: ``N(A)`` [N/m].

    Dahl with gamma = 1 uses the closed form :func:`dahl_describing_function`; every other
    model :func:`friction_describing_function` (settled cycle, scipy). Rate-independent models
    ignore ``omega``. In a positioning loop ``m x'' = u - F``, ``u = -C(s) x`` the block sits
    in negative feedback around ``H(s) = 1 / (m s^2 + C(s))``
    (:func:`prefriction.describing.friction_loop`).

    Parameters
    ----------
    system : Oscillator
        Mass [kg] (fixes the units of mass-dependent models) and friction model.
    omega : float, optional
        Angular frequency [rad/s]; required for rate-dependent models.
    **options
        Passed to :func:`friction_describing_function` (``rtol``, ``tol``, ``max_cycles``, ``method``);
        defaults :data:`BLOCK_OPTIONS` (``rtol=1e-8, tol=1e-6``).
    """

    def __init__(self, system: Oscillator, omega: Optional[float] = None, **options: Any) -> None:
        super().__init__(system, omega, options)
        self.rate_independent = system.friction.rate_independent
        f = system.friction
        self._closed = isinstance(f, Dahl) and f.gamma == 1.0 and not options

    def _evaluate(self, A: float) -> complex:
        f = self.system.friction
        if self._closed:
            return complex(dahl_describing_function(A, f.sigma, f.Fc))
        return friction_describing_function(self.system, A, self.omega or 1.0, **{**BLOCK_OPTIONS, **self._options})


class PlantDescribingFunction(_Block):
    """Mass with friction, force in [N], position out [m]: ``N(U, omega) = X1 / U`` [m/N].

    In the loop ``u = -C(s) x`` the block sits in negative feedback around the controller
    ``C(s)`` itself. This block sees stick-slip, which the friction block alone cannot
    (``docs/describing.md#plant-block``).

    Parameters
    ----------
    system : Oscillator
        Mass [kg] and friction model.
    omega : float
        Angular frequency [rad/s].
    **options
        Passed to :func:`plant_describing_function` (``rtol``, ``tol``, ``periods``, ...).
    """

    def __init__(self, system: Oscillator, omega: Optional[float] = None, **options: Any) -> None:
        super().__init__(system, omega, options)

    def _evaluate(self, A: float) -> complex:
        return plant_describing_function(self.system, A, self._need_omega(), **self._options)
