"""Whether a student function is still an untouched template stub (its body does nothing but say so)."""

from __future__ import annotations

import ast
import inspect
import textwrap
from typing import Any

_NOT_IMPLEMENTED = frozenset({"NotImplementedError", "NotImplemented"})
RAISING_STUB = "only raises NotImplementedError"
"""`stub_body` of a stub that raises NotImplementedError (with or without a docstring or `pass`)."""


def stub_body(function: Any) -> str | None:
    """What the stub's body does ("only raises NotImplementedError", ...), or None when not a stub.

    A stub's body holds only a docstring (or other bare strings), `pass`, `...` and
    `raise NotImplementedError(...)`; whatever its parameters, such a function was not attempted. The
    source is read from the submission (`inspect.getsource`); a function whose source cannot be read
    or parsed is not a stub (it is called as usual).
    """
    try:
        source = textwrap.dedent(inspect.getsource(function))
        tree = ast.parse(source)
    except Exception:  # no source (a builtin, a lambda in a string, a notebook cell without a file)
        return None
    definition = tree.body[0] if len(tree.body) == 1 else None
    if not isinstance(definition, ast.FunctionDef | ast.AsyncFunctionDef):
        return None
    raises = False
    for statement in definition.body:
        if isinstance(statement, ast.Pass):
            continue
        if isinstance(statement, ast.Expr) and isinstance(statement.value, ast.Constant):
            if statement.value.value is Ellipsis or isinstance(statement.value.value, str):
                continue
            return None
        if isinstance(statement, ast.Raise) and _raises_not_implemented(statement):
            raises = True
            continue
        return None
    return RAISING_STUB if raises else "holds nothing but `pass` or `...`"


def _raises_not_implemented(statement: ast.Raise) -> bool:
    raised = statement.exc
    if isinstance(raised, ast.Call):
        raised = raised.func
    return isinstance(raised, ast.Name) and raised.id in _NOT_IMPLEMENTED
