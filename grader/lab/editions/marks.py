"""What a submission shows of the lab and edition it was written for, read statically (never run).

The source is untrusted: it is read up to a bound without following links, parsed with `ast` only (nothing
is executed or imported), and a file that cannot be read or parsed shows no mark. A notebook's code cells come
from the bounded reader (`grader.submission.notebook.read_notebook`: its JSON is never parsed here).

`Marks` is what every lab's rules read (`grader.lab.labs.Lab.detect`): the functions the file defines with
their parameters, the modules it imports, its name, and whether it unpacks gym 0.26's five-value `step` or
two-value `reset`. A rule answers with a `Detection`.
"""

from __future__ import annotations

import ast
from dataclasses import dataclass
from pathlib import Path

from grader import parsing
from grader.lab.editions.pack import Edition
from grader.submission.notebook import MAX_NOTEBOOK_BYTES, is_notebook, read_notebook
from grader.submission.untrusted_file import UnsafeFile, read_untrusted
from grader.submission.validation import MAX_SUBMISSION_BYTES, FileVerdict


@dataclass(frozen=True)
class Detection:
    """The edition a submission was detected as, and why (one sentence a person reads).

    `shown` is False for a file that shows no edition's mark (it is then taken as its lab's default edition);
    `lab_shown` is False for a file that shows no lab either (empty, unreadable, none of any lab's functions
    or imports): a class's choice counts neither.
    """

    edition: Edition
    reason: str
    shown: bool = True
    lab_shown: bool = True

    def __post_init__(self) -> None:
        if self.shown and not self.lab_shown:
            raise ValueError(f"a file showing edition {self.edition.name} shows its lab {self.edition.lab}")


@dataclass(frozen=True)
class Signature:
    """A function the file defines at top level: its parameters in order and how many have no default."""

    name: str
    parameters: tuple[str, ...]
    required: int

    @property
    def text(self) -> str:
        """`name(p1, p2)`, as a reason names it."""
        return f"{self.name}({', '.join(self.parameters)})"


@dataclass(frozen=True)
class Marks:
    """What a file shows: its top-level functions, the top-level modules it imports, its name, and whether
    it unpacks gym 0.26's five-value `step` / two-value `reset`. `readable` is False when it could not be
    read or parsed at all (it then shows nothing)."""

    name: str
    functions: dict[str, Signature]
    imports: frozenset[str]
    new_gym_api: bool
    readable: bool = True


def read_marks(path: Path, name: str | None = None) -> Marks:
    """The marks of a `.py` or `.ipynb` submission (read without following links, within bounds), named
    ``name`` (the file's own name, where its copy on disk is numbered) or ``path.name``."""
    return _marks(_parse(path), name or path.name)


def source_marks(source: bytes, name: str) -> Marks:
    """The marks of Python source already read (a `.py` file's bytes, or the module built from a notebook's
    cells), bounded as `read_marks` bounds a file."""
    if len(source) > MAX_SUBMISSION_BYTES:
        return _marks(None, name)
    return _marks(_parsed([source]), name)


def _marks(trees: list[ast.Module] | None, name: str) -> Marks:
    if not trees:
        return Marks(name, {}, frozenset(), new_gym_api=False, readable=False)
    functions = {
        node.name: _signature(node)
        for tree in trees
        for node in tree.body
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)
    }
    imports = frozenset(name for tree in trees for name in _imported(tree))
    return Marks(name, functions, imports, new_gym_api=any(_new_gym_api(tree) for tree in trees))


def _parse(path: Path) -> list[ast.Module] | None:
    notebook = is_notebook(path.name)
    limit = MAX_NOTEBOOK_BYTES if notebook else MAX_SUBMISSION_BYTES
    try:
        data = read_untrusted(path, limit=limit)
    except UnsafeFile:
        return None
    if len(data) > limit:
        return None
    sources = _notebook_cells(data, path.name) if notebook else [data]
    if sources is None or sum(len(source) for source in sources) > MAX_SUBMISSION_BYTES:
        return None
    return _parsed(sources)


def _parsed(sources: list[bytes]) -> list[ast.Module]:
    trees: list[ast.Module] = []
    for source in sources:
        try:
            trees.append(parsing.parse(source))
        except (SyntaxError, ValueError, RecursionError, MemoryError):
            continue  # a cell with IPython syntax or a broken cell: the others still count
    return trees


def _notebook_cells(data: bytes, name: str) -> list[bytes] | None:
    read = read_notebook(data, name)
    if isinstance(read, FileVerdict):
        return None
    sources: list[bytes] = []
    for cell in read.cells:
        lines = [line for line in cell.source.splitlines() if not line.lstrip().startswith(("%", "!"))]
        sources.append("\n".join(lines).encode("utf-8", "replace"))
    return sources


def _signature(node: ast.FunctionDef | ast.AsyncFunctionDef) -> Signature:
    positional = [*node.args.posonlyargs, *node.args.args]
    names = tuple(argument.arg for argument in [*positional, *node.args.kwonlyargs])
    required = len(positional) - len(node.args.defaults)
    return Signature(node.name, names, required)


def _imported(tree: ast.Module) -> set[str]:
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            names.add(node.module.split(".")[0])
    return names


def _new_gym_api(tree: ast.Module) -> bool:
    for node in ast.walk(tree):
        if not isinstance(node, ast.Assign) or not isinstance(node.value, ast.Call):
            continue
        function = node.value.func
        method = function.attr if isinstance(function, ast.Attribute) else None
        for target in node.targets:
            if isinstance(target, ast.Tuple) and (
                (method == "step" and len(target.elts) == 5) or (method == "reset" and len(target.elts) == 2)
            ):
                return True
    return False
