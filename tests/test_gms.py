"""Generalised Maxwell-slip (GMS) friction through the protocol.

References, independent of the simulator and of the model's methods:

- ``GMSReference`` below: the oscillator ``m x'' = u(t) - F`` with GMS friction written in SI
  units straight from the equations (element forces ``F_i`` as states; sticking ``F_i' = k_i
  v``; slip when ``s F_i`` reaches ``alpha_i S(v)``; slipping ``F_i' = s C (1 - s F_i /
  (alpha_i S(v)))`` until the velocity reverses; ``F = sum_i (F_i + sigma_i F_i' / k_i) +
  sigma2 v``; ``S(v) = Fc + (Fs - Fc) exp(-|v / vs|^delta)``), integrated by scipy's DOP853 at
  rtol 1e-12 and restarted at every reversal and every element slip (terminal events located by
  scipy; a slip whose indicator dips below zero and back within one step, which scipy's sign
  test misses, is found on the dense output and located by ``brentq``);
- ``prefriction.exact_reversals`` of the Maxwell-slip system with ``W_i = alpha_i Fc``, which GMS
  becomes for ``Fs = Fc`` (a slipping element then sits on its equilibrium ``s alpha_i Fc``);
- python-control's linear closed loop (slip forces far beyond the loop's forces);
- the return-point memory of the figure script (inner loops close; measured in the script).

All models here have three elements (one compiled plant per kind of run), the figure script six.
"""

from __future__ import annotations

import dataclasses
import math
import pickle

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import prefriction as pf
from prefriction.testing import check_model

MASS = 0.1  # [kg]: sigma = 1e5 N/m, Fc = 1 N give the units 1e-5 m, 1e-3 s, 1e-2 m/s, 1 N
# the weakest element (smallest slip deflection alpha_i Fs / k_i) is soft (k_1 / sigma = 0.3)
P = dict(k=[3e4, 2e4, 5e4], alpha=[0.2, 0.3, 0.5], Fc=1.0, Fs=1.5, vs=1e-2, C=2e3)
# with micro-damping, viscous friction and a non-Gaussian Stribeck curve
PD = dict(P, sigma2=0.5, damping=[3.0, 2.0, 1.0], delta=1.5)


def gms(params):
    return pf.GMS(**params)


def rel_err(tab, rows, force_column=2):
    """Largest relative error of reversal times, positions and forces (x and F relative to their
    largest magnitude in the run) against reference rows ``(t, x, F...)``."""
    return max(
        float(np.max(np.abs(tab.t / rows[:, 0] - 1.0))),
        float(np.max(np.abs(tab.x - rows[:, 1])) / np.max(np.abs(rows[:, 1]))),
        float(np.max(np.abs(tab.F - rows[:, force_column])) / np.max(np.abs(rows[:, force_column]))),
    )


class GMSReference:
    """The GMS oscillator in SI units from the equations (module notes); no prefriction code."""

    def __init__(self, params, mass, u=None):
        n = len(params["k"])
        self.k = np.asarray(params["k"], dtype=float)
        self.alpha = np.asarray(params["alpha"], dtype=float)
        self.Fc, self.Fs, self.vs, self.C = params["Fc"], params["Fs"], params["vs"], params["C"]
        self.sigma2 = params.get("sigma2", 0.0)
        self.damping = np.asarray(params.get("damping", np.zeros(n)), dtype=float)
        self.delta = params.get("delta", 2.0)
        self.m = mass
        self.u = u if u is not None else (lambda t: 0.0)
        sig = self.k.sum()
        self.atol = 1e-14 * np.concatenate(([self.Fc / sig, self.Fc / math.sqrt(mass * sig)], np.full(n, self.Fc)))

    def S(self, v):
        return self.Fc + (self.Fs - self.Fc) * math.exp(-abs(v / self.vs) ** self.delta)

    def element_rates(self, v, Fi, slip, s):
        return np.where(slip, s * self.C * (1.0 - s * Fi / (self.alpha * self.S(v))), self.k * v)

    def force(self, v, Fi, slip, s):
        return Fi.sum() + np.sum(self.damping * self.element_rates(v, Fi, slip, s) / self.k) + self.sigma2 * v

    def run(self, v0, *, n=math.inf, t_end=math.inf):
        """Reversal rows ``(t, x, F_before, F_after)`` and the number of slips in each half-cycle
        (the last entry: after the last reversal).

        ``F_before`` is the force at ``v = 0`` with the elements' modes before the reversal,
        ``F_after`` with every element sticking again: they differ by the micro-damping force
        ``sum sigma_i F_i' / k_i`` of the elements that slipped up to the reversal (their
        ``F_i'`` does not vanish at ``v = 0``). The simulator's unforced loop records the force
        after the model's reset, its forced plant the force before it.
        """
        N = len(self.k)
        s = 1.0 if v0 >= 0 else -1.0
        slip = np.zeros(N, dtype=bool)
        y = np.concatenate(([0.0, v0], np.zeros(N)))
        t, rows, slips, self.segments = 0.0, [], [0], []
        while len(rows) < n and t < t_end:
            sl = slip.copy()

            def rhs(tt, yy, s=s, sl=sl):
                dF = self.element_rates(yy[1], yy[2:], sl, s)
                F = yy[2:].sum() + np.sum(self.damping * dF / self.k) + self.sigma2 * yy[1]
                return np.concatenate(([yy[1], (self.u(tt) - F) / self.m], dF))

            def reversal(tt, yy, s=s):
                return s * yy[1]

            def indicator(j, tt, yy, s=s, sl=sl):
                return 1.0 if sl[j] else self.alpha[j] * self.S(yy[1]) - s * yy[2 + j]

            reversal.terminal, reversal.direction = True, -1.0
            events = [reversal]
            for j in range(N):
                ev = (lambda j: lambda tt, yy: indicator(j, tt, yy))(j)
                ev.terminal, ev.direction = True, -1.0
                events.append(ev)
            sol = solve_ivp(rhs, (t, min(t_end, t + 1e6)), y, method="DOP853", rtol=1e-12, atol=self.atol,
                            events=events, dense_output=True)
            assert sol.status in (0, 1), sol.message
            hits = [(float(te[0]), i) for i, te in enumerate(sol.t_events) if len(te)]
            if not hits:  # t_end
                self.segments.append((t, sol.t[-1], sol.sol, sl, s))
                break
            te, i = min(hits)
            ye = sol.y_events[i][0].copy()
            missed = []
            for j in range(N):
                if not sl[j] and j != i - 1 and indicator(j, te, ye) < -1e-13 * self.Fs:
                    g = lambda tt, j=j: indicator(j, tt, sol.sol(tt))
                    grid = np.linspace(t, te, 400)
                    neg = int(np.argmax([g(tt) < 0.0 for tt in grid]))
                    missed.append((brentq(g, grid[neg - 1], grid[neg], xtol=1e-16, rtol=4.5e-16), j))
            if missed:
                te, j = min(missed)
                ye, i = sol.sol(te), j + 1
            self.segments.append((t, te, sol.sol, sl, s))
            t, y = te, ye
            if i == 0:  # velocity reversal: record it, every element sticks again
                assert s * (self.u(t) - self.force(0.0, y[2:], slip, s)) < 0.0, "touch or rest: not covered"
                F_before = self.force(0.0, y[2:], slip, s)
                s, slip[:], y[1] = -s, False, 0.0
                rows.append((t, y[0], F_before, self.force(0.0, y[2:], slip, s)))
                slips.append(0)
            else:
                slip[i - 1] = True
                slips[-1] += 1
        return np.array(rows), np.array(slips)

    def sample(self, times):
        """``(x, v, F)`` at ``times`` inside the integrated range."""
        out = []
        for tt in times:
            a, b, sol, sl, s = next(seg for seg in self.segments if seg[0] <= tt <= seg[1])
            yy = sol(tt)
            out.append((yy[0], yy[1], self.force(yy[1], yy[2:], sl, s)))
        return np.array(out)


def slips_seen(model, system, v0, n, rtol):
    """Simulate and return the result and the element slips the simulator counted in each
    half-cycle (``result.events``, one count per reversal; ``model`` is the system's friction)."""
    res = pf.simulate(system, v0, reversals=n, rtol=rtol)
    return res, np.asarray(res.events)


# ------------------------------------------------------------------------------ the model
@pytest.mark.parametrize(
    ("changes", "err", "words"),
    [
        (dict(k=[3e4, -2e4, 5e4]), ValueError, ["k[1]", "-20000.0", "0 < k[i] < inf", "N/m"]),
        (dict(k=[3e4, math.nan, 5e4]), ValueError, ["k[1]", "nan"]),
        (dict(alpha=[0.2, 0.3, 0.6]), ValueError, ["alpha", "sum to 1", "1.1", "[0.2, 0.3, 0.6]"]),
        (dict(alpha=[0.0, 0.5, 0.5]), ValueError, ["alpha[0]", "0.0", "0 < alpha[i] < inf"]),
        (dict(alpha=[0.5, 0.5]), ValueError, ["same length", "3 and 2"]),
        (dict(k=[]), ValueError, ["k", "1 to 100", "got 0"]),
        (dict(Fc=-1.0), ValueError, ["Fc", "-1.0", "0 < Fc < inf"]),
        (dict(Fs=0.5), ValueError, ["Fs", "0.5", "[1.0, inf)", "[N]"]),
        (dict(vs=0.0), ValueError, ["vs", "0.0", "0 < vs < inf"]),
        (dict(C=math.inf), ValueError, ["C", "inf", "0 < C < inf"]),
        (dict(sigma2=-0.1), ValueError, ["sigma2", "-0.1", "0 <= sigma2 < inf"]),
        (dict(damping=[1.0, 2.0]), ValueError, ["damping", "3 finite numbers >= 0", "shape (2,)"]),
        (dict(damping=[1.0, 2.0, -1.0]), ValueError, ["damping[2]", "-1.0", "0 <= damping[i] < inf", "N s/m"]),
        (dict(delta=0.0), ValueError, ["delta", "0.0", "0 < delta < inf"]),
        (dict(Fc="1"), TypeError, ["Fc", "'1'"]),
        (dict(k=[True, True, False]), TypeError, ["k", "bool"]),
        (dict(alpha=None), TypeError, ["alpha", "None"]),
        (dict(damping="1"), TypeError, ["damping", "'1'"]),
    ],
)
def test_invalid_parameters_are_named_with_value_and_range(changes, err, words):
    with pytest.raises(err) as info:
        pf.GMS(**dict(P, **changes))
    for w in words:
        assert w in str(info.value), (w, str(info.value))


def test_model_is_immutable_hashable_and_normalised():
    m = gms(PD)
    with pytest.raises(dataclasses.FrozenInstanceError):
        m.C = 1.0
    with pytest.raises(ValueError):  # read-only copies, not the caller's lists
        m.alpha[0] = 1.0
    with pytest.raises(ValueError):
        m.damping[0] = 1.0
    k = np.array(P["k"])
    m2 = pf.GMS(k, **{key: v for key, v in PD.items() if key != "k"})
    k[0] = 1.0
    assert m == m2 and hash(m) == hash(m2) and m != gms(dict(PD, C=2.1e3)) and m != gms(P)
    assert pickle.loads(pickle.dumps(m)) == m
    assert gms(P).damping.tolist() == [0.0, 0.0, 0.0] and gms(P).delta == 2.0 and gms(P).sigma2 == 0.0
    assert (m.sigma, m.Fc, m.n_states, m.n_flags, m.n_events) == (1e5, 1.0, 4, 3, 3)
    assert not m.rate_independent and not m.tracks_position
    # the structure is N alone
    other = pf.GMS([1.0] * 3, [0.1, 0.2, 0.7], 2.0, 3.0, 1.0, 5.0)
    assert m.structure_key() == gms(P).structure_key() == other.structure_key() == ("GMS", 3)
    assert m.structure_key() != pf.GMS([1.0, 2.0], [0.5, 0.5], 1.0, 1.0, 1.0, 1.0).structure_key()
    # normalised numbers: V = Fc / sqrt(m sigma) holds the mass
    for mass in (1.0, 0.1, 7.0):
        V = 1.0 / math.sqrt(mass * 1e5)
        q = m.runtime_params_for(pf.Scales.of(pf.Oscillator(m, mass=mass)))
        kappa = np.array([0.3, 0.2, 0.5])
        expect = [*kappa, 0.2, 0.3, 0.5, *(np.array([3.0, 2.0, 1.0]) * V / kappa), 0.5, V / 1e-2, 0.75,
                  2e3 / (1e5 * V), 0.5 * V]
        np.testing.assert_allclose(q, expect, rtol=1e-14)
    np.testing.assert_array_equal(m.runtime_params(), m.runtime_params_for(pf.Scales.of(pf.Oscillator(m, mass=1.0))))


def test_equations_in_normalised_units_are_the_si_equations():
    """The model's rate, force and indicators at random states equal the SI equations of the
    reference, converted with the units of an oscillator of mass 0.1 kg."""
    model = gms(PD)
    sys_ = pf.Oscillator(model, mass=MASS)
    sc = pf.Scales.of(sys_)
    q = model.runtime_params_for(sc).tolist()
    ref = GMSReference(PD, MASS)
    rng = np.random.default_rng(5)
    for _ in range(50):
        s = float(rng.choice([-1.0, 1.0]))
        v = s * float(rng.uniform(0.0, 3.0)) * sc.v
        slip = rng.random(3) < 0.5
        Fi = rng.uniform(-1.0, 1.0, 3) * ref.alpha * ref.Fs
        z, m = list(Fi / sc.F) + [0.0], [float(b) for b in slip]
        rate = np.array(model.rate(z, m, v / sc.v, s, q)[:3]) * sc.F / sc.t
        np.testing.assert_allclose(rate, ref.element_rates(v, Fi, slip, s), rtol=1e-12, atol=1e-12 * sc.F / sc.t)
        F = model.force(z, m, v / sc.v, s, q) * sc.F
        assert F == pytest.approx(ref.force(v, Fi, slip, s), rel=1e-12, abs=1e-14)
        ind = model.events(z, m, v / sc.v, s, q)
        for j in range(3):
            expect = 1.0 if slip[j] else 1.0 - s * Fi[j] / (ref.alpha[j] * ref.S(v))
            assert ind[j] == pytest.approx(expect, rel=1e-12, abs=1e-14)
    # steady sliding: every element at s alpha_i S(v) has zero rate; F = sign(v) S(v) + sigma2 v
    v = -0.7 * sc.v
    Fi = -ref.alpha * ref.S(v)
    z = list(Fi / sc.F) + [0.0]
    assert np.allclose(model.rate(z, [1.0] * 3, v / sc.v, -1.0, q)[:3], 0.0, atol=1e-15)
    assert model.force(z, [1.0] * 3, v / sc.v, -1.0, q) * sc.F == pytest.approx(float(model.steady_force(v)), rel=1e-14)
    assert float(model.stribeck(0.0)) == 1.5
    assert float(model.stribeck(1e-2)) == pytest.approx(1.0 + 0.5 / math.e, rel=1e-15)


def test_initial_state_lies_on_the_maxwell_slip_virgin_curve_with_slip_forces_alpha_fc():
    model = gms(P)  # kappa = 0.3, 0.2, 0.5; alpha = 0.2, 0.3, 0.5: Delta = 2/3, 3/2, 1
    for f0 in (0.3, 0.75, 0.95, -0.95, 1.0):
        for s in (1.0, -1.0):
            z, m = model.initial_state(f0, s)
            assert math.isclose(sum(z[:3]), f0, rel_tol=1e-14) and z[3] == 0.0
            at = np.isclose(np.abs(z[:3]), model.alpha, rtol=1e-14, atol=0.0)
            assert list(m) == [1.0 if (a and s * f0 > 0) else 0.0 for a in at]
            assert np.all(np.abs(z[:3]) <= model.alpha * (1 + 1e-15))  # below alpha_i S(v) for every v
    assert model.initial_state(0.3, 1.0)[0][:3] == pytest.approx([0.09, 0.06, 0.15], rel=1e-14)
    with pytest.raises(ValueError, match="f0"):
        model.initial_state(1.1, 1.0)


def test_check_model_passes_for_two_instances_of_one_structure():
    """The reusable checks (symbolic against numeric at a sibling instance, reversals against
    scipy); two instances of N = 3 in one process share the plant, so numbers baked into it
    (not taken from q) would fail the second. The initial speeds keep reversal positions away
    from x = 0, where check_model's relative position error is measured against 1e-3 of the
    largest position. No micro-damping here: check_model's reference records the reversal force
    before the model's reset and the unforced loop after it, which differ by the micro-damping
    force of the elements that slipped up to the reversal (``GMSReference.run``); the damped
    model is compared with the SI reference below, in the simulator's convention."""
    for params, v0 in ((P, 2.5), (dict(P, sigma2=0.5, delta=1.5), 1.5)):
        out = check_model(gms(params), v0=v0, reversals=12)
        assert out.n_reversals == 12 and out.max_error <= 2e-7


# ------------------------------------------------------------------- simulator vs reference
@pytest.mark.parametrize("params", [P, PD], ids=["undamped", "damped"])
def test_unforced_reversals_and_slips_match_the_reference(params):
    model = gms(params)
    sys_ = pf.Oscillator(model, mass=MASS)
    v0 = 2.5 * pf.Scales.of(sys_).v  # the first excursion slides (all elements slip)
    rows, slips = GMSReference(params, MASS).run(v0, n=14)
    assert slips.sum() >= 5 and slips[0] == 3  # 3 2 1 1 1 1 1 0 ... (undamped), 3 1 1 0 ... (damped)
    for rtol in (1e-6, 1e-9):
        res, seen = slips_seen(model, sys_, v0, 14, rtol)
        assert len(res.reversals.t) == 14
        assert rel_err(res.reversals, rows, force_column=3) <= 10 * rtol  # measured <= 0.3 rtol
        np.testing.assert_array_equal(seen, slips[:14])
        assert np.all(np.isnan(res.reversals.E_p))  # rate-dependent: no branch energy


def test_forced_run_matches_the_reference():
    """A cosine force drives the mass through gross sliding and back 22 times in 0.1 s, with
    0 to 3 slips per half-cycle. The force samples check every slip (a missed or spurious slip
    changes the element's force rate from ``k_i v`` to the slip law and the force by far more
    than 10 rtol within a fraction of a half-cycle); the slip counts of a forced run
    (``result.events``) are compared with this reference in ``tests/test_simulate_events.py``."""
    A, f = 1.3, 40.0
    model = gms(PD)
    sys_ = pf.Oscillator(model, mass=MASS, u=pf.signals.Sine(amplitude=A, frequency=f, phase=math.pi / 2))
    ref = GMSReference(PD, MASS, u=lambda t: A * math.cos(2.0 * math.pi * f * t))
    rows, slips = ref.run(0.0, t_end=0.1)
    assert len(rows) == 22 and slips.sum() >= 30 and slips.max() == 3 and slips.min() == 0
    rtol = 1e-8
    times = np.linspace(0.0, 0.1, 401)[1:]
    res = pf.simulate(sys_, 0.0, t_end=0.1, rtol=rtol, dense=times)
    assert len(res.reversals.t) == len(rows)
    # the simulator records the force just after the model's reset (all elements stick: the
    # micro-damping force of the slipping elements drops out), column 3 of the reference; the
    # two differ here, so the comparison tells the conventions apart
    assert rel_err(res.reversals, rows, force_column=3) <= 10 * rtol
    assert np.max(np.abs(rows[:, 2] - rows[:, 3])) > 1e-3 * np.max(np.abs(rows[:, 2]))
    smp = ref.sample(res.t)
    for col, got in enumerate((res.x, res.v, res.F)):
        assert np.max(np.abs(got - smp[:, col])) <= 10 * rtol * np.max(np.abs(smp[:, col]))  # measured <= 4 rtol


def test_fs_equal_fc_is_maxwell_slip_and_large_vs_approaches_it():
    """``Fs = Fc``: GMS is MaxwellSlip with ``W_i = alpha_i Fc`` exactly (the slipping element
    starts on its equilibrium), for an infinity-like ``vs`` and a large ``C`` as for any other:
    the only difference left is the simulation error of both (10 rtol, measured 4e-12 at rtol
    1e-10). ``Fs > Fc``: as ``vs`` grows, GMS approaches MaxwellSlip with ``W_i = alpha_i Fs``
    (``S(v) = Fs - (Fs - Fc) (v / vs)^2 + ...``): the error falls as ``vs^-2`` (looser
    tolerance: 2e-5 at ``vs = 1 m/s``, 100 times the normalised velocity unit)."""
    k, alpha = P["k"], np.array(P["alpha"])
    ms = pf.Oscillator(pf.MaxwellSlip(k, alpha * 1.0), mass=MASS)
    v0 = 2.0 * pf.Scales.of(ms).v
    exact = pf.exact_reversals(ms, v0, 14)
    rows = lambda tab: np.column_stack([tab.t, tab.x, tab.F])
    for vs, C in ((1e6, 1e5), (1e-2, 2e3)):
        sys_ = pf.Oscillator(pf.GMS(k, alpha, Fc=1.0, Fs=1.0, vs=vs, C=C), mass=MASS)
        res = pf.simulate(sys_, v0, reversals=14, rtol=1e-10)
        assert rel_err(res.reversals, rows(exact)) <= 1e-9
    exact_s = pf.exact_reversals(pf.Oscillator(pf.MaxwellSlip(k, alpha * 1.2), mass=MASS), v0, 14)
    errs = []
    for vs in (0.1, 1.0, 10.0):
        res = pf.simulate(pf.Oscillator(pf.GMS(k, alpha, Fc=1.0, Fs=1.2, vs=vs, C=1e5), mass=MASS), v0,
                          reversals=14, rtol=1e-11)
        errs.append(rel_err(res.reversals, rows(exact_s)))
    assert errs[1] <= 2e-5 and errs[2] <= 2e-7  # measured 1.0e-3, 1.0e-5, 1.0e-7
    np.testing.assert_allclose(np.array(errs[:2]) / np.array(errs[1:]), 100.0, rtol=0.05)


# ------------------------------------------------------------------ loops and sweeps
def test_sweep_over_two_gms_systems():
    from prefriction.simulation.integrator import _CACHE

    params = [(P, 0.1), (dict(k=[1e3, 5e3, 2e3], alpha=[0.5, 0.2, 0.3], Fc=2.0, Fs=2.6, vs=0.05, C=50.0,
                              sigma2=1.0, damping=[0.5, 0.5, 0.5], delta=3.0), 2.0)]
    systems = [pf.Oscillator(gms(p), mass=mass) for p, mass in params]
    v0 = [1.9 * pf.Scales.of(s).v for s in systems]
    pf.simulate(systems[0], v0[0], reversals=2)  # plant built (or cached) before counting
    before = len(_CACHE)
    out = pf.sweep(systems, v0, reversals=8, rtol=1e-9)
    assert not out.failed and len(_CACHE) == before  # one plant for every N = 3 model, any mass
    for (p, mass), v, r in zip(params, v0, out):
        rows, _ = GMSReference(p, mass).run(v, n=8)
        assert rel_err(r.reversals, rows, force_column=3) <= 1e-8


def test_simulate_loop_in_the_linear_regime_is_the_linear_loop():
    """Slip forces far beyond the loop's forces: every element sticks, the friction is
    ``sigma x + (sigma2 + sum sigma_i) x'``, and the PD loop is python-control's linear closed loop."""
    import control

    from prefriction import controllers

    k, m, kp, kd, tau, r0 = np.array([2e5, 3e5, 5e5]), 1.0, 2e6, 2000.0, 5e-5, 1e-6
    sigma2, damping = 30.0, np.array([10.0, 20.0, 40.0])
    stage = pf.Oscillator(pf.GMS(k, [0.2, 0.3, 0.5], Fc=1e8, Fs=1.2e8, vs=1e-3, C=1e3, sigma2=sigma2,
                                 damping=damping), mass=m)
    res = controllers.simulate_loop(stage, controllers.pd(kp, kd, tau=tau), r0, 0.02)
    C = control.tf([kd + kp * tau, kp], [tau, 1.0])
    T = control.feedback(control.tf([1.0], [m, sigma2 + damping.sum(), k.sum()]) * C, 1)
    lin = control.forced_response(T, res.t, np.full(res.t.shape, r0)).outputs
    assert float(np.max(np.abs(res.x - lin)) / np.max(np.abs(lin))) <= 1e-6


# ------------------------------------------------------------------ the figure script
@pytest.mark.slow  # an example script end to end: .ci/run's second command (-m slow)
def test_memory_figure_inner_loops_close(tmp_path):
    """``examples/gms_memory.py``: the inner loops close where they began.

    ``closure`` is the force where the final ascent passes a loop's starting reversal again,
    minus the force at that reversal and the micro-damping force ``tau |u'|`` of the moving mass
    (module notes of the script). For a rate-independent hysteresis it would vanish; what is
    left comes from the motion not being quasi-static at the slips (inertia ``m x''``, and
    ``tau`` times the transient of ``F'``), so the allowance is the largest inertial force
    ``m |x''|`` on the final ascent (0.88 mN; closures measured -0.74, -0.0001 and -0.23 mN).
    That is below 1 % of each loop's own width (0.037 to 0.38 N), the miss of a loop that did
    not close. Beyond the outermost re-entry point and on the descent from ``+A`` the nested
    run equals the outer run at equal input force (wiping-out): measured 1.5e-5 N and 3e-10 m,
    allowed 1e-4 N and 1e-9 m (the transients of the two histories have decayed there; 1e-4 of
    the loop's force and displacement amplitudes, 1 N and 11 um).
    """
    import matplotlib

    matplotlib.use("Agg")
    from prefriction.cli.paper import load_example

    out = load_example("gms_memory").main(tmp_path)
    png = out["png"]
    assert png.is_file() and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 30_000
    assert len(out["nested"].reversals.t) == 9 and len(out["outer"].reversals.t) == 3
    assert out["inertia"] <= 2e-3  # m = 0.025 kg, |u'| = 2.5 N/s: 0.88 mN
    assert np.all(np.abs(out["closure"]) <= out["inertia"])
    assert np.all(np.abs(out["closure"]) <= 0.01 * out["loop_width"])
    assert np.all(out["loop_width"] >= 0.03)  # the loops are real hysteresis loops, not elastic lines
    assert out["outer_gap"]["F"] <= 1e-4 and out["outer_gap"]["x"] <= 1e-9
