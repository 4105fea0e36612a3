"""prefriction.export.plant_source: the stage over one sample period in C (hardware in the loop).

The exported period is compiled with ``gcc -std=c99 -Wall -Werror``, driven by held forces and
compared with its period Function evaluated in Python (CasADi's erk: to the tolerance) and with an independent scipy
integration of ``m x'' = u_k - F``, Dahl's ``F' = sigma v (1 - sign(v) F / Fc)`` (3.2, gamma = 1),
written from the equations and restarted at every reversal (``v = 0``).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import prefriction as pf
from prefriction import export

needs_gcc = pytest.mark.skipif(export.gcc() is None, reason="gcc is not on the PATH: the exported C cannot be compiled")
TS = 1e-4
SIGMA, FC, MASS = 1e5, 1.0, 0.5


@pytest.fixture(scope="module")
def forces():
    """2000 periods: a 50 Hz force of 1.5 Fc (sliding, reversals), then 0.4 Fc (pre-sliding)."""
    t = np.arange(2000) * TS
    return np.where(t < 0.1, 1.5, 0.4) * np.sin(2 * np.pi * 50 * t)


@pytest.fixture(scope="module")
def exported(tmp_path_factory, forces):
    if export.gcc() is None:
        pytest.skip("gcc is not on the PATH: the exported C cannot be compiled")
    system = pf.Oscillator(pf.Dahl(SIGMA, FC, 1.0), mass=MASS)
    src = export.plant_source(system, "stage", tmp_path_factory.mktemp("plant"), Ts=TS, rtol=1e-10)
    return src, export.run_plant_c(src, forces, optimize=False)  # -O0: a quick compile, the same numbers


def scipy_reference(u, mass=MASS):
    """The stage under the held forces ``u``, integrated by scipy (DOP853, rtol 1e-12), restarted at reversals."""
    def rhs(t, y, uk, s):
        x, v, F = y
        return [v, (uk - F) / mass, SIGMA * v * (1.0 - s * F / FC)]

    def reversal(t, y, uk, s):
        return y[1]
    reversal.terminal = True
    y = np.array([0.0, 0.0, 0.0])
    out = np.zeros((u.size, 3))
    for k, uk in enumerate(u):
        t0, t1 = k * TS, (k + 1) * TS
        while True:
            s = np.sign(y[1]) if y[1] != 0.0 else np.sign(uk - y[2])
            if s == 0.0:  # at rest without a net force: it stays there
                break
            reversal.direction = -s  # v crossing zero against the branch (not the start at v = 0)
            sol = solve_ivp(rhs, (t0, t1), y, method="DOP853", rtol=1e-12, atol=1e-15, args=(uk, s),
                            events=reversal)
            y = sol.y[:, -1].copy()
            if sol.status == 1:  # a reversal: restart on the new branch
                t0, y[1] = sol.t[-1], 0.0
                continue
            break
        out[k] = y
    return out


@needs_gcc
def test_c_plant_matches_its_function_in_python(exported, forces):
    """The C is the native driver (step size carried from period to period), the Function CasADi's
    erk restarted each period: two integrations of one tableau, equal to the tolerance (1e-10)."""
    src, run = exported
    ref = export.evaluate_plant(src, forces)
    assert np.all(run.status == 0) and np.all(ref.status == 0)
    for a, b in ((run.x, ref.x), (run.v, ref.v), (run.F, ref.F)):
        assert np.max(np.abs(a - b)) <= 1e-10 * np.max(np.abs(b))


@needs_gcc
def test_c_plant_matches_an_independent_scipy_integration(exported, forces):
    _src, run = exported
    ref = scipy_reference(forces)
    assert np.ptp(run.x) > 5e-5 and np.count_nonzero(np.diff(np.sign(run.v))) > 8  # it slides and reverses
    assert np.max(np.abs(run.x - ref[:, 0])) <= 1e-10 * np.max(np.abs(ref[:, 0]))  # rtol = 1e-10
    assert np.max(np.abs(run.F - ref[:, 2])) <= 1e-10 * FC


@needs_gcc
def test_plant_header_and_status(exported):
    src, run = exported
    h = src.header.read_text()
    assert "int stage_step(stage_state *s, double u);" in h and "void stage_reset(stage_state *s, double x0, double v0);" in h
    assert run.ns_per_step > 0 and "periods" in run.summary()
    assert src.kind == "plant" and "Dahl stage of 0.5 kg" in repr(src)
    text = src.source.read_text()
    includes = {line.split()[1] for line in text.splitlines() if line.startswith("#include")}
    assert includes == {"<math.h>", '"stage.h"'}  # CasADi's erk integrator generated in, no casadi header
    assert "malloc" not in text and "printf" not in text


def test_plant_arguments_are_checked(tmp_path):
    system = pf.Oscillator(pf.Dahl(SIGMA, FC), mass=MASS)
    with pytest.raises(ValueError, match="Ts must be finite and > 0"):
        export.plant_source(system, "p", tmp_path, Ts=0.0)
    with pytest.raises(TypeError, match="system must be a prefriction.Oscillator"):
        export.plant_source(pf.Dahl(SIGMA, FC), "p", tmp_path, Ts=TS)
    with pytest.raises(ValueError, match="system must have no input force"):
        export.plant_source(pf.Oscillator(pf.Dahl(SIGMA, FC), u=1.0), "p", tmp_path, Ts=TS)
    with pytest.raises(ValueError, match=r"F0 must be within \+-1.0 N"):
        export.plant_source(system, "p", tmp_path, Ts=TS, F0=2.0)
    with pytest.raises(ValueError, match="rtol must be in"):
        export.plant_source(system, "p", tmp_path, Ts=TS, rtol=2.0)


@needs_gcc
def test_periods_with_several_reversals_are_resolved(tmp_path):
    """A 1 mg stage on a 1e5 N/m Dahl contact rings at 50 kHz: a 0.1 ms period holds several
    reversals; the exported C resolves them (status 0) and matches scipy, where CasADi's period
    Function stops after two (status 1)."""
    stage = pf.Oscillator(pf.Dahl(SIGMA, FC), mass=1e-6)
    src = export.plant_source(stage, "fast", tmp_path, Ts=TS, rtol=1e-10)
    u = np.full(3, 0.5)
    run, fun = export.run_plant_c(src, u, optimize=False), export.evaluate_plant(src, u)
    ref = scipy_reference(u, mass=1e-6)
    assert np.all(run.status == 0) and np.all(fun.status == 1)
    assert np.max(np.abs(run.x - ref[:, 0])) <= 1e-9 * np.max(np.abs(ref[:, 0]))
    assert np.max(np.abs(run.F - ref[:, 2])) <= 1e-9 * FC


@needs_gcc
def test_a_period_with_more_reversals_than_the_plant_resolves_is_reported(tmp_path):
    """The same stage over 1 ms periods: some 100 reversals each, more than the 48 the exported
    plant resolves; every step says so (status 1)."""
    stage = pf.Oscillator(pf.Dahl(SIGMA, FC), mass=1e-6)
    src = export.plant_source(stage, "fast", tmp_path, Ts=1e-3)
    run = export.run_plant_c(src, np.full(3, 0.5), optimize=False)
    assert np.all(run.status == 1)
    assert "1 not completed" not in repr(run) and "3 not completed" in repr(run)


@needs_gcc
def test_two_exported_plants_link_into_one_program(tmp_path):
    """Every symbol of the exported native driver carries the export's name: a Dahl and a LuGre
    plant compile (``-std=c99 -Wall -Werror``) and link into one program that steps both."""
    import subprocess

    export.plant_source(pf.Oscillator(pf.Dahl(SIGMA, FC), mass=MASS), "dahl", tmp_path, Ts=TS)
    export.plant_source(pf.Oscillator(pf.LuGre(1e5, 300.0, 0.4, 1.0, 1.3, 1e-3), mass=MASS), "lugre", tmp_path, Ts=TS)
    (tmp_path / "main.c").write_text(
        '#include <stdio.h>\n#include "dahl.h"\n#include "lugre.h"\n'
        "int main(void) { dahl_state a; lugre_state b; int s;\n"
        "  dahl_reset(&a, 0.0, 0.0); lugre_reset(&b, 0.0, 0.0);\n"
        "  s = dahl_step(&a, 0.5) + lugre_step(&b, 0.5);\n"
        '  printf("%d %.17g %.17g\\n", s, a.F, b.F); return 0; }\n')
    exe = tmp_path / "both"
    subprocess.run([export.gcc(), "-std=c99", "-Wall", "-Werror", "-O0", "-o", str(exe), "main.c", "dahl.c",
                    "lugre.c", "-lm"], cwd=tmp_path, check=True, capture_output=True)
    status, Fa, Fb = subprocess.run([str(exe)], capture_output=True, text=True, check=True).stdout.split()
    assert status == "0" and 0.0 < float(Fa) < 0.5 and 0.0 < float(Fb) < 0.5  # both pushed forward, below u
