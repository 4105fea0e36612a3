"""Parametric input signals: structure compiled once, numbers given at run time.

A signal (an input force [N], a reference position [m], ...) is split in two parts:

- its *structure*, :attr:`Signal.key`: the kind of signal (``("Sine",)``, ``("Step",)``,
  ``("Sum", ("Sine",), ("Step",))``, ...). Only the structure shapes the CasADi code that
  :meth:`Signal.expr` generates, so the simulator compiles one function per key;
- its *numbers*, :meth:`Signal.params` (amplitudes, frequencies, switching times, ...) and, for
  sampled signals, the per-interval numbers :meth:`Signal.piece`. They are inputs of the compiled
  function, so each kind compiles once and takes its numbers at run time: two ``Sine`` signals
  with different amplitudes share one compiled function.

Kinds: :class:`Constant`, :class:`Step`, :class:`Ramp`, :class:`Sine`, :class:`Chirp`,
:class:`Samples` (piecewise linear data), :class:`PointToPoint` (S-curve and trapezoidal moves), :class:`Traced` (an arbitrary traceable Python
function; compiled once *per function object*) and :class:`Sum` (made with ``+``).
:func:`as_signal` converts the user-facing forms (number, ``(t, values)``, callable) to signals.

Modules: ``base`` (:class:`Signal`), ``algebra`` (:class:`Sum`), ``piecewise`` (constant, step,
ramp), ``periodic`` (sine, chirp), ``samples``, ``traced``, ``compiled`` (the form the simulator
compiles, :func:`compiled_form`) and ``conversion`` (:func:`as_signal`); every name is
importable from ``prefriction.signals``.

Example
-------
>>> import casadi as ca
>>> u = Sine(amplitude=0.5, frequency=2.0) + Step(time=1.0, before=0.0, after=0.1)
>>> t, theta = ca.SX.sym("t"), ca.SX.sym("theta", u.n_params)
>>> f = ca.Function("u", [t, theta], [u.expr(t, theta)])      # compiled once per key
>>> v = Sine(amplitude=2.0, frequency=0.1) + Step(time=0.0, before=1.0, after=-1.0)
>>> v.key == u.key and abs(float(f(0.3, v.params())) - v(0.3)) < 1e-12
True
"""

from prefriction.signals.algebra import Sum
from prefriction.signals.base import Signal
from prefriction.signals.compiled import compiled_form
from prefriction.signals.conversion import as_signal
from prefriction.signals.motion import PointToPoint
from prefriction.signals.periodic import Chirp, Sine
from prefriction.signals.piecewise import Constant, Ramp, Step
from prefriction.signals.samples import MAX_SAMPLES, Samples
from prefriction.signals.traced import Traced

__all__ = [
    "compiled_form",
    "Chirp",
    "Constant",
    "PointToPoint",
    "Ramp",
    "Samples",
    "Signal",
    "Sine",
    "Step",
    "Sum",
    "Traced",
    "as_signal",
    "MAX_SAMPLES",
]
