"""Read a notebook (untrusted bytes) in a child process bounded in CPU time, memory and wall time.

Python's parser, ``json``, ``symtable`` and the reduction of `grader.submission.notebook.building` are all
recursive and allocate in proportion to their input: a cell of ten thousand nested brackets raises
``RecursionError``, a crafted file can ask for gigabytes. None of that may reach the trusted parent (a
``gymgrade grade`` batch grades every other file), so the parent only spawns ``python -m
grader.submission.notebook.bounded``, sends the bytes, and validates the reply; whatever goes wrong in the
child (an exception, a limit, a crash) becomes that submission's verdict with a message saying what to fix.
The CPU and memory limits are set where the system has them (`grader.sandbox.host`); elsewhere (Windows) the
wall-clock limit and the recursion limit bound the reader.

The child is the only place a notebook's JSON is parsed. What it read (the code cells, with the notes on
what was ignored) comes back with its reply and is kept in the parent by the bytes' digest, so edition
detection, grading and similarity ask `read_notebook` and parse a notebook once per process: grading
sends the kept cells (a few kilobytes) to the child that builds the module, not the file again.
"""

from __future__ import annotations

import hashlib
import importlib
import json
import os
import subprocess
import sys
import threading
import traceback
from collections import OrderedDict
from collections.abc import Collection
from pathlib import Path
from typing import Literal

from pydantic import BaseModel, ConfigDict, ValidationError

from grader.sandbox.host import HOST, Feature, signal_number
from grader.submission.notebook.models import NotebookModule, NotebookSummary
from grader.submission.notebook.reading import MAX_NOTEBOOK_BYTES, Cell, NotebookCells
from grader.submission.validation import FileVerdict

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
ROOT = Path(__file__).resolve().parents[3]
KEPT_CHARACTERS = 32_000_000
"""Characters of code cells the parent keeps of the notebooks it read (an honest lab notebook has tens of
thousands; the least recently used are dropped first, and read again by a child if asked for)."""


class _Read(BaseModel):
    """What the child read of a notebook: its code cells (number, In [n], source) and the ignored notes."""

    model_config = ConfigDict(extra="forbid")

    code: list[tuple[int, int | None, str]]
    ignored: list[str]

    @classmethod
    def of(cls, read: NotebookCells) -> _Read:
        code = [(cell.number, cell.execution_count, cell.source) for cell in read.cells]
        return cls(code=code, ignored=read.ignored)

    def cells(self) -> NotebookCells:
        return NotebookCells([Cell(*cell) for cell in self.code], list(self.ignored))


class _Reply(BaseModel):
    """What the child prints: the module built, or the verdict."""

    model_config = ConfigDict(extra="forbid")

    status: Literal["module", "read", "missing", "error", "as_is"]
    message: str = ""
    source: str = ""
    summary: NotebookSummary | None = None
    origins: list[tuple[int, int] | None] = []
    cells: list[tuple[int, str]] = []
    read: _Read | None = None
    """The notebook as read, whatever became of the module (None: the file itself was refused)."""


class _Kept:
    """The notebooks this process read, by digest of their bytes and name: cells, or the reading's verdict
    (similarity reads a batch's files in threads, hence the lock)."""

    def __init__(self, characters: int) -> None:
        self.characters = characters
        self.entries: OrderedDict[tuple[bytes, str], NotebookCells | FileVerdict] = OrderedDict()
        self.size = 0
        self.lock = threading.Lock()

    def get(self, key: tuple[bytes, str]) -> NotebookCells | FileVerdict | None:
        with self.lock:
            found = self.entries.get(key)
            if found is not None:
                self.entries.move_to_end(key)
            return found

    def put(self, key: tuple[bytes, str], read: NotebookCells | FileVerdict) -> None:
        with self.lock:
            if key in self.entries:
                return
            self.entries[key] = read
            self.size += _characters(read)
            while self.size > self.characters and self.entries:
                _, dropped = self.entries.popitem(last=False)
                self.size -= _characters(dropped)


def _characters(read: NotebookCells | FileVerdict) -> int:
    if isinstance(read, FileVerdict):
        return len(read.message)
    return sum(len(cell.source) for cell in read.cells) + sum(len(note) for note in read.ignored)


_KEPT = _Kept(KEPT_CHARACTERS)


def read_notebook(data: bytes, name: str) -> NotebookCells | FileVerdict:
    """A notebook's code cells, read once per process in a bounded child (what edition detection and
    similarity compare; `build_module` reuses it).

    Args:
        data: The ``.ipynb`` file's bytes (untrusted).
        name: Its file name, used in messages.

    Returns:
        The code cells and the notes on what was ignored, or the verdict saying why the file cannot be
        read (the one grading gives it).
    """
    key = _key(data, name)
    kept = _KEPT.get(key)
    if kept is not None:
        return kept
    reply = _run(data, name, {"mode": "read"})
    # A file the reader died on is kept too: grading and similarity give it the same verdict at once.
    read = reply if isinstance(reply, FileVerdict) else _as_read(reply)
    _KEPT.put(key, read)
    return read


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
    key = _key(data, name)
    kept = _KEPT.get(key)
    if isinstance(kept, FileVerdict):
        return kept
    mode: dict[str, object] = {"mode": "module", "graded": None if graded is None else sorted(graded)}
    if kept is None:
        reply = _run(data, name, mode)
    else:
        reply = _run(_Read.of(kept).model_dump_json().encode(), name, {**mode, "input": "read"})
    if isinstance(reply, FileVerdict):
        return reply
    if kept is None:
        _KEPT.put(key, _as_read(reply))
    if reply.status != "module" or reply.summary is None:
        return FileVerdict(_status(reply), reply.message)
    return NotebookModule(
        source=reply.source, summary=reply.summary, origins=tuple(reply.origins), cells=tuple(reply.cells)
    )


def build_script(
    data: bytes, name: str, graded: Collection[str], served: Collection[str] = ()
) -> NotebookModule | FileVerdict | None:
    """A `.py` read as the notebook it may have been, in a bounded child
    (`grader.submission.notebook.script.build_script`).

    Args:
        data: The file's bytes (untrusted, UTF-8 Python: `check_source` passed).
        name: Its name, in messages.
        graded: The functions problems call.
        served: Those whose globals the file's cells set before they are called.

    Returns:
        The module, None when the file is graded as it is, or a verdict (the module is not Python, or the
        reader died on the file: the caller may grade the file as it is).
    """
    request: dict[str, object] = {"mode": "script", "graded": sorted(graded), "served": sorted(served)}
    reply = _run(data, name, request)
    if isinstance(reply, FileVerdict):
        return reply
    if reply.status == "as_is":
        return None
    if reply.status != "module" or reply.summary is None:
        return FileVerdict(_status(reply), reply.message)
    return NotebookModule(
        source=reply.source, summary=reply.summary, origins=tuple(reply.origins), cells=tuple(reply.cells)
    )


def _key(data: bytes, name: str) -> tuple[bytes, str]:
    return hashlib.blake2b(data, digest_size=20).digest(), name


def _as_read(reply: _Reply) -> NotebookCells | FileVerdict:
    """What a reply says of the notebook as read: its cells, or the verdict on the file."""
    return reply.read.cells() if reply.read is not None else FileVerdict(_status(reply), reply.message)


def _status(reply: _Reply) -> Literal["missing", "error"]:
    return "missing" if reply.status == "missing" else "error"


def _run(data: bytes, name: str, request: dict[str, object]) -> _Reply | FileVerdict:
    """Run the reading child on ``data`` (a notebook, or cells already read); its reply, or the verdict
    when it died, ran out of time or answered nonsense."""
    if len(data) > MAX_NOTEBOOK_BYTES:
        return FileVerdict(
            "error",
            f"{name} is {len(data):,} bytes; a notebook may be at most {MAX_NOTEBOOK_BYTES:,} bytes. "
            "Clear its outputs (Kernel > Restart & Clear Output) and submit again.",
        )
    # The request travels as an argument, so the notebook's bytes are piped as they are (never copied).
    header = json.dumps({"name": name, **request})
    try:
        completed = subprocess.run(
            [sys.executable, "-m", "grader.submission.notebook.bounded", header],
            input=data,
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
        return _Reply.model_validate_json(completed.stdout)
    except ValidationError:
        return _unreadable(name, "the reader's reply was not understood")


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
    from grader.submission.notebook.building import build_from_cells
    from grader.submission.notebook.ipython import TransformerUnavailable
    from grader.submission.notebook.reading import read_cells

    header = json.loads(sys.argv[1])
    data = sys.stdin.buffer.read()
    name, graded = str(header["name"]), header.get("graded")
    built: NotebookModule | FileVerdict | None = None
    read: NotebookCells | FileVerdict | None = None
    if header["mode"] == "script":
        from grader.submission.notebook.script import build_script as build_script_module

        try:
            script = build_script_module(data, name, graded, header.get("served", []))
        except TransformerUnavailable as error:
            script = FileVerdict("error", _no_transformer_message(name, str(error)))
        except (RecursionError, MemoryError, SyntaxError, ValueError) as error:
            script = FileVerdict(
                "error", _unreadable_message(name, f"{type(error).__name__} while reading it")
            )
        reply = _reply(None, script) if script is not None else _Reply(status="as_is")
        sys.stdout.buffer.write(reply.model_dump_json().encode("utf-8"))
        return
    try:
        if header.get("input") == "read":
            read = _Read.model_validate_json(data).cells()
        else:
            read = read_cells(data, name)
        if header["mode"] == "module" and not isinstance(read, FileVerdict):
            built = build_from_cells(read, name, graded)
    except TransformerUnavailable as error:  # the grader's installation, not the notebook: said so
        built = FileVerdict("error", _no_transformer_message(name, str(error)))
    except RecursionError:
        built = FileVerdict("error", _unreadable_message(name, "its code nests too deeply for the reader"))
    except MemoryError:
        built = FileVerdict(
            "error",
            _unreadable_message(name, f"reading it needed more than {MEMORY_BYTES // 2**20:,} MiB of memory"),
        )
    reply = _reply(read, built)
    sys.stdout.buffer.write(reply.model_dump_json().encode("utf-8"))


def _reply(read: NotebookCells | FileVerdict | None, built: NotebookModule | FileVerdict | None) -> _Reply:
    kept = _Read.of(read) if isinstance(read, NotebookCells) else None
    if isinstance(built, NotebookModule):
        return _Reply(
            status="module",
            source=built.source,
            summary=built.summary,
            origins=list(built.origins),
            cells=list(built.cells),
            read=kept,
        )
    verdict = built if built is not None else read
    if isinstance(verdict, FileVerdict):
        return _Reply(status=verdict.status, message=verdict.message, read=kept)
    return _Reply(status="read", read=kept)


def _unreadable_message(name: str, what: str) -> str:
    return _unreadable(name, what).message


def _no_transformer_message(name: str, what: str) -> str:
    return (
        f"{name} cannot be read: the grader could not load IPython's input transformer ({what}). "
        "It reads the %magics and !commands of notebook cells; this is a fault of the grader's installation, not of your notebook. "  # noqa: E501
        "Tell the course staff; a .py file of your code is graded meanwhile."
    )


if __name__ == "__main__":
    try:
        _main()
    except MemoryError:
        traceback.print_exc(limit=1)
        sys.exit(3)
