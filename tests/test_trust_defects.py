"""Defects of issue 26, item 10: symbolic.plant_step checks, FrictionStream copy and pickle,
PointToPoint at extreme limits.

References: the Dahl branch from the virgin state in closed form, ``F = Fc (1 - exp(-sigma x / Fc))``
(gamma = 1, a monotone move); the S-curve's end position is its distance by construction.
"""

from __future__ import annotations

import copy
import math
import pickle

import numpy as np
import pytest

import prefriction as pf
from prefriction.signals import PointToPoint
from prefriction.symbolic import plant_step


@pytest.fixture(scope="module")
def step():
    return plant_step(pf.Dahl(sigma=1e4, Fc=1.0))


GOOD = dict(y0=[0.0, 1.0, 0.0, 1.0], q=[1.0], u=0.0, h=3.0, rtol=1e-10)


@pytest.mark.parametrize("name, value, said", [
    ("h", -1.0, "h must be a finite step >= 0"),
    ("h", math.nan, "h must be a finite step >= 0"),
    ("h", math.inf, "h must be a finite step >= 0"),
    ("u", math.nan, "u must be a finite"),
    ("rtol", 0.0, "rtol must lie in"),
    ("rtol", math.nan, "rtol must lie in"),
    ("rtol", 0.5, "rtol must lie in"),
    ("y0", [0.0, math.nan, 0.0, 1.0], "y0 must be 4 finite numbers"),
    ("y0", [0.0, 1.0, 0.0], "y0 must be 4 finite numbers"),
    ("q", [math.inf], "q must be"),
])
def test_plant_step_refuses_bad_numbers(step, name, value, said) -> None:
    """A negative step reported ok = 1; NaN force or zero/NaN rtol gave raw CasADi errors."""
    args = {**GOOD, name: value}
    with pytest.raises(ValueError, match=said):
        step(*args.values())


def test_plant_step_too_long_a_step_is_a_solver_error(step) -> None:
    """h = 1e12 (normalised) is more events than one step holds: a SolverError saying what helps."""
    with pytest.raises(pf.SolverError, match="Take shorter steps"):
        step(*{**GOOD, "h": 1e12}.values())


def test_plant_step_still_symbolic_and_right(step) -> None:
    """Checked numeric calls give the documented numbers; symbolic calls pass through."""
    import casadi as ca

    y1, n, ok = step(*GOOD.values())
    assert int(n) == 1 and int(ok) == 1
    y = ca.MX.sym("y", 4)
    out = step(y, [1.0], 0.0, 3.0, 1e-10)
    f = ca.Function("f", [y], [out[0]])
    np.testing.assert_array_equal(np.asarray(f(GOOD["y0"])), np.asarray(y1))


def _virgin_dahl(x: float, sigma: float = 1e5, Fc: float = 1.0) -> float:
    return Fc * (1.0 - math.exp(-sigma * x / Fc))


def test_friction_stream_copy_is_independent() -> None:
    """copy.copy shared the state with the original (both then 1.66 N off)."""
    stream = pf.FrictionStream(pf.Dahl(sigma=1e5, Fc=1.0), x0=0.0)
    assert stream.step(1e-5, 1.0) == pytest.approx(_virgin_dahl(1e-5), rel=1e-12)
    for twin in (copy.copy(stream), copy.deepcopy(stream)):
        assert twin.step(2e-5, 2.0) == pytest.approx(_virgin_dahl(2e-5), rel=1e-12)
    assert stream.step(2e-5, 2.0) == pytest.approx(_virgin_dahl(2e-5), rel=1e-12)
    assert stream.step(3e-5, 3.0) == pytest.approx(_virgin_dahl(3e-5), rel=1e-12)


def test_friction_stream_pickles() -> None:
    """Pickling failed with a raw SWIG error; now the stream resumes where it was."""
    stream = pf.FrictionStream(pf.Dahl(sigma=1e5, Fc=1.0), x0=0.0)
    stream.step(1e-5, 1.0)
    again = pickle.loads(pickle.dumps(stream))
    assert (again.x, again.t, again.F) == (stream.x, stream.t, stream.F)
    assert again.step(2e-5, 2.0) == pytest.approx(_virgin_dahl(2e-5), rel=1e-12)
    assert stream.step(2e-5, 2.0) == pytest.approx(_virgin_dahl(2e-5), rel=1e-12)


@pytest.mark.parametrize("args, kw", [((1e-5, 1e100, 1e100), {"j_max": 1e100}),
                                      ((1e-310, 1e-3, 1e-2), {"j_max": 1.0})])
def test_point_to_point_that_cannot_be_evaluated_is_refused(args, kw) -> None:
    """These ended at 3.5e9 m and 1.1e-95 m instead of their distance."""
    with pytest.raises(ValueError, match="cannot be evaluated in double precision"):
        PointToPoint(*args, **kw)


@pytest.mark.parametrize("args, kw", [((1e-5, 2e-4, 5e-3), {"j_max": 0.5}), ((1e-5, 2e-4, 5e-3), {}),
                                      ((-3e-3, 1e-2, 1.0), {"j_max": 1e3, "position": 0.5}),
                                      ((1e-9, 1e-3, 1e2), {"j_max": 1e6})])
def test_point_to_point_ordinary_moves_still_land(args, kw) -> None:
    move = PointToPoint(*args, **kw)
    end = move(move.start + move.duration + 1.0)
    assert end == pytest.approx(move.position + move.distance, rel=1e-9, abs=1e-20)


# --- item 11: size limits that count memory, not samples -----------------------------------

def test_friction_along_limit_counts_the_state() -> None:
    """A 100-element Maxwell-slip along half the sample limit asked for 15 GiB; now refused at once."""
    from prefriction._memory import MAX_BYTES

    model = pf.MaxwellSlip(np.full(100, 1e3), np.full(100, 1e-3))
    k = model.n_states + model.n_flags
    n = MAX_BYTES // (8 * (16 + 3 * k)) + 1000  # just above what fits
    t = np.linspace(0.0, 1.0, n)
    with pytest.raises(ValueError, match=r"friction_along of MaxwellSlip .* GiB, more than the limit of 4 GiB"):
        pf.friction_along(model, t, 1e-6 * np.sin(t))


def test_sum_of_models_cannot_bypass_the_element_limit() -> None:
    """Ten 100-element Maxwell-slip models (1,010 states) took 106 s to compile; now refused."""
    m = pf.MaxwellSlip(np.full(100, 1e3), np.full(100, 1e-3))
    with pytest.raises(ValueError, match="at most 256 states in all"):
        pf.models.Parallel.of(*[m] * 10)
    assert (m + m).n_states == 202  # two still fit


def test_simulate_loop_limit_counts_memory() -> None:
    """At its own sample limit a loop needed more than 4 GB and ended in a raw MemoryError."""
    from prefriction import controllers

    stage = pf.Oscillator(pf.Dahl(2e5, 1.5), mass=0.5)
    C = controllers.design_pid(stage, wn=2 * np.pi * 150)
    with pytest.raises(ValueError, match=r"sampled loop of Dahl: 9_900_001 sample instants .* limit of 4 GiB"):
        controllers.simulate_loop(stage, C, 1e-6, 990.0, Ts=1e-4)


# --- item 15: the smaller items --------------------------------------------------------------

@pytest.fixture(scope="module")
def loop_case():
    from prefriction import controllers

    stage = pf.Oscillator(pf.Dahl(2e5, 1.5), mass=0.5)
    return stage, controllers.design_pid(stage, wn=2 * np.pi * 150)


def test_mismatch_names_itself(loop_case) -> None:
    """``mismatch=(nan, 1)`` named "stiffness", an argument simulate_loop does not have."""
    from prefriction import controllers

    stage, C = loop_case
    with pytest.raises(ValueError, match=r"mismatch\[0\] \(the stiffness factor\) must be finite"):
        controllers.simulate_loop(stage, C, 1e-6, 0.01, Ts=1e-4, compensator=controllers.Feedforward(stage.friction),
                                  mismatch=(math.nan, 1.0))


def test_mismatch_with_a_disturbance_observer_is_refused(loop_case) -> None:
    """``mismatch`` was silently ignored with the model-free DisturbanceObserver."""
    from prefriction import controllers

    stage, C = loop_case
    dob = controllers.DisturbanceObserver(mass=0.5, bandwidth=2 * np.pi * 300)
    with pytest.raises(ValueError, match="DisturbanceObserver has none"):
        controllers.simulate_loop(stage, C, 1e-6, 0.01, Ts=1e-4, compensator=dob, mismatch=(1.2, 0.8))


@pytest.mark.parametrize("kw, said", [({"x0": math.nan}, "x0 must be finite"), ({"v0": math.inf}, "v0 must be finite"),
                                      ({"F0": 3.0}, r"F0 must lie in \[-1.5, 1.5\] N")])
def test_compensated_loop_start_is_checked(loop_case, kw, said) -> None:
    """With a compensator, x0 = nan, v0 = inf and F0 = 2 Fc ended in SolverError instead of ValueError."""
    from prefriction import controllers

    stage, C = loop_case
    with pytest.raises(ValueError, match=said):
        controllers.simulate_loop(stage, C, 1e-6, 0.01, Ts=1e-4, compensator=controllers.Feedforward(stage.friction),
                                  **kw)


@pytest.fixture(scope="module")
def along():
    t = np.linspace(0.0, 1.0, 50)
    return pf.friction_along(pf.Dahl(sigma=1e5, Fc=1.0), t, 1e-5 * np.sin(2 * np.pi * t))


def test_plot_path_errors_are_clear(along, tmp_path) -> None:
    """Plot paths raised raw FileNotFoundError / NotADirectoryError."""
    with pytest.raises(ValueError, match="path .*does not exist"):
        along.plot(tmp_path / "missing" / "a.png")
    (tmp_path / "file").write_text("")
    with pytest.raises(ValueError, match="path .*(does not exist|cannot be written)"):
        along.plot(tmp_path / "file" / "a.png")
    with pytest.raises(ValueError, match="must name a file"):
        along.plot(tmp_path)


def test_figure_outdir_errors_name_outdir(tmp_path) -> None:
    """plotting.save checks its ``outdir`` like an export's ``directory`` (one shared check)."""
    from prefriction.plotting import new_figure, save

    fig, _ = new_figure(1, 1)
    (tmp_path / "file").write_text("")
    with pytest.raises(ValueError, match="outdir must be a directory, got the file"):
        save(fig, tmp_path / "file", "a.png")
    with pytest.raises(ValueError, match="outdir must name a directory, got ''"):
        save(fig, "", "a.png")
    with pytest.raises(TypeError, match="outdir must be a str or pathlib.Path, got int 3"):
        save(fig, 3, "a.png")
    out = save(fig, tmp_path / "new" / "deeper", "a.png")
    assert out == tmp_path / "new" / "deeper" / "a.png" and out.read_bytes()[:4] == b"\x89PNG"


def test_plot_does_not_write_through_a_link(along, tmp_path) -> None:
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    link = tmp_path / "along.png"
    link.symlink_to(victim)
    out = along.plot(link)
    assert victim.read_text() == "precious" and not out.is_symlink()
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.slow
def test_point_to_point_with_eight_phases_starts() -> None:
    """Dahl gamma = 2 with 8 phases failed at its start point (Invalid_Number_Detected after 0
    iterations: the first guess drove a wrong-way branch to NaN). Now it solves, and its extra
    phases collapse: the same time as the two-phase move (the optimum has no other reversal)."""
    from prefriction.optimal import point_to_point

    stage = pf.Oscillator(pf.Dahl(1e4, 1.0, 2.0), mass=1.0)
    eight = point_to_point(stage, 1e-3, u_max=5.0, modes=(1.0, -1.0) * 4, intervals=12)
    two = point_to_point(stage, 1e-3, u_max=5.0, modes=(1.0, -1.0), intervals=12)
    assert eight.t_final == pytest.approx(two.t_final, rel=1e-4)


# --- item 15: wrong facts in the documentation ------------------------------------------------

def _doc(name: str) -> str:
    from pathlib import Path

    return (Path(__file__).resolve().parent.parent / "docs" / name).read_text()


def test_reliability_budget_is_the_code_s() -> None:
    """docs/reliability.md said the reversal budget is 1e6 where the code holds 1e7."""
    import re

    from prefriction.simulation.simulate import MAX_REVERSALS

    (value,) = re.findall(r"`MAX_REVERSALS = ([0-9.e+]+)`", _doc("reliability.md"))
    assert float(value) == MAX_REVERSALS


def test_interpreted_fallback_is_not_claimed_bit_identical() -> None:
    """The interpreted fallback was said to give "the same results"; it differs by rounding
    (8.6e-10 relative seen on Maxwell-slip). The pages that describe it must not claim more."""
    import prefriction.simulation.compiled as compiled

    for text in (_doc("simulator.md"), _doc("sweeps.md"), _doc("reliability.md"), compiled.__doc__):
        assert "same results" not in " ".join(text.split())
    assert "not bit for bit" in " ".join(_doc("reliability.md").split()) and "#security" in _doc("reliability.md")
