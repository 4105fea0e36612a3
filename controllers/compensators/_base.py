"""The compensator interface shared by the feedforward and the observers, and model mismatch."""

from __future__ import annotations

import dataclasses
from abc import ABC, abstractmethod
from typing import Any

import casadi as ca
import numpy as np

from prefriction._validation import check_positive
from prefriction.models import GMS, Dahl, ElastoPlastic, LuGre, MaxwellSlip
from prefriction.models.base import FrictionModel

__all__ = ["Compensator", "scaled_model"]


class Compensator(ABC):
    """A force added to the controller's at every sample of a sampled loop.

    The per-sample update is the CasADi Function of :meth:`update_function`,
    ``(state, meas, ref, params) -> (state_next, force)``:

    - ``meas = [y_k, u_{k-1}]``: the measured position [m] and the total force [N] applied over
      the previous period (controller plus compensation, after the limit);
    - ``ref = [r_k, r_{k+1}, r'_k, r'_{k+1}]``: the reference position [m] at this and the next
      sample and its velocity [m/s];
    - ``params``: the numbers of :meth:`numbers` (model, gains, mass, sample time).

    The structure (what is compiled) is :meth:`structure`; every number is a run-time input.
    """

    @abstractmethod
    def structure(self) -> Any:
        """Hashable structure of the compiled update (equal structures share one compile)."""

    @abstractmethod
    def numbers(self, mass: float, Ts: float, x0: float) -> tuple[np.ndarray, np.ndarray]:
        """``(params, state0)``: the run-time numbers and the initial state of the update.

        Parameters
        ----------
        mass : float
            Moving mass of the stage [kg] (the feedforward's inertia, the observers' model).
        Ts : float
            Sample time [s].
        x0 : float
            Initial position [m] (the stage at rest there).

        Returns
        -------
        (numpy.ndarray, numpy.ndarray)
        """

    def update_function(self) -> ca.Function:
        """The per-sample update ``(state, meas, ref, params) -> (state_next, force)`` (CasADi).

        Returns
        -------
        casadi.Function
            Inputs ``state`` (``n_state``), ``meas`` (2), ``ref`` (4), ``params`` (``n_param``);
            outputs the next state and the force [N]. With :meth:`numbers` this is all a
            code generator needs (``Function.generate``).
        """
        f = self.structure().function()
        names = ["state", "meas", "ref", "params"]
        syms = [ca.SX.sym(n, f.size1_in(i)) for i, n in enumerate(names)]
        return ca.Function(f.name(), syms, f(*syms), names, ["state_next", "force"])

    def with_model(self, model: FrictionModel) -> "Compensator":
        """The same compensator with another friction model (model mismatch); model-free
        compensators return themselves."""
        return dataclasses.replace(self, model=model) if hasattr(self, "model") else self


def scaled_model(model: FrictionModel, stiffness: float = 1.0, coulomb: float = 1.0) -> FrictionModel:
    """``model`` with its stiffness and its friction forces multiplied by factors (model mismatch).

    Parameters
    ----------
    model : Dahl, LuGre, ElastoPlastic, MaxwellSlip or GMS
        The model.
    stiffness : float, default 1.0
        Factor of the rest stiffness [-], ``> 0``: Dahl ``sigma``, LuGre and ElastoPlastic ``sigma0``
        (ElastoPlastic's ``z_ba`` by ``coulomb / stiffness``: the same breakaway fraction), every element
        stiffness of Maxwell-slip and GMS.
    coulomb : float, default 1.0
        Factor of the friction forces [-], ``> 0``: ``Fc`` (and LuGre's and GMS's ``Fs``, so the
        Stribeck ratio is kept; Maxwell-slip's slip forces).

    Returns
    -------
    FrictionModel

    Raises
    ------
    TypeError
        If ``model`` is of another kind.
    ValueError
        If a factor is not finite and positive.
    """
    ks, kc = check_positive("stiffness", stiffness), check_positive("coulomb", coulomb)
    if isinstance(model, Dahl):
        return dataclasses.replace(model, sigma=model.sigma * ks, Fc=model.Fc * kc)
    if isinstance(model, LuGre):
        return dataclasses.replace(model, sigma0=model.sigma0 * ks, Fc=model.Fc * kc, Fs=model.Fs * kc)
    if isinstance(model, ElastoPlastic):  # the breakaway at the same fraction of Fc / sigma0
        return dataclasses.replace(model, sigma0=model.sigma0 * ks, Fc=model.Fc * kc, Fs=model.Fs * kc,
                                   z_ba=model.z_ba * kc / ks)
    if isinstance(model, GMS):
        return dataclasses.replace(model, k=np.asarray(model.k) * ks, Fc=model.Fc * kc, Fs=model.Fs * kc)
    if isinstance(model, MaxwellSlip):
        return dataclasses.replace(model, stiffness=np.asarray(model.stiffness) * ks,
                                   slip_force=np.asarray(model.slip_force) * kc)
    raise TypeError(f"model must be a Dahl, LuGre, ElastoPlastic, MaxwellSlip or GMS model, got {model!r} of type {type(model).__name__}")
