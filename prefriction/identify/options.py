"""The solver options every identification route takes, and their allowed ranges."""

from __future__ import annotations

from typing import Any

from prefriction._validation import check_count, check_positive

__all__ = ["MAX_ITER", "TOL_RANGE", "check_solver"]

TOL_RANGE = (1e-14, 1e-6)
"""Allowed solver tolerances: a looser one stops the solver before the estimates settle within a
fraction of their standard errors (``fit(tol=10)`` stopped at gamma 1.21 for a truth of 1.5)."""
MAX_ITER = 100_000
"""Most solver iterations ``max_iter`` may ask for."""


def check_solver(max_iter: Any, tol: Any, limit: Any) -> tuple[int, float, float]:
    """The checked ``(max_iter, tol, identifiability_limit)`` of a fit.

    Raises
    ------
    ValueError
        Naming the option, its value and the allowed range.
    """
    max_iter = check_count("max_iter", max_iter, 1, MAX_ITER, "solver iterations")
    tol = check_positive("tol", tol)
    if not TOL_RANGE[0] <= tol <= TOL_RANGE[1]:
        raise ValueError(f"tol must be in [{TOL_RANGE[0]:g}, {TOL_RANGE[1]:g}], got {tol!r}: a looser tolerance "
                         f"stops the solver before the estimates settle, a tighter one is below rounding")
    return max_iter, tol, check_positive("identifiability_limit", limit)
