"""A CasADi SX ``Function`` written out as straight-line C statements on named scalars.

The C pass of :func:`prefriction.friction_along` (``native.c``) puts the model's interval step
inside its loop over the samples. CasADi's code generator writes a function that reads its
inputs and writes its outputs through arrays of pointers, which keeps the compiler from holding
the state in registers from one sample to the next; here every operation of the expression graph
becomes one ``const double`` of its own (``v0, v1, ...``; a truth value an ``int``), the inputs and outputs are C
expressions the caller names, and the compiler sees one block of scalar code. The operations are
written as CasADi's code generator writes them (``casadi/core/calculus.hpp``), so the results are
the same; one pattern is joined: ``if_else_zero(c, a) + if_else_zero(!c, b)``, how an SX
``if_else(c, a, b)`` is stored, is written ``c ? a : b`` (it differs only in the sign of a zero
result).
"""

from __future__ import annotations

from typing import Callable, Sequence

import casadi as ca

__all__ = ["straight_line"]

_BINARY: dict[int, Callable[[str, str], str]] = {
    ca.OP_ADD: lambda a, b: f"{a} + {b}", ca.OP_SUB: lambda a, b: f"{a} - {b}",
    ca.OP_MUL: lambda a, b: f"{a} * {b}", ca.OP_DIV: lambda a, b: f"(double){a} / {b}",  # an int over an int too
    ca.OP_LT: lambda a, b: f"{a} < {b}", ca.OP_LE: lambda a, b: f"{a} <= {b}",
    ca.OP_EQ: lambda a, b: f"{a} == {b}", ca.OP_NE: lambda a, b: f"{a} != {b}",
    ca.OP_AND: lambda a, b: f"{a} && {b}", ca.OP_OR: lambda a, b: f"{a} || {b}",
    ca.OP_IF_ELSE_ZERO: lambda a, b: f"{a} ? {b} : 0.0", ca.OP_FMIN: lambda a, b: f"fmin({a}, {b})",
    ca.OP_FMAX: lambda a, b: f"fmax({a}, {b})", ca.OP_POW: lambda a, b: f"pow({a}, {b})",
    ca.OP_CONSTPOW: lambda a, b: f"pow({a}, {b})", ca.OP_ATAN2: lambda a, b: f"atan2({a}, {b})",
    ca.OP_COPYSIGN: lambda a, b: f"copysign({a}, {b})", ca.OP_FMOD: lambda a, b: f"fmod({a}, {b})",
    ca.OP_HYPOT: lambda a, b: f"hypot({a}, {b})",
}
_UNARY: dict[int, Callable[[str], str]] = {
    ca.OP_NEG: lambda a: f"-{a}", ca.OP_NOT: lambda a: f"!{a}", ca.OP_SQ: lambda a: f"{a} * {a}",
    ca.OP_TWICE: lambda a: f"{a} + {a}", ca.OP_INV: lambda a: f"1.0 / {a}", ca.OP_ASSIGN: lambda a: a,
    ca.OP_SIGN: lambda a: f"({a} < 0.0 ? -1.0 : {a} > 0.0 ? 1.0 : {a})",
    **{op: (lambda name: lambda a: f"{name}({a})")(name) for op, name in (
        (ca.OP_EXP, "exp"), (ca.OP_LOG, "log"), (ca.OP_SQRT, "sqrt"), (ca.OP_FABS, "fabs"),
        (ca.OP_EXPM1, "expm1"), (ca.OP_LOG1P, "log1p"), (ca.OP_SIN, "sin"), (ca.OP_COS, "cos"),
        (ca.OP_TAN, "tan"), (ca.OP_ASIN, "asin"), (ca.OP_ACOS, "acos"), (ca.OP_ATAN, "atan"),
        (ca.OP_SINH, "sinh"), (ca.OP_COSH, "cosh"), (ca.OP_TANH, "tanh"), (ca.OP_ASINH, "asinh"),
        (ca.OP_ACOSH, "acosh"), (ca.OP_ATANH, "atanh"), (ca.OP_FLOOR, "floor"), (ca.OP_CEIL, "ceil"),
        (ca.OP_ERF, "erf"))},
}

_LOGICAL = {ca.OP_LT, ca.OP_LE, ca.OP_EQ, ca.OP_NE, ca.OP_AND, ca.OP_OR, ca.OP_NOT}


def _constant(value: float) -> str:
    if value != value:
        return "NAN"
    if value in (float("inf"), float("-inf")):
        return "INFINITY" if value > 0 else "(-INFINITY)"
    return f"{value!r}" if "." in repr(value) or "e" in repr(value) else f"{value!r}.0"


def straight_line(fun: ca.Function, inputs: Sequence[Callable[[int], str]],
                  outputs: Sequence[Callable[[int], str]], prefix: str) -> str:
    """C statements evaluating the SX Function ``fun``: ``inputs[i](j)`` is the C expression of
    nonzero ``j`` of input ``i``, ``outputs[i](j)`` the lvalue that nonzero ``j`` of output ``i``
    is assigned to; local names start with ``prefix``. ``NotImplementedError`` for an operation
    without a C form here (the caller then uses CasADi's code generator)."""
    work: dict[int, str] = {}  # work slot -> the name of the value it holds now
    define: dict[str, tuple[int, list[str]]] = {}  # name -> (operation, operand names)
    lines: list[str] = []
    ints: set[str] = set()
    for k in range(fun.n_instructions()):
        op, ins, outs = fun.instruction_id(k), fun.instruction_input(k), fun.instruction_output(k)
        if op == ca.OP_OUTPUT:
            lines.append(f"  {outputs[outs[0]](outs[1])} = {work[ins[0]]};")
            continue
        name = f"{prefix}{k}"
        if op == ca.OP_INPUT:
            expr = inputs[ins[0]](ins[1])
        elif op == ca.OP_CONST:
            expr = _constant(float(fun.instruction_constant(k)))
        elif op in _UNARY:
            define[name] = (op, [work[ins[0]]])
            expr = _UNARY[op](work[ins[0]])
        elif op in _BINARY:
            a, b = work[ins[0]], work[ins[1]]
            define[name] = (op, [a, b])
            expr = _pick(define, a, b) if op == ca.OP_ADD else None
            expr = expr or _BINARY[op](a, b)
        else:
            raise NotImplementedError(f"CasADi operation {op} has no straight-line C form here")
        # truth values and their sums (event counts) stay ints: no conversions on the path
        kind = "int" if op in _LOGICAL or (op == ca.OP_ADD and ints.issuperset(define[name][1])) else "double"
        if kind == "int":
            ints.add(name)
        lines.append(f"  const {kind} {name} = {expr};")
        work[outs[0]] = name
    return "\n".join(lines)


def _pick(define: dict[str, tuple[int, list[str]]], a: str, b: str) -> str | None:
    """``c ? x : y`` if ``a + b`` is ``if_else_zero(c, x) + if_else_zero(!c, y)`` (either order)."""
    da, db = define.get(a), define.get(b)
    if not (da and db and da[0] == db[0] == ca.OP_IF_ELSE_ZERO):
        return None
    for (c, x), (nc, y) in ((da[1], db[1]), (db[1], da[1])):
        neg = define.get(nc)
        if neg and neg[0] == ca.OP_NOT and neg[1][0] == c:
            return f"{c} ? {x} : {y}"
    return None
