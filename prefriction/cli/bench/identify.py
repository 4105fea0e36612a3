"""``prefriction bench --identify``: success rate, coverage, and time and memory against the length.

First the tables of :mod:`prefriction.cli.bench.identify_rates` (success rate of Motion fits against
the start distance per stage, coverage of the 95 % intervals, cost of force-displacement fits),
then the time and memory of a closed-loop Motion fit against its length:

Each size runs in a fresh Python process (``python -m prefriction.cli.bench.identify N``), so its
memory is its own: an EMPS-like record (:func:`prefriction.identify.synthetic_loop.closed_loop_record`:
95.1 kg stage, PD loop at 1 kHz, LuGre friction with viscous ``sigma2`` and a force offset,
encoder steps of 5e-8 m and 1e-7 m of position noise) is generated, then fitted with mass,
``sigma0``, ``sigma2``, ``Fc`` and the offset free, from start values 1.5 times, 0.5 times and
0.5 times the truth (``sigma0``, ``sigma2``, ``Fc``) and a mass of 80 kg. Reported: the fit's wall
time and CPU time (``time.process_time``: all the process's threads), the process's peak resident
set size (``resource.getrusage``, ``ru_maxrss``: everything, CasADi's C++ included) before and
after the fit, the peak of Python's traced allocations during
the fit (``tracemalloc``: numpy arrays and Python objects, not CasADi's own memory), and the
largest ``|estimate - truth| / stderr``. Targets (issue 17): 25,000 samples in at most 300 s and
2048 MB, growth at most linear in the samples.
"""

from __future__ import annotations

import json
import re
import resource
import subprocess
import sys
import time
import tracemalloc
import warnings

import numpy as np

__all__ = ["SIZES", "QUICK_SIZES", "format_rows", "main", "measure"]

SIZES = (1_000, 5_000, 25_000)
QUICK_SIZES = (500, 1_000, 2_000)
TIME_LIMIT = 300.0
MEMORY_LIMIT = 2048.0
TRUTH = {"sigma0": 2.0e5, "sigma2": 203.5, "Fc": 20.39, "mass": 95.1, "offset": -3.16}


def _rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # kB on Linux


def measure(n: int, seed: int = 1) -> dict:
    """Generate one record of ``n`` samples and fit it, in this process; the row of the table."""
    import prefriction as pf
    from prefriction import identify
    from prefriction.identify.synthetic_loop import ClosedLoop, closed_loop_record

    T = TRUTH
    true = pf.LuGre(sigma0=T["sigma0"], sigma1=300.0, sigma2=T["sigma2"], Fc=T["Fc"], Fs=25.0, vs=0.01)
    loop = ClosedLoop(true, mass=T["mass"], offset=T["offset"], noise=1e-7)
    t0 = time.perf_counter()
    rec = closed_loop_record(loop, n, np.random.default_rng(seed))
    gen = time.perf_counter() - t0
    data = identify.Motion(rec.t, rec.x, rec.u, None)
    start = pf.LuGre(sigma0=1.5 * T["sigma0"], sigma1=300.0, sigma2=0.5 * T["sigma2"], Fc=0.5 * T["Fc"], Fs=25.0,
                     vs=0.01)
    rss0 = _rss_mb()
    tracemalloc.start()
    t0, c0 = time.perf_counter(), time.process_time()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = identify.fit(start, data, fixed=["sigma1", "Fs", "vs"], mass0=80.0, offset=True)
    elapsed, cpu = time.perf_counter() - t0, time.process_time() - c0
    traced = tracemalloc.get_traced_memory()[1] / 2**20
    tracemalloc.stop()
    z = max(abs(res.estimate(k) - v) / res.stderr[res.names.index(k)] for k, v in T.items())
    it = re.search(r"(\d+) Jacobian evaluations", res.message)
    seg = re.search(r"(\d+) segments of (\d+) samples, (\d+) RK4", res.message)
    return {"n": n, "generate_s": gen, "fit_s": elapsed, "cpu_s": cpu, "rss_before_mb": rss0, "rss_peak_mb": _rss_mb(),
            "traced_mb": traced, "z_max": z, "iterations": int(it.group(1)) if it else -1,
            "segments": int(seg.group(1)) if seg else -1, "substeps": int(seg.group(3)) if seg else -1}


def _fresh(n: int) -> dict:
    out = subprocess.run([sys.executable, "-m", "prefriction.cli.bench.identify", str(n)], capture_output=True,
                         text=True, check=False)
    if out.returncode != 0:
        raise RuntimeError(f"the Motion fit of {n} samples failed:\n{out.stderr[-2000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def format_rows(rows: list[dict]) -> list[str]:
    """The table and the target lines."""
    head = (f"{'samples':>8} {'segments':>8} {'substeps':>8} {'iter':>5} {'fit [s]':>9} {'CPU [s]':>8} "
            f"{'ms/sample':>9} "
            f"{'RSS before [MB]':>15} {'RSS peak [MB]':>13} {'traced [MB]':>11} {'max |z|':>8}")
    lines = ["Motion fit of an EMPS-like closed-loop record (LuGre + offset, mass free), each size in a fresh "
             "process;", "RSS = resource ru_maxrss of the whole process, traced = tracemalloc peak during the fit "
             "(Python and numpy only)", head, "-" * len(head)]
    for r in rows:
        lines.append(f"{r['n']:>8} {r['segments']:>8} {r['substeps']:>8} {r['iterations']:>5} {r['fit_s']:>9.1f} "
                     f"{r.get('cpu_s', float('nan')):>8.1f} "
                     f"{1e3 * r['fit_s'] / r['n']:>9.2f} {r['rss_before_mb']:>15.0f} {r['rss_peak_mb']:>13.0f} "
                     f"{r['traced_mb']:>11.1f} {r['z_max']:>8.2f}")
    big = rows[-1]
    lines.append("")
    ok_t, ok_m = big["fit_s"] <= TIME_LIMIT, big["rss_peak_mb"] <= MEMORY_LIMIT
    lines.append(f"target Motion fit of {big['n']} samples <= {TIME_LIMIT:.0f} s: {big['fit_s']:.1f} s "
                 f"{'PASS' if ok_t else 'FAIL'}")
    lines.append(f"target Motion fit of {big['n']} samples <= {MEMORY_LIMIT:.0f} MB peak RSS: "
                 f"{big['rss_peak_mb']:.0f} MB {'PASS' if ok_m else 'FAIL'}")
    small = rows[0]
    ratio = (big["traced_mb"] / small["traced_mb"]) / (big["n"] / small["n"])
    lines.append(f"target traced memory at most linear in the samples: x{big['n'] / small['n']:.0f} samples, "
                 f"x{big['traced_mb'] / small['traced_mb']:.1f} memory {'PASS' if ratio <= 1.5 else 'FAIL'}")
    return lines


def main(quick: bool = False) -> int:
    """Print the success-rate, coverage and force-displacement cost tables
    (:mod:`prefriction.cli.bench.identify_rates`), then run the Motion sizes (:data:`QUICK_SIZES`
    with ``quick``) and print their table; 0 if every target passes."""
    from prefriction.cli.bench.identify_rates import main_rates

    ok = main_rates(quick)
    rows = []
    for n in QUICK_SIZES if quick else SIZES:
        print(f"bench --identify: fitting {n} samples ...", file=sys.stderr, flush=True)
        rows.append(_fresh(n))
    lines = format_rows(rows)
    print("\n".join(lines))
    return 0 if ok and all("PASS" in line for line in lines if line.startswith("target")) else 1


if __name__ == "__main__":
    print(json.dumps(measure(int(sys.argv[1]))))
