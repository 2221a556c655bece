"""Jupyter notebooks as submissions: the graded module built from their code cells, in bounded time and
memory (see `grader.submission.notebook.building` for what is kept, `grader.submission.notebook.bounded` for
the bounds).

In detail:

A notebook is graded as the module its code cells make: the parent builds that module in a bounded child
process (never running student code), and the sandbox imports it like any `.py` submission.

- `grader/submission/notebook/__init__.py`: the public face (`build_module`, `read_notebook`, `is_notebook`,
  the models).
- **A notebook's JSON is parsed once, in the bounded child, never in the parent.** `read_notebook(data,
  name) -> NotebookCells | FileVerdict` (edition detection and similarity use it) and `build_module` (grading)
  both ask the child; its reply carries the code cells as read (`_Read`: number, In [n], source, and the
  ignored notes), which the parent keeps by the bytes' blake2b digest and the file name (`_Kept`, least
  recently used dropped past `KEPT_CHARACTERS` = 32,000,000 characters of code). `build_module` of bytes
  already read sends the kept cells (a few KB) to the child, which builds the module from them
  (`building.build_from_cells`) without the file: `grade --similarity` on a notebook runs two children
  (read for detection, build) and parses its JSON once. The request travels as the child's argument, so
  the notebook's bytes are piped without a copy. Figures: bench/notebook_memory.py.
- `build_module(data, name, graded) -> NotebookModule | FileVerdict`: `NotebookModule(source, summary:
  NotebookSummary, origins)`: the module the sandbox imports (code cells' imports, definitions and simple
  constants, in cell order, `__future__` imports first) and `NotebookSummary(code_cells, kept_statements,
  skipped: list[SkippedCode], unbound_globals: list[UnboundGlobal])`. What may run at import is decided
  statement by statement: imports, `def`/`class` (their defaults and decorators must be simple), string
  constants, assignments to names of "simple" expressions (literals, operators, names already bound by kept
  statements, and the calls in `CHEAP_CALLS`), and `if`/`try` blocks made only of those. Everything else is a
  `SkippedCode`. `UnboundGlobal`: a top-level function that reads (directly or through other top-level
  functions, found with `symtable`) a global only skipped statements set.
- `grader.grading.grade.grade_files` builds the module of every `.ipynb` into a temporary directory as
  `<name>.ipynb.py` and grades that file; `grader.grading.outcomes.with_notebook(report, module)` attaches
  `Report.notebook`, prefixes the affected problems' feedback with `UnboundGlobal.note()` and rewrites
  `File "<name>.ipynb.py", line N` into `File "<name>.ipynb", cell C, line L`. `Report.submission` and
  `Report.sha256` stay the notebook's.
- `grader/submission/notebook/bounded.py`: `build_module(data, name, graded)` spawns `python -m
  grader.submission.notebook.bounded REQUEST` (cwd and PYTHONPATH = the project root), which sets its own
  RLIMIT_AS (1.5 GiB), RLIMIT_CPU (30 s) and recursion limit before reading stdin, runs
  `building.build_module`, and prints a `_Reply` (pydantic) that the parent validates. A wall timeout (60 s),
  a limit signal, a crash, a `RecursionError`/`MemoryError` or an unreadable reply becomes a
  `FileVerdict("error", ...)`: that submission's `submission_error`, never the batch's. Figures:
  bench/notebook_reader.py.
- `grader/submission/notebook/reading.py`: bytes -> `NotebookCells(cells, ignored)`. JSON is read directly
  (nbformat 4, any minor, or 3's worksheets); the nbformat schema is checked on the cells' sources and
  metadata only (outputs blanked) and a failure is a note in `NotebookSummary.ignored`, not an error. Errors
  only when the cells cannot be read (not JSON, no list of cells, more than `MAX_CELLS` = 10,000 cells, a code
  cell whose source is not text, another language, more than 2,000,000 characters of code).
- `grader/submission/notebook/ipython.py`: `transform_cell(source, defined)` with IPython's own
  `inputtransformer2` (its cleanup transforms, cell-magic test, token grouping and each token transformer's
  `find`), loaded alone from the installed IPython without running `IPython/__init__.py` (which imports
  pexpect and `pty` on POSIX; a Windows-shaped interpreter has neither: tests/grader/test_portable.py):
  leading indent, `>>>`/`In [n]:` prompts, `%%cell magics`, and, per logical line from one tokenization,
  `!`/`!!`/`%`/`?`/`??`/`,`/`;`/`/` escapes, `x = !cmd`, `x = %magic`, trailing `?` where IPython accepts
  the target; one-line cells get automagic (`pip install gym`) unless the name is bound, a builtin or a
  keyword. Special lines become `pass` (line numbers kept) and are listed as skipped. A cell that parses as
  it is is not tokenized (no transformation can apply to valid Python). A transformer that cannot be
  loaded alone is that notebook's `FileVerdict("error", ...)`, saying it is the installation's fault.
- `grader/submission/notebook/rules.py`: `Kind` (SAFE, PLAIN_CLASS, PROPERTY, STUDENT) and `evaluate(expr,
  scope)`, one case per `ast.expr` kind, default deny. Only SAFE values (literals, imports other than
  `submission`/`__main__`, what `CHEAP_CALLS` return for SAFE arguments, operators on SAFE values) may be
  operated on; student names may only be stored; subscripts yield STUDENT (a container may hold anything).
  Decorators outside `KEPT_DECORATORS` are dropped (the function is graded undecorated, with a note). Classes
  are kept when their bases are SAFE or plain student classes (no `__init_subclass__`, no student metaclass,
  not Enum) and every statement of their body is keepable.
- `grader/submission/notebook/script.py`: a `.py` read as the notebook it came from (Jupyter's, Colab's,
  jupytext's exports). `build_script(data, name, graded, served)` (run by `bounded.build_script` in the
  reading child; `grader.grading.grade._prepare` calls it for every `.py` whose top level does more than
  import and define, `script.defines_only`): cells by nbconvert's `# In[N]:` / jupytext's `# %%` markers,
  else one per top-level statement; ``get_ipython().run_line_magic / .run_cell_magic / .system /
  .getoutput`` lines written back as the `%`, `%%` and `!` lines they were, then read by `building` with the
  notebook's rules. The module keeps each kept statement on its own line of the file where it can (so a
  traceback's line is the file's), and every `SkippedCode`, `UnboundGlobal` and origin is cell
  `SCRIPT_CELL` (0) with the file's own line (`NotebookSummary.script`). `None` (the file graded as it is)
  when the rules leave out nothing but decorators; the whole file (IPython lines made `pass`, as its cells
  run) when a graded or template function uses what a left-out statement sets or changes
  (`building.touched_names`, `building.globals_needed`), except the globals of `served` functions
  (compare()'s, set by its cells run). A file that is not Python as it is is read when IPython's transformer
  makes it Python (``!pip`` written as it is) or its marked cells hold the error (left out as in a notebook).
  `NotebookModule.cells` of a `.py`: its marked cells, or the file as one cell, each `SCRIPT_CELL` (run as a
  script: `cells.runnable_cells`).
- `grader/submission/notebook/building.py`: cells -> module. Per cell: size budget (200,000 characters),
  IPython transformation, `ast.parse`, depth budget (500, measured without recursion); a cell failing any of
  these is skipped as a whole with a note, the graded functions it defines get a stand-in raising
  `SyntaxError` that names the cell ("opengym.ipynb, code cell 7 (In [12]) is not valid Python: ..."), and its
  other names become `UnboundGlobal(broken_cell=True)` notes for the graded functions that use them. The
  global-use analysis (`symtable`, one pass) searches from the `graded` functions only (the grading plan's
  problem ids, passed by `grader.grading.grade._prepare`), at most 20 notes each.
"""

from __future__ import annotations

from grader.submission.notebook.bounded import build_module, read_notebook
from grader.submission.notebook.models import NotebookModule, NotebookSummary, SkippedCode, UnboundGlobal
from grader.submission.notebook.reading import MAX_NOTEBOOK_BYTES

NOTEBOOK_SUFFIX = ".ipynb"


def is_notebook(name: str) -> bool:
    """True when a submission's file name says it is a Jupyter notebook."""
    return name.lower().endswith(NOTEBOOK_SUFFIX)


__all__ = [
    "MAX_NOTEBOOK_BYTES",
    "NOTEBOOK_SUFFIX",
    "NotebookModule",
    "NotebookSummary",
    "SkippedCode",
    "UnboundGlobal",
    "build_module",
    "is_notebook",
    "read_notebook",
]
