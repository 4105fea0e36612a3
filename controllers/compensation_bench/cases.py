"""The stage, plants, compensators, tasks and conditions of the compensation bench (SI units)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Optional

import prefriction as pf
from prefriction.signals import PointToPoint, Sine

from .._linear import design_pid
from .._pid import PID
from ..compensators import Compensator, DisturbanceObserver, Feedforward, FrictionObserver, LuGreObserver

M, SIGMA, FC, FS, VS = 1.0, 1e6, 1.0, 1.3, 1e-4  # kg, N/m, N, N, m/s
TS = 1e-4  # s (10 kHz)
WINDOW = 0.1  # s: the reversal spike is the largest |e| within this time after a reference reversal
BAND = 1e-8  # m: the settling band of the point-to-point moves
MISMATCH = (1.2, 0.8)  # the compensators' stiffness +20 %, Coulomb force -20 %
QUANT, NOISE = 5e-9, 2e-9  # m: encoder step and measurement noise (rms) of the "quantised" condition


def plants() -> dict[str, pf.FrictionModel]:
    """The three friction models of the stage: rest stiffness about ``SIGMA``, Coulomb ``FC``."""
    return {
        "Dahl": pf.Dahl(sigma=SIGMA, Fc=FC),
        "LuGre": pf.LuGre(sigma0=SIGMA, sigma1=200.0, sigma2=0.0, Fc=FC, Fs=FS, vs=VS),
        "GMS": pf.GMS(k=[0.6 * SIGMA, 0.3 * SIGMA, 0.1 * SIGMA], alpha=[0.2, 0.3, 0.5], Fc=FC, Fs=FS, vs=VS, C=2e3),
    }


def lugre_of(model: pf.FrictionModel) -> pf.LuGre:
    """The LuGre model an observer designer would fit to ``model`` (same rest stiffness and forces;
    a Dahl model with gamma = 1 is the LuGre model with ``Fs = Fc``, no damping)."""
    if isinstance(model, pf.LuGre):
        return model
    Fs = getattr(model, "Fs", model.Fc)
    return pf.LuGre(sigma0=model.sigma, sigma1=0.0, sigma2=0.0, Fc=model.Fc, Fs=Fs, vs=getattr(model, "vs", 1.0))


def controller(system: pf.Oscillator) -> PID:
    """The PID tuned for disturbance rejection: poles at 150 Hz (damping 0.7) and a real pole at
    150 Hz on the pre-sliding linearisation (high integral gain against the friction force)."""
    return design_pid(system, wn=2.0 * math.pi * 150.0, zeta=0.7)


def compensators(model: pf.FrictionModel) -> dict[str, Optional[Compensator]]:
    """PID alone and the four compensators, each with the plant's (nominal) model."""
    return {
        "PID alone": None,
        "feedforward": Feedforward(model),
        "LuGre observer": LuGreObserver(lugre_of(model), gain=2e3),
        "friction observer": FrictionObserver(pf.Dahl(sigma=model.sigma, Fc=model.Fc), pole=1000.0),
        "disturbance observer": DisturbanceObserver(bandwidth=2.0 * math.pi * 300.0),
    }


@dataclass(frozen=True)
class Task:
    """A reference, its length [s] and the times [s] of its reversals and of the ends of its moves."""

    name: str
    reference: Any
    t_end: float
    reversals: tuple
    move_ends: tuple


def tasks() -> list[Task]:
    """Sine tracking through zero velocity (5 um amplitude, 1 Hz, from rest at 0) and two S-curve
    moves of 10 um (out and back)."""
    sine = Sine(5e-6, 1.0, phase=-math.pi / 2, offset=5e-6)
    out = PointToPoint(1e-5, v_max=2e-4, a_max=5e-3, j_max=0.5)
    back = PointToPoint(-1e-5, v_max=2e-4, a_max=5e-3, j_max=0.5, start=0.3)
    return [
        Task("sine", sine, 2.0, (0.5, 1.0, 1.5), ()),
        Task("point-to-point", out + back, 0.6, (0.3,), (out.duration, 0.3 + back.duration)),
    ]


CONDITIONS = {
    "nominal": {},
    "mismatch": {"mismatch": MISMATCH},
    "quantised": {"quantization": QUANT, "noise_rms": NOISE, "seed": 1},
}
"""The conditions: nominal, the compensators' model off by ``MISMATCH``, and the measurement
rounded to ``QUANT`` with noise of rms ``NOISE`` (nominal models)."""
