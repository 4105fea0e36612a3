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

__all__ = ["fit_structures", "other_structure"]


def other_structure(model: FrictionModel) -> FrictionModel | None:
    """The start model on the other side of its structure boundary, or ``None`` if it has none.

    Parameters
    ----------
    model : FrictionModel
        The start model.

    Returns
    -------
    FrictionModel or None
        Dahl with ``gamma = 0.5`` for a start at ``gamma >= 1``, ``gamma = 1.5`` otherwise.
    """
    from prefriction.models.dahl import Dahl

    if isinstance(model, Dahl):
        return dataclasses.replace(model, gamma=0.5 if model.gamma >= 1.0 else 1.5)
    return None


def _label(model: FrictionModel) -> str:
    return f"gamma {'>=' if model.gamma >= 1.0 else '<'} 1 (started at gamma = {model.gamma:g})"


def fit_structures(model: FrictionModel, one: Callable[[FrictionModel], FitResult], compare: bool) -> FitResult:
    """``one(model)``, or the better of ``one`` on both structures when ``compare`` is true.

    Parameters
    ----------
    model : FrictionModel
        The start model.
    one : callable
        Fits one start model and returns its :class:`FitResult` (may raise :class:`SolverError`).
    compare : bool
        Try the other structure too (if the model has one).

    Returns
    -------
    FitResult
        The fit with the smaller residual sum of squares; its ``notes`` say what was compared.

    Raises
    ------
    prefriction.SolverError
        If every structure's fit fails (the start model's error).
    """
    other = other_structure(model) if compare else None
    if other is None:
        return one(model)
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
        g = res.estimate("gamma")
        flag = res.flags[res.names.index("gamma")]
        lines.append(f"{_label(start)}: rms {res.rms:.4g}, gamma = {g:.4g}" + (f", {flag}" if flag else ""))
    kept = "gamma >= 1" if best[1].model.gamma >= 1.0 else "gamma < 1"
    note = f"compared both Dahl structures: {'; '.join(lines)}; kept {kept} (smaller residual)"
    for w in best[2]:
        warnings.warn(w.message, w.category, stacklevel=4)
    return dataclasses.replace(best[1], notes=best[1].notes + (note,))

