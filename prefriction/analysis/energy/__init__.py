"""Energy analysis of pre-sliding trajectories (paper section 2, (2.3)-(2.12)).

Works on any trajectory, given either as dense samples ``(t, x, v, F)`` in SI units or as
the states at the velocity reversals (a :class:`prefriction.ReversalTable`).

Building blocks (model-free unless said otherwise):

- :func:`find_reversals`: velocity reversals ``x'(t_i) = 0`` located between samples;
- :func:`kinetic_energy`, :func:`integrated_power` (2.8, time form), :func:`work_integral`
  (2.8, displacement form);
- :func:`loop_integral`: dissipation ``oint F dx`` of a closed hysteresis cycle (2.5)/(2.7);
  zero for a linear spring (2.6);
- :func:`branch_energy`, :func:`total_energy` (Dahl model): energy stored on a branch relative
  to its force zero crossing, (3.9) for ``gamma = 1``;
- :func:`dissipation` (2.10), :func:`series` (2.11), :func:`bound_check` (2.12);
- :func:`analyze_samples`, :func:`analyze_table`: all of it at once, as an :class:`EnergyReport`;
  :func:`analyze_result` of a run with samples (``prefriction.simulate``, an entry of
  ``prefriction.sweep``, ``controllers.simulate_loop``), counting the work of the applied force
  ``result.u``, a controller's too (held between the samples of a sampled controller).

Models: any rate-independent :class:`prefriction.FrictionModel` with a branch energy (Dahl,
Maxwell-slip); a :class:`prefriction.GMS` with ``Fs = Fc`` and no damping, analysed as the equal
Maxwell-slip model; and :class:`prefriction.LuGre`, for which :func:`analyze_samples` returns a
:class:`LuGreEnergyReport` with the stored bristle energy at the reversals and the viscous and
hysteretic dissipation per half-cycle apart (:func:`bristle_deflection` recovers the
deflection from the samples; docs/mathematics.md#lugre-energy).

Every public function raises ``TypeError`` or ``ValueError`` naming the argument, its value and
the allowed range for ``None``, strings, complex numbers, NaN, inf, negative energies, empty or
mismatched arrays and unsorted times.

Conventions (as in :class:`prefriction.ReversalTable`): reversal ``k`` ends half-cycle ``k``
(half-cycle 0 is the first excursion from the initial state); ``E_p[k]`` is the potential
energy at reversal ``k``, i.e. the energy the new branch returns as kinetic energy until its
force zero crossing; ``E_d[k]`` and ``W_u[k]`` of a report are the energy dissipated and the
input's work in the half-cycle that *ends* at reversal ``k``, one entry per reversal, so
``report.E_d[k]`` and ``table.E_d[k]`` are the same half-cycle. ``E_d[k]`` for ``k >= 1`` is the
paper's ``E_d(k - 1)`` in (2.10). The functions on bare arrays, :func:`dissipation` and
:func:`series`, take the half-cycles between reversals (``E_d[1:]``).

The functions live in private modules of :mod:`prefriction.analysis.energy`: reversals in
samples ``sampled_reversals``, energies along samples ``sampled_energy``, the input's work
between reversals ``work``, energies at reversals ``balance``, the report ``report``, the
analysis of samples and runs ``analyze``, of reversal tables ``table_report``, LuGre ``lugre``
and ``lugre_report``, argument checks ``checks``.
"""

from __future__ import annotations

from prefriction.analysis.energy.balance import BoundCheck, bound_check, branch_energy, dissipation, series
from prefriction.analysis.energy.lugre import bristle_deflection
from prefriction.analysis.energy.lugre_report import LuGreEnergyReport
from prefriction.analysis.energy.analyze import analyze_result, analyze_samples
from prefriction.analysis.energy.report import EnergyReport
from prefriction.analysis.energy.table_report import analyze_table
from prefriction.analysis.energy.sampled_energy import integrated_power, kinetic_energy, loop_integral, total_energy, work_integral
from prefriction.analysis.energy.sampled_reversals import SampledReversals, find_reversals

__all__ = [
    "BoundCheck",
    "EnergyReport",
    "LuGreEnergyReport",
    "SampledReversals",
    "analyze_result",
    "analyze_samples",
    "analyze_table",
    "bound_check",
    "bristle_deflection",
    "branch_energy",
    "dissipation",
    "find_reversals",
    "integrated_power",
    "kinetic_energy",
    "loop_integral",
    "series",
    "total_energy",
    "work_integral",
]
