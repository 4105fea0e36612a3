"""Fit both structures of a model whose parameter range is split (Dahl ``gamma < 1`` and
``gamma >= 1``, ``docs/models.md#structure``) and keep the better one.

The two Dahl structures use different states, so one fit cannot cross ``gamma = 1``: started on
the wrong side it ends on the structure boundary. :func:`fit_structures` runs the fit from the
start model and from the other side, keeps the smaller residual sum of squares, passes on the
winner's warnings only, and records what it compared in ``FitResult.notes``.
"""

from __future__ import annotations

import dataclasses
import warnings
from typing import Callable

from prefriction.errors import SolverError
from prefriction.identify.result import FitResult
from prefriction.models.base import FrictionModel

__all__ = ["fit_structures", "gamma_entry", "other_structure"]


def gamma_entry(model: FrictionModel) -> str | None:
    """The fit's name of the Dahl ``gamma`` of ``model`` (a Dahl, or a sum with exactly one
    Dahl), or ``None``.

    Parameters
    ----------
    model : FrictionModel
        The start model.

    Returns
    -------
    str or None
        ``"gamma"``, or its name in a sum (``"dahl.gamma"`` if another term has a ``gamma``).
    """
    from prefriction.identify.parameters import _entries
    from prefriction.models.dahl import Dahl

    parts = getattr(model, "models", (model,))
    dahl = [i for i, m in enumerate(parts) if isinstance(m, Dahl)]
    if len(dahl) != 1:
        return None
    if parts == (model,):
        return "gamma"
    return next(e.name for e in _entries(model) if e.part == dahl[0] and e.local == "gamma")


def other_structure(model: FrictionModel) -> FrictionModel:
    """The start model on the other side of Dahl's structure boundary ``gamma = 1``.

    Parameters
    ----------
    model : FrictionModel
        A Dahl, or a sum with exactly one Dahl (:func:`gamma_entry` is not ``None``).

    Returns
    -------
    FrictionModel
        The model with the Dahl's ``gamma = 0.5`` for a start at ``gamma >= 1``, ``1.5`` otherwise.
    """
    from prefriction.models.dahl import Dahl

    def swap(m: FrictionModel) -> FrictionModel:
        return dataclasses.replace(m, gamma=0.5 if m.gamma >= 1.0 else 1.5) if isinstance(m, Dahl) else m

    parts = getattr(model, "models", None)
    return swap(model) if parts is None else type(model)(tuple(swap(m) for m in parts))


def _gamma(model: FrictionModel) -> float:
    from prefriction.models.dahl import Dahl

    return next(m.gamma for m in getattr(model, "models", (model,)) if isinstance(m, Dahl))


def _label(model: FrictionModel) -> str:
    g = _gamma(model)
    return f"gamma {'>=' if g >= 1.0 else '<'} 1 (started at gamma = {g:g})"


def fit_structures(model: FrictionModel, one: Callable[[FrictionModel], FitResult], compare: str | None) -> FitResult:
    """``one(model)``, or the better of ``one`` on both structures when ``compare`` is true.

    Parameters
    ----------
    model : FrictionModel
        The start model.
    one : callable
        Fits one start model and returns its :class:`FitResult` (may raise :class:`SolverError`).
    compare : str or None
        The fit's name of the Dahl ``gamma`` to try on both sides of 1, or ``None`` (fit ``model``
        only).

    Returns
    -------
    FitResult
        The fit with the smaller residual sum of squares; its ``notes`` say what was compared.

    Raises
    ------
    prefriction.SolverError
        If every structure's fit fails (the start model's error).
    """
    if compare is None:
        return one(model)
    other = other_structure(model)
    runs = []
    for start in (model, other):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                res: FitResult | SolverError = one(start)
            except SolverError as exc:
                res = exc
        runs.append((start, res, caught))
    done = [r for r in runs if isinstance(r[1], FitResult)]
    if not done:
        raise runs[0][1]
    best = min(done, key=lambda r: float(r[1].residuals @ r[1].residuals))
    lines = []
    for start, res, _ in runs:
        if isinstance(res, SolverError):
            lines.append(f"{_label(start)}: failed ({res})")
            continue
        g = res.estimate(compare)
        flag = res.flags[res.names.index(compare)]
        lines.append(f"{_label(start)}: rms {res.rms:.4g} N, gamma = {g:.4g}" + (f", {flag}" if flag else ""))
    kept = "gamma >= 1" if _gamma(best[1].model) >= 1.0 else "gamma < 1"
    note = f"compared both Dahl structures: {'; '.join(lines)}; kept {kept} (smaller residual)"
    if kept == "gamma < 1":
        note += ("; controllers.FrictionObserver and optimal.point_to_point refuse gamma < 1 (fit with "
                 "structures='given' from gamma >= 1 for them, docs/conventions.md#fits-downstream)")
    for w in best[2]:
        warnings.warn(w.message, w.category, stacklevel=3)
    return dataclasses.replace(best[1], notes=best[1].notes + (note,))

