"""Constraints between an actuator's design parameters: one comparison of arithmetic.

A constraint (``"t_mm < r_mm"``, ``"2 * wall_mm < chamber_length_mm"``) is parsed
once, when its description is built (:func:`parse_constraint`: only names of
design parameters, numbers, ``+ - * /`` and ``< <= > >=``), and evaluated on
rows of design codes (:func:`evaluate`).
"""

from __future__ import annotations

import ast
import math
import operator
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from softbend.actuators.parameters import ActuatorError

_COMPARE: dict[type, Callable[[Any, Any], Any]] = {
    ast.Lt: operator.lt,
    ast.LtE: operator.le,
    ast.Gt: operator.gt,
    ast.GtE: operator.ge,
}
_ARITHMETIC: dict[type, Callable[[Any, Any], Any]] = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
}


def parse_constraint(text: str, names: Sequence[str]) -> ast.Compare:
    """``text`` as one comparison of arithmetic on ``names`` and numbers (nothing else)."""
    if not isinstance(text, str) or len(text) > 200:
        raise ActuatorError(f"A constraint must be text of at most 200 characters; got {text!r}.")
    try:
        tree = ast.parse(text, mode="eval").body
    except SyntaxError:
        raise ActuatorError(
            f"The constraint {text!r} is not a comparison such as 't_mm < r_mm' or "
            "'2*wall_mm + gap_mm <= 10'."
        ) from None
    if not isinstance(tree, ast.Compare) or not all(type(op) in _COMPARE for op in tree.ops):
        raise ActuatorError(
            f"The constraint {text!r} must compare with <, <=, > or >= (such as 't_mm < r_mm')."
        )
    for node in ast.walk(tree):
        if isinstance(node, ast.Name) and node.id not in names:
            raise ActuatorError(
                f"The constraint {text!r} names {node.id!r}, which is not a design parameter "
                f"({', '.join(names)})."
            )
        allowed = (ast.Compare, ast.BinOp, ast.UnaryOp, ast.USub, ast.UAdd, ast.Name, ast.Load)
        if isinstance(node, ast.Constant):
            if isinstance(node.value, bool) or not isinstance(node.value, int | float):
                raise ActuatorError(f"The constraint {text!r} may hold only numbers and names.")
        elif (
            not isinstance(node, allowed)
            and type(node) not in _COMPARE
            and type(node) not in _ARITHMETIC
        ):
            raise ActuatorError(
                f"The constraint {text!r} may use only + - * / and comparisons of the "
                "design parameters and numbers."
            )
    for side in (tree.left, *tree.comparators):
        _fold(side, text)
    return tree


def _part(text: str, node: ast.AST) -> str:
    """The part of the constraint ``text`` that ``node`` was parsed from, as typed."""
    return ast.get_source_segment(text, node) or ast.unparse(node)


def _fold(node: ast.AST, text: str) -> float | None:
    """The value of ``node`` if it holds no name (None otherwise), checked finite.

    Each part of a constraint made of numbers alone is computed once, when the
    description is read: one that divides by zero or is not a finite number is
    refused there, naming the constraint, instead of failing (or, on arrays,
    silently giving inf or NaN) while designs are checked.
    """
    if isinstance(node, ast.Constant):
        value = float(node.value)  # type: ignore[arg-type]  # a number, as parsed
    elif isinstance(node, ast.Name):
        return None
    elif isinstance(node, ast.UnaryOp):
        inner = _fold(node.operand, text)
        if inner is None:
            return None
        value = -inner if isinstance(node.op, ast.USub) else inner
    else:
        assert isinstance(node, ast.BinOp)
        left, right = _fold(node.left, text), _fold(node.right, text)
        if left is None or right is None:
            return None
        try:
            value = _ARITHMETIC[type(node.op)](left, right)
        except ZeroDivisionError:
            raise ActuatorError(
                f"The constraint {text!r} divides by zero ({_part(text, node)}); its numbers "
                "must give finite values."
            ) from None
    if not math.isfinite(value):
        raise ActuatorError(
            f"The constraint {text!r} holds a number too large to compute "
            f"({_part(text, node)}); its numbers must give finite values."
        )
    return value


def evaluate(node: ast.AST, values: Mapping[str, np.ndarray]) -> Any:
    if isinstance(node, ast.Constant):  # a number: parse_constraint allows no other constant
        return float(node.value)  # type: ignore[arg-type]
    if isinstance(node, ast.Name):
        return values[node.id]
    if isinstance(node, ast.UnaryOp):
        inner = evaluate(node.operand, values)
        return -inner if isinstance(node.op, ast.USub) else inner
    if isinstance(node, ast.BinOp):
        return _ARITHMETIC[type(node.op)](evaluate(node.left, values), evaluate(node.right, values))
    assert isinstance(node, ast.Compare)
    result = np.ones(np.shape(next(iter(values.values()))), dtype=bool)
    left = evaluate(node.left, values)
    for op, comparator in zip(node.ops, node.comparators, strict=True):
        right = evaluate(comparator, values)
        result &= np.asarray(_COMPARE[type(op)](left, right), dtype=bool)
        left = right
    return result
