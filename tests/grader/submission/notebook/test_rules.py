"""Kept top-level statements cannot call student code: every kind of Python expression is judged.

Each case is a cell after a prelude that defines student objects whose hooks record a call
(`Hooked.__class_getitem__`, `Hooked.__init_subclass__`, `hooked()`); the built module is then executed
and must record none. Cases are keyed by the expression kind they exercise, and a test holds the keys
equal to `ast.expr`'s subclasses, so a kind Python adds cannot slip through unjudged.
"""

from __future__ import annotations

import ast
import sys
import types

import nbformat
import pytest
from nbformat.v4 import new_code_cell, new_notebook

from grader.sandbox.child.importer import MODULE_NAME
from grader.submission.notebook import rules
from grader.submission.notebook.building import build_module
from grader.submission.notebook.models import NotebookModule

PRELUDE = """\
import numpy as np
import gymnasium as gym
CALLED = []
class Hooked:
    def __class_getitem__(cls, item):
        CALLED.append("__class_getitem__")
        return cls
    def __init_subclass__(cls, **kwargs):
        CALLED.append("__init_subclass__")
def hooked(*args, **kwargs):
    CALLED.append("hooked()")
    return 1
"""


def built(*cells: str) -> NotebookModule:
    data = nbformat.writes(new_notebook(cells=[new_code_cell(PRELUDE), *map(new_code_cell, cells)])).encode()
    module = build_module(data, "lab.ipynb", None)
    assert isinstance(module, NotebookModule), module
    return module


def run(module: NotebookModule) -> list[str]:
    """Execute the built module as the sandbox imports it (as module `submission`); the hooks it called."""
    submission = types.ModuleType(MODULE_NAME)
    sys.modules[MODULE_NAME] = submission
    try:
        exec(compile(module.source, "lab.ipynb.py", "exec"), vars(submission))
    finally:
        del sys.modules[MODULE_NAME]
    called = vars(submission)["CALLED"]
    assert isinstance(called, list)
    return called


def kept(module: NotebookModule) -> bool:
    return not any(entry.cell == 2 for entry in module.summary.skipped)


SKIPPED, KEPT = False, True
EXPRESSIONS: dict[str, list[tuple[str, bool]]] = {
    "BoolOp": [("x = Hooked or 1", SKIPPED), ("x = 0 or 2", KEPT)],
    "NamedExpr": [("x = (y := Hooked)", SKIPPED)],
    "BinOp": [("x = Hooked + 1", SKIPPED), ("x = 1 + Hooked", SKIPPED), ("x = 2 ** 10 // 3", KEPT)],
    "UnaryOp": [("x = -Hooked", SKIPPED), ("x = not Hooked", SKIPPED), ("x = -1", KEPT)],
    "Lambda": [("f = lambda: Hooked[0]", KEPT), ("f = lambda x=Hooked[0]: x", SKIPPED)],
    "IfExp": [("x = 1 if Hooked else 2", SKIPPED), ("x = Hooked if True else hooked", KEPT)],
    "Dict": [("x = {Hooked: 1}", SKIPPED), ("x = {'policy': hooked}", KEPT), ("x = {**Hooked}", SKIPPED)],
    "Set": [("x = {Hooked}", SKIPPED), ("x = {1, 2}", KEPT)],
    "ListComp": [("x = [c for c in Hooked]", SKIPPED), ("x = [n * n for n in range(5)]", KEPT),
                 ("x = [c[0] for c in [Hooked]]", SKIPPED)],
    "SetComp": [("x = {c for c in Hooked}", SKIPPED), ("x = {n % 3 for n in range(9)}", KEPT)],
    "DictComp": [("x = {c: 1 for c in Hooked}", SKIPPED), ("x = {n: 0.0 for n in range(3)}", KEPT)],
    "GeneratorExp": [("x = (c for c in Hooked)", SKIPPED), ("x = (n for n in range(3))", KEPT)],
    "Await": [("x = await hooked()", SKIPPED)],
    "Yield": [("x = (yield Hooked)", SKIPPED)],
    "YieldFrom": [("x = (yield from Hooked)", SKIPPED)],
    "Compare": [("x = Hooked == 1", SKIPPED), ("x = 1 in Hooked", SKIPPED), ("x = 1 < 2", KEPT)],
    "Call": [("x = hooked()", SKIPPED), ("x = list(Hooked)", SKIPPED), ("x = Hooked()", SKIPPED),
             ("x = np.zeros((500, 6))", KEPT), ("env = gym.make('CartPole-v1')", KEPT)],
    "FormattedValue": [("x = f'{Hooked:>10}'", SKIPPED), ("x = f'{Hooked!r}'", SKIPPED), ("x = f'{3:>4}'", KEPT)],  # noqa: E501
    "JoinedStr": [("x = f'{Hooked}'", SKIPPED), ("x = f'run {1}'", KEPT)],
    "Constant": [("x = 'text'", KEPT), ("x = ...", KEPT)],
    "Attribute": [("x = Hooked.anything", SKIPPED), ("x = hooked.__name__", SKIPPED), ("x = np.pi", KEPT)],
    "Subscript": [("x = Hooked[int]", SKIPPED), ("x = (1, 2)[Hooked]", SKIPPED),
                  ("import sys\nx = sys.modules['submission'].Hooked[0]", SKIPPED), ("x = (1, 2)[0]", KEPT)],
    "Starred": [("x = [*Hooked]", SKIPPED), ("x = (*range(3),)", KEPT)],
    "Name": [("policy = hooked", KEPT), ("x = undefined_name", SKIPPED)],
    "List": [("x = [Hooked, hooked]", KEPT), ("x = [*Hooked]", SKIPPED)],
    "Tuple": [("x = (Hooked, hooked)", KEPT), ("a, b = Hooked", SKIPPED), ("a, b = 1, 2", KEPT)],
    "Slice": [("x = (1, 2)[Hooked:]", SKIPPED), ("x = (1, 2, 3)[1:2]", KEPT)],
}  # fmt: skip
CASES = [(kind, cell, expected) for kind, cases in EXPRESSIONS.items() for cell, expected in cases]


def test_every_kind_of_expression_has_cases() -> None:
    assert set(EXPRESSIONS) == {kind.__name__ for kind in ast.expr.__subclasses__()}


@pytest.mark.parametrize(("kind", "cell", "expected"), CASES, ids=[f"{k}: {c}" for k, c, _ in CASES])
def test_an_expression_is_kept_only_when_it_cannot_call_student_code(
    kind: str, cell: str, expected: bool
) -> None:
    assert any(type(node).__name__ == kind for node in ast.walk(ast.parse(cell)))
    module = built(cell)
    assert kept(module) is expected, module.summary.skipped
    assert run(module) == []


STATEMENTS = [
    ("except-type", "try:\n    import missing_module\nexcept Hooked.error:\n    pass", SKIPPED),
    ("except-type-library", "try:\n    import gymnasium\nexcept ImportError:\n    gymnasium = None", KEPT),
    ("annotation", "x: Hooked[int] = 1", SKIPPED),
    ("parameter-annotation", "def f(a: Hooked[int]):\n    return a", SKIPPED),
    ("return-annotation", "def f() -> Hooked[int]:\n    return 1", SKIPPED),
    ("annotation-name", "def f(a: Hooked) -> np.ndarray:\n    return a", KEPT),
    ("default", "def f(a=Hooked[0]):\n    return a", SKIPPED),
    ("default-name", "def f(policy=hooked):\n    return policy", KEPT),
    ("subclass-of-hooked", "class Child(Hooked):\n    pass", SKIPPED),
    ("metaclass", "class Meta(type):\n    pass\nclass Child(metaclass=Meta):\n    pass", SKIPPED),
    ("class-keyword", "class Child(demo=hooked()):\n    pass", SKIPPED),
    ("class-body", "class Agent:\n    table = hooked()", SKIPPED),
    ("class-body-subscript", "class Agent:\n    kind = Hooked[0]", SKIPPED),
    ("class-body-plain", "class Agent:\n    rate = .1\n    def act(self):\n        return Hooked[0]", KEPT),
    ("plain-base", "class Base:\n    pass\nclass Agent(Base):\n    pass", KEPT),
    ("enum", "import enum\nclass Color(enum.Enum):\n    RED = 1\n    def __init__(self, value):\n        hooked()", SKIPPED),  # noqa: E501
    ("augmented", "N = 1\nN += Hooked", SKIPPED),
    ("augmented-constant", "N = 1\nN += 2", KEPT),
    ("if-test", "if Hooked:\n    import math", SKIPPED),
    ("own-module", f"import {MODULE_NAME}\nx = {MODULE_NAME}.Hooked[0]", SKIPPED),
    ("shadowed-builtin", "def len(x):\n    return hooked()\nN = len('abc')", SKIPPED),
]  # fmt: skip


@pytest.mark.parametrize(("cell", "expected"), [c[1:] for c in STATEMENTS], ids=[c[0] for c in STATEMENTS])
def test_a_statement_is_kept_only_when_it_cannot_call_student_code(cell: str, expected: bool) -> None:
    module = built(cell)
    skipped = [entry for entry in module.summary.skipped if entry.cell == 2]
    assert (not skipped) is expected or (expected is SKIPPED and skipped), module.summary.skipped
    assert run(module) == []


def test_a_student_decorator_is_not_applied_and_the_function_is_graded_without_it() -> None:
    module = built(
        "@hooked\ndef taxi():\n    return 1",
        "import functools\n@functools.lru_cache\ndef car():\n    return 2",
    )
    assert "def taxi" in module.source and "@hooked" not in module.source
    assert [(entry.cell, entry.code) for entry in module.summary.skipped] == [(2, "@hooked")]
    assert run(module) == []


def test_a_property_setter_in_a_class_body_is_kept() -> None:
    cell = "class Agent:\n    @property\n    def rate(self):\n        return 1\n    @rate.setter\n    def rate(self, v):\n        pass"  # noqa: E501
    module = built(cell)
    assert kept(module)
    assert run(module) == []


def test_the_sandbox_module_name_is_one_the_rules_refuse() -> None:
    assert MODULE_NAME in rules.UNSAFE_MODULES
