"""The code a problem that runs the notebook's cells executes: the cells of a notebook, or a script.

A problem such as edition 4's `compare()` reads the globals the notebook's own training cells made, so its
configuration may ask for the cells to run first (in the sandbox, `grader.sandbox.child.cells`). Building
the graded module (`grader.submission.notebook.building`) keeps every code cell Jupyter's "Run All" would
run; the grading run writes them beside the module it imports (`write_cells`), and the problem's run reads
them back (`runnable_cells`) into the argument of the sandbox's cells call. A `.py` runs as a script
(`python opengym.py`, so its `if __name__ == "__main__":` block too): graded as it is, the whole file; read as
the notebook it came from (`grader.submission.notebook.script`), the export's cells with IPython's lines read
as the notebook's were, each numbered `SCRIPT_CELL` and starting on its own line of the file.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

CELLS_SUFFIX = ".cells.json"
"""The file beside a notebook's graded module that holds its runnable cells."""
RAN_CELLS = "ran_notebook_cells"
"""The measurement a problem's result carries when the notebook's cells ran before its calls (its globals
were set, so the report adds no "global set by a skipped statement" note)."""
SCRIPT_CELL = 0
"""The cell number of a `.py` submission's code run as a script (a notebook's cells are numbered from 1)."""


def cells_path(module: Path) -> Path:
    """Where the runnable cells of the graded module at `module` are kept."""
    return module.with_name(module.name + CELLS_SUFFIX)


def write_cells(module: Path, cells: tuple[tuple[int, str], ...]) -> None:
    """Keep a notebook's runnable cells (trusted: built by the bounded reader) beside its graded module."""
    cells_path(module).write_text(json.dumps([list(cell) for cell in cells]), encoding="utf-8")


def runnable_cells(module: Path) -> list[dict[str, Any]]:
    """The cells call's argument for the submission whose graded module is `module`.

    Returns:
        One ``{"cell": number, "source": python, "script": False}`` per code cell of a notebook, in order;
        for a `.py` submission ``{"cell": 0, "source": python, "script": True}``: the file, or each cell of
        the export it was read as.
    """
    kept = cells_path(module)
    if kept.is_file():
        return [
            {"cell": int(number), "source": str(source), "script": int(number) == SCRIPT_CELL}
            for number, source in json.loads(kept.read_text(encoding="utf-8"))
        ]
    source = module.read_bytes().decode("utf-8", errors="replace")
    return [{"cell": SCRIPT_CELL, "source": source, "script": True}]
