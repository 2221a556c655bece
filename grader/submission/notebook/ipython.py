"""Read a cell the way IPython does before Python sees it: IPython's own input transformations.

IPython's ``IPython.core.inputtransformer2`` turns ``%magic``, ``%%cell magic``, ``!shell``, ``x = !cmd``,
``obj?``, ``,autocall`` and prompts pasted from a console into Python that calls ``get_ipython()``; its
prefilter's automagic does the same to a one-line cell such as ``pip install gym``. The grader runs none of
those commands, so each such line becomes ``pass`` (same indentation, same line numbers) and is listed as
skipped. What counts as special is IPython's: its cleanup transforms (leading indent, ``>>>`` and ``In [n]:``
prompts), its cell-magic test, its grouping of tokens by logical line (``make_tokens_by_line``) and each of
its token transformers' ``find`` (MagicAssign, SystemAssign, EscapedCommand, HelpEnd, in its priority
order; a help request is one only when HelpEnd's own ``transform`` accepts it). Two things are ours:

- the driver: ``TransformerManager.transform_cell`` re-tokenizes the whole cell after each special line
  (quadratic, and it gives up after 500), so every logical line of one tokenization is asked, and another
  pass runs only when a special line stopped the tokenizer (an unclosed quote in a shell command);
- automagic (`_automagic`, `LINE_MAGICS`): a rule of IPython's prefilter, which needs a running shell.

IPython's module is loaded alone (`load_transformer`), not imported: ``import IPython.core.inputtransformer2``
runs ``IPython/__init__.py``, which imports the terminal, pexpect and, on a POSIX ``sys.platform``, ``pty``
(the Windows-shaped interpreter of tests/grader/test_portable.py has none, and every notebook failed there):
542 modules and 0.24 s of CPU, against one module and 2 ms loaded alone (bench/ipython_transformer.py;
bench/RESULTS.md, "IPython's transformer loaded alone"). Its imports are the standard library and, from
IPython 8.15 on, ``IPython.utils.tokenutil`` (standard library only), loaded alone the same way; any other
import is refused, and tests/grader/submission/notebook/test_ipython.py fails when an installed IPython
grows one. This runs in the notebook reader's bounded child only (`grader.submission.notebook.bounded`),
where a failure to load becomes the notebook's verdict (`TransformerUnavailable`), never the batch's.
"""

from __future__ import annotations

import ast
import builtins
import importlib.util
import keyword
import re
import sys
import tokenize
import types
from collections.abc import Container, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path
from typing import Any

from grader import parsing

ESCAPES = {"!": "shell command", "%": "IPython magic", "?": "help request", ",": "IPython autocall",
           ";": "IPython autocall", "/": "IPython autocall"}  # fmt: skip
"""What the line an escape starts is called in the report (IPython's ESCAPE_SINGLES; ``!!`` and ``??``
start with one of them)."""
LINE_MAGICS = frozenset(
    [
        "alias",
        "alias_magic",
        "autoawait",
        "autocall",
        "automagic",
        "autosave",
        "bookmark",
        "cat",
        "cd",
        "clear",
        "colors",
        "conda",
        "config",
        "connect_info",
        "cp",
        "debug",
        "dhist",
        "dirs",
        "doctest_mode",
        "ed",
        "edit",
        "env",
        "gui",
        "hist",
        "history",
        "killbgscripts",
        "ldir",
        "less",
        "lf",
        "lk",
        "ll",
        "load",
        "load_ext",
        "loadpy",
        "logoff",
        "logon",
        "logstart",
        "logstate",
        "logstop",
        "ls",
        "lsmagic",
        "lx",
        "macro",
        "magic",
        "man",
        "matplotlib",
        "mkdir",
        "more",
        "mv",
        "notebook",
        "page",
        "pastebin",
        "pdb",
        "pdef",
        "pdoc",
        "pfile",
        "pinfo",
        "pinfo2",
        "pip",
        "popd",
        "pprint",
        "precision",
        "prun",
        "psearch",
        "psource",
        "pushd",
        "pwd",
        "pycat",
        "pylab",
        "qtconsole",
        "quickref",
        "recall",
        "rehashx",
        "reload_ext",
        "rep",
        "rerun",
        "reset",
        "reset_selective",
        "rm",
        "rmdir",
        "run",
        "save",
        "sc",
        "set_env",
        "store",
        "sx",
        "system",
        "tb",
        "time",
        "timeit",
        "unalias",
        "unload_ext",
        "who",
        "who_ls",
        "whos",
        "xdel",
        "xmode",
    ]
)
"""The line magics (and shell aliases) of an IPython 8 kernel, which automagic runs without their ``%``."""
PASSES = 20
"""Rounds of tokenization: one finds every special line the tokenizer reaches; another is needed only
when a special line stopped the tokenizer (an unclosed quote in a shell command)."""
TRANSFORMER = "IPython.core.inputtransformer2"
"""IPython's input transformer module."""
ALONE = frozenset({TRANSFORMER, "IPython.utils.tokenutil"})
"""The IPython modules loaded alone (without ``IPython/__init__.py``); their imports must be the standard
library or each other."""
_AUTOMAGIC = re.compile(r"^\s*([\w*.]+)(.*)$")
_BUILTIN_NAMES = frozenset(dir(builtins))
_INDENT = re.compile(r"^[ \t]+")
_TRIGGER = re.compile(r"[!%?]|^[ \t]*[,;/]", re.M)
"""A character without which no token transformation applies (a cell of none is not tokenized)."""


class TransformerUnavailable(Exception):
    """IPython's input transformer could not be loaded (not installed, or an import it grew)."""


@dataclass(frozen=True)
class SpecialLine:
    """A line IPython would have turned into a command: what it is and the names it would bind."""

    line: int
    kind: str
    code: str
    binds: tuple[str, ...] = ()


@dataclass
class TransformedCell:
    """A cell as Python sees it after IPython's transformations.

    Attributes:
        source: The Python source (as many lines as the cell).
        special: The lines turned into ``pass``.
        cell_magic: ``%%name`` when the cell is a cell magic (its first line is then blank in ``source``).
        tree: ``source`` parsed, when it was already (a valid cell is parsed once).
    """

    source: str
    special: list[SpecialLine] = field(default_factory=list)
    cell_magic: str | None = None
    tree: ast.Module | None = None


def transform_cell(source: str, defined: Container[str]) -> TransformedCell:
    """The cell as IPython's input transformations leave it, special lines replaced by ``pass``.

    Args:
        source: The cell's text.
        defined: Names earlier cells set (a name shadows the automagic of a magic of the same name).

    Returns:
        The transformed cell.

    Raises:
        TransformerUnavailable: IPython's transformer cannot be loaded.
    """
    transforms = transformer()
    lines = source.splitlines()
    first = next((index for index, line in enumerate(lines) if line.strip()), 0)
    # IPython drops the leading blank lines; they are kept here, emptied, for the line numbers.
    lines = [""] * first + _cleaned(transforms, lines[first:])
    result = TransformedCell("")
    if lines and transforms.cell_magic([lines[first] + "\n"]) != [lines[first] + "\n"]:
        result.cell_magic = lines[first].split()[0]
        lines[first] = ""
        # IPython runs the body of %%time/%%capture as Python; it has no escapes of its own.
    parsed = _parsed(lines)
    special_syntax = parsed is None and _TRIGGER.search("\n".join(lines)) is not None
    for _ in range(PASSES if special_syntax else 0):
        found, complete = _special_lines(transforms, lines)
        for special, end in found:
            indent = _INDENT.match(lines[special.line - 1])
            lines[special.line - 1] = (indent.group(0) if indent else "") + "pass"
            for index in range(special.line, min(end, len(lines))):
                lines[index] = ""
            result.special.append(special)
        if complete or not found:  # a new pass only when the tokenizer stopped early (an unclosed quote)
            break
    magic = _automagic(lines, defined) if result.cell_magic is None else None
    if magic is not None:
        result.special.append(magic)
        lines[magic.line - 1] = "pass"
    result.special.sort(key=lambda special: special.line)
    result.source = "\n".join(lines)
    result.tree = parsed if not result.special else None
    return result


@cache
def transformer() -> types.ModuleType:
    """IPython's ``inputtransformer2``, loaded alone from the installed IPython (once per process).

    Raises:
        TransformerUnavailable: IPython is not installed where a file can be loaded, or the module (or
            one it imports) failed to load.
    """
    spec = importlib.util.find_spec("IPython")  # finds the package without running its __init__
    locations = list(spec.submodule_search_locations or []) if spec is not None else []
    if not locations:
        raise TransformerUnavailable(
            "IPython is not installed as a package of files (importlib found no IPython directory); "
            "reinstall the grader (pip install ipython)"
        )
    return load_transformer(Path(locations[0]))


def load_transformer(package: Path) -> types.ModuleType:
    """IPython's ``inputtransformer2`` loaded from the IPython package directory ``package`` without
    running ``IPython/__init__.py``: its imports are served from the standard library and from the other
    modules of `ALONE` (loaded alone too); any other import is refused.

    Args:
        package: The ``IPython`` directory.

    Returns:
        The module, under a private name (``IPython.core.inputtransformer2`` stays unimported).

    Raises:
        TransformerUnavailable: The module, or one it imports, failed to load.
    """
    loaded: dict[str, types.ModuleType] = {}
    try:
        return _load_alone(package, TRANSFORMER, loaded)
    except TransformerUnavailable:
        raise
    except Exception as error:  # whatever IPython's code raised while loading: the grader's fault, said so
        raise TransformerUnavailable(
            f"loading {TRANSFORMER} from {package} failed: {type(error).__name__}: {error}"
        ) from error


def _load_alone(package: Path, name: str, loaded: dict[str, types.ModuleType]) -> types.ModuleType:
    if name in loaded:
        return loaded[name]
    path = package.joinpath(*name.split(".")[1:]).with_suffix(".py")
    spec = importlib.util.spec_from_file_location(f"_gymgrade_alone.{name}", path)
    if spec is None or spec.loader is None or not path.is_file():
        raise TransformerUnavailable(f"{name} is not at {path}; reinstall the grader (pip install ipython)")
    module = importlib.util.module_from_spec(spec)
    module.__dict__["__builtins__"] = {
        **builtins.__dict__,
        "__import__": lambda *args: _import(package, loaded, *args),
    }
    loaded[name] = module
    spec.loader.exec_module(module)
    return module


def _import(
    package: Path,
    loaded: dict[str, types.ModuleType],
    name: str,
    globals: Mapping[str, object] | None = None,
    locals: Mapping[str, object] | None = None,
    fromlist: Sequence[str] | None = (),
    level: int = 0,
) -> types.ModuleType:
    """``__import__`` for a module loaded alone: the standard library as usual, an IPython module of
    `ALONE` (``from IPython.utils import tokenutil``) loaded alone, anything else refused."""
    if level == 0 and name.partition(".")[0] in sys.stdlib_module_names:
        return importlib.__import__(name, globals, locals, fromlist or (), level)
    wanted = [f"{name}.{item}" for item in fromlist or ()] if level == 0 else []
    if wanted and all(module in ALONE for module in wanted):
        parent = types.ModuleType(name)
        for module in wanted:
            setattr(parent, module.rpartition(".")[2], _load_alone(package, module, loaded))
        return parent
    taken = f"{'.' * level}{name} {list(fromlist or ())}"
    raise TransformerUnavailable(
        f"IPython's input transformer imports {taken}: neither the standard library nor one of {sorted(ALONE)}. "  # noqa: E501
        "This IPython cannot be loaded alone; install one whose inputtransformer2 can (pip install 'ipython>=8,<10') or extend grader.submission.notebook.ipython.ALONE"  # noqa: E501
    )


def _cleaned(transforms: types.ModuleType, lines: list[str]) -> list[str]:
    """IPython's cleanup transforms after its leading blank lines (indentation, then ``>>>`` / ``...`` or
    ``In [n]:`` prompts), given the lines with their endings as IPython gives them."""
    ended = [line + "\n" for line in lines]
    for transform in (transforms.leading_indent, transforms.classic_prompt, transforms.ipython_prompt):
        ended = transform(ended)
    return [line.removesuffix("\n") for line in ended]


def _parsed(lines: list[str]) -> ast.Module | None:
    """The cell's syntax tree when it parses as it is: then no token transformation applies (each one's
    trigger, a line starting with ``!``, ``%``, ``?``, ``,``, ``;`` or ``/``, ``= !``, ``= %name`` or a
    trailing ``?``, is a syntax error in Python), and the tokenizer, pure Python and slow, need not run."""
    try:
        return parsing.parse("\n".join(lines))
    except (SyntaxError, ValueError, MemoryError, RecursionError):
        return None


def _special_lines(
    transforms: types.ModuleType, lines: list[str]
) -> tuple[list[tuple[SpecialLine, int]], bool]:
    """Each special line of the cell with the index after its last (backslash-continued) line, and whether
    the whole cell was tokenized.

    IPython's ``make_tokens_by_line`` groups the tokens by logical line; on each, every token transformer's
    ``find`` is asked, and the match IPython would apply first (``TokenTransformBase.sortby``) whose
    transformation IPython accepts says what the line is.
    """
    ended = [line + "\n" for line in lines]
    found: list[tuple[SpecialLine, int]] = []
    tokens_by_line = transforms.make_tokens_by_line(ended)
    complete = bool(tokens_by_line) and tokens_by_line[-1][-1].type == tokenize.ENDMARKER
    finders = (transforms.MagicAssign, transforms.SystemAssign, transforms.EscapedCommand, transforms.HelpEnd)
    for tokens in tokens_by_line:
        matches = [match for finder in finders if (match := _find(finder, tokens)) is not None]
        for match in sorted(matches, key=transforms.TokenTransformBase.sortby):
            special = _special(transforms, match, tokens, ended)
            if special is not None:
                found.append(special)
                break
    return found, complete


def _find(finder: Any, tokens: list[tokenize.TokenInfo]) -> Any:
    """``finder.find`` on one logical line; a line it trips over (MagicAssign indexes past the end of a
    line the tokenizer cut short: ``x = %\"\"\"``) is no match, as IPython would fail on it."""
    try:
        return finder.find([tokens])
    except IndexError:
        return None


def _special(
    transforms: types.ModuleType, match: Any, tokens: list[tokenize.TokenInfo], ended: list[str]
) -> tuple[SpecialLine, int] | None:
    """The special line one of IPython's token transformers found, with the index after its last line
    (None: IPython refuses to transform it, as HelpEnd refuses ``print(x)?``)."""
    row = match.start_line
    binds: tuple[str, ...] = ()
    if isinstance(match, transforms.HelpEnd):
        window = ended[row : match.q_line + 1]  # HelpEnd.transform on the lines it reads, renumbered
        rebased = transforms.HelpEnd((1, match.start_col), (match.q_line - row + 1, match.q_col))
        try:
            rebased.transform(window)
        except SyntaxError:
            return None
        kind, end = "help request", match.q_line + 1
    else:
        end = transforms.find_end_of_continued_line(ended, row) + 1
        if isinstance(match, transforms.EscapedCommand):
            kind = ESCAPES.get(ended[row][match.start_col], "IPython command")  # an escape IPython added
        else:  # x = %magic, x = !cmd: the names before the escape are bound
            position = (row + 1, match.start_col)
            binds = tuple(
                token.string for token in tokens if token.type == tokenize.NAME and token.start < position
            )
            kind = "IPython magic" if isinstance(match, transforms.MagicAssign) else "shell command"
    first = next(token for token in tokens if token.type not in (tokenize.INDENT, tokenize.DEDENT))
    line = first.start[0]
    return SpecialLine(line, kind, ended[line - 1].strip(), binds), end


def _automagic(lines: list[str], defined: Container[str]) -> SpecialLine | None:
    """A one-line cell whose first word is a magic's name (``pip install gym``), as IPython's prefilter
    runs it: only for one-line cells, unless the name is a variable, builtin or keyword, and not when the
    rest of the line assigns (``time = 3``)."""
    meaningful = [
        (index, line) for index, line in enumerate(lines) if line.strip() and line.strip() != "pass"
    ]
    if len(meaningful) != 1 or any(line.strip() == "pass" for line in lines):
        return None
    index, line = meaningful[0]
    match = _AUTOMAGIC.match(line)
    if match is None:
        return None
    word, rest = match.group(1), match.group(2)
    head = word.split(".", 1)[0]
    if word not in LINE_MAGICS or head in defined or keyword.iskeyword(head) or head in _BUILTIN_NAMES:
        return None
    if rest.strip()[:1] in ("=", ","):
        return None
    return SpecialLine(index + 1, "IPython magic (automagic)", line.strip())
