"""Which of a student's files is graded: the lab's file name, else the only candidate, else the one
defining the lab's functions; never a test file or a checkpoint. Each choice says why."""

from __future__ import annotations

import json
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import PurePosixPath

from grader.classroom.model import SubmittedFile

LAB_FILE_NAMES = (
    "opengym.py", "opengym.ipynb", "gymnasium.ipynb", "policy_iteration.py", "policy_function_iteration.py",
)  # fmt: skip
"""The labs' own file names, in order of preference: the first lab's (its text says opengym.py; the notebook
editions opengym.ipynb and gymnasium.ipynb), then the second lab's (policy_iteration.py; the 2026 template's
policy_function_iteration.py). `grader.lab.labs.Lab.file_names` declares them; a test holds this equal
(imported here without the packs, which a class's file choice does not need)."""
SOURCE_SUFFIXES = (".py", ".ipynb")
MAX_SCAN_BYTES = 4 * 2**20
_DEF = re.compile(r"^def\s+([A-Za-z_]\w*)\s*\(", re.MULTILINE)
_NUMBERED_COPY = re.compile(r"^(?P<stem>.+?)(?:-\d+| \(\d+\))(?P<suffix>\.[A-Za-z]+)$")


@dataclass(frozen=True)
class GradedFileRule:
    """The rule an assignment states for choosing the graded file.

    Attributes:
        names: The lab's file names, most preferred first.
        functions: The lab's function names (the enabled problems' ids), to recognise the file defining them.
    """

    names: tuple[str, ...] = LAB_FILE_NAMES
    functions: tuple[str, ...] = ()


def is_candidate(original_name: str) -> bool:
    """Whether a file may be graded: Python or a notebook, and not a test, conftest or checkpoint."""
    name = original_name.lower().rsplit("/", 1)[-1]
    if not name.endswith(SOURCE_SUFFIXES) or name.startswith("."):
        return False
    stem = PurePosixPath(name).stem
    return not (
        stem.startswith("test_")
        or stem.endswith("_test")
        or stem == "conftest"
        or stem.endswith("-checkpoint")
        or stem == "setup"
    )


def base_name(original_name: str) -> str:
    """The name without the copy number an LMS or a browser adds (``opengym-1.py``, ``opengym (2).py``)."""
    match = _NUMBERED_COPY.match(original_name)
    return f"{match['stem']}{match['suffix']}" if match else original_name


def defined_functions(data: bytes, *, notebook: bool) -> set[str]:
    """Names of the top-level functions a file's text defines (notebooks: in their code cells)."""
    text = data[:MAX_SCAN_BYTES].decode("utf-8", errors="replace")
    if notebook:
        try:
            cells = json.loads(text).get("cells", [])
            text = "\n".join(
                "".join(cell.get("source", ""))
                if isinstance(cell.get("source"), list)
                else str(cell.get("source", ""))
                for cell in cells
                if isinstance(cell, dict) and cell.get("cell_type") == "code"
            )
        except (ValueError, AttributeError, TypeError):
            text = text.replace("\\n", "\n").replace('"def ', "def ")
    return set(_DEF.findall(text))


def choose(files: Sequence[SubmittedFile], rule: GradedFileRule) -> tuple[SubmittedFile | None, str]:
    """The graded file of a submission and why (or None and why none can be chosen).

    Args:
        files: Every file of the submission.
        rule: The assignment's rule.

    Returns:
        The chosen file (None when there is no candidate or the choice is ambiguous) and a sentence.
    """
    candidates = [file for file in files if is_candidate(file.original_name)]
    if not candidates:
        return None, "no .py or .ipynb file to grade (test files and checkpoints are never graded)"
    for name in rule.names:
        named = [file for file in candidates if base_name(_leaf(file.original_name)).lower() == name]
        if named:
            shallowest = min(len(file.relative.split("/")) for file in named)
            top = [file for file in named if len(file.relative.split("/")) == shallowest]
            if len(top) == 1:
                return top[0], f"named {name}, the lab's file name"
            return None, f"{len(top)} files are named {name} at the same depth ({_listing(top)}): keep one"
    if len(candidates) == 1:
        return candidates[0], f"the only .py/.ipynb file ({_others(files, candidates[0])})"
    defined = {
        file: len(
            defined_functions(_read(file), notebook=file.original_name.lower().endswith(".ipynb"))
            & set(rule.functions)
        )
        for file in candidates
    }
    best = max(defined.values())
    leaders = [file for file in candidates if defined[file] == best]
    if best == 0:
        return (
            None,
            f"none of {_listing(candidates)} defines the lab's functions ({', '.join(rule.functions)}) or is named {' / '.join(rule.names)}",  # noqa: E501
        )
    if len(leaders) > 1:
        return (
            None,
            f"{_listing(leaders)} each define {best} of the lab's functions: rename the one to grade {rule.names[0]}",  # noqa: E501
        )
    return (
        leaders[0],
        f"defines {best} of the lab's {len(rule.functions)} functions, more than {_listing([f for f in candidates if f is not leaders[0]])}",  # noqa: E501
    )


def _leaf(name: str) -> str:
    return name.rsplit("/", 1)[-1]


def _read(file: SubmittedFile) -> bytes:
    try:
        with file.path.open("rb") as stream:
            return stream.read(MAX_SCAN_BYTES)
    except OSError:
        return b""


def _listing(files: Sequence[SubmittedFile]) -> str:
    return ", ".join(file.original_name for file in files)


def _others(files: Sequence[SubmittedFile], chosen: SubmittedFile) -> str:
    others = [file for file in files if file is not chosen]
    return f"besides {len(others)} other file{'s' if len(others) != 1 else ''}" if others else "nothing else"
