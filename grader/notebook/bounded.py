"""Read a notebook (untrusted bytes) in a child process bounded in CPU time, memory and wall time.

Python's parser, ``json``, ``symtable`` and the reduction of `grader.notebook.building` are all recursive
and allocate in proportion to their input: a cell of ten thousand nested brackets raises
``RecursionError``, a crafted file can ask for gigabytes. None of that may reach the trusted parent (a
``gymgrade grade`` batch grades every other file), so the parent only spawns ``python -m
grader.notebook.bounded``, sends the bytes, and validates the reply; whatever goes wrong in the child
(an exception, a limit, a crash) becomes that submission's verdict with a message saying what to fix.
The CPU and memory limits are set where the system has them (`grader.sandbox.host`); elsewhere (Windows)
the wall-clock limit and the recursion limit bound the reader.
"""

from __future__ import annotations

import importlib
import json
import os
import subprocess
import sys
import traceback
from collections.abc import Collection
from pathlib import Path
from typing import Literal

from pydantic import BaseModel, ConfigDict, ValidationError

from grader.notebook.models import NotebookModule, NotebookSummary
from grader.notebook.reading import MAX_NOTEBOOK_BYTES
from grader.sandbox.host import HOST, Feature, signal_number
from grader.validation import FileVerdict

MEMORY_BYTES = 1536 * 1024 * 1024
"""Address space of the reading child: the interpreter and nbformat take about 150 MiB; a 20 MB notebook
of outputs parses into a few hundred MiB of Python objects."""
CPU_SECONDS = 30
"""CPU time of the reading child: an honest notebook takes well under a second (bench/notebook_reader.py)."""
WALL_SECONDS = 60.0
"""Wall time, for a machine busy with grading (the CPU limit is what a hostile file meets first)."""
RECURSION_LIMIT = 10_000
"""The child's recursion limit: deep enough for any honest cell, while the C stack (8 MiB main thread,
raised below when allowed) holds the frames of a cell that exhausts it."""
ROOT = Path(__file__).resolve().parents[2]


class _Reply(BaseModel):
    """What the child prints: the module built, or the verdict."""

    model_config = ConfigDict(extra="forbid")

    status: Literal["module", "missing", "error"]
    message: str = ""
    source: str = ""
    summary: NotebookSummary | None = None
    origins: list[tuple[int, int] | None] = []
    cells: list[tuple[int, str]] = []


def build_module(data: bytes, name: str, graded: Collection[str] | None = ()) -> NotebookModule | FileVerdict:
    """Turn a notebook's bytes into the Python module the grader imports, in a bounded child process.

    Args:
        data: The ``.ipynb`` file's bytes (untrusted).
        name: Its file name, used in messages.
        graded: The functions problems call (the globals they reach are checked, and a graded function in
            a cell that cannot be read raises an error naming the cell); None: every top-level function.

    Returns:
        The module and its summary, or the verdict saying why the notebook cannot be graded, including
        a file that exhausts the reader's time or memory.
    """
    if len(data) > MAX_NOTEBOOK_BYTES:
        return FileVerdict(
            "error",
            f"{name} is {len(data):,} bytes; a notebook may be at most {MAX_NOTEBOOK_BYTES:,} bytes. "
            "Clear its outputs (Kernel > Restart & Clear Output) and submit again.",
        )
    header = json.dumps({"name": name, "graded": None if graded is None else sorted(graded)}).encode()
    try:
        completed = subprocess.run(
            [sys.executable, "-m", "grader.notebook.bounded"],
            input=header + b"\n" + data,
            capture_output=True,
            timeout=WALL_SECONDS,
            cwd=ROOT,
            env={
                **os.environ,
                "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])),
            },
            check=False,
        )
    except subprocess.TimeoutExpired:
        return _unreadable(name, f"reading it took more than {WALL_SECONDS:.0f} seconds")
    if completed.returncode != 0:
        return _unreadable(name, _death(completed.returncode, completed.stderr))
    try:
        reply = _Reply.model_validate_json(completed.stdout)
    except ValidationError:
        return _unreadable(name, "the reader's reply was not understood")
    if reply.status != "module" or reply.summary is None:
        return FileVerdict("missing" if reply.status == "missing" else "error", reply.message)
    return NotebookModule(
        source=reply.source, summary=reply.summary, origins=tuple(reply.origins), cells=tuple(reply.cells)
    )


def _unreadable(name: str, what: str) -> FileVerdict:
    return FileVerdict(
        "error",
        f"{name} cannot be read: {what}. A notebook of ordinary cells reads in well under a second; "
        "look for a cell that is enormous or nests brackets or expressions thousands deep, remove it, save the notebook and submit again (or submit your code as a .py file).",  # noqa: E501
    )


def _death(returncode: int, stderr: bytes) -> str:
    if returncode < 0 and -returncode in (signal_number("SIGXCPU"), signal_number("SIGKILL")):
        return f"reading it used more than {CPU_SECONDS} seconds of CPU"
    if b"MemoryError" in stderr[-2000:]:
        return f"reading it needed more than {MEMORY_BYTES // 2**20:,} MiB of memory"
    if returncode < 0:
        return f"the reader crashed on it (signal {-returncode})"
    return f"the reader failed on it (exit status {returncode})"


def _limit_self() -> None:
    sys.setrecursionlimit(RECURSION_LIMIT)
    if not HOST.has(Feature.RESOURCE_LIMITS):
        return
    resource = importlib.import_module("resource")
    limits = {"RLIMIT_CORE": (0, 0), "RLIMIT_AS": (MEMORY_BYTES, MEMORY_BYTES)}
    limits["RLIMIT_CPU"] = (CPU_SECONDS, CPU_SECONDS + 1)
    for name, values in limits.items():
        try:
            resource.setrlimit(getattr(resource, name), values)
        except (ValueError, OSError):  # macOS refuses some address-space limits; Linux has every one
            if HOST.has(Feature.LINUX_KERNEL):
                raise


def _main() -> None:
    _limit_self()
    from grader.notebook.building import build_module as build_in_process

    raw = sys.stdin.buffer.read()
    header_line, _, data = raw.partition(b"\n")
    header = json.loads(header_line)
    name, graded = str(header["name"]), header["graded"]
    try:
        built = build_in_process(data, name, graded)
    except RecursionError:
        built = FileVerdict("error", _unreadable_message(name, "its code nests too deeply for the reader"))
    except MemoryError:
        built = FileVerdict(
            "error",
            _unreadable_message(name, f"reading it needed more than {MEMORY_BYTES // 2**20:,} MiB of memory"),
        )
    if isinstance(built, FileVerdict):
        reply = _Reply(status=built.status, message=built.message)
    else:
        reply = _Reply(
            status="module",
            source=built.source,
            summary=built.summary,
            origins=list(built.origins),
            cells=list(built.cells),
        )
    sys.stdout.buffer.write(reply.model_dump_json().encode("utf-8"))


def _unreadable_message(name: str, what: str) -> str:
    return _unreadable(name, what).message


if __name__ == "__main__":
    try:
        _main()
    except MemoryError:
        traceback.print_exc(limit=1)
        sys.exit(3)
