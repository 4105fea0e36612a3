"""The inverse-model route: mass, offset and friction from the force balance along the measured motion.

For a record of a driven mass (:class:`prefriction.identify.Motion` with the applied force ``u``)
the force balance (2.1) ``u = m a + F + F_off`` is fitted where it is measured: velocity and
acceleration come from the filtered positions (:mod:`prefriction.identify.derivatives`), the
friction force ``F`` is the model's force along the filtered motion (a static map in closed form,
a dynamic model through :func:`prefriction.friction_along`), and every column of the regression
and the force are decimated alike. The residuals

    r = D(u) - m D(a) - F_off D(1) - D(F(x_f, v_f; theta))                               (1)

(``D`` the border cut and decimation; ``D(1)`` is the decimation filter's gain at zero frequency,
0.989, as in the reference script) are minimised over ``m``, ``F_off`` and the model's
parameters. Direction-dependent friction: ``Fc_neg``, ``b_neg`` of a :class:`StaticFriction`
(``directional=True``), or a :class:`prefriction.DirectionalViscous` term in a dynamic model
whose Coulomb asymmetry is the offset (``s Fc + F_off`` has the levels ``Fc + F_off`` and
``Fc - F_off``). No simulation: the route cannot drift, whatever the record's length or loop.
A linear static map (no Stribeck term) is solved in closed form (``numpy.linalg.lstsq``, the
EMPS reference script's ``X \\ y``), otherwise ``scipy.optimize.least_squares`` (trust-region
reflective) with an analytic (static map) or finite-difference (dynamic model) Jacobian.

Uncertainty: the Gauss-Newton statistics of every fit (identifiability, condition;
:func:`prefriction.identify.statistics.gauss_newton`) with standard errors from the Newey-West
sandwich (:mod:`prefriction.identify.hac`): the decimated residuals stay correlated (EMPS: lag-1
autocorrelation 0.68), where ``s^2 (J^T J)^-1`` would understate the spread about twofold.
Student-t 95 % intervals; the lag used is in ``FitResult.notes``.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from prefriction._blas_threads import one_blas_thread
from prefriction.identify.data import ForceDisplacement, Motion
from prefriction.identify.hac import sandwich
from prefriction.identify.options import check_solver
from prefriction.identify.derivatives import Derivatives, derivatives
from prefriction.identify.result import FitResult
from prefriction.identify.static_map import StaticFriction
from prefriction.identify.statistics import ConvergenceWarning, IdentifiabilityWarning, at_bounds, gauss_newton
from prefriction.models.base import FrictionModel

__all__ = ["applied", "fit_inverse", "inverse_start", "static_inverse"]


def _check(model: Any, data: Any) -> None:
    if not isinstance(model, (FrictionModel, StaticFriction)):
        raise TypeError(f"model must be a prefriction.FrictionModel or an identify.StaticFriction, got "
                        f"{type(model).__name__}")
    if not isinstance(data, Motion):
        raise TypeError(f"data must be prefriction.identify.Motion (positions and the applied force), got "
                        f"{type(data).__name__}")
    if data.free_decay:
        raise ValueError("the inverse-model route needs the applied force: data.u is zero everywhere (a free decay "
                         "cannot separate the mass from the friction; use identify.fit)")


def applied(data: Motion, delay: float) -> Motion:
    """``data`` with its force delayed by ``delay`` samples (0 to 4, linear between samples).

    The force balance at sample ``k`` (central differences) sees the force held over the two
    intervals around it: a loop that computes ``u_k`` from ``x_k`` and holds it over
    ``[t_k, t_k+1]`` acts, on average, half a sample late (``delay = 0.5``), one that applies it a
    sample later 1.5 samples late. The EMPS reference script aligns ``u_k`` with ``a_k``
    (``delay = 0``, the default, to reproduce it).
    """
    delay = float(delay)
    if not 0.0 <= delay <= 4.0:
        raise ValueError(f"delay must be in [0, 4] samples, got {delay!r}")
    if delay == 0.0:
        return data
    k = np.arange(len(data)) - delay
    u = np.interp(k, np.arange(len(data)), data.u)   # held at u[0] before the record
    return Motion(data.t, data.x, u, data.mass, hold=data.hold)


def static_inverse(data: Motion, deriv: Derivatives | None = None, *, directional: bool = False,
                   offset: bool = True) -> dict[str, float]:
    """Closed-form inverse model ``u = m a + b v + Fc sign(v) + F_off`` (EMPS ``Script_IDIM_LS.m``).

    Parameters
    ----------
    data : Motion
        Positions and the applied force (``data.mass`` is ignored: the mass is fitted).
    deriv : Derivatives, optional
        Filtered derivatives; default :func:`prefriction.identify.derivatives.derivatives` of the data.
    directional : bool, default False
        Separate Coulomb and viscous terms for each direction (the EMPS asymmetric reference model
        ``Script_IDIM_LS_Asym_Fric.m``: ``Fc``, ``b`` for ``v > 0``, ``Fc_neg``, ``b_neg`` for
        ``v < 0``, no offset: a Coulomb asymmetry and an offset are the same columns).
    offset : bool, default True
        Fit a force offset (ignored with ``directional``).

    Returns
    -------
    dict
        ``mass`` [kg], ``b`` [N s/m], ``Fc`` [N], ``offset`` [N] (0 if not fitted) and, with
        ``directional``, ``b_neg``, ``Fc_neg``.
    """
    d = derivatives(data.t, data.x) if deriv is None else deriv
    s = np.sign(d.v)
    pos, neg = (1.0 + s) / 2.0, (1.0 - s) / 2.0
    if directional:
        names, cols = ["mass", "b", "Fc", "b_neg", "Fc_neg"], [d.a, d.v * pos, s * pos, d.v * neg, -s * neg]
    else:
        names = ["mass", "b", "Fc"] + (["offset"] if offset else [])
        cols = [d.a, d.v, s] + ([np.ones_like(s)] if offset else [])
    X = d.regress(np.column_stack(cols))
    beta = np.linalg.lstsq(X, d.regress(data.u), rcond=None)[0]
    out = {"offset": 0.0, **{n: float(b) for n, b in zip(names, beta)}}
    return out


def inverse_start(model: FrictionModel | StaticFriction, data: Motion, deriv: Derivatives | None = None,
                  delay: float = 0.0) -> tuple[Any, float, float]:
    """Start values for any route from the closed-form inverse model (:func:`static_inverse`).

    The model's Coulomb level ``Fc`` (``Fs`` in the same proportion) and its viscous coefficient
    (``b`` of a :class:`prefriction.Viscous` term or of a :class:`StaticFriction`, LuGre's
    ``sigma2``) take the inverse model's values where they come out positive; other parameters
    (stiffnesses, ``gamma``) keep the model's values.

    ``delay`` is the loop's delay in samples (:func:`applied`).

    Returns
    -------
    (model, float, float)
        The start model, the mass [kg] and the offset [N].
    """
    _check(model, data)
    est = static_inverse(applied(data, delay), deriv)
    Fc, b = est["Fc"], est["b"]
    if isinstance(model, StaticFriction):
        vals = {}
        if Fc > 0:
            vals.update(Fc=Fc, **({"Fs": model.Fs * Fc / model.Fc} if model.Fs is not None else {}))
        if b > 0:
            vals["b"] = b
        return model.replace(vals), est["mass"], est["offset"]
    from prefriction.identify.parameters import ParameterSpace
    space = ParameterSpace(model, None, None, None)
    vals = dict(space.start)
    if Fc > 0 and "Fc" in vals:
        ratio = Fc / vals["Fc"]
        vals["Fc"] = Fc
        if "Fs" in vals:
            vals["Fs"] *= ratio
    for name in ("b", "sigma2"):
        if b > 0 and name in vals:
            vals[name] = b
            break
    return space.build(vals), est["mass"], est["offset"]


def fit_inverse(model: FrictionModel | StaticFriction, data: Motion, *, offset: bool = True,
                directional: bool = False, free: Any = None, fixed: Any = None, bounds: dict | None = None,
                mass0: float | None = None, offset0: float = 0.0, deriv: Derivatives | None = None,
                delay: float = 0.0, max_iter: int = 200, tol: float = 1e-10,
                identifiability_limit: float = 0.5) -> FitResult:
    """Fit mass, offset and friction to a driven-mass record by the inverse model (1).

    Parameters
    ----------
    model : FrictionModel or StaticFriction
        The friction model; its values are the start values (as given: see :func:`inverse_start`
        for start values from the data).
    data : Motion
        Positions [m] and applied force [N]; ``data.mass`` known holds the mass, ``None`` fits it.
    offset : bool, default True
        Fit a constant force offset ``"offset"`` [N].
    directional : bool, default False
        Direction-dependent viscous friction: ``b_neg`` of a :class:`StaticFriction` (added if
        the map has none; with ``Fc_neg`` too the map is the EMPS asymmetric model and the offset
        must be off). A dynamic model takes a :class:`prefriction.DirectionalViscous` term instead.
    free, fixed, bounds :
        As :func:`prefriction.identify.fit`, for a dynamic model's parameters (a
        :class:`StaticFriction` map is fitted whole).
    mass0 : float, optional
        Start of a fitted mass [kg]; default the closed-form inverse model's (said in the notes).
    offset0 : float, default 0.0
        Start of the offset [N].
    deriv : Derivatives, optional
        Filtered derivatives (:func:`prefriction.identify.derivatives.derivatives`); default from
        the record's sample rate and noise.
    delay : float, default 0.0
        Samples the recorded force is shifted by before the balance (:func:`applied`): 0.5 for a
        force held over the sample after the one it was computed at, 1.5 if it is applied a
        sample later; 0 as the EMPS reference script.
    max_iter : int, default 200
        Most function evaluations of the solver.
    tol : float, default 1e-10
        Solver tolerance.
    identifiability_limit : float, default 0.5
        Relative standard error above which a parameter is reported as not identifiable.

    Returns
    -------
    FitResult
        Estimates (model parameters, ``mass``, ``offset``) with 95 % intervals; ``data`` is the
        friction force ``D(u) - m D(a)`` the fit explains at the decimated samples (a
        :class:`ForceDisplacement`), ``residuals`` and ``fitted`` are on those samples [N].

    Raises
    ------
    TypeError, ValueError
        For a model or data of the wrong kind, a free decay, unknown names or bad bounds.
    """
    from scipy.optimize import least_squares

    _check(model, data)
    check_solver(max_iter, tol, identifiability_limit)
    data = applied(data, delay)
    d = derivatives(data.t, data.x) if deriv is None else deriv
    notes = [d.summary()] + ([f"force delayed by {delay:g} sample(s)"] if delay else [])
    mass_free = data.mass is None
    closed_form = isinstance(model, StaticFriction) and model.Fs is None
    if mass_free and mass0 is None and closed_form:
        mass0 = 1.0   # only the scale of the mass column: the closed form needs no start
    elif mass_free and mass0 is None:
        mass0 = static_inverse(data, d, offset=offset)["mass"]
        notes.append(f"mass started at the closed-form inverse model's {mass0:.6g} kg")
    if isinstance(model, StaticFriction):
        given = [n for n, v in (("free", free), ("fixed", fixed), ("bounds", bounds)) if v is not None]
        if given:
            raise ValueError(f"{', '.join(given)} apply to a dynamic model; a StaticFriction map is fitted whole in "
                             f"closed form (drop a term by leaving it out of the map, e.g. Fc_neg=None)")
        if directional and model.b_neg is None:
            model = model.replace({"b_neg": model.b})
        if offset and model.Fc_neg is not None:
            raise ValueError("offset=True with a StaticFriction having Fc_neg: an offset and a Coulomb asymmetry are "
                             "the same columns when the record never rests exactly; give offset=False or Fc_neg=None")
        problem = _StaticProblem(model, d, data, offset, mass_free, mass0, offset0)
    elif directional:
        raise ValueError("directional=True is for a StaticFriction map; add a prefriction.DirectionalViscous term "
                         "to a dynamic model (pf.Dahl(...) + pf.DirectionalViscous(b, b_neg)) and fit the offset")
    else:
        problem = _DynamicProblem(model, d, data, offset, free, fixed, bounds, mass_free, mass0, offset0)
    y = d.regress(data.u)
    names, scale = problem.names, problem.scale
    lo, hi = problem.bounds()
    if problem.linear and np.all(np.isinf(lo)) and np.all(np.isinf(hi)):
        J = problem.jacobian(problem.theta0)
        theta = np.linalg.lstsq(J, y - problem.force(np.zeros_like(problem.theta0)), rcond=None)[0]
        message, success = "closed-form linear least squares", True
    else:
        def res(th: np.ndarray) -> np.ndarray:
            return problem.force(th) - y
        with one_blas_thread():
            sol = least_squares(res, problem.theta0, jac=problem.jacobian, bounds=(lo, hi), method="trf", x_scale=1.0,
                                xtol=tol, ftol=tol, gtol=tol, max_nfev=max_iter)
        theta, message, success = sol.x, f"least_squares: {sol.message}", bool(sol.status > 0)
    r = problem.force(theta) - y
    J = problem.jacobian(theta)
    est = theta * scale
    stats = gauss_newton(J, r, names, est, scale, limit=identifiability_limit)
    stats, lag = sandwich(J, r, stats, est, scale, names=names, limit=identifiability_limit)
    for name, reason in stats.unidentifiable:
        warnings.warn(f"the data cannot identify {name}: {reason}; fix it or excite it", IdentifiabilityWarning,
                      stacklevel=2)
    low, high, flags = at_bounds(names, est, stats.low, stats.high, scale, *problem.limits())
    rho = float(np.corrcoef(r[:-1], r[1:])[0, 1]) if r.size > 3 else float("nan")
    notes.append(f"residual lag-1 autocorrelation {rho:.3f} after decimation: Newey-West standard errors, lag {lag}")
    if not success:
        notes.append(f"the solver stopped without converging ({message}); the estimates are its last")
        warnings.warn(f"fit_inverse stopped without converging ({message}); raise max_iter or start closer "
                      f"(inverse_start)", ConvergenceWarning, stacklevel=2)
    fitted_model, mass = problem.build(theta)
    # the data of the result: the friction force the fit explains, u - m a, at the decimated samples [N]
    force = ForceDisplacement(d.regress(d.t), d.regress(d.x), y - mass * problem.acceleration)
    return FitResult(fitted_model, mass, tuple(names), tuple(problem.units), est, stats.stderr, low, high,
                     stats.correlation, -r, y + r - mass * problem.acceleration, force, stats,
                     {}, message, success=success, flags=flags, notes=tuple(["route: inverse model"] + notes))


class _StaticProblem:
    """Residual columns of a static map (analytic Jacobian; linear without a Stribeck term)."""

    def __init__(self, model: StaticFriction, d: Derivatives, data: Motion, offset: bool, mass_free: bool,
                 mass0: float | None, offset0: float) -> None:
        self.model, self.d, self.mass_free = model, d, mass_free
        self.mass_known = data.mass
        self.names = (["mass"] if mass_free else []) + list(model.names) + (["offset"] if offset else [])
        start = {**model.values(), "mass": mass0, "offset": offset0}
        fscale = max(float(np.std(data.u)), 1e-300)
        self.scale = np.array([abs(start[n]) if start[n] else fscale for n in self.names])
        self.theta0 = np.array([start[n] for n in self.names]) / self.scale
        self.units = ["kg" if n == "mass" else "N" if n == "offset" else model.unit(n) for n in self.names]
        self.linear = model.Fs is None
        self._a, self._one = d.regress(d.a), d.regress(np.ones_like(d.a))
        self._cache: dict[tuple, np.ndarray] = {}
        self.acceleration = self._a

    def _vals(self, theta: np.ndarray) -> dict[str, float]:
        return {n: float(t) * s for n, t, s in zip(self.names, theta, self.scale)}

    def _map(self, vals: dict[str, float]) -> StaticFriction:
        return self.model.replace({n: max(vals[n], 1e-12) if n in ("Fc", "Fs", "vs", "delta", "Fc_neg", "Fs_neg")
                                   else vals[n] for n in self.model.names})

    def _columns(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        vals = self._vals(theta)
        F, Jm = self._map(vals).force_and_jacobian(self.d.v)
        key = tuple(np.round(theta, 15))
        if key not in self._cache:
            self._cache = {key: self.d.regress(np.column_stack([F, Jm]))}
        return self._cache[key][:, 0], self._cache[key][:, 1:]

    def force(self, theta: np.ndarray) -> np.ndarray:
        vals = self._vals(theta)
        F = self._columns(theta)[0] if not self.linear else self._columns(theta)[1] @ np.array(
            [vals[n] for n in self.model.names])
        m = vals["mass"] if self.mass_free else self.mass_known
        return m * self._a + F + vals.get("offset", 0.0) * self._one

    def jacobian(self, theta: np.ndarray) -> np.ndarray:
        Jm = self._columns(theta)[1]
        cols = []
        for n in self.names:
            cols.append(self._a if n == "mass" else self._one if n == "offset"
                        else Jm[:, list(self.model.names).index(n)])
        return np.column_stack(cols) * self.scale

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        lo = np.array([0.0 if n in ("b", "b_neg") else 1e-12 if n not in ("offset", "mass") else -np.inf
                       for n in self.names])
        lo = np.where(np.array([n == "mass" for n in self.names]), 0.0, lo)
        if self.linear:
            lo[:] = -np.inf
        return lo / self.scale, np.full(len(self.names), np.inf)

    def limits(self) -> tuple[dict, dict, dict, dict]:
        lo = {n: (-np.inf if n == "offset" else 0.0) for n in self.names}
        hi = {n: np.inf for n in self.names}
        why = {n: "the declared range" for n in self.names}
        return lo, hi, why, dict(why)

    def build(self, theta: np.ndarray) -> tuple[StaticFriction, float]:
        vals = self._vals(theta)
        bad = [n for n in self.model.names if vals[n] <= 0.0 and n not in ("b", "b_neg") or vals[n] < 0.0]
        if bad:
            raise ValueError(f"the inverse model gives {', '.join(f'{n} = {vals[n]:.4g}' for n in bad)}, outside "
                             f"the map's range: the record does not excite that term (check the force's sign "
                             f"convention, or drop the term)")
        return self.model.replace({n: vals[n] for n in self.model.names}), (vals["mass"] if self.mass_free
                                                                           else float(self.mass_known))


class _DynamicProblem:
    """Residual (1) of a dynamic model along the filtered motion (finite-difference Jacobian)."""

    linear = False

    def __init__(self, model: FrictionModel, d: Derivatives, data: Motion, offset: bool, free: Any, fixed: Any,
                 bounds: Any, mass_free: bool, mass0: float | None, offset0: float) -> None:
        from prefriction.identify.parameters import ParameterSpace, name_list

        fscale = max(float(np.std(data.u)), 1e-300)
        self.space = ParameterSpace(model, name_list("free", free), name_list("fixed", fixed), bounds,
                                    mass=mass0 if mass_free else None, offset=fscale if offset else None)
        self.d, self.mass_known = d, data.mass
        self.names, self.scale = list(self.space.free), self.space.scale
        self.theta0 = self.space.theta0.copy()
        if offset:
            self.theta0[self.space.free.index("offset")] = offset0 / fscale
        self.units = [self.space.units[n] for n in self.space.free]
        self._a, self._one = d.regress(d.a), d.regress(np.ones_like(d.a))
        self.acceleration = self._a

    def _friction(self, model: FrictionModel) -> np.ndarray:
        from prefriction.along import friction_along
        return self.d.regress(friction_along(model, self.d.t, self.d.x, v=self.d.v).F)

    def force(self, theta: np.ndarray) -> np.ndarray:
        vals = self.space.values(theta)
        m = vals["mass"] if self.mass_known is None else self.mass_known
        F = self._friction(self.space.build(vals))
        return m * self._a + F + vals.get("offset", 0.0) * self._one

    def jacobian(self, theta: np.ndarray) -> np.ndarray:
        f0 = self.force(theta)
        J = np.empty((f0.size, theta.size))
        for i in range(theta.size):
            h = 1e-5 * max(abs(theta[i]), 1e-2)
            th = theta.copy()
            th[i] += h
            J[:, i] = (self.force(th) - f0) / h
        return J

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        return self.space.theta_bounds()

    def limits(self) -> tuple[dict, dict, dict, dict]:
        sp = self.space
        lo = {n: sp.low[n] for n in sp.free}
        hi = {n: sp.high[n] for n in sp.free}
        why_lo = {n: sp.why_low.get(n, "the declared range") for n in sp.free}
        why_hi = {n: sp.why_high.get(n, "the declared range") for n in sp.free}
        return lo, hi, why_lo, why_hi

    def build(self, theta: np.ndarray) -> tuple[FrictionModel, float]:
        vals = self.space.values(theta)
        return self.space.build(vals), float(vals["mass"] if self.mass_known is None else self.mass_known)
