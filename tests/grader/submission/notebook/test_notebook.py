"""The graded module of a notebook: what runs at import, what is skipped and said, what cannot be graded."""

from __future__ import annotations

import csv
import json
import signal
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import nbformat
import pytest
from grading_support import SUBMISSIONS
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook

from grader import cli
from grader.grading.grade import grade_submission
from grader.grading.outcomes import with_notebook
from grader.report import ProblemResult, Report
from grader.sandbox import IsolationPolicy
from grader.submission.notebook import NotebookModule, bounded, build_module
from grader.submission.notebook.building import MAX_LISTED_SKIPPED, MAX_NOTED_GLOBALS, build_from_cells
from grader.submission.notebook.reading import NotebookCells, read_cells
from grader.submission.validation import FileVerdict


def notebook_bytes(*sources: str, markdown_first: bool = False) -> bytes:
    cells = [new_markdown_cell("# Lab")] if markdown_first else []
    cells += [new_code_cell(source) for source in sources]
    return nbformat.writes(new_notebook(cells=cells)).encode()


def built(*sources: str) -> NotebookModule:
    """The module of a notebook of these cells, built by the reader's pure core in this process.

    The rules of reading (what runs, what is skipped and said) are the core's; the tests below that call
    `build_module` hold the bounded child that runs the same core (its reply, its verdicts, its limits).
    """
    data = notebook_bytes(*sources)
    read = read_cells(data, "lab.ipynb")
    assert isinstance(read, NotebookCells), read
    module = build_from_cells(read, "lab.ipynb", None)
    assert isinstance(module, NotebookModule), module
    return module


DEFINITION = "def cartpole():\n    return 1"
COMPUTED = "assignment computed by a call (a demo or training run, not run at import)"


@pytest.mark.parametrize(
    ("cell", "reason"),
    [
        ("!pip install gym", "shell command"),
        ("%matplotlib inline", "IPython magic"),
        ("files = !ls", "shell command"),
        ("gym.make?", "help request"),
        ("%%bash\nls", "cell magic %%bash: the whole cell is left out"),
        ("print(cartpole())", "call of print(...) (a demo, not run at import)"),
        ("cartpole()", "call of cartpole(...) (a demo, not run at import)"),
        ("env.action_space", "expression whose value Jupyter displays"),
        ("for i in range(3):\n    cartpole()", "loop (a demo or training run, not run at import)"),
        ("q = find_qvalues('Taxi-v3')", COMPUTED),
        ("rates = [cartpole() for n in range(21)]", COMPUTED),
        ("if __name__ == '__main__':\n    cartpole()", "`if __name__ == '__main__':` block (a demo)"),
        ("env = gym.make('CartPole-v0')\ntry:\n    env.render()\nfinally:\n    env.close()",
         "`try` block running code (a demo, not run at import)"),
        ("with open('x') as f:\n    pass", "`with` block (a demo, not run at import)"),
        ("d = {}\nd['k'] = 1", "assignment into an object (not run at import)"),
    ],
    ids=["shell", "line-magic", "shell-assignment", "help", "bash-cell", "print", "call", "display", "loop",
         "training-run", "comprehension-of-calls", "main-guard", "render-demo", "with", "item-assignment"],
)  # fmt: skip
def test_demo_statements_are_skipped_and_listed(cell: str, reason: str) -> None:
    module = built("import gym\n" + DEFINITION, cell)
    assert [skipped.reason for skipped in module.summary.skipped] == [reason]
    assert module.summary.skipped[0].cell == 2
    assert "def cartpole" in module.source


@pytest.mark.parametrize(
    "cell",
    [
        "import numpy as np\nfrom IPython.display import clear_output",
        "ALPHA, GAMMA = .1, .6\nN = 10_000\nNAMES = ['a', 'b']\nHALF = N // 2",
        "import gym\nenv = gym.make('Taxi-v3')",
        "import numpy as np\nq = np.zeros((500, 6))\ndomain = np.arange(1, 22)",
        "SQUARES = [n * n for n in range(5)]",
        "try:\n    import gym\nexcept ImportError:\n    import gymnasium as gym",
        "'''Module docstring.'''",
        "class Agent:\n    rate = .1\n    def act(self, obs):\n        return 0",
        "import functools\n@functools.lru_cache\ndef helper(n=3):\n    return n",
    ],
    ids=["imports", "constants", "gym-make", "numpy-constructors", "comprehension-of-constants",
         "import-fallback", "docstring", "class", "decorated-definition"],
)  # fmt: skip
def test_imports_definitions_and_simple_constants_run(cell: str) -> None:
    module = built(cell, DEFINITION)
    assert module.summary.skipped == []
    compile(module.source, "lab.ipynb.py", "exec")


def test_a_global_set_only_by_a_skipped_statement_is_named_for_every_function_reaching_it() -> None:
    module = built(
        "import numpy as np",
        "def find_qvalues(env):\n    return np.zeros((500, 6))",
        "q_table = find_qvalues('Taxi-v3')",
        "def greedy(state):\n    return int(np.argmax(q_table[state]))",
        "def taxi():\n    return greedy(0)",
        "def cartpole():\n    return 1",
    )
    unbound = [
        (entry.function, entry.name, entry.cell, entry.line) for entry in module.summary.unbound_globals
    ]
    assert unbound == [("greedy", "q_table", 3, 1), ("taxi", "q_table", 3, 1)]
    assert module.summary.notes_for("cartpole") == []
    assert module.summary.notes_for("taxi") == [
        "Notebook: taxi() reads the global `q_table`, which only a skipped top-level statement sets (cell 3, "
        "line 1: `q_table = find_qvalues('Taxi-v3')`). The grader runs only imports, definitions and simple "
        "constants of a notebook, so there is no `q_table` when taxi() is called: compute it inside the "
        "function."
    ]


def test_a_global_read_by_a_method_of_a_class_the_function_uses_is_named() -> None:
    module = built(
        "table = train()",
        "class Agent:\n    def act(self, state):\n        return table[state]",
        "def taxi():\n    return Agent().act(0)",
    )
    assert [(entry.function, entry.name) for entry in module.summary.unbound_globals] == [("taxi", "table")]


def test_a_global_that_a_kept_statement_also_sets_is_not_reported() -> None:
    module = built("q = compute()", "q = None", "def taxi():\n    return q")
    assert module.summary.unbound_globals == []


def test_tracebacks_point_at_the_notebook_cell() -> None:
    module = built("import gym  # first", "print('demo')\ndef car():\n    x = 1\n    return y")
    line = module.source.splitlines().index("    return y") + 1
    cited = module.cited(f'File "/submission/lab.ipynb.py", line {line}, in car', "lab.ipynb.py")
    assert cited == 'File "lab.ipynb", cell 2, line 4, in car'


def test_a_time_cell_keeps_its_definitions_and_skips_its_demos() -> None:
    module = built("import gym", "%%time\n" + DEFINITION + "\nprint(cartpole())")
    assert [(entry.line, entry.reason) for entry in module.summary.skipped] == [
        (1, "cell magic %%time (the cell's statements are judged like any other's)"),
        (4, "call of print(...) (a demo, not run at import)"),
    ]
    assert "def cartpole" in module.source


def test_future_imports_move_to_the_top() -> None:
    module = built("import gym", "from __future__ import annotations\n" + DEFINITION)
    assert module.source.startswith("from __future__ import annotations\n")
    compile(module.source, "lab.ipynb.py", "exec")


@pytest.mark.parametrize(
    ("data", "status", "message"),
    [
        (b'{"cells": [', "error", "lab.ipynb is not a readable notebook: it is not valid JSON"),
        (b"", "missing", "lab.ipynb is empty: nothing to grade."),
        (json.dumps({"nbformat": 3, "nbformat_minor": 0, "worksheets": [], "metadata": {}}).encode(), "missing",  # noqa: E501
         "lab.ipynb has no code cells: nothing to grade."),
        (json.dumps({"nbformat": 4, "nbformat_minor": 5, "cells": "x", "metadata": {}}).encode(), "error",
         "lab.ipynb is JSON but not a Jupyter notebook"),
        (json.dumps({"nbformat": 4, "nbformat_minor": 5, "cells": [{"cell_type": "code", "source": 3}]}).encode(),  # noqa: E501
         "error", "lab.ipynb is not a readable notebook: the source of code cell 1 is a int, not text."),
        (nbformat.writes(new_notebook(cells=[new_markdown_cell("# only text")])).encode(), "missing",
         "lab.ipynb has no code cells: nothing to grade."),
        (notebook_bytes("print('hello')", "%timeit 1"), "missing",
         "lab.ipynb has code cells, but none of them defines anything"),
        (notebook_bytes("def taxi(:\n    pass", markdown_first=True), "error",
         "lab.ipynb, code cell 2 is not valid Python: invalid syntax (line 1 of the cell). Fix the cell"),
        (nbformat.writes(new_notebook(cells=[new_code_cell("x <- 1")],
                                      metadata={"language_info": {"name": "R"}})).encode(), "error",
         "lab.ipynb is a R notebook; the lab is graded in Python."),
    ],
    ids=["invalid-json", "empty", "nbformat-3-empty", "not-a-notebook", "unreadable-cell", "no-code-cells",
         "only-demos", "only-a-broken-definition", "other-language"],
)  # fmt: skip
def test_bad_notebooks_get_a_clear_verdict(data: bytes, status: str, message: str) -> None:
    verdict = build_module(data, "lab.ipynb")
    assert isinstance(verdict, FileVerdict)
    assert verdict.status == status
    assert verdict.message.startswith(message), verdict.message


def test_a_bad_notebook_is_a_submission_error_without_running_anything(tmp_path: Path) -> None:
    path = tmp_path / "lab.ipynb"
    path.write_bytes(b"not json at all")
    report = grade_submission(path, only=["cartpole"], policy=IsolationPolicy.ALLOW_FALLBACK)
    assert report.submission_error is not None
    assert report.submission_error.startswith("lab.ipynb is not a readable notebook")
    assert [problem.status for problem in report.problems] == ["error"]


def test_the_report_carries_the_summary_and_the_notes() -> None:
    module = build_module(
        (SUBMISSIONS / "notebooks" / "taxi_global_table.ipynb").read_bytes(), "t.ipynb", ["taxi"]
    )
    assert isinstance(module, NotebookModule)
    result = ProblemResult(
        id="taxi", title="Taxi", status="error", score=0, max_score=1,
        feedback='NameError\nFile "/submission/t.ipynb.py", line 74, in taxi',
    )  # fmt: skip
    report = Report(
        submission="t.ipynb", sha256="0", seed=0, gymnasium_version="1", grader_version="1", score=0,
        max_score=1, problems=[result],
    )  # fmt: skip
    annotated = with_notebook(report, module)
    assert annotated.notebook == module.summary
    feedback = annotated.problems[0].feedback
    assert feedback.startswith("Notebook: taxi() reads the global `q_table`")
    assert 'File "t.ipynb", cell 4, line' in feedback


def test_the_check_summary_lists_what_was_skipped_cell_by_cell() -> None:
    from grader.render.text import summary

    module = built("!pip install gym\nimport gym", DEFINITION + "\nprint(cartpole())")
    report = Report(
        submission="lab.ipynb", sha256="0", seed=0, gymnasium_version="1", grader_version="1", score=0,
        max_score=0, notebook=module.summary,
    )  # fmt: skip
    assert summary(report).splitlines()[1:4] == [
        "Notebook: 2 imports, definitions and constants from 2 code cells ran at import; "
        "2 statements did not:",
        "  cell 1 (no run), line 1: !pip install gym  <- shell command",
        "  cell 2 (no run), line 3: print(cartpole())  <- call of print(...) (a demo, not run at import)",
    ]


HOSTILE = SUBMISSIONS / "hostile"
NOTEBOOKS = SUBMISSIONS / "notebooks"


def _json_notebook(*sources: str) -> dict[str, Any]:
    loaded: dict[str, Any] = json.loads(notebook_bytes(*sources))
    return loaded


def _without_display_name(notebook: dict[str, Any]) -> None:
    notebook["metadata"]["kernelspec"] = {"name": "python3", "language": "python"}


def _odd_metadata(notebook: dict[str, Any]) -> None:
    notebook["metadata"] = []
    notebook["nbformat_minor"] = 99
    for cell in notebook["cells"]:
        del cell["id"]


def _no_metadata(notebook: dict[str, Any]) -> None:
    del notebook["metadata"]
    del notebook["cells"][0]["outputs"]


@pytest.mark.parametrize(
    ("change", "ignored"),
    [
        (_without_display_name, "'display_name' is a required property"),
        (_odd_metadata, "[] is not of type 'object'"),
        (_no_metadata, "is a required property"),
    ],
    ids=["kernelspec-without-display-name", "odd-metadata-future-minor-no-ids", "no-metadata-no-outputs"],
)
def test_metadata_that_does_not_validate_is_noted_and_ignored(
    change: Callable[[dict[str, Any]], None], ignored: str
) -> None:
    notebook = _json_notebook(DEFINITION)
    change(notebook)
    module = build_module(json.dumps(notebook).encode(), "lab.ipynb")
    assert isinstance(module, NotebookModule), module
    assert "def cartpole" in module.source
    [note] = module.summary.ignored
    assert ignored in note and "the grader read its code cells" in note


def test_an_old_nbformat_3_notebook_is_read() -> None:
    module = build_module((NOTEBOOKS / "old_format_v3.ipynb").read_bytes(), "old.ipynb")
    assert isinstance(module, NotebookModule), module
    assert "def cartpole" in module.source
    assert module.summary.ignored == ["an nbformat 3 notebook (IPython 1-3); its cells were read as such"]
    assert [(entry.cell, entry.execution_count) for entry in module.summary.skipped] == [(4, 3)]


def test_a_half_written_cell_is_left_out_and_the_rest_is_graded() -> None:
    module = build_module((NOTEBOOKS / "automagic_and_half_written.ipynb").read_bytes(), "lab.ipynb", ["car"])
    assert isinstance(module, NotebookModule), module
    assert "def cartpole" in module.source and "def car" in module.source
    reasons = {entry.code: entry.reason for entry in module.summary.skipped}
    assert reasons["pip install gym==0.17.3"] == "IPython magic (automagic)"
    assert reasons["def plot_car_positions(:"] == (
        "not valid Python, so Jupyter ran none of it either: the whole cell is left out"
    )
    assert "plot_car_positions" not in module.source


def test_a_graded_function_in_a_broken_cell_raises_an_error_naming_the_cell() -> None:
    module = build_module((NOTEBOOKS / "car_in_broken_cell.ipynb").read_bytes(), "opengym.ipynb", ["car"])
    assert isinstance(module, NotebookModule), module
    stand_in = module.source.split("# --- notebook cell 3 (not valid Python) ---\n")[1].split("# ---")[0]
    namespace: dict[str, Any] = {}
    exec(compile(stand_in, "opengym.ipynb.py", "exec"), namespace)
    with pytest.raises(SyntaxError) as raised:
        namespace["car"]()
    assert str(raised.value).startswith(
        "opengym.ipynb, code cell 3 (In [12]) is not valid Python: '(' was never closed (line 7 of the cell), "  # noqa: E501
        "so car() was never defined."
    )
    line = module.source.splitlines().index("def car(*args, **kwargs):") + 1
    assert module.cited(f'File "opengym.ipynb.py", line {line}', "opengym.ipynb.py") == (
        'File "opengym.ipynb", cell 3, line 1'
    )


def test_a_helper_in_a_broken_cell_is_named_in_the_note_of_the_function_using_it() -> None:
    data = notebook_bytes(
        "def helper():\n    return 1\ndef unfinished(:\n", "def car():\n    return helper()"
    )
    module = build_module(data, "lab.ipynb", ["car"])
    assert isinstance(module, NotebookModule), module
    assert "def helper" not in module.source
    assert module.summary.notes_for("car") == [
        "Notebook: car() uses `helper`, which only cell 1 defines, and that cell cannot be read (line 3: "
        "`def unfinished(:`), so Jupyter ran none of it either: fix that cell, run it, save the notebook and "
        "submit again."
    ]


@pytest.mark.parametrize(
    ("sample", "message"),
    [
        (
            "deep_json.ipynb",
            "deep_json.ipynb is not a readable notebook: its JSON nests too deeply for the reader.",
        ),
    ],
    ids=["json-nesting"],
)
def test_a_file_the_reader_cannot_take_is_that_submissions_error(sample: str, message: str) -> None:
    verdict = build_module((HOSTILE / sample).read_bytes(), sample, ["cartpole"])
    assert isinstance(verdict, FileVerdict)
    assert verdict.message.startswith(message)


@pytest.mark.slow
def test_cells_that_nest_too_deeply_or_are_too_large_are_left_out_with_a_note() -> None:
    module = build_module((HOSTILE / "deep_nesting.ipynb").read_bytes(), "deep.ipynb", ["cartpole"])
    assert isinstance(module, NotebookModule), module
    assert [(entry.cell, entry.reason) for entry in module.summary.skipped] == [
        (3, "its code nests too deeply to parse: the whole cell is left out"),
        (4, "its code nests too deeply to parse: the whole cell is left out"),
        (5, "its code nests too deeply to parse: the whole cell is left out"),
    ]
    too_large = built(DEFINITION, "x = [" + "1, " * 70_000 + "]")
    assert too_large.summary.skipped[0].reason == (
        "the cell has 210,006 characters, more than the 200,000 the grader reads: the whole cell is left out"
    )


@pytest.mark.slow
def test_thousands_of_functions_are_read_and_the_graded_ones_analysed() -> None:
    module = build_module((HOSTILE / "thousands_of_functions.ipynb").read_bytes(), "many.ipynb", ["cartpole"])
    assert isinstance(module, NotebookModule), module
    assert module.summary.kept_statements == 10_004
    assert {entry.function for entry in module.summary.unbound_globals} == {"cartpole"}
    assert len(module.summary.unbound_globals) == MAX_NOTED_GLOBALS  # of the 50 it reads


@pytest.mark.parametrize(
    ("returncode", "stderr", "expected"),
    [
        (-signal.SIGXCPU, b"", "reading it used more than 30 seconds of CPU"),
        (-signal.SIGKILL, b"", "reading it used more than 30 seconds of CPU"),
        (3, b"Traceback...\nMemoryError\n", "reading it needed more than 1,536 MiB of memory"),
        (-signal.SIGSEGV, b"", "the reader crashed on it (signal 11)"),
    ],
    ids=["cpu-limit", "killed", "memory", "crash"],
)
def test_the_death_of_the_reading_child_is_worded(returncode: int, stderr: bytes, expected: str) -> None:
    assert bounded._death(returncode, stderr) == expected


@pytest.mark.slow  # a grading through the sandbox
def test_a_batch_with_poisoned_notebooks_grades_every_honest_one(tmp_path: Path) -> None:
    inputs = tmp_path / "inputs"
    inputs.mkdir()
    samples = {
        "alice.ipynb": NOTEBOOKS / "bad_metadata.ipynb",
        "bob.ipynb": HOSTILE / "deep_json.ipynb",
        "carol.ipynb": HOSTILE / "deep_nesting.ipynb",
        "dave.ipynb": HOSTILE / "import_hooks.ipynb",
        "erin.ipynb": NOTEBOOKS / "automagic_and_half_written.ipynb",
    }
    for name, sample in samples.items():
        (inputs / name).write_bytes(sample.read_bytes())
    out = tmp_path / "out"
    assert cli.main(["grade", str(inputs), "--out", str(out), "--only", "cartpole", "--seed", "7"]) == 0
    rows = {row["student"]: row for row in csv.DictReader((out / "grades.csv").open())}
    assert {name: row["cartpole"] for name, row in rows.items()} == {
        "alice": "1", "bob": "0", "carol": "1", "dave": "1", "erin": "1",
    }  # fmt: skip
    assert rows["bob"]["note"].startswith("bob.ipynb is not a readable notebook: its JSON nests too deeply")


def test_thousands_of_skipped_lines_are_listed_up_to_a_cap_and_counted() -> None:
    module = built(DEFINITION, "\n".join(["!echo hi"] * 3000))
    assert len(module.summary.skipped) == MAX_LISTED_SKIPPED + 1
    assert module.summary.skipped[-1].reason == (
        "this and 1,999 more statements left out (not listed one by one)"
    )


def _empty_objects_notebook(size: int = 19_900_000) -> tuple[bytes, int]:
    """Issue 33's hostile sample: a valid notebook (the lab's own) padded with millions of empty JSON objects
    among its cells, each costing the parser ~25 times its 3 bytes; and its number of cells."""
    text = (NOTEBOOKS / "classic_complete.ipynb").read_text(encoding="utf-8")
    at = text.index('"cells": [') + len('"cells": [')
    filler = (size - len(text)) // 3
    return (text[:at] + "{}," * filler + text[at:]).encode(), filler + len(json.loads(text)["cells"])


class _Decodes:
    """Counts every JSON decoding in this process (json.loads and json.load go through it)."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch) -> None:
        self.calls = 0
        original = json.JSONDecoder.decode

        def counted(decoder: json.JSONDecoder, text: str, *args: Any) -> Any:
            self.calls += 1
            return original(decoder, text, *args)

        monkeypatch.setattr(json.JSONDecoder, "decode", counted)


def test_a_notebook_is_parsed_once_in_the_reader_and_never_in_the_parent(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from grader.classroom.similarity.sources import SourceText, read_source
    from grader.lab.editions.detection import detect_edition

    path = tmp_path / "opengym.ipynb"
    path.write_bytes((NOTEBOOKS / "taxi_global_table.ipynb").read_bytes() + b"\n")  # new bytes: not kept yet
    decodes = _Decodes(monkeypatch)
    children: list[list[str]] = []
    run = bounded.subprocess.run

    def counted_run(arguments: list[str], **options: Any) -> Any:
        children.append(arguments)
        return run(arguments, **options)

    monkeypatch.setattr(bounded.subprocess, "run", counted_run)
    assert detect_edition(path).edition.name == "classic"
    assert isinstance(read_source(path), SourceText)
    module = build_module(path.read_bytes(), path.name, ["taxi"])
    assert isinstance(module, NotebookModule)
    assert decodes.calls == 0, "the parent decoded JSON"
    requests = [json.loads(arguments[-1]) for arguments in children]
    assert [(request["mode"], request.get("input")) for request in requests] == [
        ("read", None),
        ("module", "read"),
    ]


@pytest.mark.slow  # starts the reader child for every sample notebook
@pytest.mark.parametrize("sample", sorted(path.name for path in NOTEBOOKS.glob("*.ipynb")))
def test_a_module_built_from_kept_cells_is_the_module_built_from_the_file(sample: str) -> None:
    data = (NOTEBOOKS / sample).read_bytes()
    fresh = bounded.build_module(data + b" ", sample, ["cartpole", "taxi"])  # new bytes: read by the child
    read = bounded.read_notebook(data + b"  ", sample)
    from_kept = bounded.build_module(data + b"  ", sample, ["cartpole", "taxi"])  # the kept cells
    assert not isinstance(read, FileVerdict)
    assert from_kept == fresh


@pytest.mark.slow
@pytest.mark.expected_skip("reads VmHWM from /proc (Linux)")
@pytest.mark.skipif(not Path("/proc/self/status").is_file(), reason="reads VmHWM from /proc (Linux)")
def test_a_notebook_of_millions_of_empty_objects_is_refused_and_the_parent_stays_small(
    tmp_path: Path,
) -> None:
    path = tmp_path / "mallory.ipynb"
    data, cells = _empty_objects_notebook()
    path.write_bytes(data)
    measured = subprocess.run(
        [
            sys.executable,
            "-c",
            "import re, sys\nfrom pathlib import Path\n"
            "from grader.lab.editions.detection import detect_edition\n"
            "from grader.submission.notebook import build_module\nfrom grader.classroom.similarity.sources import read_source\n"  # noqa: E501
            # VmHWM: the process's own peak since its exec (ru_maxrss counts its parent's size at the fork)
            "def peak():\n"
            "    return int(re.search(r'VmHWM:\\s+(\\d+) kB', Path('/proc/self/status').read_text())[1])\n"
            "path = Path(sys.argv[1])\nbefore = peak()\n"
            "print(detect_edition(path).reason)\nprint(read_source(path).reason)\n"
            "print(build_module(path.read_bytes(), path.name, ['cartpole']).message)\n"
            "print((peak() - before) // 1024)\n",
            str(path),
        ],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.splitlines()
    refusal = (
        f"mallory.ipynb has {cells:,} cells; a notebook may have at most 10,000. Delete the cells that are "
        "not part of your solution (or submit your code as a .py file) and submit again."
    )
    assert measured[:3] == [
        "mallory.ipynb could not be read as Python, so it shows no edition",
        f"left out: {refusal}",
        refusal,
    ]
    # Parsed in the parent, these objects took ~495 MiB there (bench/notebook_memory.py); read by the
    # bounded child, the parent holds the file's 20 MB bytes and the child's short reply.
    assert int(measured[3]) < 100, f"the parent grew by {measured[3]} MiB"


def test_the_kept_readings_drop_the_least_recently_used_past_their_budget() -> None:
    from grader.submission.notebook.reading import Cell, NotebookCells

    kept = bounded._Kept(characters=10)
    for name in ("a", "b", "c"):
        kept.put((b"digest", name), NotebookCells([Cell(1, None, "x" * 4)], []))
    assert kept.get((b"digest", "a")) is None, "12 characters: the oldest went"
    assert kept.get((b"digest", "b")) is not None  # now the most recently used: c goes next
    kept.put((b"digest", "d"), FileVerdict("missing", "dddd"))
    assert [key[1] for key in kept.entries] == ["b", "d"] and kept.size == 8
