"""The packed trip of a chunk's outcomes (prefriction.simulation.packed) and the chunk sizes."""

from __future__ import annotations

import dataclasses
import math
import pickle

import numpy as np
import pytest

import prefriction as pf
from prefriction.simulation.chunks import MAX_CHUNK, chunk_size, chunk_sizes
from prefriction.simulation.packed import Packed, pack
from prefriction.simulation.result import RunStats


def _result(k: int, n_rev: int, dense: bool, rng: np.random.Generator) -> pf.SimulationResult:
    """A result with every kind of field: reversal columns of ``n_rev`` rows, samples (``xc`` 2-D)
    or none, int events, ``steps`` an int or None."""
    tab = pf.ReversalTable(t=np.cumsum(rng.uniform(0.1, 1.0, n_rev)), x=rng.normal(size=n_rev),
                           F=rng.normal(size=n_rev), E_p=rng.uniform(size=n_rev), E_d=np.full(n_rev, np.nan),
                           E_0=float(k) + 0.5)
    stats = RunStats(wall_time=1e-3 * (k + 1), setup_time=0.0, calls=3 * k, steps=None if k % 2 else k,
                     jit="cached" if k % 3 else "compiled", events=k)
    samples = {}
    if dense:
        n_t = 5 + k
        samples = {name: rng.normal(size=n_t) for name in ("t", "x", "v", "F", "E_k", "E_f", "u")}
        samples["xc"] = rng.normal(size=(n_t, 2))
    return pf.SimulationResult(reversals=tab, status=k % 2, message=f"run {k}", stats=stats,
                               work_input=rng.normal(size=n_rev), events=np.arange(n_rev) % 3, **samples)


def _assert_same(a: object, b: object) -> None:
    """``b`` equals ``a`` field by field (arrays: bitwise, same dtype and shape; others: type and value)."""
    assert type(a) is type(b)
    if not dataclasses.is_dataclass(a):
        assert str(a) == str(b)  # an exception, or anything else that travels as it is
        return
    for field in dataclasses.fields(a):
        x, y = getattr(a, field.name), getattr(b, field.name)
        if dataclasses.is_dataclass(x):
            _assert_same(x, y)
        elif isinstance(x, np.ndarray):
            assert isinstance(y, np.ndarray) and x.dtype == y.dtype and x.shape == y.shape, field.name
            assert x.tobytes() == y.tobytes(), field.name  # bitwise, NaN included
        else:
            assert type(x) is type(y) and (x == y or (isinstance(x, float) and math.isnan(x) and math.isnan(y)))


@pytest.mark.parametrize("dense", [False, True])
def test_pack_and_unpack_after_pickling_give_the_outcomes_back(dense: bool) -> None:
    rng = np.random.default_rng(1)
    same_length = [_result(k, 6, dense, rng) for k in range(4)]  # one length: rows of one block
    ragged = [_result(k, 3 + k, dense, rng) for k in range(4)]
    for outcomes in (same_length, ragged):
        outcomes = outcomes[:2] + [ValueError("run 2 failed"), "not a result"] + outcomes[2:]
        packed = pickle.loads(pickle.dumps(pack(outcomes), protocol=5))
        assert isinstance(packed, Packed) and len(packed) == len(outcomes)
        back = packed.unpack()
        assert len(back) == len(outcomes) and back[3] == "not a result"
        for a, b in zip(outcomes, back):
            _assert_same(a, b)
        assert back[0].summary() == outcomes[0].summary() and repr(back[1]) == repr(outcomes[1])
        back[0].reversals.F[:] = 0.0  # arrays are writable and a result's own rows
        assert np.array_equal(back[1].reversals.F, outcomes[1].reversals.F)


def test_a_chunk_without_results_and_mixed_columns() -> None:
    rng = np.random.default_rng(2)
    assert pickle.loads(pickle.dumps(pack([KeyError("a"), KeyError("b")]))).unpack()[1].args == ("b",)
    assert pack([]).unpack() == []
    a, b = _result(0, 4, False, rng), _result(1, 4, False, rng)
    b = dataclasses.replace(b, work_input=b.work_input.astype(np.float32))  # two dtypes: the column as a list
    c = dataclasses.replace(_result(2, 4, False, rng), events=None)  # an array and None in one column
    for x, y in zip([a, b, c], pickle.loads(pickle.dumps(pack([a, b, c]))).unpack()):
        _assert_same(x, y)


def test_chunk_sizes_cover_the_runs_and_shrink_at_the_end() -> None:
    for n, workers in ((1, 2), (17, 2), (999, 2), (9_999, 2), (100_000, 48)):
        sizes = chunk_sizes(n, workers)
        full = chunk_size(n, workers)
        assert sum(sizes) == n and min(sizes) >= 1 and max(sizes) == full <= MAX_CHUNK
        assert all(a >= b for a, b in zip(sizes, sizes[1:]))  # non-increasing
        tail = sizes[-workers:]  # the last chunk of each worker: at most a quarter of a full one (or the rest)
        assert max(tail) <= max(math.ceil(full / 4), 1) or len(sizes) <= workers
    assert chunk_sizes(9_999, 2)[:16] == [500] * 16 and len(chunk_sizes(9_999, 2)) == 25
    assert chunk_sizes(10, 2, 3) == [3, 3, 3, 1] and chunk_sizes(9, 2, 3) == [3, 3, 3]
