"""Energy analysis of closed loops and sweeps: the controller's work counted (issue 12).

``energy.analyze_result`` of ``controllers.simulate_loop`` (PD and PID, continuous and sampled)
and of ``prefriction.sweep`` entries, for Dahl, Maxwell-slip, GMS as Maxwell-slip and LuGre,
against an independent reference: the closed loop ``m x'' = u - F``, ``u = C(r - x)`` written
here from the models' equations (Dahl (3.2); Maxwell-slip elements that stick at slope ``k_i``
and slip at ``+-W_i``; LuGre, Canudas de Wit et al. 1995, (1)-(3)) and the controllers'
equations (``kp e + ki int e + kd (e - e_f) / tau`` with the filtered error ``e_f``; the
sampled PD ``kp e_k + kd (e_k - e_k-1) / Ts`` held over each sample), integrated by scipy
(DOP853, Radau for LuGre; rtol 1e-11) and restarted at every reversal and element slip, with
the input's work ``int u v dt`` as an extra ODE state. The potential energy at a reversal is
computed from the reference state: (3.9) for Dahl, ``sigma0 z^2 / 2`` for LuGre, and for
Maxwell-slip the work ``-int F dx`` that the unloading branch returns until ``F = 0``,
following every element of the reference state.
"""

from __future__ import annotations

import math
import warnings

import control
import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp
from scipy.optimize import brentq

from prefriction import controllers
import prefriction as pf
from prefriction import energy

M, R0, T_END = 1.0, 2e-5, 0.05
KP, KI, KD, TAU = 3e4, 3e5, 50.0, 1e-4
DAHL = pf.Dahl(1e5, 1.0, 1.0)
K, W = np.array([6e4, 3e4, 1e4]), np.array([0.2, 0.3, 0.5])
LUGRE = (1e5, math.sqrt(1e5), 0.4, 1.0, 1.5, 1e-3)  # sigma0, sigma1, sigma2, Fc, Fs, vs (1995, Table I)
MODELS = {
    "Dahl": DAHL,
    "Maxwell-slip": pf.MaxwellSlip(K, W),
    "GMS": pf.GMS(k=K, alpha=W, Fc=1.0, Fs=1.0, vs=1e-3, C=2e3),  # Fs = Fc, no damping: Maxwell-slip
    "LuGre": pf.LuGre(*LUGRE),
}


# ------------------------------------------------------------------ the reference
def friction_rhs(name, s, stuck):
    """``(F(v, w), w')`` of the model's states ``w`` in direction ``s`` (``stuck``: Maxwell-slip
    elements that follow ``k_i v``)."""
    if name == "Dahl":
        return lambda v, w: (w[0], [DAHL.sigma * v * (1.0 - s * w[0] / DAHL.Fc)])
    if name == "LuGre":
        s0, s1, s2, Fc, Fs, vs = LUGRE

        def lugre(v, w):
            zd = v - s0 * s * v * w[0] / (Fc + (Fs - Fc) * math.exp(-((v / vs) ** 2)))
            return s0 * w[0] + s1 * zd + s2 * v, [zd]
        return lugre
    return lambda v, w: (sum(w), list(np.where(stuck, K * v, 0.0)))


def reference(name, controller, t_end, Ts=None):
    """Closed loop from rest at ``x = 0``: reversal times, the model states and the work
    ``int u v dt`` at each reversal. ``controller`` is ``"PD"`` or ``"PID"`` (continuous) or
    ``"sampled PD"`` (``Ts``)."""
    nw = 3 if name in ("Maxwell-slip", "GMS") else 1
    ki = KI if controller == "PID" else 0.0
    y = np.zeros(5 + nw)  # x, v, e_f (filtered error), int e, W_u, model states
    s, stuck = 1.0, np.ones(nw, bool)  # the step pushes forward
    t, revs, uk, e_prev = 0.0, [], 0.0, 0.0
    edges = np.arange(0.0, t_end + 0.5 * Ts, Ts) if Ts else np.array([0.0, t_end])
    for a, b in zip(edges[:-1], edges[1:]):
        if Ts:
            e = R0 - y[0]
            uk, e_prev = KP * e + KD * (e - e_prev) / Ts, e
        t = a
        while t < b:
            fr = friction_rhs(name, s, stuck)

            def rhs(_, yy, fr=fr):
                e = R0 - yy[0]
                u = uk if Ts else KP * e + ki * yy[3] + KD * (e - yy[2]) / TAU
                F, dw = fr(yy[1], yy[5:])
                return [yy[1], (u - F) / M, (e - yy[2]) / TAU, e, u * yy[1], *dw]

            def reversal(_, yy, s=s):
                return s * yy[1]
            reversal.terminal, reversal.direction = True, -1
            slips = []
            for i in np.flatnonzero(stuck) if nw == 3 else []:
                def slip(_, yy, i=i, s=s):
                    return s * yy[5 + i] - W[i]
                slip.terminal, slip.direction = True, 1
                slips.append(slip)
            sol = solve_ivp(rhs, (t, b), y, method="Radau" if name == "LuGre" else "DOP853",
                            rtol=1e-9 if name == "LuGre" else 1e-11,
                            atol=1e-13 * np.array([1e-5, 1e-2, 1e-5, 1e-7, 1e-5] + [1.0] * nw),
                            events=[reversal] + slips)
            y, t = sol.y[:, -1].copy(), sol.t[-1]
            if sol.status == 1 and sol.t_events[0].size:
                y[1] = 0.0
                revs.append((t, y.copy()))
                s, stuck = -s, np.ones(nw, bool)
            elif sol.status == 1:
                i = np.flatnonzero(stuck)[[k for k, ev in enumerate(sol.t_events[1:]) if ev.size][0]]
                y[5 + i], stuck[i] = s * W[i], False
    return revs


def ms_unloading_energy(F_el, s):
    """Work returned from a reversal with element forces ``F_el`` in the new direction ``s`` until
    the total force is zero (each element moves at ``k_i`` until ``s W_i``); NaN if the force
    already points in the new direction (no zero crossing ahead)."""
    def force(d):
        return float(np.sum(np.clip(F_el + s * K * d, -W, W)))
    if s * force(0.0) > 0.0:
        return math.nan
    d0 = brentq(lambda d: s * force(d), 0.0, 4.0 * W.sum() / K.min())
    return -s * quad(force, 0.0, d0, points=list(np.abs(s * W - F_el) / K), epsabs=1e-16, epsrel=1e-13)[0]


def ref_E_p(name, y, s_new):
    if name == "Dahl":  # int_0^f phi / (1 - phi) dphi, f = s F / Fc; (3.9) for f = -a < 0
        f = s_new * y[5] / DAHL.Fc
        return DAHL.Fc**2 / DAHL.sigma * (-f - math.log1p(-f))
    if name == "LuGre":
        return 0.5 * LUGRE[0] * y[5] ** 2
    return ms_unloading_energy(y[5:], s_new)


# ------------------------------------------------------------------ the runs
T_OUT = np.concatenate((np.linspace(0.0, 1e-3, 201)[:-1], np.linspace(1e-3, T_END, 2000)))  # resolves tau
CONTROLLERS = {"PD": controllers.pd(KP, KD, tau=TAU), "PID": controllers.pid(KP, KI, KD, tau=TAU)}


def loop(name, controller, Ts=None):
    stage = pf.Oscillator(MODELS[name], mass=M)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", controllers.UnstableLoopWarning)  # LuGre's linearisation
        if Ts:
            C = control.tf([KP + KD / Ts, -KD / Ts], [1.0, 0.0], Ts)
            return controllers.simulate_loop(stage, C, R0, T_END, rtol=1e-11)
        return controllers.simulate_loop(stage, CONTROLLERS[controller], R0, T_END,
                                         t_out=T_OUT, rtol=1e-11)


TOL = {False: dict(rtol_t=1e-7, tol_W=1e-6, tol_E=1e-5),  # references at rtol 1e-11
       True: dict(rtol_t=1e-6, tol_W=1e-6, tol_E=1e-5)}  # LuGre, Radau at rtol 1e-9


def compare(rep, revs, name, *, rtol_t, tol_W, tol_E):
    n = min(len(rep), len(revs))
    assert n >= 2 and abs(len(rep) - len(revs)) <= 1, (len(rep), len(revs))
    t_ref = np.array([r[0] for r in revs[:n]])
    W_ref = np.array([r[1][4] for r in revs[:n]])
    E_ref = np.array([ref_E_p(name, r[1], rep.direction[k]) for k, r in enumerate(revs[:n])])
    np.testing.assert_allclose(rep.t[:n], t_ref, rtol=rtol_t)
    scale = float(np.max(np.abs(W_ref)))
    assert rep.W_u[0] == pytest.approx(W_ref[0], abs=tol_W * scale)
    np.testing.assert_allclose(rep.W_u[1:n], np.diff(W_ref), atol=tol_W * scale)
    ok = np.isfinite(E_ref)  # Maxwell-slip: reversals with a force zero crossing ahead
    assert np.count_nonzero(ok) >= 2
    top = float(np.max(E_ref[ok]))
    np.testing.assert_allclose(rep.E_p[:n][ok], E_ref[ok], rtol=tol_E, atol=tol_E * top)
    # the balance at every reversal: the initial energy plus the input's work, less the loss
    lost = np.cumsum(rep.E_d[:n])
    W_cum = np.cumsum(rep.W_u[:n])
    np.testing.assert_allclose(rep.E_0 + W_cum - lost, rep.E_p[:n], atol=1e-12 * scale)
    return n


@pytest.mark.parametrize("controller", ["PD", "PID"])
@pytest.mark.parametrize("name", list(MODELS))
def test_continuous_loop_counts_the_controller_work(name, controller):
    res = loop(name, controller)
    rep = energy.analyze_result(res, method="simpson")
    assert isinstance(rep, energy.LuGreEnergyReport if name == "LuGre" else energy.EnergyReport)
    revs = reference(name, controller, T_END)
    compare(rep, revs, name, **TOL[name == "LuGre"])
    without = energy.analyze_samples(res.t, res.x, res.v, res.F, system=res.system)  # system.u only: no work
    assert np.all(without.W_u == 0.0)
    if name != "LuGre":  # (2.10) against int F dx: leaving the controller's force out is detected
        assert without.residual_2_10 > 1e-3 and without.residual_2_10 > 100 * rep.residual_2_10


def test_sampled_pd_loop_counts_the_held_force_exactly():
    """A sampled PD (ZOH): the force is constant between the samples, its work ``u_k (x_k+1 - x_k)``;
    the trapezoid rule on ``u v`` would smear each jump of ``u`` over an interval."""
    Ts = 2e-4
    res = loop("Dahl", "sampled PD", Ts=Ts)
    assert res.Ts == Ts and res.t.size == round(T_END / Ts) + 1
    revs = reference("Dahl", "sampled PD", T_END, Ts=Ts)
    rep = energy.analyze_result(res)  # zoh from res.Ts
    # 250 samples: reversals and forces are interpolated between samples (third / second order)
    n = compare(rep, revs, "Dahl", rtol_t=1e-6, tol_W=1e-6, tol_E=1e-5)
    smeared = energy.analyze_result(res, zoh=False)
    W_ref = np.diff([r[1][4] for r in revs[:n]])
    err = float(np.max(np.abs(rep.W_u[1:n] - W_ref)))
    assert float(np.max(np.abs(smeared.W_u[1:n] - W_ref))) > 100 * err  # measured: 2e-3 vs 1e-8 of max |W|


def test_sweep_results_with_a_feedback_force():
    """``analyze_result`` of each ``sweep`` entry (a PD loop as ``simulate``'s feedback): the
    samples' ``u`` holds the feedback force; one structure per model, no new compile."""
    C = CONTROLLERS["PD"].ss()
    fb = pf.LinearFeedback(A=C.A, B=C.B, C=C.C, D=C.D, reference=R0)
    names = ["Dahl", "Maxwell-slip", "LuGre"]
    systems = [pf.Oscillator(MODELS[n], mass=M) for n in names]
    out = pf.sweep(systems, 0.0, t_end=T_END, dense=T_OUT, feedback=fb, rtol=1e-11, progress=False)
    for name, system, res in zip(names, systems, out):
        rep = energy.analyze_result(res, system=system, method="simpson")
        compare(rep, reference(name, "PD", T_END), name, **TOL[name == "LuGre"])
