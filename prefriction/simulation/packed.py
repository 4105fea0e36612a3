"""The outcomes of one chunk of a sweep in a few arrays, for the trip from a worker to the parent.

A :class:`prefriction.SimulationResult` of 50 reversals pickles to 3.2 kB in eight objects and
six arrays, and dask.distributed serializes a returned list element by element: at 10,000
systems the parent's event loop (which also runs a ``LocalCluster``'s scheduler) spent 1 s in
10,000 ``pickle.loads`` calls, CPU taken from the workers on a machine with as many cores as
workers. :func:`pack` puts each field of the chunk's results into one column (the arrays of all
results concatenated, the numbers in one array, anything else in one list);
:meth:`Packed.unpack` rebuilds the results in the parent, bitwise equal; their arrays are
views into one array per field and chunk (a kept ``reversals.F`` keeps that field's array of
its chunk, not the other fields). Exceptions and anything that is not a plain
``SimulationResult`` travel as they are, in their places.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from prefriction.reversals import ReversalTable
from prefriction.simulation.lazy_table import LazyReversalTable
from prefriction.simulation.result import RunStats, SimulationResult

__all__ = ["Packed", "pack"]

_PARTS = {"": SimulationResult, "reversals": ReversalTable, "stats": RunStats}  # "" is the result itself
_FIELDS = {part: tuple(f.name for f in dataclasses.fields(cls)) for part, cls in _PARTS.items()}
_KEYS = {part: frozenset(names) for part, names in _FIELDS.items()}
_OWN = tuple(name for name in _FIELDS[""] if name not in _PARTS)  # the result's fields but its parts
_INT64 = (-(2 ** 63), 2 ** 63 - 1)


class Packed:
    """The outcomes of one chunk, packed by :func:`pack`; :meth:`unpack` gives them back.

    Attributes
    ----------
    n : int
        Number of outcomes.
    positions : numpy.ndarray
        Positions (in the chunk) of the packed :class:`prefriction.SimulationResult` objects.
    columns : dict
        Column name (``"status"``, ``"reversals.t"``, ``"stats.jit"``, ...) -> encoded column.
    others : list of tuple
        ``(position, outcome)`` of the outcomes that travel as they are (exceptions).
    """

    __slots__ = ("n", "positions", "columns", "others")

    def __init__(self, n: int, positions: np.ndarray, columns: dict, others: list) -> None:
        self.n, self.positions, self.columns, self.others = n, positions, columns, others

    def __reduce__(self) -> tuple:
        return Packed, (self.n, self.positions, self.columns, self.others)

    def __len__(self) -> int:
        return self.n

    def unpack(self) -> list:
        """The outcomes in chunk order: the rebuilt results and the others.

        Returns
        -------
        list
            ``n`` entries, as the list :func:`pack` was given.
        """
        count = len(self.positions)
        values = {name: _decode(col, count) for name, col in self.columns.items()}
        for part in ("reversals", "stats"):
            values[part] = _rebuild(_PARTS[part], _FIELDS[part], [values[f"{part}.{name}"] for name in _FIELDS[part]])
        results = _rebuild(SimulationResult, _FIELDS[""], [values[name] for name in _FIELDS[""]])
        if not self.others:
            return results
        out: list[Any] = [None] * self.n
        for k, result in zip(self.positions.tolist(), results):
            out[k] = result
        for k, outcome in self.others:
            out[k] = outcome
        return out


def pack(outcomes: list) -> Packed:
    """Pack the outcomes of a chunk (results and exceptions) for pickling.

    Parameters
    ----------
    outcomes : list
        :class:`prefriction.SimulationResult` objects and exceptions, in chunk order.

    Returns
    -------
    Packed
        Each field of the plain results in one column; the other outcomes as they are.
    """
    positions, results, others = [], [], []
    for k, outcome in enumerate(outcomes):
        if type(outcome) is SimulationResult and isinstance(outcome.reversals, LazyReversalTable):
            outcome = dataclasses.replace(outcome, reversals=outcome.reversals.eager())  # energies computed here
        if _plain(outcome):
            positions.append(k)
            results.append(outcome)
        else:
            others.append((k, outcome))
    columns = {name: _encode([r.__dict__[name] for r in results]) for name in _OWN}
    for part in ("reversals", "stats"):
        objs = [r.__dict__[part].__dict__ for r in results]
        for name in _FIELDS[part]:
            columns[f"{part}.{name}"] = _encode([d[name] for d in objs])
    return Packed(len(outcomes), np.array(positions, dtype=np.int64), columns, others)


def _plain(outcome: Any) -> bool:
    """True for a :class:`SimulationResult` whose result, table and stats hold their fields only."""
    return (type(outcome) is SimulationResult and outcome.__dict__.keys() == _KEYS[""]
            and type(outcome.reversals) is ReversalTable and outcome.reversals.__dict__.keys() == _KEYS["reversals"]
            and type(outcome.stats) is RunStats and outcome.stats.__dict__.keys() == _KEYS["stats"])


def _rebuild(cls: type, names: tuple, columns: list) -> list:
    """Instances of the dataclass ``cls``, one per row of ``columns`` (one per field of ``names``),
    made as unpickling makes them (no ``__init__``: the worker built and checked the originals)."""
    new, set_dict = object.__new__, object.__setattr__
    out = []
    for row in zip(*columns):
        obj = new(cls)
        set_dict(obj, "__dict__", dict(zip(names, row)))
        out.append(obj)
    return out


def _encode(values: list) -> tuple:
    """One column: ``("none",)``, ``("float", array)``, ``("int", array)``, ``("array", data,
    shapes)`` (arrays of one dtype and ndim >= 1, or None: shape row of -1) or ``("list", values)``."""
    kinds = {type(v) for v in values}
    if kinds <= {type(None)}:
        return ("none",)
    if kinds == {float}:
        return ("float", np.array(values, dtype=np.float64))
    if kinds == {int} and _INT64[0] <= min(values) and max(values) <= _INT64[1]:
        return ("int", np.array(values, dtype=np.int64))
    arrays = [v for v in values if v is not None]
    if kinds <= {np.ndarray, type(None)} and _uniform(arrays):
        ndim = arrays[0].ndim
        shapes = np.array([(-1,) * ndim if v is None else v.shape for v in values], dtype=np.int64).reshape(-1, ndim)
        data = np.concatenate([v.ravel() for v in arrays])
        return ("array", data, shapes)
    return ("list", values)


def _uniform(arrays: list) -> bool:
    """True if the arrays share one numeric or boolean dtype and one ndim >= 1."""
    dtype, ndim = arrays[0].dtype, arrays[0].ndim
    return (dtype.kind in "biufc" and ndim >= 1
            and all(a.dtype == dtype and a.ndim == ndim for a in arrays))


def _decode(col: tuple, count: int) -> list:
    """The ``count`` values of a column made by :func:`_encode`; arrays are views into the
    column's data (made writable), so a kept array holds at most its column of the chunk."""
    kind = col[0]
    if kind == "none":
        return [None] * count
    if kind in ("float", "int"):
        return col[1].tolist()
    if kind == "list":
        return col[1]
    data, shapes = col[1] if col[1].flags.writeable else col[1].copy(), col[2]  # dask's arrive read-only
    if shapes.shape[1] == 1 and count and (shapes[:, 0] == shapes[0, 0]).all() and shapes[0, 0] >= 0:
        return list(data.reshape(count, int(shapes[0, 0])))  # one length (the usual case): the rows
    sizes = np.where(shapes[:, 0] < 0, 0, np.prod(shapes, axis=1))
    ends = np.cumsum(sizes).tolist()
    out = []
    for shape, end, size in zip(shapes.tolist(), ends, sizes.tolist()):
        out.append(None if shape[0] < 0 else data[end - size:end].reshape(shape))
    return out
