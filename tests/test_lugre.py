"""LuGre model (Canudas de Wit et al. 1995): protocol, validation, sweeps, and the experiments
of ``examples/lugre_experiments.py`` against an independent stiff reference.

The reference (:func:`radau`) is written here from the paper's equations in SI units, without
the package: scipy ``Radau`` at tight tolerance on the branch ``|v| = s v``, restarted at every
zero of the velocity (a reversal if the net force ``u - sigma0 z`` turns the mass back, rest if it
vanishes) and at the breaks of the input.

Error measures (the simulator's error control, ``simulate(atol=...)``): positions relative to the largest
``|x|``; velocities and friction forces relative to the amplitude of the motion, the largest
``hypot(v / V, F / Fc)`` with the velocity unit ``V = Fc / sqrt(m sigma0)``. Relative to its own
largest value the friction force in gross sliding is less accurate by the factor
``sigma1 |v| / Fc`` (30-120 here): ``F = sigma0 z + sigma1 z'`` and ``z'`` multiplies the
state's error by the stiff rate ``sigma0 |v| / g(v)``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import prefriction as pf
from prefriction.cli.paper import load_example
from prefriction.testing import check_model

S0, S1, S2, FC, FS, VS = 1e5, math.sqrt(1e5), 0.4, 1.0, 1.5, 1e-3  # Table I of the paper
PAPER = dict(sigma0=S0, sigma1=S1, sigma2=S2, Fc=FC, Fs=FS, vs=VS)
RTOL = 1e-8  # simulator
REF_RTOL = 1e-10  # reference


@pytest.fixture(scope="module")
def ex():
    return load_example("lugre_experiments")


# ------------------------------------------------------------------------------ reference
def radau(u, t_end, times, *, m=1.0, p=(S0, S1, S2, FC, FS, VS), y0=(0.0, 0.0, 0.0), extra=None, breaks=(),
          scale=(1.0, 1.0), rtol=REF_RTOL):
    """LuGre oscillator ``m x'' = u(t, y) - F`` in SI, ``y = [x, v, z, extra...]``.

    Returns ``(Y, F, reversals)``: states at ``times`` (rows x, v, z, ...), the friction force
    there and the reversals ``(t, x, F)``.
    """
    s0, s1, s2, Fc, Fs, vs = p
    y = np.array(y0, dtype=float)
    n = y.size
    atol = rtol * np.array([scale[0], scale[1], Fs / s0] + [scale[0] * t_end] * (n - 3))
    rest_tol = 1e-12 * Fc
    ext = (lambda t, y: []) if extra is None else extra

    def friction(y, s):
        v, z = y[1], y[2]
        g = Fc + (Fs - Fc) * math.exp(-((v / vs) ** 2))
        zd = v - s0 * s * v * z / g  # |v| = s v on the branch
        return zd, s0 * z + s1 * zd + s2 * v

    times = np.asarray(times, dtype=float)
    out = np.full((n, times.size), np.nan)
    revs = []
    a = u(0.0, y) - s0 * y[2]
    s = math.copysign(1.0, y[1] if y[1] else a)
    rest = y[1] == 0.0 and abs(a) <= rest_tol
    t, stalls = 0.0, 0
    for stop in sorted(b for b in breaks if 0 < b < t_end) + [t_end]:
        while t < stop:
            if rest:
                def rhs(tt, yy):
                    return [0.0, 0.0, 0.0, *ext(tt, yy)]

                def event(tt, yy):
                    return rest_tol - abs(u(tt, yy) - s0 * yy[2])
            else:
                def rhs(tt, yy, s=s):
                    zd, F = friction(yy, s)
                    return [yy[1], (u(tt, yy) - F) / m, zd, *ext(tt, yy)]

                def event(tt, yy, s=s):
                    return s * yy[1] + 1e-300  # positive at the start of the branch (v = 0)
            event.terminal, event.direction = True, -1.0
            sol = solve_ivp(rhs, (t, stop), y, method="Radau", rtol=rtol, atol=atol, events=[event], dense_output=True)
            assert sol.status >= 0, sol.message
            hit = sol.status == 1
            t_last = float(sol.t_events[0][0]) if hit else float(sol.t[-1])
            k = np.flatnonzero((times >= t) & (times <= t_last))
            if k.size:
                out[:, k] = sol.sol(times[k])
            if not hit:
                t, y = stop, sol.y[:, -1].copy()
                continue
            stalls = stalls + 1 if t_last <= t + 1e-14 * t_end else 0
            assert stalls <= 20, f"reference makes no progress at t = {t}"
            t, y = t_last, np.array(sol.y_events[0][0])
            a = u(t, y) - s0 * y[2]
            if rest:
                rest, new = False, math.copysign(1.0, a)
            else:
                y[1] = 0.0
                rest = abs(a) <= rest_tol
                new = s if rest else math.copysign(1.0, a)
            if new != s:
                revs.append((t, y[0], s0 * y[2]))
                s = new
    F = np.array([friction(out[:, j], 1.0 if out[1, j] >= 0 else -1.0)[1] for j in range(times.size)])
    return out, F, np.array(revs).reshape(-1, 3)


def errors(x, v, F, Y, F_ref, m=1.0):
    """``(ex, ev, eF)``: ``x`` relative to max |x|, ``v`` and ``F`` relative to the amplitude."""
    V = FC / math.sqrt(m * S0)
    amp = np.max(np.hypot(Y[1] / V, F_ref / FC))
    return (float(np.max(np.abs(x - Y[0])) / np.max(np.abs(Y[0]))),
            float(np.max(np.abs(v - Y[1])) / V / amp),
            float(np.max(np.abs(F - F_ref)) / FC / amp))


# ------------------------------------------------------------------------------ protocol
def test_check_model_paper_and_variants():
    for model, v0 in ((pf.LuGre(**PAPER), 1.5), (pf.LuGre(2e4, 0.0, 0.0, 2.0, 2.0, 1e-2), 3.0),
                      (pf.LuGre(1e6, 50.0, 3.0, 0.5, 1.0, 5e-4), 0.8)):
        out = check_model(model, v0=v0, reversals=10)
        assert out.n_reversals == 10 and out.max_error <= 20 * 1e-8
        assert out.branch_energy_error == 0.0  # rate-dependent: no energy checks
    assert not pf.LuGre.rate_independent


def test_normalised_numbers_follow_the_mass():
    lg = pf.LuGre(**PAPER)
    for m in (1.0, 2.5):
        sc = pf.Scales.of(pf.Oscillator(lg, m))
        V = FC / math.sqrt(m * S0)
        np.testing.assert_allclose(lg.runtime_params_for(sc), [S1 * V / FC, S2 * V / FC, FS / FC - 1.0, VS / V], rtol=1e-15)
    np.testing.assert_allclose(lg.runtime_params(), lg.runtime_params_for(pf.Scales.of(pf.Oscillator(lg, 1.0))))
    np.testing.assert_allclose(lg.runtime_params(), [1.0, 0.4 / math.sqrt(1e5), 0.5, 1e-3 * math.sqrt(1e5)], rtol=1e-14)
    assert lg.sigma == S0 and lg.structure_key() == pf.LuGre(1.0, 2.0, 3.0, 4.0, 5.0, 6.0).structure_key()
    # the force and rate in SI agree with the paper's equations on both branches
    sc = pf.Scales.of(pf.Oscillator(lg, 2.5))
    q = lg.runtime_params_for(sc).tolist()
    for v, z in ((3e-4, 1.2e-5), (-2e-3, 4e-6), (5e-2, -1e-5)):
        s = math.copysign(1.0, v)
        g = FC + (FS - FC) * math.exp(-((v / VS) ** 2))
        zd = v - S0 * abs(v) * z / g
        zeta = S0 * z / FC
        assert lg.rate([zeta], [], v / sc.v, s, q)[0] * sc.F / sc.t / S0 == pytest.approx(zd, rel=1e-12)
        assert lg.force([zeta], [], v / sc.v, s, q) * sc.F == pytest.approx(S0 * z + S1 * zd + S2 * v, rel=1e-12)
        assert lg.reverse([zeta], [], -s, q, 1e-8) == ([zeta], [])


@pytest.mark.parametrize("name, value, match", [
    ("sigma0", 0.0, r"sigma0 must be finite and > 0, got 0.0 \(allowed range: 0 < sigma0 < inf\)"),
    ("sigma0", -1e5, r"sigma0 .*got -100000.0"),
    ("sigma1", -0.1, r"sigma1 must be finite and >= 0, got -0.1 \(allowed range: 0 <= sigma1 < inf\)"),
    ("sigma2", math.inf, r"sigma2 .*got inf"),
    ("Fc", 0.0, r"Fc must be finite and > 0, got 0.0"),
    ("Fs", 0.5, r"Fs must be finite and >= Fc = 1.0, got 0.5 \(allowed range: Fc <= Fs < inf"),
    ("Fs", math.inf, r"Fs must be finite"),
    ("vs", 0.0, r"vs must be finite and > 0, got 0.0 \(allowed range: 0 < vs < inf\)"),
    ("vs", math.nan, r"vs .*got nan"),
])
def test_validation_names_argument_value_and_range(name, value, match):
    with pytest.raises(ValueError, match=match):
        pf.LuGre(**{**PAPER, name: value})


def test_validation_types():
    with pytest.raises(TypeError, match="sigma1"):
        pf.LuGre(**{**PAPER, "sigma1": "0.3"})
    assert pf.LuGre(**{**PAPER, "Fs": 1.0}).Fs == 1.0  # Fs = Fc: no Stribeck dip
    assert pf.LuGre(**{**PAPER, "sigma1": 0, "sigma2": 0}).sigma1 == 0.0


def test_sweep_over_two_lugre_systems():
    """Unforced oscillators, masses 1 and 3 kg (other normalised numbers, one structure), from
    sliding at 5 mm/s: both against the reference."""
    from prefriction.simulation.integrator import _CACHE

    systems = [pf.Oscillator(pf.LuGre(**PAPER), 1.0), pf.Oscillator(pf.LuGre(**{**PAPER, "sigma1": 100.0}), 3.0)]
    before = len(_CACHE)
    out = pf.sweep(systems, 5e-3, reversals=6, rtol=RTOL)
    assert len(_CACHE) - before <= 1 and not out.failed
    for sys_, res, s1 in zip(systems, out, (S1, 100.0)):
        _, _, revs = radau(lambda t, y: 0.0, 2.0, [0.0], m=sys_.mass, p=(S0, s1, S2, FC, FS, VS), y0=(0.0, 5e-3, 0.0),
                           scale=(1e-4, 5e-3))
        tab = res.reversals
        np.testing.assert_allclose(tab.t, revs[:6, 0], rtol=10 * RTOL)
        np.testing.assert_allclose(tab.x, revs[:6, 1], rtol=10 * RTOL)
        span = np.max(np.abs(revs[:6, 2]))
        assert np.max(np.abs(tab.F - revs[:6, 2])) <= 10 * RTOL * span
        assert np.all(np.isnan(tab.E_p))  # no stored energy of a rate-dependent model


# ------------------------------------------------------------------------------ experiments
def test_presliding_ramps_against_reference(ex):
    """Experiment 1 without the holds: x [um] within 10 rtol; the loop (virgin curve from 0 to
    45.1 um, back to -10.0 um, and up again to the same displacement at the same force)."""
    d = ex.presliding(hold=False, n=2001)
    tu, uu = ex.presliding_input(hold=False)
    Y, F, revs = radau(lambda t, y: float(np.interp(t, tu, uu)), float(tu[-1]), d["t"], breaks=tuple(tu),
                       scale=(5e-5, 3e-5))
    e = errors(d["x"], d["v"], d["F"], Y, F)
    assert max(e) <= 10 * RTOL, e
    tab = d["result"].reversals
    assert len(tab.t) == len(revs) == 2
    np.testing.assert_allclose(tab.t, revs[:, 0], rtol=10 * RTOL)
    np.testing.assert_allclose(tab.x, revs[:, 1], rtol=10 * RTOL)
    assert np.max(d["x"]) == pytest.approx(45.13e-6, abs=0.01e-6)
    assert np.min(d["x"]) == pytest.approx(-10.00e-6, abs=0.01e-6)
    x10 = float(np.interp(10.0, d["t"], d["x"]))  # u = 0.95 Fs, rising, at t = 10 s and at 50 s
    assert d["x"][-1] == pytest.approx(x10, rel=1e-3)  # the loop closes (nearly rate-independent)


def test_presliding_with_holds_against_reference(ex):
    """Experiment 1 as in the paper (5-s holds at +-0.95 Fs): within 10 rtol of the reference.
    In the holds the mass comes to rest; the simulator's rest test (net force below ``EPS_TOUCH``
    times the tolerance times the amplitude, the error level of the net force) finds that rest
    instead of reversals at the level of its integration error (there were 306 such reversals,
    and a creep of 50 rtol, when the test sat at 1e-14 of the amplitude, below that error)."""
    d = ex.presliding(hold=True, n=1201)
    tu, uu = ex.presliding_input(hold=True)
    Y, F, revs = radau(lambda t, y: float(np.interp(t, tu, uu)), float(tu[-1]), d["t"], breaks=tuple(tu),
                       scale=(5e-5, 3e-5))
    e = errors(d["x"], d["v"], d["F"], Y, F)
    assert max(e) <= 10 * RTOL, e
    # the reversals of the ramps, and at most the few damped ones at the start of each hold
    # that the reference (rest below 1e-12 Fc) also finds
    n = len(d["result"].reversals.t)
    assert 2 <= n <= len(revs), (n, len(revs))


def test_friction_lag_against_reference(ex):
    """Experiment 2 (prescribed velocity, CasADi cvodes at 1e-10): F(t) against Radau; loops
    widen with the frequency (friction higher while the velocity rises)."""
    lag = ex.friction_lag(n=400)
    widths = []
    for om, d in lag.items():
        T = 2 * math.pi / om

        def rhs(t, z, om=om):
            v = 1e-3 * (math.cos(om * t) + 1.5)
            return [v - S0 * v * z[0] / (FC + (FS - FC) * math.exp(-((v / VS) ** 2)))]

        sol = solve_ivp(rhs, (0.0, 2 * T), [0.0], method="Radau", rtol=1e-10, atol=1e-17, t_eval=d["t"])
        v = 1e-3 * (np.cos(om * sol.t) + 1.5)
        z = sol.y[0]
        zd = v - S0 * v * z / (FC + (FS - FC) * np.exp(-((v / VS) ** 2)))
        F = S0 * z + S1 * zd + S2 * v
        assert np.max(np.abs(d["F"] - F)) <= 1e-8 * FS
        widths.append(ex.loop_width(d["v"], d["F"]))
    assert 0 < widths[0] < widths[1] < widths[2]
    np.testing.assert_allclose(widths, [1.22e-3, 12.8e-3, 36.1e-3], rtol=0.01)


def test_breakaway_against_reference(ex):
    """Experiment 3: first maximum of the friction force under u = rate t. Falls from 1.432 N
    (1 N/s) to 1.220 N (10 N/s) and 1.007 N (50 N/s): the rate-dependent break-away of the paper."""
    rates = (1.0, 10.0, 50.0)
    b = ex.breakaway(rates, n=2001)
    for rate, Fb in zip(rates, b["F_break"]):
        r = b["runs"][rate]
        t = r["t"]
        Y, F, _ = radau(lambda tt, y, rate=rate: rate * tt, 1.8 / rate, t, scale=(1e-4, 1e-2))
        e = errors(r["x"], r["v"], r["F"], Y, F)
        assert max(e) <= 10 * RTOL, e
        assert abs(Fb - ex.peak(t, F)[1]) <= 10 * RTOL * Fb
    assert np.all(np.diff(b["F_break"]) < 0)
    np.testing.assert_allclose(b["F_break"], [1.4324, 1.2200, 1.0075], atol=2e-4)


def test_stick_slip_against_reference(ex):
    """Experiment 4 (10 s): spring k = 2 N/m pulled at 0.1 m/s. Sticks until F = 1.477 N at
    t = 7.41 s, slips at up to 0.370 m/s."""
    d = ex.stick_slip(10.0, n=2001)
    Y, F, revs = radau(lambda t, y: 2.0 * (0.1 * t - y[0]), 10.0, d["t"], scale=(1.0, 0.3))
    e = errors(d["x"], d["v"], d["F"], Y, F)
    assert max(e) <= 10 * RTOL, e
    tab = d["result"].reversals
    assert len(tab.t) == len(revs)
    np.testing.assert_allclose(tab.t, revs[:, 0], atol=10 * RTOL * 10.0)
    np.testing.assert_allclose(d["u"], 2.0 * (0.1 * d["t"] - d["x"]), atol=1e-12)
    k = int(np.argmax(F))
    assert F[k] == pytest.approx(1.4766, abs=1e-4) and d["t"][k] == pytest.approx(7.405, abs=0.006)
    assert np.max(d["v"]) == pytest.approx(0.370, abs=1e-3)


def test_hunting_against_reference(ex):
    """Experiment 5 (30 s): the paper's loop u = -Kv v + Kp (1 - x) + Ki int (1 - x) written
    as such in the reference; the example folds Kv into sigma2. Hunting: the mass sticks off the
    set point, alternately above and below it."""
    d = ex.hunting(30.0, n=3001)
    Y, F, revs = radau(lambda t, y: 3.0 * (1.0 - y[0]) + 4.0 * y[3] - 6.0 * y[1], 30.0, d["t"], y0=(0.0, 0.0, 0.0, 0.0),
                       extra=lambda t, y: [1.0 - y[0]], scale=(1.0, 0.3))
    e = errors(d["x"], d["v"], d["F"], Y, F)
    assert max(e) <= 10 * RTOL, e
    np.testing.assert_allclose(d["xi"], Y[3], atol=10 * RTOL * 30.0)
    u_ref = 3.0 * (1.0 - Y[0]) + 4.0 * Y[3] - 6.0 * Y[1]
    assert np.max(np.abs(d["u"] - u_ref)) <= 10 * RTOL * np.max(np.abs(u_ref))
    tab = d["result"].reversals
    assert len(tab.t) == len(revs)
    np.testing.assert_allclose(tab.t, revs[:, 0], atol=10 * RTOL * 30.0)
    # stuck plateaus (|v| < 0.1 mm/s for 1 s and more) alternate about the set point and stay off it
    still = np.abs(d["v"]) < 1e-4
    plateaus, k = [], 0
    while k < len(still):
        if still[k]:
            j = k
            while j < len(still) and still[j]:
                j += 1
            if d["t"][j - 1] - d["t"][k] >= 1.0 and d["t"][k] > 1.0:
                plateaus.append(d["x"][k] - 1.0)
            k = j
        else:
            k += 1
    assert len(plateaus) >= 3
    np.testing.assert_allclose(plateaus[:3], [-0.2334, 0.1167, -0.0742], atol=5e-4)
    assert all(a * b < 0 for a, b in zip(plateaus, plateaus[1:]))
    assert min(abs(p) for p in plateaus) > 0.05


@pytest.mark.slow  # an example script end to end: .ci/run's second command (-m slow)
def test_example_writes_its_figures(ex, tmp_path):
    out = ex.main(tmp_path, quick=True)
    assert len(out["pngs"]) == 5 and all(p.stat().st_size > 20_000 for p in out["pngs"])
    assert out["bench"] is None


def test_initial_bristle_force_up_to_fs():
    """``simulate`` accepts a LuGre bristle force ``Fc < |F0| <= Fs`` (max_hysteretic_force) and
    refuses one above ``Fs``; released from rest at ``F0 = 1.4 N`` against the reference."""
    system = pf.Oscillator(pf.LuGre(**PAPER), 1.0)
    assert system.friction.max_hysteretic_force == FS and pf.Dahl(1e4, 2.0).max_hysteretic_force == 2.0
    res = pf.simulate(system, 0.0, F0=1.4, reversals=4, rtol=RTOL)
    _, _, revs = radau(lambda t, y: 0.0, 0.1, [0.0], y0=(0.0, 0.0, 1.4 / S0), scale=(2e-5, 3e-3))
    np.testing.assert_allclose(res.reversals.t, revs[:4, 0], rtol=10 * RTOL)
    np.testing.assert_allclose(res.reversals.x, revs[:4, 1], rtol=0, atol=10 * RTOL * 1.4 / S0)
    with pytest.raises(ValueError, match=r"F0 must lie in \[-1.5, 1.5\] N \(the model's max_hysteretic_force, LuGre\), got 1.6"):
        pf.simulate(system, 0.0, F0=1.6, reversals=2)


def test_first_dense_sample_is_the_force_at_the_initial_velocity():
    """A rate-dependent model's friction force at t = 0 includes the damping of the initial
    velocity: ``F(0) = F0 + sigma1 z'(0) + sigma2 v0`` with ``z'(0) = v0 (1 - |v0| F0 / (v0 g(v0)))``
    (the paper's (1)-(3)), not the bristle force ``F0`` alone; the samples after it follow the
    reference."""
    system = pf.Oscillator(pf.LuGre(**PAPER), 1.0, u=0.2)  # the forced dense plant of the experiments
    v0, F0 = 5e-3, 0.3
    times = np.linspace(0.0, 2e-3, 21)
    res = pf.simulate(system, v0, F0=F0, t_end=2e-3, dense=times, rtol=RTOL)
    g = FC + (FS - FC) * math.exp(-((v0 / VS) ** 2))
    F_0 = F0 + S1 * (v0 - abs(v0) * F0 / g) + S2 * v0
    assert F_0 > 1.4  # the damping term dominates: far from F0
    assert res.F[0] == pytest.approx(F_0, rel=1e-12)
    Y, F, _ = radau(lambda t, y: 0.2, 2e-3, times, y0=(0.0, v0, F0 / S0), scale=(1e-5, 5e-3))
    e = errors(res.x, res.v, res.F, Y, F)
    assert max(e) <= 10 * RTOL, e


def test_sharp_stribeck_curve_after_each_reversal():
    """``vs = 1e-5`` m/s (100x sharper than Table I): the Stribeck curve is crossed within about
    1 % of a half-cycle after each reversal. A fixed first step of the integrator spanned it and
    passed the error test (reversal times 3.8e-6 off, 296 rtol at rtol 1e-8); the first step is
    now estimated from the right-hand side. 6 reversals within 10 rtol of the reference."""
    p = (S0, S1, S2, FC, FS, 1e-5)
    system = pf.Oscillator(pf.LuGre(*p), 1.0)
    v0 = FC / math.sqrt(S0)  # the velocity unit
    _, _, revs = radau(lambda t, y: 0.0, 0.1, [0.0], p=p, y0=(0.0, v0, 0.0), scale=(1e-5, v0))
    for rtol in (1e-6, 1e-8):
        tab = pf.simulate(system, v0, reversals=6, rtol=rtol).reversals
        np.testing.assert_allclose(tab.t, revs[:6, 0], rtol=10 * rtol)
        np.testing.assert_allclose(tab.x, revs[:6, 1], rtol=0, atol=10 * rtol * np.max(np.abs(revs[:6, 1])))
        assert np.max(np.abs(tab.F - revs[:6, 2])) <= 10 * rtol * np.max(np.abs(revs[:6, 2]))
