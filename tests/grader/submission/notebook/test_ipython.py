"""Cells are read as IPython reads them: its input transformations (IPython's own module, loaded alone) and
one-line automagic."""

from __future__ import annotations

import ast
import importlib.util
import shutil
import subprocess
import sys
from pathlib import Path

import nbformat
import pytest
from nbformat.v4 import new_code_cell, new_notebook
from shaped_python import shaped_python

from grader.sandbox.host import HOST
from grader.submission.notebook import NotebookModule, build_module
from grader.submission.notebook.ipython import (
    ALONE,
    LINE_MAGICS,
    TRANSFORMER,
    TransformerUnavailable,
    load_transformer,
    transform_cell,
    transformer,
)


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
        ("%time?", "pass", [(1, "help request", ())]),
        ("  a = 1\n  b = 2", "a = 1\nb = 2", []),
        (">>> a = 1\n... b = 2", "a = 1\nb = 2", []),
        ("In [3]: a = 1\n   ...: b = 2", "a = 1\nb = 2", []),
    ],
    ids=["shell", "shell-capture", "line-magic", "system-assign", "magic-assign", "help-end", "help-start",
         "help-detail", "autocall", "escape-in-a-block", "continued-magic", "automagic-pip",
         "automagic-matplotlib", "automagic-alias", "help-on-a-magic", "leading-indent", "classic-prompt",
         "ipython-prompt"],
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


@pytest.mark.parametrize(
    "cell",
    ["print(x)?", "f(1)?", "x ?", "x? ", "x?  # comment", "x = [\n1,\n2]?", "1 if x else 2?",
     "//evil.example/x", 'x = %"""'],
    ids=["call-then-help", "call-with-argument", "space-before", "space-after", "comment-after",
         "bracket-over-lines", "expression", "floor-division-first", "magic-assign-cut-short"],
)  # fmt: skip
def test_what_ipython_refuses_to_transform_stays_broken(cell: str) -> None:
    """IPython 8 leaves these as they are (HelpEnd's transform refuses the target, ``//`` is not an escape,
    MagicAssign raises IndexError on the last): a SyntaxError in Jupyter too, so the cell is left out as
    broken rather than read more kindly than the student's kernel ran it."""
    transformed = transform_cell(cell, set())
    assert (transformed.source, transformed.special) == (cell, [])


def _imports(path: Path) -> list[tuple[int, str, tuple[str, ...]]]:
    """Every import of a module (top level or not): its level, module and the names it takes."""
    found: list[tuple[int, str, tuple[str, ...]]] = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found += [(0, alias.name, ()) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            found.append((node.level, node.module or "", tuple(alias.name for alias in node.names)))
    return found


def _installed_ipython() -> Path:
    spec = importlib.util.find_spec("IPython")
    assert spec is not None and spec.submodule_search_locations, "IPython is a dependency (pyproject.toml)"
    return Path(next(iter(spec.submodule_search_locations)))


def _outside_imports(package: Path) -> list[str]:
    """The imports of IPython's inputtransformer2 (and of each IPython module of `ALONE` it takes) that are
    neither the standard library nor a module of `ALONE`, as "module: import [names]"."""
    outside: list[str] = []
    pending, seen = [TRANSFORMER], set()
    while pending:
        name = pending.pop()
        seen.add(name)
        for level, module, names in _imports(package.joinpath(*name.split(".")[1:]).with_suffix(".py")):
            if level == 0 and module.partition(".")[0] in sys.stdlib_module_names:
                continue
            wanted = [f"{module}.{item}" for item in names] if level == 0 else []
            if wanted and all(item in ALONE for item in wanted):
                pending += [item for item in wanted if item not in seen]
                continue
            outside.append(f"{name}: {'.' * level}{module} {list(names)}")
    return outside


def test_the_installed_transformer_imports_only_what_loading_it_alone_serves() -> None:
    """The guard of the loader's assumption: IPython's inputtransformer2, and each IPython module it takes
    (``from IPython.utils import tokenutil`` from IPython 8.15 on), import the standard library and each
    other only. An IPython upgrade that adds another import fails here, not in every student's notebook."""
    package = _installed_ipython()
    assert _outside_imports(package) == [], f"IPython at {package} can no longer be loaded alone"


@pytest.mark.parametrize(
    ("first_line", "outside"),
    [
        ("from IPython.utils import tokenutil\n", []),
        ("def f():\n    import numpy\n", ["IPython.core.inputtransformer2: numpy []"]),
        ("from IPython.utils import tokenutil, py3compat\n",
         ["IPython.core.inputtransformer2: IPython.utils ['tokenutil', 'py3compat']"]),
        ("from .. import release\n", ["IPython.core.inputtransformer2: .. ['release']"]),
    ],
    ids=["tokenutil-as-8.15-on", "third-party-in-a-function", "another-ipython-module", "relative"],
)  # fmt: skip
def test_the_guard_fails_on_an_import_loading_alone_cannot_serve(
    tmp_path: Path, first_line: str, outside: list[str]
) -> None:
    package = _fake_ipython(tmp_path, first_line + _real_transformer_source(), tokenutil=True)
    assert _outside_imports(package) == outside


def test_loading_it_alone_runs_nothing_of_the_ipython_package() -> None:
    code = (
        "import sys; from grader.submission.notebook.ipython import transformer, transform_cell\n"
        "transformer(); cell = transform_cell('!pip install gym\\nx = 1', set())\n"
        "print(sorted(name for name in sys.modules if name.split('.')[0] in ('IPython', 'pexpect', 'pty')))"
    )
    completed = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert completed.stdout.strip() == "[]", completed.stdout


def _fake_ipython(root: Path, transformer_source: str, tokenutil: bool = False) -> Path:
    """An IPython package directory whose ``__init__`` raises: loading alone must never run it."""
    package = root / "IPython"
    (package / "core").mkdir(parents=True)
    (package / "__init__.py").write_text("raise ImportError('IPython/__init__.py ran')\n", encoding="utf-8")
    (package / "core" / "inputtransformer2.py").write_text(transformer_source, encoding="utf-8")
    if tokenutil:
        (package / "utils").mkdir()
        shutil.copy(_installed_ipython() / "utils" / "tokenutil.py", package / "utils" / "tokenutil.py")
    return package


def _real_transformer_source() -> str:
    return (_installed_ipython() / "core" / "inputtransformer2.py").read_text(encoding="utf-8")


def test_a_transformer_that_takes_tokenutil_as_ipython_8_15_on_does_loads_alone(tmp_path: Path) -> None:
    source = "from IPython.utils import tokenutil\n" + _real_transformer_source()
    module = load_transformer(_fake_ipython(tmp_path, source, tokenutil=True))
    assert module.tokenutil.__name__ == "_gymgrade_alone.IPython.utils.tokenutil"
    assert module.make_tokens_by_line(["x = 1\n"])[0][0].string == "x"
    assert "IPython" not in sys.modules or sys.modules["IPython"].__file__ != str(
        tmp_path / "IPython" / "__init__.py"
    )


@pytest.mark.parametrize(
    ("source", "message"),
    [
        ("import numpy\n", "imports numpy []: neither the standard library nor one of"),
        ("from IPython.utils import py3compat\n", "imports IPython.utils ['py3compat']: neither"),
        ("import IPython\n", "imports IPython []: neither"),
        ("from . import release\n", "imports . ['release']: neither"),
        ("def broken(:\n", "failed: SyntaxError: invalid syntax"),
        ("raise RuntimeError('upgrade')\n", "failed: RuntimeError: upgrade"),
    ],
    ids=["third-party", "another-ipython-module", "the-package", "relative", "syntax-error", "raises"],
)
def test_a_transformer_that_cannot_load_alone_says_why(tmp_path: Path, source: str, message: str) -> None:
    with pytest.raises(TransformerUnavailable, match=message.replace("[", r"\[").replace("]", r"\]")):
        load_transformer(_fake_ipython(tmp_path, source))


def test_a_missing_transformer_says_where_it_was_looked_for(tmp_path: Path) -> None:
    package = _fake_ipython(tmp_path, "")
    (package / "core" / "inputtransformer2.py").unlink()
    with pytest.raises(
        TransformerUnavailable, match=r"IPython\.core\.inputtransformer2 is not at .*reinstall"
    ):
        load_transformer(package)


def test_the_transformer_is_loaded_once_per_process() -> None:
    assert transformer() is transformer()


def _notebook(*sources: str) -> bytes:
    return nbformat.writes(new_notebook(cells=[new_code_cell(source) for source in sources])).encode()


@pytest.mark.slow
def test_the_reader_child_loads_ipythons_modules_alone_and_a_failure_is_the_notebooks_verdict(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """First an IPython whose ``__init__`` raises, with its real transformer: the child reads the magics
    (the package never ran); then one whose transformer imports what cannot be loaded alone: that notebook's
    verdict says so, the parent goes on."""
    honest, broken = tmp_path / "honest", tmp_path / "broken"
    _fake_ipython(honest, _real_transformer_source())
    _fake_ipython(broken, "import numpy\n" + _real_transformer_source())
    data = _notebook("!pip install gym\n%matplotlib inline", "def f():\n    return 1")
    monkeypatch.setenv("PYTHONPATH", str(honest))
    module = build_module(data, "honest.ipynb")
    assert isinstance(module, NotebookModule), module
    assert [entry.reason for entry in module.summary.skipped] == ["shell command", "IPython magic"]
    monkeypatch.setenv("PYTHONPATH", str(broken))
    verdict = build_module(data + b" ", "broken.ipynb")
    assert not isinstance(verdict, NotebookModule)
    assert verdict.status == "error"
    assert verdict.message == (
        "broken.ipynb cannot be read: the grader could not load IPython's input transformer (IPython's input "
        "transformer imports numpy []: neither the standard library nor one of "
        "['IPython.core.inputtransformer2', 'IPython.utils.tokenutil']. This IPython cannot be loaded alone; "
        "install one whose inputtransformer2 can (pip install 'ipython>=8,<10') or extend "
        "grader.submission.notebook.ipython.ALONE). It reads the %magics and !commands of notebook cells; "
        "this is a fault of the grader's installation, not of your notebook. Tell the course staff; a .py "
        "file of your code is graded meanwhile."
    )


@pytest.mark.slow
@pytest.mark.expected_skip("shapes this Linux CPython")
@pytest.mark.skipif(HOST.system != "Linux", reason="shapes this Linux CPython; CI compares real runs")
def test_a_windows_shaped_interpreter_reads_magics_where_importing_ipython_fails(tmp_path: Path) -> None:
    """The shape has no pty (Windows has none) but says "linux", so IPython's package picks its POSIX process
    helpers and its import fails there (the control); the transformer loaded alone reads the cell."""
    python = shaped_python(tmp_path / "windows", "windows")
    root = Path(__file__).resolve().parents[4]
    environment = {"PYTHONPATH": str(root), "PATH": "/usr/bin:/bin"}
    control = subprocess.run(
        [str(python), "-c", "import IPython.core.inputtransformer2"],
        capture_output=True,
        text=True,
        env=environment,
    )
    assert control.returncode != 0 and "pty" in control.stderr, control.stderr[-500:]
    code = (
        "from grader.submission.notebook.ipython import transform_cell\n"
        "cell = transform_cell('!pip install gym\\n%matplotlib inline\\nx = 1', set())\n"
        "print([line.kind for line in cell.special])"
    )
    read = subprocess.run(
        [str(python), "-c", code], capture_output=True, text=True, env=environment, check=True
    )
    assert read.stdout.strip() == "['shell command', 'IPython magic']"
