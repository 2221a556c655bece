"""A `.py` read as the notebook it came from (`grader.submission.notebook.script`): its cells, IPython's lines
as the exports write them, the module its import runs, the file's own lines in what is reported, and a plain
module (or one whose functions use what its top level sets) graded as it is."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest
from notebook_exports import colab_export, nbconvert_export

from grader.submission.notebook.building import build_module
from grader.submission.notebook.cells import SCRIPT_CELL, runnable_cells, write_cells
from grader.submission.notebook.models import NotebookModule
from grader.submission.notebook.script import build_script, may_be_export, script_cells, unexported

SUBMISSIONS = Path(__file__).resolve().parents[4] / "submissions"
GRADED = (
    "random_blackjack",
    "blackjack",
    "cartpole",
    "car",
    "taxi",
    "find_qvalues",
    "epsilon_decay",
    "sarsa0",
)
HONEST_NOTEBOOKS = (
    "notebooks/classic_complete.ipynb",
    "notebooks/bad_metadata.ipynb",
    "notebooks/old_format_v3.ipynb",
    "editions/rl1_template_honest.ipynb",
    "editions/compare_honest.ipynb",
    "templates/rl1.ipynb",
)


def _statements(source: str) -> list[str]:
    """The module's statements but strings (an export's markdown and Colab's header are strings)."""
    body = ast.parse(source).body
    return [ast.dump(s) for s in body if not (isinstance(s, ast.Expr) and isinstance(s.value, ast.Constant))]


@pytest.mark.parametrize(
    ("exported", "notebook"),
    [
        ("get_ipython().run_line_magic('matplotlib', 'inline')", "%matplotlib inline"),
        ("get_ipython().run_line_magic('timeit', 'car()')", "%timeit car()"),
        ("get_ipython().system('pip install gym')", "!pip install gym"),
        ("get_ipython().getoutput('ls')", "!!ls"),
        ("files = get_ipython().getoutput('ls')", "files = !ls"),
        ("t = get_ipython().run_line_magic('time', 'x = 1')", "t = %time x = 1"),
        ("get_ipython().run_line_magic('pinfo', 'gym.make')", "gym.make?"),
        ("get_ipython().run_line_magic('pinfo2', 'gym.make')", "gym.make??"),
    ],
)
def test_ipython_lines_are_written_back_as_the_notebook_had_them(exported: str, notebook: str) -> None:
    (cell,) = script_cells(exported + "\n")
    assert cell.source == notebook


def test_a_cell_magic_is_its_cell_and_an_indented_line_keeps_its_indent() -> None:
    text = (
        "import numpy as np\n"
        "get_ipython().run_cell_magic('time', '', 'table = np.ones(3)\\nprint(table)\\n')\n"
        "for _ in range(2):\n"
        "    get_ipython().system('echo hi')\n"
    )
    cells = script_cells(text)
    assert [cell.first_line for cell in cells] == [1, 2, 3]
    assert cells[1].source == "%%time\ntable = np.ones(3)\nprint(table)"
    assert cells[2].source == "for _ in range(2):\n    !echo hi"


def test_markers_split_cells_outside_statements_only() -> None:
    text = (
        '# In[1]:\n\n\nimport gym\n\n\n# In[ ]:\n\n\ndef f():\n    """\n# %%\n"""\n    return 1\n'
        "# %%\nx = f()\n"
    )
    assert [cell.first_line for cell in script_cells(text)] == [1, 7, 15]


def test_unexported_leaves_other_calls_alone() -> None:
    assert unexported(["get_ipython().kernel", "print(1)"], [], 1) == (
        ["get_ipython().kernel", "print(1)"],
        [1, 2],
    )


def test_a_module_of_definitions_and_constants_is_graded_as_it_is() -> None:
    text = "import gym\nALPHA = 0.1\n\n@functools.wraps(len)\ndef taxi(q):\n    return 1, 2\n"
    assert build_script(text.encode(), "opengym.py", GRADED) is None


def test_demo_statements_are_left_out_and_cited_by_the_files_lines() -> None:
    text = (
        "# In[1]:\n\n\nget_ipython().run_line_magic('matplotlib', 'inline')\nimport numpy as np\n\n\n"
        "# In[2]:\n\n\ndef taxi(q):\n    return float(q.sum()), 0.0\n\n\n"
        "# In[3]:\n\n\nq_table = np.zeros((500, 6))\nprint(taxi(q_table))\nfor i in range(10**9):\n    pass\n"
    )
    built = build_script(text.encode(), "gymnasium.py", GRADED)
    assert isinstance(built, NotebookModule)
    assert built.summary.script
    found = [(entry.cell, entry.line, entry.reason.split(" (")[0]) for entry in built.summary.skipped]
    assert found == [
        (SCRIPT_CELL, 4, "IPython magic"),
        (SCRIPT_CELL, 19, "call of print(...)"),
        (SCRIPT_CELL, 20, "loop"),
    ]
    lines = built.source.splitlines()
    assert lines[10] == "def taxi(q):" and lines[17] == "q_table = np.zeros((500, 6))"  # the file's own lines
    assert "print(taxi" not in built.source and "get_ipython" not in built.source
    traceback = 'File "/tmp/x/gymnasium.py", line 12, in taxi'
    assert built.cited(traceback, "gymnasium.py.py") == 'File "gymnasium.py", line 12, in taxi'


def test_a_function_using_what_the_top_level_sets_gets_the_whole_file_as_always(tmp_path: Path) -> None:
    text = (
        "import gymnasium as gym\nget_ipython().system('pip install gym')\n"
        "env = gym.make('Taxi-v3')\nenv.reset(seed=1)\nprint(env)\n"
        "def taxi(q):\n    return env.unwrapped.s, 0\n"
    )
    built = build_script(text.encode(), "opengym.py", GRADED)
    assert isinstance(built, NotebookModule)
    assert [entry.line for entry in built.summary.skipped] == [2]
    assert built.summary.ignored == [
        "your functions use what top-level statements set or change (`env`), so the whole file ran at "
        "import, as a .py always did, but for its IPython lines"
    ]
    assert built.source.splitlines()[1:5] == [
        "pass",
        "env = gym.make('Taxi-v3')",
        "env.reset(seed=1)",
        "print(env)",
    ]
    without_ipython = text.replace("get_ipython().system('pip install gym')\n", "")
    assert build_script(without_ipython.encode(), "opengym.py", GRADED) is None


def test_globals_served_by_the_cells_ask_nothing_of_the_import(tmp_path: Path) -> None:
    text = (
        "import numpy as np\ndef qlearn():\n    return np.zeros((500, 6))\n"
        "def compare():\n    return table.sum(), 0\n"
        "table = qlearn()\nif __name__ == '__main__':\n    print(compare())\n"
    )
    built = build_script(text.encode(), "gymnasium.py", (*GRADED, "compare"), served=("compare",))
    assert isinstance(built, NotebookModule)
    assert [entry.line for entry in built.summary.skipped] == [6]  # the main guard is no news for a .py
    assert [(entry.function, entry.name, entry.line) for entry in built.summary.unbound_globals] == [
        ("compare", "table", 6)
    ]
    module = tmp_path / "gymnasium.py"
    module.write_text(built.source, encoding="utf-8")
    write_cells(module, built.cells)
    assert runnable_cells(module) == [{"cell": SCRIPT_CELL, "source": text, "script": True}]


@pytest.mark.slow  # nbconvert and IPython's transformer, on every honest notebook sample
@pytest.mark.parametrize("notebook", HONEST_NOTEBOOKS)
@pytest.mark.parametrize("export", ["nbconvert", "colab"])
def test_an_export_imports_the_module_its_notebook_does(notebook: str, export: str) -> None:
    data = (SUBMISSIONS / notebook).read_bytes()
    text = nbconvert_export(data) if export == "nbconvert" else colab_export(data, Path(notebook).name)
    graded = (*GRADED, "compare")
    from_notebook = build_module(data, Path(notebook).name, graded)
    from_export = build_script(text.encode(), "gymnasium.py", graded, served=("compare",))
    assert isinstance(from_notebook, NotebookModule) and isinstance(from_export, NotebookModule)
    assert _statements(from_export.source) == _statements(from_notebook.source)
    assert [entry.reason for entry in from_export.summary.skipped] == [
        entry.reason for entry in from_notebook.summary.skipped
    ]
    exported_lines = text.splitlines()
    for entry in from_export.summary.skipped:  # each cited line is the file's own
        assert exported_lines[entry.line - 1].strip(), entry


def test_ipython_lines_written_as_they_are_are_read_as_the_notebook_reads_them() -> None:
    text = "!pip install gym\n%matplotlib inline\nimport gym\n\ndef car():\n    return 1\n\nprint(car())\n"
    built = build_script(text.encode(), "opengym.py", GRADED)
    assert isinstance(built, NotebookModule)
    assert [(entry.line, entry.reason.split(" (")[0]) for entry in built.summary.skipped] == [
        (1, "shell command"),
        (2, "IPython magic"),
        (8, "call of print(...)"),
    ]
    assert built.source.splitlines()[2:6] == ["import gym", "", "def car():", "    return 1"]


def test_a_half_written_marked_cell_is_left_out_as_in_the_notebook() -> None:
    text = "# In[1]:\n\n\ndef cartpole():\n    return 1\n\n\n# In[2]:\n\n\ndef car(:\n    return 2\n"
    built = build_script(text.encode(), "opengym.py", GRADED)
    assert isinstance(built, NotebookModule)
    assert [entry.line for entry in built.summary.skipped] == [11]
    assert "never defined" in built.source  # car() raises an error naming the cell, as the notebook's would


def test_a_file_that_is_not_python_even_so_is_not_read() -> None:
    with pytest.raises(SyntaxError):  # the reading child's error: the file keeps check_source's verdict
        build_script(b"def car(:\n    return 2\n", "opengym.py", GRADED)


@pytest.mark.parametrize(
    ("demo", "whole_file"),
    [
        ("print(N, table[0])", False),
        ("plt.plot(table[0])", False),
        ("np.random.shuffle(table)", True),
        ("table[0, 0] = 1.0", True),
        ("table.fill(2.0)", True),
        ("N = int('7')", True),
    ],
)
def test_what_a_left_out_statement_may_change_keeps_the_whole_file(demo: str, whole_file: bool) -> None:
    text = (
        "import numpy as np\nfrom matplotlib import pyplot as plt\nN = 3\ntable = np.zeros((500, 6))\n"
        f"def taxi(q, n=N):\n    return float(table.sum()), 0.0\n{demo}\nget_ipython().system('ls')\n"
    )
    built = build_script(text.encode(), "opengym.py", GRADED)
    assert isinstance(built, NotebookModule)
    assert (demo in built.source) is whole_file


@pytest.mark.parametrize(
    ("text", "may_be"),
    [
        ("def car(:\n    return 1\n", False),
        ("!pip install gym\n", True),
        ("    %timeit car()\n", True),
        ("gym.make?\n", True),
        ("# %%\ndef car(:\n", True),
    ],
)
def test_only_a_file_with_ipython_lines_or_markers_may_be_an_export(text: str, may_be: bool) -> None:
    assert may_be_export(text) is may_be


def test_a_file_defining_nothing_is_graded_as_it_is() -> None:
    assert build_script(b"import os\nraise RuntimeError('boom at import')\n", "opengym.py", GRADED) is None
