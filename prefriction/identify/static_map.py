"""Static friction maps: Coulomb + viscous + Stribeck, with direction-dependent levels.

The classic steady-sliding friction (FrictionModels.jl ``CoulombModel``, ``ViscousModel``,
``StribeckModel``; Olsson et al., *Friction models and friction compensation*, Eur. J. Control
4(3), 1998, (7))::

    F(v) = s (Fc_s + (Fs_s - Fc_s) exp(-|v / vs|^delta)) + b_s v,   s = sign(v),      (1)

with the Coulomb level ``Fc_s``, the static level ``Fs_s`` and the viscous coefficient ``b_s`` of
the direction ``s``: the same for both directions by default, ``Fc_neg``, ``Fs_neg``, ``b_neg``
for ``v < 0`` when given (EMPS and most drives are asymmetric). Without ``Fs`` the map is Coulomb + viscous, linear in its parameters.
Fitted to :class:`prefriction.identify.ForceVelocity` data by :func:`prefriction.identify.fit`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from prefriction._validation import check_nonnegative, check_positive

__all__ = ["StaticFriction"]

_UNITS = {"Fc": "N", "b": "N s/m", "Fs": "N", "vs": "m/s", "delta": "-", "Fc_neg": "N", "Fs_neg": "N",
          "b_neg": "N s/m"}


@dataclass(frozen=True)
class StaticFriction:
    """Steady-sliding friction map (1): Coulomb, viscous and Stribeck terms, optionally
    direction-dependent.

    Parameters
    ----------
    Fc : float
        Coulomb force [N] (of ``v > 0`` when ``Fc_neg`` is given), ``0 < Fc < inf``.
    b : float, default 0.0
        Viscous coefficient [N s/m], ``0 <= b < inf``.
    Fs : float or None, default None
        Static (breakaway) force [N] of the Stribeck term, ``0 < Fs < inf``; ``None``: no
        Stribeck term.
    vs : float, default 1e-3
        Stribeck velocity [m/s], ``0 < vs < inf`` (used with ``Fs``).
    delta : float, default 2.0
        Stribeck shape exponent [-], ``0 < delta < inf`` (2: Gaussian; used with ``Fs``).
    Fc_neg, Fs_neg : float or None, default None
        Coulomb and static force magnitudes [N] for ``v < 0``; ``None``: the same as for ``v > 0``.
        ``Fs_neg`` needs ``Fs``.
    b_neg : float or None, default None
        Viscous coefficient [N s/m] for ``v < 0``, ``0 <= b_neg < inf``; ``None``: ``b``.

    Raises
    ------
    ValueError
        If a value is outside its range or ``Fs_neg`` is given without ``Fs`` (the message
        names the argument).
    TypeError
        If a value is not a real number.

    Examples
    --------
    >>> import prefriction as pf
    >>> m = pf.identify.StaticFriction(Fc=20.0, b=200.0, Fc_neg=18.0)
    >>> [round(float(f), 3) for f in m.force([-0.1, 0.1])]
    [-38.0, 40.0]
    """

    Fc: float
    b: float = 0.0
    Fs: float | None = None
    vs: float = 1e-3
    delta: float = 2.0
    Fc_neg: float | None = None
    Fs_neg: float | None = None
    b_neg: float | None = None

    def __post_init__(self) -> None:
        for name in ("Fc", "vs", "delta") + tuple(n for n in ("Fs", "Fc_neg", "Fs_neg") if getattr(self, n) is not None):
            object.__setattr__(self, name, check_positive(name, getattr(self, name)))
        object.__setattr__(self, "b", check_nonnegative("b", self.b))
        if self.b_neg is not None:
            object.__setattr__(self, "b_neg", check_nonnegative("b_neg", self.b_neg))
        if self.Fs_neg is not None and self.Fs is None:
            raise ValueError(f"Fs_neg = {self.Fs_neg!r} needs a Stribeck term: give Fs too (or Fs_neg=None)")

    @property
    def names(self) -> tuple[str, ...]:
        """The parameters the map uses (``Fs``, ``vs``, ``delta`` only with a Stribeck term)."""
        out = ["Fc", "b"] + (["Fs", "vs", "delta"] if self.Fs is not None else [])
        return tuple(out + [n for n in ("Fc_neg", "Fs_neg", "b_neg") if getattr(self, n) is not None])

    @staticmethod
    def unit(name: str) -> str:
        """The unit of parameter ``name``."""
        return _UNITS[name]

    def values(self) -> dict[str, float]:
        """The used parameters by name."""
        return {n: float(getattr(self, n)) for n in self.names}

    def replace(self, values: dict[str, float]) -> "StaticFriction":
        """A map with ``values`` (by name) in place of these (checked as on construction)."""
        kw = {n: getattr(self, n) for n in ("Fc", "b", "Fs", "vs", "delta", "Fc_neg", "Fs_neg", "b_neg")}
        kw.update(values)
        return StaticFriction(**kw)

    def force(self, v: Any) -> np.ndarray:
        """Friction force (1) [N] at the sliding velocities ``v`` [m/s] (0 at ``v = 0``)."""
        return self.force_and_jacobian(np.asarray(v, dtype=float))[0]

    def force_and_jacobian(self, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Force (1) [N] at ``v`` [m/s] and its derivatives with respect to :attr:`names` (columns)."""
        v = np.asarray(v, dtype=float)
        names = self.names
        J = np.zeros((v.size, len(names)))
        s = np.sign(v)
        pos = v > 0
        col = {n: i for i, n in enumerate(names)}
        lv = {"Fc": np.where(pos, self.Fc, self.Fc if self.Fc_neg is None else self.Fc_neg)}
        cname = np.where(pos, "Fc", "Fc" if self.Fc_neg is None else "Fc_neg")
        if self.b_neg is None:
            F = self.b * v
            J[:, col["b"]] = v
        else:
            F = np.where(pos, self.b, self.b_neg) * v
            J[:, col["b"]] = np.where(pos, v, 0.0)
            J[:, col["b_neg"]] = np.where(pos, 0.0, v)
        if self.Fs is None:
            F = F + s * lv["Fc"]
            for n in set(cname.tolist()):
                J[:, col[n]] += np.where(cname == n, s, 0.0)
            return F, J
        Fs = np.where(pos, self.Fs, self.Fs if self.Fs_neg is None else self.Fs_neg)
        sname = np.where(pos, "Fs", "Fs" if self.Fs_neg is None else "Fs_neg")
        r = np.abs(v / self.vs)
        p = r ** self.delta
        e = np.exp(-p)
        F = F + s * (lv["Fc"] + (Fs - lv["Fc"]) * e)
        for n in set(cname.tolist()):
            J[:, col[n]] += np.where(cname == n, s * (1.0 - e), 0.0)
        for n in set(sname.tolist()):
            J[:, col[n]] += np.where(sname == n, s * e, 0.0)
        gap = s * (Fs - lv["Fc"]) * e
        J[:, col["vs"]] = gap * p * self.delta / self.vs
        with np.errstate(divide="ignore", invalid="ignore"):
            J[:, col["delta"]] = np.where(r > 0, -gap * p * np.log(np.where(r > 0, r, 1.0)), 0.0)
        return F, J

    def __repr__(self) -> str:
        body = ", ".join(f"{n}={getattr(self, n):.6g}" for n in self.names)
        return f"StaticFriction({body})"

