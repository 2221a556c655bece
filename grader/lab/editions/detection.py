"""Which edition a submission was written for, read statically from its source (never run) in the parent.

The source is untrusted: it is read up to a bound without following links, parsed with `ast` only (nothing
is executed or imported), and a file that cannot be read or parsed simply shows no marker. A notebook's code
cells come from the bounded reader (`grader.submission.notebook.read_notebook`: its JSON is never parsed
here).

The rules, newest edition first, each with the reason the command line prints:

1. a function only the current edition asks for (`epsilon_decay`, `qlearn`, `sarsa0`, `compare`), or a
   `taxi` with two required parameters: `rl1`;
2. `cartpole`/`car` with a `render` parameter, or `import gymnasium`: `volume2`;
3. `import gym_toytext`, or gym 0.26's five-value `step` / two-value `reset` unpacking: `gym026`;
4. `import gym` with none of the above: `classic`;
5. otherwise the file shows no edition (`Detection.shown` is False: an empty file, one that cannot be read or
   parsed, one defining a shared function and importing no gym); it is taken as the first edition, `classic`,
   but a class's choice does not count it.

Editions 1-3 grade the same problems (the compatibility layer runs every gym API), so telling them apart
only names the edition; rule 1 changes what is graded. Detection chooses the edition of a student's own
`check`; grading for a gradebook grades the edition the instructor chose, and `edition_note` tells a file
written for other problems so.
"""

from __future__ import annotations

import ast
from dataclasses import dataclass
from pathlib import Path

from grader.lab.editions.classic import CLASSIC
from grader.lab.editions.gym026 import GYM026
from grader.lab.editions.pack import Edition
from grader.lab.editions.rl1 import RL1
from grader.lab.editions.volume2 import VOLUME2
from grader.submission.notebook import MAX_NOTEBOOK_BYTES, is_notebook, read_notebook
from grader.submission.untrusted_file import UnsafeFile, read_untrusted
from grader.submission.validation import MAX_SUBMISSION_BYTES, FileVerdict


@dataclass(frozen=True)
class Detection:
    """The edition a submission was detected as, and why (one sentence a person reads).

    `shown` is False for a file that shows no edition's mark (it is then taken as the first edition).
    """

    edition: Edition
    reason: str
    shown: bool = True


@dataclass(frozen=True)
class _Function:
    name: str
    parameters: tuple[str, ...]
    required: int


def detect_edition(path: Path) -> Detection:
    """The edition of a `.py` or `.ipynb` submission, from the functions it defines and what it imports."""
    return _detected(_parse(path), path.name)


def detect_source(source: bytes, name: str) -> Detection:
    """The edition of Python source already read (a `.py` file's bytes, or the module built from a
    notebook's cells), bounded as `detect_edition` bounds a file."""
    if len(source) > MAX_SUBMISSION_BYTES:
        return _detected(None, name)
    return _detected(_parsed([source]), name)


def _detected(trees: list[ast.Module] | None, name: str) -> Detection:
    if trees is None or not trees:
        return Detection(CLASSIC, f"{name} could not be read as Python, so it shows no edition", shown=False)
    functions = {
        node.name: _signature(node)
        for tree in trees
        for node in tree.body
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)
    }
    imports = {name for tree in trees for name in _imported(tree)}
    other_names = {function.name for edition in (CLASSIC, GYM026, VOLUME2) for function in edition.functions}
    only_rl1 = [
        function for name, function in functions.items() if name not in other_names and RL1.function(name)
    ]
    if only_rl1:
        names = ", ".join(f"{function.name}({', '.join(function.parameters)})" for function in only_rl1)
        return Detection(RL1, f"it defines {names}, which only edition {RL1.number} ({RL1.title}) asks for")
    taxi = functions.get("taxi")
    if taxi is not None and taxi.required >= 2:
        return Detection(
            RL1, f"its taxi({', '.join(taxi.parameters)}) takes two tables, as only edition {RL1.number} asks"
        )
    rendered = [
        name for name in ("cartpole", "car") if name in functions and "render" in functions[name].parameters
    ]
    if rendered:
        return Detection(
            VOLUME2,
            f"its {' and '.join(f'{name}(render=...)' for name in rendered)} take a render flag, as editions "
            f"{VOLUME2.number} and {RL1.number} write them, and it defines none of edition {RL1.number}'s new functions",  # noqa: E501
        )
    if "gymnasium" in imports:
        return Detection(VOLUME2, "it imports gymnasium and defines none of edition 4's new functions")
    if "gym_toytext" in imports:
        return Detection(GYM026, "it imports gym_toytext, as the gym 0.26 notebook does")
    if "gym" in imports and any(_new_gym_api(tree) for tree in trees):
        return Detection(
            GYM026, "it imports gym and unpacks the five values of gym 0.26's step (or reset's two)"
        )
    if "gym" in imports:
        return Detection(
            CLASSIC,
            "it imports gym and shows no mark of a later edition (their functions, render flags or APIs)",
        )
    return Detection(
        CLASSIC,
        "it shows no edition: it imports no gym and defines none of a later edition's functions or render flags",  # noqa: E501
        shown=False,
    )


def edition_note(graded: Edition, found: Detection) -> str | None:
    """What a report tells a file written for other problems than the edition graded (None: it is not).

    Editions grading the same problems (1-3) are not told: the compatibility layer runs each one's API.
    """
    if not found.shown or found.edition.registry is graded.registry:
        return None
    return (
        f"This file looks written for edition {found.edition.number} ({found.edition.name}, "
        f"{found.edition.title}): {found.reason}. Your assignment is edition {graded.number} ({graded.name}, "
        f"{graded.title}), so it was graded on that edition's problems; check the assignment's template."
    )


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
            trees.append(ast.parse(source))
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


def _signature(node: ast.FunctionDef | ast.AsyncFunctionDef) -> _Function:
    positional = [*node.args.posonlyargs, *node.args.args]
    names = tuple(argument.arg for argument in [*positional, *node.args.kwonlyargs])
    required = len(positional) - len(node.args.defaults)
    return _Function(node.name, names, required)


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
