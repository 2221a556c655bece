"""An untouched template stub is recognised by its body, whatever its parameters."""

import textwrap
from pathlib import Path
from types import ModuleType

import pytest

from grader.sandbox.child.stubs import stub_body

STUBS = {
    "raise": (
        "def taxi(q_table, q_table_decay):\n    raise NotImplementedError('Problem 5 Incomplete')\n",
        "only raises NotImplementedError",
    ),
    "docstring raise": (
        'def car():\n    """Problem 4."""\n    raise NotImplementedError\n',
        "only raises NotImplementedError",
    ),
    "pass": ("def cartpole(render=False):\n    # TODO\n    pass\n", "holds nothing but `pass` or `...`"),
    "ellipsis": ('def blackjack(n=11):\n    """Docs."""\n    ...\n', "holds nothing but `pass` or `...`"),
    "not implemented value": ("def car():\n    raise NotImplemented\n", "only raises NotImplementedError"),
}
NOT_STUBS = {
    "returns": "def car():\n    return 1\n",
    "raises after work": "def car():\n    x = 1\n    raise NotImplementedError\n",
    "raises another error": "def car():\n    raise ValueError('no')\n",
    "pass then return": "def car():\n    pass\n    return None\n",
}


def _function(source: str, tmp_path: Path):  # type: ignore[no-untyped-def]
    path = tmp_path / "student.py"
    path.write_text(textwrap.dedent(source), encoding="utf-8")
    module = ModuleType("student")
    module.__file__ = str(path)
    exec(compile(path.read_text(encoding="utf-8"), str(path), "exec"), module.__dict__)
    return next(
        value for name, value in vars(module).items() if callable(value) and not name.startswith("__")
    )


@pytest.mark.parametrize(("source", "body"), list(STUBS.values()), ids=list(STUBS))
def test_a_stub_is_recognised_whatever_its_signature(source: str, body: str, tmp_path: Path) -> None:
    assert stub_body(_function(source, tmp_path)) == body


@pytest.mark.parametrize("source", list(NOT_STUBS.values()), ids=list(NOT_STUBS))
def test_a_body_that_does_something_is_not_a_stub(source: str, tmp_path: Path) -> None:
    assert stub_body(_function(source, tmp_path)) is None


def test_a_function_without_source_is_not_a_stub() -> None:
    namespace: dict[str, object] = {}
    exec("def car():\n    raise NotImplementedError\n", namespace)  # no file: getsource fails
    assert stub_body(namespace["car"]) is None
