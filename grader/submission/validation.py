"""Checks a submission file must pass before any of it runs: size, text, UTF-8, Python syntax."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

MAX_SUBMISSION_BYTES = 1_000_000
"""The lab's solution is a few hundred lines; anything past a megabyte is not a hand-written answer."""


@dataclass(frozen=True)
class FileVerdict:
    """Why a file cannot be graded.

    Attributes:
        status: ``missing`` when there is nothing to grade (empty file), ``error`` otherwise.
        message: What was expected, what was found and what to do.
    """

    status: Literal["missing", "error"]
    message: str


def check_source(data: bytes, name: str, *, max_bytes: int = MAX_SUBMISSION_BYTES) -> FileVerdict | None:
    """Decide whether a file's bytes are a gradable Python source, without executing any of it.

    ``compile()`` only parses and builds bytecode, so it is safe to run on untrusted text in the parent.

    Args:
        data: The file's bytes.
        name: The file name, used in messages.
        max_bytes: Largest size accepted.

    Returns:
        None when the file is UTF-8 Python that compiles, else the verdict explaining why not.
    """
    if len(data) > max_bytes:
        return FileVerdict(
            "error",
            f"{name} is {len(data):,} bytes; a submission may be at most {max_bytes:,} bytes. "
            "Submit only your solution's .py file.",
        )
    if not data.strip():
        return FileVerdict(
            "missing",
            f"{name} is empty: nothing to grade. "
            "Submit the .py file holding your functions (random_blackjack, blackjack, cartpole, car, taxi).",
        )
    nul = data.find(b"\0")
    if nul >= 0:
        return FileVerdict(
            "error",
            f"{name} is not a text file (it contains a NUL byte at offset {nul}): "
            "submit the Python source (.py), not a notebook export, archive or compiled file.",
        )
    try:
        data.decode("utf-8")
    except UnicodeDecodeError as error:
        line = data[: error.start].count(b"\n") + 1
        return FileVerdict(
            "error",
            f"{name} is not UTF-8 text: byte 0x{data[error.start]:02x} on line {line} cannot be decoded. "
            "Save the file as UTF-8 in your editor and submit again.",
        )
    try:
        compile(data, name, "exec", dont_inherit=True)  # bytes, so a BOM is read exactly as import reads it
    except SyntaxError as error:
        where = f"line {error.lineno}" + (f", column {error.offset}" if error.offset else "")
        return FileVerdict(
            "error",
            f"{name} is not valid Python: {error.msg} ({where}). "
            f"Fix the syntax (`python -m py_compile {name}` shows it) and submit again.",
        )
    except (ValueError, RecursionError, MemoryError, OverflowError) as error:
        return FileVerdict(
            "error",
            f"{name} could not be compiled as Python ({type(error).__name__}: {error}). "
            "Simplify the offending expression and submit again.",
        )
    return None
