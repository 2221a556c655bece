"""Cells are read as IPython reads them: its input transformations and one-line automagic."""

from __future__ import annotations

import pytest

from grader.submission.notebook.ipython import LINE_MAGICS, transform_cell


@pytest.mark.parametrize(
    ("cell", "source", "special"),
    [
        ("!pip install gym", "pass", [(1, "shell command", ())]),
        ("!!ls", "pass", [(1, "shell command", ())]),
        ("%matplotlib inline\nimport gym", "pass\nimport gym", [(1, "IPython magic", ())]),
        ("files = !ls", "pass", [(1, "shell command", ("files",))]),
        ("names = %who_ls", "pass", [(1, "IPython magic", ("names",))]),
        ("gym.make?", "pass", [(1, "help request", ())]),
        ("?gym.make", "pass", [(1, "help request", ())]),
        ("np.zeros??", "pass", [(1, "help request", ())]),
        ("/print 1", "pass", [(1, "IPython autocall", ())]),
        ("def f():\n    !ls\n    return 1", "def f():\n    pass\n    return 1", [(2, "shell command", ())]),
        ("%timeit \\\n  f()\ny = 1", "pass\n\ny = 1", [(1, "IPython magic", ())]),
        ("pip install gym", "pass", [(1, "IPython magic (automagic)", ())]),
        ("matplotlib inline", "pass", [(1, "IPython magic (automagic)", ())]),
        ("ls", "pass", [(1, "IPython magic (automagic)", ())]),
        ("  a = 1\n  b = 2", "a = 1\nb = 2", []),
        (">>> a = 1\n... b = 2", "a = 1\nb = 2", []),
        ("In [3]: a = 1\n   ...: b = 2", "a = 1\nb = 2", []),
    ],
    ids=["shell", "shell-capture", "line-magic", "system-assign", "magic-assign", "help-end", "help-start",
         "help-detail", "autocall", "escape-in-a-block", "continued-magic", "automagic-pip",
         "automagic-matplotlib", "automagic-alias", "leading-indent", "classic-prompt", "ipython-prompt"],
)  # fmt: skip
def test_ipython_syntax_becomes_pass_and_is_listed(
    cell: str, source: str, special: list[tuple[int, str, tuple[str, ...]]]
) -> None:
    transformed = transform_cell(cell, set())
    assert transformed.source == source
    assert [(line.line, line.kind, line.binds) for line in transformed.special] == special


@pytest.mark.parametrize(
    "cell",
    [
        "import gym\npip install gym",  # automagic is for one-line cells only: a SyntaxError in IPython too
        "time = 3",
        "x = '''\n!not a command\n%neither\n'''",
        "a != b",
        "x %= 3",
        "d = {'a': 1,\n     'b': 2}",
        "pip.main(['install', 'gym'])",
    ],
    ids=["automagic-in-a-longer-cell", "assignment-to-a-magic-name", "inside-a-string", "not-equal",
         "modulo-assign", "continued-brackets", "dotted-call"],
)  # fmt: skip
def test_python_is_left_as_it_is(cell: str) -> None:
    transformed = transform_cell(cell, set())
    assert transformed.source == cell
    assert transformed.special == []


def test_a_variable_shadows_the_automagic_of_its_name() -> None:
    assert transform_cell("time", {"time"}).special == []
    assert [line.kind for line in transform_cell("time", set()).special] == ["IPython magic (automagic)"]


def test_a_cell_magic_is_named_and_its_line_blanked() -> None:
    transformed = transform_cell("%%time\nx = 1", set())
    assert (transformed.cell_magic, transformed.source) == ("%%time", "\nx = 1")


def test_the_automagic_names_include_what_students_type() -> None:
    assert {"pip", "conda", "matplotlib", "cd", "ls", "time", "timeit", "load_ext"} <= LINE_MAGICS


def test_thousands_of_escapes_are_transformed_in_one_pass() -> None:
    cell = "\n".join(["!echo hi"] * 5000 + ["x = 1"])
    transformed = transform_cell(cell, set())
    assert len(transformed.special) == 5000
    assert transformed.source.splitlines()[-1] == "x = 1"


def test_a_builtin_or_keyword_is_never_automagic() -> None:
    assert transform_cell("print", set()).special == []
    assert transform_cell("pass", set()).special == []
