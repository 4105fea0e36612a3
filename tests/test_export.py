"""prefriction.export.c_source: the C99 friction model along measured positions.

Each export is compiled with ``gcc -std=c99 -Wall -Werror`` (and ``-pedantic``), run on 1e5
samples and compared with the CasADi Function it came from (to 1e-12 of the force range) and
with references written from the models' equations, independent of the toolbox's code: Dahl's
exponential branches (gamma = 1, 3.2), the stop operators of Maxwell-slip, and LuGre's exact
solution at a constant velocity over each sample interval; and with ``pf.friction_along``, which
it streams.
"""

from __future__ import annotations

import inspect
import math
import subprocess

import numpy as np
import pytest

import prefriction as pf
from prefriction import export

needs_gcc = pytest.mark.skipif(export.gcc() is None, reason="gcc is not on the PATH: the exported C cannot be compiled")
N = 100_000
TS = 2.0**-13
"""Sample time [s] (8.2 kHz), exact in binary: ``np.diff(t)`` of ``t = k Ts`` is ``Ts`` itself, so
friction_along sees the intervals the C code assumes."""


@pytest.fixture(scope="module")
def motion():
    """1e5 positions at 8.2 kHz: a 3 Hz sine of growing and shrinking amplitude (minor loops,
    1 um to 20 um), plus a stretch at rest and repeated equal samples."""
    t = np.arange(N) * TS
    x = 1e-5 * np.sin(2 * np.pi * 3 * t) * (1.0 + 0.9 * np.sin(2 * np.pi * 0.7 * t)) + 2e-6
    x[5000:5100] = x[5000]
    return x


def _rel(a, b):
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


def dahl1_reference(sigma, Fc, x):
    """Dahl gamma = 1 from its branches: ``s F / Fc = 1 - (1 - s F_r / Fc) exp(-sigma |x - x_r| / Fc)``
    from the last reversal ``(x_r, F_r)`` (3.2 integrated; virgin start F = 0 at x[0])."""
    F = np.zeros(x.size)
    s, xr, Fr = 0.0, x[0], 0.0
    for i in range(1, x.size):
        dx = x[i] - x[i - 1]
        if dx != 0.0:
            sn = 1.0 if dx > 0 else -1.0
            if sn != s:
                s, xr, Fr = sn, x[i - 1], F[i - 1]
        F[i] = F[i - 1] if s == 0.0 else s * Fc * (1.0 - (1.0 - s * Fr / Fc) * math.exp(-sigma * abs(x[i] - xr) / Fc))
    return F


def maxwell_reference(k, W, x):
    """Maxwell-slip: each element a stop operator ``F_i <- clip(F_i + k_i dx, -W_i, W_i)``."""
    Fi = np.zeros(len(k))
    F = np.zeros(x.size)
    for i in range(1, x.size):
        Fi = np.clip(Fi + np.asarray(k) * (x[i] - x[i - 1]), -np.asarray(W), np.asarray(W))
        F[i] = Fi.sum()
    return F


def lugre_reference(m, x, Ts):
    """LuGre (Canudas de Wit et al. 1995, (1)-(3)) at the constant velocity ``v = dx / Ts`` over
    each interval: ``z' = v - sigma0 |v| z / g(v)`` is linear in ``z``, so
    ``z(Ts) = s g / sigma0 + (z0 - s g / sigma0) exp(-sigma0 |v| Ts / g)``;
    ``F = sigma0 z + sigma1 z' + sigma2 v`` at the end of the interval."""
    z, F = 0.0, np.zeros(x.size)
    for i in range(1, x.size):
        v = (x[i] - x[i - 1]) / Ts
        g = m.Fc + (m.Fs - m.Fc) * math.exp(-(v / m.vs) ** 2)
        if v != 0.0:
            zs = math.copysign(g / m.sigma0, v)
            z = zs + (z - zs) * math.exp(-m.sigma0 * abs(v) * Ts / g)
        dz = v - m.sigma0 * abs(v) * z / g
        F[i] = m.sigma0 * z + m.sigma1 * dz + m.sigma2 * v
    return F


CASES = {
    "dahl1": (pf.Dahl(2e5, 1.5, 1.0), None, 1),
    "dahl_sat": (pf.Dahl(2e5, 1.5, 0.5), None, 1),
    "dahl3": (pf.Dahl(2e5, 1.5, 3.0), None, 4),
    "maxwell": (pf.MaxwellSlip([1e5, 6e4, 3e4], [0.3, 0.5, 0.6]), None, 1),
    "lugre": (pf.LuGre(2e5, 400.0, 0.5, 1.2, 1.6, 2e-3), TS, 8),
    "gms": (pf.GMS([1e5, 6e4, 3e4], [0.3, 0.3, 0.4], 1.2, 1.6, 2e-3, 50.0), TS, 4),
}


@pytest.fixture(scope="module")
def runs(tmp_path_factory, motion):
    """Each case exported, compiled with gcc -std=c99 -Wall -Werror -O2 and run over the motion."""
    if export.gcc() is None:
        pytest.skip("gcc is not on the PATH: the exported C cannot be compiled")
    d = tmp_path_factory.mktemp("export")
    out = {}
    for name, (model, Ts, n_sub) in CASES.items():
        src = export.c_source(model, name, d, Ts=Ts, n_sub=n_sub)
        out[name] = (src, export.run_c(src, motion))
    return out


@needs_gcc
@pytest.mark.parametrize("name", list(CASES))
def test_c_matches_its_function_in_python(runs, motion, name):
    """On the first 2e4 of the 1e5 samples (CasADi's virtual machine is slow; friction_along
    checks all of them below)."""
    src, run = runs[name]
    assert run.F.size == N and np.all(np.isfinite(run.F))
    n = 20_000
    assert _rel(run.F[:n], export.evaluate(src, motion[:n])) <= 1e-12
    assert np.ptp(run.F) > 0.1  # the motion exercises the model


@needs_gcc
@pytest.mark.parametrize("name", list(CASES))
def test_c_matches_friction_along_on_1e5_samples(runs, motion, name):
    """The streaming form of friction_along: equal from the second sample on; at the first the
    stream returns the virgin force 0 (friction_along takes the rate-dependent part of its first
    sample from the first interval's velocity, which a stream does not know yet)."""
    src, run = runs[name]
    along = pf.friction_along(src.model, np.arange(N) * TS, motion)
    assert run.F[0] == 0.0
    assert np.max(np.abs(run.F[1:] - along.F[1:])) <= 1e-12 * np.max(np.abs(along.F))


@needs_gcc
def test_dahl_gamma_1_matches_its_exponential_branches(runs, motion):
    m = CASES["dahl1"][0]
    assert _rel(runs["dahl1"][1].F, dahl1_reference(m.sigma, m.Fc, motion)) <= 1e-12


@needs_gcc
def test_maxwell_slip_matches_stop_operators(runs, motion):
    m = CASES["maxwell"][0]
    assert _rel(runs["maxwell"][1].F, maxwell_reference(m.stiffness, m.slip_force, motion)) <= 1e-12


@needs_gcc
def test_lugre_matches_the_exact_interval_solution(runs, motion):
    m = CASES["lugre"][0]
    assert _rel(runs["lugre"][1].F, lugre_reference(m, motion, TS)) <= 1e-12


@needs_gcc
def test_export_is_plain_c99_without_casadi_header(runs, tmp_path):
    for src, _run in runs.values():
        text = src.source.read_text() + src.header.read_text()
        includes = {line.split()[1] for line in text.splitlines() if line.startswith("#include")}
        assert includes == {"<math.h>", f'"{src.name}.h"'}
        assert "casadi" not in src.header.read_text()
        done = subprocess.run([export.gcc(), "-std=c99", "-Wall", "-Werror", "-pedantic", "-c",
                               str(src.source), "-I", str(src.header.parent), "-o", str(tmp_path / "o.o")],
                              capture_output=True, text=True)
        assert done.returncode == 0, done.stderr


@needs_gcc
def test_header_has_the_fixed_interface(runs):
    src = runs["lugre"][0]
    h = src.header.read_text()
    assert "typedef struct {" in h and "} lugre_state;" in h
    assert "void lugre_reset(lugre_state *s, double x0);" in h
    assert "double lugre_force(lugre_state *s, double x);" in h
    assert repr(src).startswith("CSource('lugre', model: LuGre(") and f"Ts = {TS!r} s" in src.summary()


def test_rate_dependent_models_need_the_sample_time(tmp_path):
    for model in (CASES["lugre"][0], CASES["gms"][0]):
        with pytest.raises(ValueError, match=r"Ts is required for (LuGre|GMS): the model is rate-dependent"):
            export.c_source(model, "m", tmp_path)
    with pytest.raises(ValueError, match=r"Ts must be finite and > 0, got -0.001"):
        export.c_source(CASES["lugre"][0], "m", tmp_path, Ts=-1e-3)


@pytest.mark.parametrize("name", ["", "1abc", "a-b", "int", "casadi_x", "x" * 64])
def test_bad_names_are_refused(tmp_path, name):
    with pytest.raises(ValueError, match=f"name must be a C identifier.*got {name!r}"[:60].replace("(", r"\(")):
        export.c_source(pf.Dahl(1e5, 1.0), name, tmp_path)


def test_bad_arguments_are_refused(tmp_path):
    with pytest.raises(TypeError, match="name must be a str"):
        export.c_source(pf.Dahl(1e5, 1.0), 3, tmp_path)
    with pytest.raises(TypeError, match="model must be a prefriction.FrictionModel"):
        export.c_source("dahl", "d", tmp_path)
    with pytest.raises(TypeError, match="directory must be a str or pathlib.Path"):
        export.c_source(pf.Dahl(1e5, 1.0), "d", 5)
    with pytest.raises(ValueError, match="n_sub"):
        export.c_source(pf.Dahl(1e5, 1.0), "d", tmp_path, n_sub=0)
    (tmp_path / "file").write_text("")
    with pytest.raises(ValueError, match="directory must be a directory"):
        export.c_source(pf.Dahl(1e5, 1.0), "d", tmp_path / "file")


@pytest.mark.parametrize("name", export.__all__)
def test_public_names_have_numpydoc_docstrings(name):
    obj = getattr(export, name)
    doc = inspect.getdoc(obj)
    assert doc and len(doc.splitlines()[0]) > 10
    params = [p for p in inspect.signature(obj).parameters if p != "self"] if inspect.isfunction(obj) else []
    if params:
        assert "Parameters\n----------" in doc


@needs_gcc
@pytest.mark.parametrize("model", [pf.Dahl(sigma=40384.0, Fc=2.3444, gamma=0.024824),
                                   pf.MaxwellSlip([3e4, 1.5e4, 5e3], [0.8, 0.9, 0.7])], ids=["dahl", "maxwell"])
def test_tribometer_record_in_c_matches_friction_along(tmp_path, model):
    """The measured tribometer record (42,579 samples at uneven steps of 5-10 ms) through the
    Dahl model fitted to it in docs/export.md (parameters rounded) and a 3-element Maxwell-slip
    model; rate-independent, so the uneven steps need no sample time."""
    from prefriction import data

    rec = data.tribometer()
    src = export.c_source(model, "tribo", tmp_path)
    run = export.run_c(src, rec.x)
    along = pf.friction_along(model, rec.t, rec.x)
    assert np.max(np.abs(run.F - along.F)) <= 1e-12 * np.max(np.abs(along.F))
    assert along.reversals.size > 100  # the record's 117 reversals
    loaded = (rec.t >= 12.0) & (rec.t <= 60.0)  # the fitted window, under the normal load
    miss = run.F[loaded] - rec.F[loaded]
    assert np.sqrt(np.mean((miss - miss.mean()) ** 2)) < 0.3  # it describes the record [N]


def test_bench_export_option_is_checked():
    from prefriction.cli.bench.options import parse

    assert parse(["--export", "--repeats", "3"]).export
    with pytest.raises(SystemExit) as exc:
        parse(["--export", "--quick"])
    assert exc.value.code == 2


def test_export_is_a_lazy_subpackage_of_prefriction():
    assert pf.export is export and "export" in pf.__all__


def test_run_arguments_are_checked(tmp_path):
    src = export.c_source(pf.Dahl(1e5, 1.0), "d", tmp_path)
    with pytest.raises(ValueError, match=r"x must be a 1-d array of 1 to 1000000 positions \[m\], got shape \(1000001,\)"):
        export.evaluate(src, np.zeros(1_000_001))
    with pytest.raises(ValueError, match="x must be a 1-d array"):
        export.run_c(src, np.zeros((2, 2)))
    with pytest.raises(TypeError, match="source must be the CSource of prefriction.export.c_source"):
        export.run_c("d.c", [0.0])
    with pytest.raises(ValueError, match="rounds"):
        export.run_c(src, [0.0], rounds=0)


@needs_gcc
def test_a_sum_of_models_exports_like_friction_along(tmp_path, motion):
    model = pf.Dahl(2e5, 1.5, 0.5) + pf.Viscous(2.0)
    with pytest.raises(ValueError, match="Ts is required for Parallel"):
        export.c_source(model, "sum", tmp_path)
    src = export.c_source(model, "sum", tmp_path, Ts=TS)
    assert "Dahl(sigma=200000.0, Fc=1.5, gamma=0.5) + Viscous(b=2.0)" in repr(src)
    n = 20_000
    run = export.run_c(src, motion[:n])
    along = pf.friction_along(model, np.arange(n) * TS, motion[:n])
    assert np.max(np.abs(run.F[1:] - along.F[1:])) <= 1e-12 * np.max(np.abs(along.F))


@needs_gcc
def test_unoptimised_compile_gives_the_same_forces(runs, motion, tmp_path):
    src, run = runs["dahl_sat"]
    assert np.array_equal(export.run_c(src, motion[:20_000], optimize=False).F, run.F[:20_000])
    with pytest.raises(TypeError, match="optimize"):
        export.run_c(src, motion[:10], optimize="yes")
