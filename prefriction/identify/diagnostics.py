"""Residual diagnostics of a fit: structure the model does not explain, and whom it misleads.

Three checks on the residuals ``r`` of :func:`prefriction.identify.fit`, in sample order:

- runs: the number ``R`` of runs of equal sign against its mean and variance for independent
  signs (Wald and Wolfowitz, *Ann. Math. Statist.* 11, 1940, 147-162):
  ``E R = 1 + 2 n+ n- / n``, ``Var R = 2 n+ n- (2 n+ n- - n) / (n^2 (n - 1))``, ``z = (R - E R) / sqrt(Var R)``
  (eq. D1);
- autocorrelation ``rho_l = sum r_t r_{t-l} / sum r_t^2`` for lags up to 50 (eq. D2);
- spikes at reversals: the rms residual over the first tenth of the samples between two
  reversals, after each reversal, against the rms elsewhere (eq. D3).

The residuals show *structure* when the runs are far too few (``z < -4``) and
``rho_1 > 0.3`` (a smooth misfit holds at least 30 % of their variance), or the reversal
rms is more than twice the rest, or (a :class:`Motion` record with its position noise
declared) the residual rms is more than twice the measurement's,
``sqrt(x_noise^2 + quantum^2 / 12)`` (eq. D4). Which estimates that misleads is read from the influence
``psi_t`` of each sample on each estimate (``statistics.py``, eq. S1): an estimate is to be
distrusted when the samples after the reversals pull it by more than 2 standard errors
(``|sum_{t in reversal windows} psi_t| > 2 se``), or when its HAC standard error is more than
twice the white-residual one (its information comes from stretches of correlated residuals).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from prefriction.identify.data import ForceDisplacement, Motion
from prefriction.identify.positions import noise_sd, reversal_indices

__all__ = ["ResidualDiagnostics", "diagnose", "diagnose_fit"]

RUNS_Z = -4.0
"""Runs z-score below which the runs are too few (eq. D1)."""
LAG1 = 0.3
"""Lag-1 autocorrelation above which the residuals hold a smooth misfit (eq. D2)."""
SPIKE_RATIO = 2.0
"""Ratio of the rms after reversals to the rms elsewhere above which reversals spike (eq. D3)."""
NOISE_RATIO = 2.0
"""Residual rms over the declared measurement noise above which the model leaves signal unexplained (eq. D4)."""
PULL = 2.0
"""Standard errors by which the reversal windows may pull an estimate before it is distrusted."""
LAGS = 50
"""Lags of the autocorrelation kept."""


@dataclass(frozen=True)
class ResidualDiagnostics:
    """What the residuals of a fit say (``FitResult.diagnostics``).

    Attributes
    ----------
    runs : int
        Runs of equal sign.
    runs_expected : float
        Their mean for independent residuals (eq. D1).
    runs_z : float
        The runs test's z-score (negative: too few runs, a smooth misfit).
    acf : numpy.ndarray
        Autocorrelation at lags 0, 1, ... (eq. D2).
    reversals : numpy.ndarray
        Sample indices of the velocity reversals.
    window : int
        Samples after each reversal in the spike check.
    reversal_ratio : float
        rms residual in those windows over the rms elsewhere (eq. D3; NaN without reversals).
    findings : tuple of str
        The structure found (empty: none).
    distrust : tuple of (str, str)
        Estimates to distrust and why.
    """

    runs: int
    runs_expected: float
    runs_z: float
    acf: np.ndarray
    reversals: np.ndarray
    window: int
    reversal_ratio: float
    findings: tuple[str, ...]
    distrust: tuple[tuple[str, str], ...]

    @property
    def structured(self) -> bool:
        """True if the residuals show structure the model does not explain."""
        return bool(self.findings)

    def summary(self) -> str:
        """A few lines: the three checks, what was found and which estimates to distrust."""
        ratio = "no reversals" if not np.isfinite(self.reversal_ratio) else f"{self.reversal_ratio:.2f}"
        lines = [f"residual runs {self.runs} (independent: {self.runs_expected:.0f}, z = {self.runs_z:.1f}), "
                 f"lag-1 autocorrelation {self.acf[1] if self.acf.size > 1 else np.nan:.2f}, "
                 f"rms after reversals / elsewhere {ratio} ({self.reversals.size} reversals, {self.window} samples)"]
        if not self.findings:
            lines.append("no structure the model leaves unexplained (docs/identify.md#diagnostics)")
        lines.extend(f"STRUCTURE: {f}" for f in self.findings)
        lines.extend(f"DISTRUST {n}: {why}" for n, why in self.distrust)
        return "\n".join(lines)


def _runs(r: np.ndarray) -> tuple[int, float, float]:
    s = r[r != 0.0] > 0.0
    n = s.size
    if n < 2:
        return n, float(n), 0.0
    n1 = int(np.count_nonzero(s))
    n2 = n - n1
    R = 1 + int(np.count_nonzero(s[1:] != s[:-1]))
    if n1 == 0 or n2 == 0:
        return R, 1.0, 0.0
    mean = 1.0 + 2.0 * n1 * n2 / n
    var = 2.0 * n1 * n2 * (2.0 * n1 * n2 - n) / (n * n * (n - 1.0))
    return R, mean, float((R - mean) / np.sqrt(var)) if var > 0.0 else 0.0


def _acf(r: np.ndarray) -> np.ndarray:
    r = r - r.mean()
    d = float(r @ r)
    lags = min(LAGS, r.size - 1)
    if d <= 0.0:
        return np.r_[1.0, np.zeros(lags)]
    return np.array([1.0] + [float(r[l:] @ r[:-l]) / d for l in range(1, lags + 1)])


def diagnose(residuals: np.ndarray, x: np.ndarray, names: tuple[str, ...] | list[str], stderr: np.ndarray,
             stderr_iid: np.ndarray | None, influence: np.ndarray | None,
             reversals: np.ndarray | None = None, noise: float = 0.0) -> ResidualDiagnostics:
    """The diagnostics of one fit (module text).

    Parameters
    ----------
    residuals : numpy.ndarray
        Data minus fit, in sample order.
    x : numpy.ndarray
        Positions [m] at the samples (the reversals are theirs).
    names : sequence of str
        The fitted parameters.
    stderr, stderr_iid : numpy.ndarray
        Their standard errors (HAC) and the white-residual ones.
    influence : numpy.ndarray or None
        ``psi`` of ``statistics.py`` (eq. S1), shape ``(k, n)``.
    reversals : numpy.ndarray, optional
        Sample indices of the reversals, if known (a Motion fit locates its own, small ones
        included); default: those of ``x`` by more than 1 % of its range.
    noise : float, default 0.0
        Standard deviation of the measurement error of the fitted signal, if declared (a
        :class:`Motion` fit's positions, eq. D4); 0: not compared.

    Returns
    -------
    ResidualDiagnostics
    """
    r = np.asarray(residuals, dtype=float)
    n = r.size
    R, mean, z = _runs(r)
    acf = _acf(r)
    rev = reversal_indices(x) if reversals is None else np.unique(np.asarray(reversals, dtype=int))
    window = int(max(2, n // (10 * (rev.size + 1)))) if rev.size else 0
    mask = np.zeros(n, dtype=bool)
    for i in rev:
        mask[i: i + window] = True
    ratio = np.nan
    if rev.size and 0 < np.count_nonzero(mask) < n:
        rest = float(np.sqrt(np.mean(r[~mask] ** 2)))
        ratio = float(np.sqrt(np.mean(r[mask] ** 2))) / rest if rest > 0.0 else np.inf
    findings = []
    if z < RUNS_Z and acf.size > 1 and acf[1] > LAG1:
        findings.append(f"{R} runs of equal sign where independent residuals give {mean:.0f} (z = {z:.1f}) and a "
                        f"lag-1 autocorrelation of {acf[1]:.2f}: a smooth misfit the model does not explain")
    if np.isfinite(ratio) and ratio > SPIKE_RATIO:
        findings.append(f"the residuals after the {rev.size} reversals are {ratio:.1f} times the rest (rms over "
                        f"{window} samples after each): the model's reversal transient differs from the data's")
    level = float(np.sqrt(np.mean(r ** 2)))
    if noise > 0.0 and level > NOISE_RATIO * noise:
        findings.append(f"the residual rms {level:.3g} is {level / noise:.1f} times the declared measurement noise "
                        f"{noise:.3g}: the model leaves motion unexplained")
    distrust = []
    if findings:
        for i, name in enumerate(names):
            why = []
            if influence is not None and np.isfinite(stderr[i]) and stderr[i] > 0.0 and np.isfinite(ratio) \
                    and ratio > SPIKE_RATIO:
                pull = abs(float(influence[i, mask].sum())) / stderr[i]
                if pull > PULL:
                    why.append(f"the samples after the reversals pull it by {pull:.1f} standard errors")
            if stderr_iid is not None and np.isfinite(stderr[i]) and stderr_iid[i] > 0.0 \
                    and stderr[i] > 2.0 * stderr_iid[i]:
                why.append(f"its interval is {stderr[i] / stderr_iid[i]:.1f} times the white-residual one (its "
                           f"information comes from correlated stretches)")
            if why:
                distrust.append((name, "; ".join(why)))
    return ResidualDiagnostics(R, mean, z, acf, rev, window, ratio, tuple(findings), tuple(distrust))


def diagnose_fit(res: Any) -> ResidualDiagnostics:
    """:func:`diagnose` of a :class:`prefriction.identify.FitResult` (its :attr:`diagnostics`):
    the positions of the record (the estimated path of :class:`ForceDisplacement` data), the
    fitted reversal times if any, and the position noise of :class:`Motion` data.

    Raises
    ------
    TypeError
        If the fit's data are not a record in time (``ForceDisplacement`` or ``Motion``).
    """
    data = res.data
    if not isinstance(data, (ForceDisplacement, Motion)):
        raise TypeError(f"residual diagnostics need a fit of ForceDisplacement or Motion data (records in time), "
                        f"got {type(data).__name__}")
    x = data.path if isinstance(data, ForceDisplacement) else data.x
    st = res.statistics
    times = next((np.atleast_1d(v) for k, v in res.nuisance.items() if k.startswith("reversal times")), None)
    rev = None if times is None else np.clip(np.searchsorted(data.t, times), 0, len(data.t) - 1)
    noise = noise_sd(data.x_noise, data.quantum) if isinstance(data, Motion) else 0.0
    return diagnose(res.residuals, x, res.names, res.stderr, st.stderr_iid, st.influence, rev, noise)
