"""Sums of signals: :class:`Sum` (what ``+`` of signals makes)."""

from __future__ import annotations

from collections.abc import Hashable
from typing import Any, Optional, Union

import numpy as np

from prefriction.signals.base import Signal

__all__ = ["Sum"]


class Sum(Signal):
    """Sum of signals; nested sums are flattened. Usually made with ``+``.

    Parameters
    ----------
    *terms : Signal
        At least one signal.
    """

    __slots__ = ("terms",)

    def __init__(self, *terms: Signal) -> None:
        if not terms:
            raise ValueError("terms must hold at least one Signal, got none")
        flat = []
        for term in terms:
            if not isinstance(term, Signal):
                raise TypeError(f"terms must be Signals, got {term!r} of type {type(term).__name__}")
            flat.extend(term.terms if isinstance(term, Sum) else (term,))
        self._set(terms=tuple(flat))

    @property
    def key(self) -> Hashable:
        """``("Sum", key1, key2, ...)``."""
        return ("Sum", *(term.key for term in self.terms))

    @property
    def n_params(self) -> int:
        """Total number of run-time parameters of the terms."""
        return sum(term.n_params for term in self.terms)

    @property
    def n_piece(self) -> int:
        """Total number of per-interval numbers of the terms."""
        return sum(term.n_piece for term in self.terms)

    def params(self) -> np.ndarray:
        """Run-time parameters of the terms, concatenated (length :attr:`n_params`)."""
        return np.concatenate([term.params() for term in self.terms])

    def linear_piece(self, ta: float, tb: float) -> Optional[tuple[float, float]]:
        """Sum of the terms' pieces if every term is piecewise linear, else ``None``."""
        a = b = 0.0
        for term in self.terms:
            lp = term.linear_piece(ta, tb)
            if lp is None:
                return None
            a, b = a + lp[0], b + lp[1]
        return a, b

    def piece(self, ta: float, tb: float) -> np.ndarray:
        """Per-interval numbers of the terms on ``[ta, tb]`` [s], concatenated (length :attr:`n_piece`)."""
        return np.concatenate([np.zeros(0)] + [term.piece(ta, tb) for term in self.terms])

    def _expr(self, t: Any, theta: Any, piece: Any, ops: Any) -> Any:
        total, i, j = 0.0, 0, 0
        for term in self.terms:
            n, m = term.n_params, term.n_piece
            total = total + term._expr(t, theta[i:i + n], piece[j:j + m], ops)
            i, j = i + n, j + m
        return total

    def __call__(self, t: Any) -> Union[float, np.ndarray]:
        """Numeric value at the time(s) ``t`` [s]: the sum of the terms' values, shaped like ``t``."""
        value = sum(np.asarray(term(t), dtype=float) for term in self.terms)
        return float(value) if np.ndim(value) == 0 else value

    def velocity(self, t: Any) -> Union[float, np.ndarray]:
        """Time derivative [signal units / s] at the time(s) ``t`` [s]: the sum of the terms' (:meth:`Signal.velocity`)."""
        value = sum(np.asarray(term.velocity(t), dtype=float) for term in self.terms)
        return float(value) if np.ndim(value) == 0 else value

    def breaks(self) -> np.ndarray:
        """Union of the terms' breaks: sorted unique times [s]."""
        return np.unique(np.concatenate([np.zeros(0)] + [term.breaks() for term in self.terms]))

    def bound(self, t_end: float) -> float:
        """Sum of the terms' bounds over ``[0, t_end]`` [signal units] (:meth:`Signal.bound`)."""
        return float(sum(term.bound(t_end) for term in self.terms))

    def __repr__(self) -> str:
        return "Sum(" + ", ".join(repr(term) for term in self.terms) + ")"


Signal._sum = Sum  # Signal.__add__ builds it (the kinds import Signal, not the reverse)
