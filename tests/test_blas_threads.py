"""prefriction._blas_threads: one OpenBLAS thread inside the fits, the previous count restored,
nested and concurrent callers sharing it. The reference is each loaded OpenBLAS library's own
``*get_num_threads`` entry point."""

from __future__ import annotations

import threading

import numpy as np
import pytest
import scipy.linalg  # noqa: F401 - scipy's OpenBLAS loaded too

from prefriction import _blas_threads as bt

pytestmark = pytest.mark.skipif(not bt._controls(), reason="no OpenBLAS found in /proc/self/maps")


@pytest.fixture
def two_threads():
    controls = bt._controls()
    before = [get() for _s, get in controls]
    for setter, _g in controls:
        setter(2)
    yield
    for (setter, _g), n in zip(controls, before):
        setter(n)


def test_one_thread_inside_and_restored_after(two_threads):
    assert set(bt.blas_thread_counts()) == {2}
    with bt.one_blas_thread():
        assert set(bt.blas_thread_counts()) == {1}
        with bt.one_blas_thread():
            assert set(bt.blas_thread_counts()) == {1}
        assert set(bt.blas_thread_counts()) == {1}      # the inner exit does not restore
        a = np.random.default_rng(0).standard_normal((300, 300))
        np.testing.assert_allclose(a @ np.linalg.inv(a), np.eye(300), atol=1e-8)
    assert set(bt.blas_thread_counts()) == {2}


def test_restored_after_an_error_and_across_threads(two_threads):
    with pytest.raises(RuntimeError):
        with bt.one_blas_thread():
            raise RuntimeError("inside")
    assert set(bt.blas_thread_counts()) == {2}
    inside, go = threading.Barrier(3), threading.Event()
    seen = []

    def worker():
        with bt.one_blas_thread():
            inside.wait()
            go.wait()
            seen.append(bt.blas_thread_counts())

    threads = [threading.Thread(target=worker) for _ in range(2)]
    for th in threads:
        th.start()
    inside.wait()                                   # both inside
    assert set(bt.blas_thread_counts()) == {1}
    go.set()
    for th in threads:
        th.join()
    assert all(set(s) == {1} for s in seen)         # the first to leave did not restore under the other
    assert set(bt.blas_thread_counts()) == {2}


def test_the_fit_solves_with_one_thread(two_threads, monkeypatch):
    import prefriction as pf
    from prefriction import identify
    from prefriction.identify import prescribed

    counts = []

    def spy(original):
        def wrapped(*args, **kwargs):
            counts.append(bt.blas_thread_counts())
            return original(*args, **kwargs)
        return wrapped

    monkeypatch.setattr(prescribed, "least_squares", spy(prescribed.least_squares))   # the solve
    monkeypatch.setattr(np.linalg, "eigh", spy(np.linalg.eigh))                       # the statistics
    sigma, Fc = 1e6, 1.0        # Dahl (gamma = 1) in closed form: up from rest to 5 um, then down to -5 um
    up = np.linspace(0.0, 5e-6, 200)
    down = np.linspace(5e-6, -5e-6, 400)[1:]
    F_up = Fc * -np.expm1(-sigma * up / Fc)
    F_down = -Fc + (F_up[-1] + Fc) * np.exp(-sigma * (5e-6 - down) / Fc)
    x = np.r_[up, down]
    data = identify.ForceDisplacement(np.arange(x.size) * 1e-3, x, np.r_[F_up, F_down])
    res = identify.fit(pf.Dahl(sigma=1.5e6, Fc=0.8), data, fixed=["gamma"])
    assert res.model.sigma == pytest.approx(sigma, rel=1e-3)
    assert len(counts) >= 2 and all(set(c) == {1} for c in counts)
    assert set(bt.blas_thread_counts()) == {2}
