"""Cost measurements of ``prefriction bench``: target 3 (linear cost) and the exact analytics.

:func:`linear_cost` compares the warm time per reversal at 50 and at ``n`` reversals in
interleaved rounds (``docs/bench.md#targets``); :func:`analytics_timing` times the exact
reference itself (``docs/bench.md#other-output``).
"""

from __future__ import annotations

import math

import numpy as np

from prefriction.analysis.dahl import next_amplitude
from prefriction.cli.bench.cases import HEADLINE, N_REV, exact
from prefriction.cli.bench.timing import min_time
from prefriction.simulation.simulate import simulate


def analytics_timing(repeats: int, n_amp: int = 1_000_000, n_rev: int = 10_000) -> list[str]:
    """Lines timing the exact analytics.

    :func:`prefriction.analysis.dahl.next_amplitude` on ``n_amp`` amplitudes against
    ``numpy.exp`` on the same array, and :func:`prefriction.exact_reversals` for ``n_rev``
    reversals of the headline case (minimum of ``repeats`` warm runs).

    Parameters
    ----------
    repeats : int
        Warm repeats (half as many, at least one, for ``exact_reversals``).
    n_amp : int, optional
        Amplitudes, log-spaced over [1e-12, 1].
    n_rev : int, optional
        Reversals of the exact table.

    Returns
    -------
    list of str
        Two printable lines.
    """
    a = np.logspace(-12, 0, n_amp)
    _, t_map = min_time(lambda: next_amplitude(a), calls=repeats, stop_best=0.5)
    _, t_exp = min_time(lambda: np.exp(a), calls=repeats, stop_best=0.5)
    _, t_ref = min_time(lambda: exact(HEADLINE, n_rev), calls=max(1, repeats // 2), stop_best=0.5)
    return [
        f"next_amplitude on {n_amp:.0e} amplitudes in [1e-12, 1]: {t_map * 1e3:.1f} ms "
        f"= {t_map / t_exp:.0f} x numpy.exp on the same array ({t_exp * 1e3:.2f} ms)",
        f"exact_reversals, {n_rev} reversals of the headline case: {t_ref * 1e3:.0f} ms "
        f"({t_ref / n_rev * 1e6:.1f} us per reversal)",
    ]


def linear_cost(tol: float, n_long: int, repeats: int) -> tuple[float, float]:
    """Warm time per reversal of the headline case at 50 and at ``n_long`` reversals [s].

    Load on the machine must neither fake a failure nor a pass, so the two are measured in
    interleaved rounds of equal length: one round is ``n_long / 50`` runs of 50 reversals
    followed by one run of ``n_long`` reversals (the same number of reversals, so both see the
    same load), and for each the minimum over at least three rounds is kept.

    Parameters
    ----------
    tol : float
        ``rtol`` of the runs.
    n_long : int
        Reversals of the long run.
    repeats : int
        Rounds (at least three).

    Returns
    -------
    (float, float)
        Time per reversal at 50 and at ``n_long`` reversals [s].
    """
    case = HEADLINE

    def wall(n: int) -> float:
        return simulate(case.system, case.v0, reversals=n, rtol=tol).stats.wall_time

    wall(N_REV)
    wall(n_long)  # compiled code loaded, caches warm
    k = max(1, round(n_long / N_REV))
    t50 = tl = math.inf
    for _ in range(max(3, repeats)):
        t50 = min(t50, sum(wall(N_REV) for _ in range(k)) / (k * N_REV))
        tl = min(tl, wall(n_long) / n_long)
    return t50, tl
