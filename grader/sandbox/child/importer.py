"""Import the student's file as module "submission" and describe failures with the student's frames only."""

from __future__ import annotations

import importlib.util
import inspect
import sys
import traceback
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType, TracebackType
from typing import Any

MODULE_NAME = "submission"
MAX_LISTED_NAMES = 500
MAX_LISTED_PARAMETERS = 64
MAX_NAME_LENGTH = 200
MAX_TEXT = 20_000


@dataclass(frozen=True)
class ImportFailure:
    """Why the submission could not be imported: a one-line message and the student's traceback."""

    message: str
    traceback: str


def import_submission(path: Path, name: str | None = None) -> ModuleType | ImportFailure:
    """Execute the file at `path` as module "submission" (so `if __name__ == "__main__":` is skipped).

    Returns the module, or an `ImportFailure` whose traceback starts at the student's file; its message
    names the file `name` (the file's own name as the grader shows it: the sandbox's copy may be numbered),
    `path.name` when None.
    `SystemExit` is not caught: exiting at import ends the child and the runner reports it.
    Any other exception, `KeyboardInterrupt` and student-defined `BaseException`s included, fails.
    """
    shown = name or path.name
    spec = importlib.util.spec_from_file_location(MODULE_NAME, path)
    if spec is None or spec.loader is None:
        return ImportFailure(f"{shown} cannot be loaded as a Python module", "")
    module = importlib.util.module_from_spec(spec)
    sys.modules[MODULE_NAME] = module
    try:
        spec.loader.exec_module(module)
    except SystemExit:
        raise
    except BaseException as error:  # KeyboardInterrupt or a BaseException subclass raised by the student
        sys.modules.pop(MODULE_NAME, None)
        if isinstance(error, SyntaxError) and error.filename == str(path):
            detail = "".join(traceback.format_exception_only(type(error), error))
            return ImportFailure(
                shortened(f"{shown} is not valid Python: {error.msg} (line {error.lineno})"),
                shortened(_renamed(detail, path, name)),
            )
        return ImportFailure(
            shortened(f"importing {shown} raised {describe_exception(error)}"),
            shortened(student_traceback(error, path, name)),
        )
    return module


def _renamed(text: str, path: Path, name: str | None) -> str:
    """A traceback's frames in the file shown as ``name`` (in the file's folder), not as its copy's name."""
    return text.replace(f'File "{path}"', f'File "{path.parent}/{name}"') if name else text


MISSING_MODULE_HINT = (
    "; the grader has no module `{name}`: "
    "use the packages your course provides, or ask your instructor to add it; "
    "instructors install the package into the grader's Python (for example in pyproject.toml's dependencies) and list `{name}` in [sandbox] student_modules of the assignment (docs/operations.md)"  # noqa: E501
)


def describe_exception(error: BaseException) -> str:
    """`TypeName: message`, the last line of a traceback (with how to get a missing module added)."""
    line = "".join(traceback.format_exception_only(type(error), error)).strip().splitlines()[-1]
    name = getattr(error, "name", None) if isinstance(error, ModuleNotFoundError) else None
    if isinstance(name, str) and name.partition(".")[0].isidentifier():
        line += MISSING_MODULE_HINT.format(name=name.partition(".")[0])
    return line


def student_traceback(error: BaseException, path: Path, name: str | None = None) -> str:
    """Format `error`'s traceback starting at the first frame in the student's file, its frames there
    naming the file `name` (its own name as the grader shows it), `path.name` when None.

    Frames above it (the harness, importlib) are dropped; frames below it (libraries the student
    called) are kept. Without a frame in the student's file only the outermost (harness) frame
    is dropped.
    """
    tb = _first_student_frame(error.__traceback__, str(path))
    formatted = "".join(traceback.format_exception(type(error), error.with_traceback(tb), tb))
    return _renamed(formatted, path, name)


def function_table(module: ModuleType) -> dict[str, dict[str, Any]]:
    """Public top-level names of the module with their call signatures, for the `ready` frame."""
    table: dict[str, dict[str, Any]] = {}
    for name, value in list(vars(module).items()):
        listed = type(name) is str and not name.startswith("_") and len(name) <= MAX_NAME_LENGTH
        if not listed or type(value) is ModuleType:
            continue
        if len(table) >= MAX_LISTED_NAMES:
            break
        table[name] = {"parameters": parameter_list(value), "is_callable": callable(value)}
    return table


def parameter_list(value: Any) -> list[dict[str, Any]]:
    """The parameters of a callable as plain data (empty when not callable or not inspectable)."""
    if not callable(value):
        return []
    try:
        signature = inspect.signature(value)
    except Exception:  # builtins without a signature, or student objects whose __signature__ fails
        return []
    return [
        {
            "name": parameter.name[:MAX_NAME_LENGTH],
            "kind": parameter.kind.name,
            "has_default": parameter.default is not inspect.Parameter.empty,
        }
        for parameter in list(signature.parameters.values())[:MAX_LISTED_PARAMETERS]
    ]


def shortened(text: str) -> str:
    """`text`, or its beginning and end if it is longer than `MAX_TEXT` characters."""
    if len(text) <= MAX_TEXT:
        return text
    half = MAX_TEXT // 2
    return f"{text[:half]}\n... ({len(text) - 2 * half} characters left out) ...\n{text[-half:]}"


def _first_student_frame(tb: TracebackType | None, filename: str) -> TracebackType | None:
    current = tb
    while current is not None:
        if current.tb_frame.f_code.co_filename == filename:
            return current
        current = current.tb_next
    return tb.tb_next if tb is not None and tb.tb_next is not None else tb
