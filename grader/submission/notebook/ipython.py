"""Read a cell the way IPython does before Python sees it: IPython's own input transformations.

IPython's ``IPython.core.inputtransformer2`` turns ``%magic``, ``%%cell magic``, ``!shell``, ``x = !cmd``,
``obj?``, ``,autocall`` and prompts pasted from a console into Python that calls ``get_ipython()``; its
prefilter's automagic does the same to a one-line cell such as ``pip install gym``. The grader runs none of
those commands, so each such line becomes ``pass`` (same indentation, same line numbers) and is listed as
skipped. The cleanup transforms, the cell-magic test, the tokenizer grouping and each token transformer's
``find`` (MagicAssign, SystemAssign, EscapedCommand, HelpEnd) are IPython's; this module only applies them
to every logical line of one tokenization, where ``TransformerManager.transform_cell`` re-tokenizes the
whole cell after each special line (quadratic: a 200,000-character cell of ``!echo`` lines would take
minutes). Automagic, a prefilter rule outside the transformer, is written out (`_automagic`). This module
runs in the notebook reader's bounded child (`grader.submission.notebook.bounded`), where IPython's import
costs nothing the parent pays.
"""

from __future__ import annotations

import ast
import builtins
import importlib
import keyword
import re
import tokenize
from collections.abc import Container
from dataclasses import dataclass, field
from types import ModuleType
from typing import Any

ESCAPES = {"!": "shell command", "%": "IPython magic", "?": "help request", ",": "IPython autocall",
           ";": "IPython autocall", "/": "IPython autocall"}  # fmt: skip
"""IPython's ESC_* characters (``!!``, ``%%`` and ``??`` start with one of them)."""
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
_AUTOMAGIC = re.compile(r"^\s*([\w*.]+)(.*)$")
_INDENT = re.compile(r"^[ \t]+")
_BUILTIN_NAMES = frozenset(dir(builtins))
_TRIGGER = re.compile(r"[!%?]|^[ \t]*[,;/]", re.M)
"""A character without which no token transformation applies (a cell of none is not tokenized)."""


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
    """
    lines = source.splitlines()
    first = next((index for index, line in enumerate(lines) if line.strip()), 0)
    # IPython drops the leading blank lines first; they are kept here (and untouched) for the line numbers.
    lines = lines[:first] + _cleaned(lines[first:])
    result = TransformedCell("")
    if lines and _inputtransformer2().cell_magic([lines[first]]) != [lines[first]]:
        result.cell_magic = lines[first].split()[0]
        lines[first] = ""
        # IPython runs the body of %%time/%%capture as Python; it has no escapes of its own.
    parsed = _parsed(lines)
    special_syntax = parsed is None and _TRIGGER.search("\n".join(lines)) is not None
    for _ in range(PASSES if special_syntax else 0):
        found, complete = _special_lines(lines)
        for special, end in found:
            indent = _INDENT.match(lines[special.line - 1])
            lines[special.line - 1] = (indent.group(0) if indent else "") + "pass"
            for index in range(special.line, end):
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


def _inputtransformer2() -> ModuleType:
    """IPython's input transformer module, imported when a cell is first read (in the reader's child)."""
    return importlib.import_module("IPython.core.inputtransformer2")


def _cleaned(lines: list[str]) -> list[str]:
    """IPython's cleanup transforms after its leading blank lines: the first line's indentation removed
    from every line, then ``>>>`` / ``...`` or ``In [n]:`` prompts."""
    transforms = _inputtransformer2()
    for transform in (transforms.leading_indent, transforms.classic_prompt, transforms.ipython_prompt):
        lines = transform(lines)
    return lines


def _parsed(lines: list[str]) -> ast.Module | None:
    """The cell's syntax tree when it parses as it is: then no token transformation applies (each one's
    trigger, a line starting with ``!``, ``%``, ``?``, ``,``, ``;`` or ``/``, ``= !``, ``= %name`` or a
    trailing ``?``, is a syntax error in Python), and the tokenizer, pure Python and slow, need not run."""
    try:
        return ast.parse("\n".join(lines))
    except (SyntaxError, ValueError, MemoryError, RecursionError):
        return None


def _special_lines(lines: list[str]) -> tuple[list[tuple[SpecialLine, int]], bool]:
    """Each special line of the cell with the index after its last (backslash-continued) line, and whether
    the whole cell was tokenized.

    IPython's `make_tokens_by_line` groups the tokens by logical line; on each, every token transformer's
    ``find`` is asked, and the match IPython would apply first (`TokenTransformBase.sortby`) says what the
    line is. A help request whose target IPython's `_help_end_re` refuses is no transformation (IPython
    raises SyntaxError there, and the cell stays broken).
    """
    transforms = _inputtransformer2()
    ended = [line + "\n" for line in lines]
    found: list[tuple[SpecialLine, int]] = []
    tokens_by_line = transforms.make_tokens_by_line(ended)
    complete = _tokenized_to_the_end(tokens_by_line)
    for tokens in tokens_by_line:
        matches = [match for finder in _finders(transforms) if (match := finder.find([tokens])) is not None]
        for match in sorted(matches, key=transforms.TokenTransformBase.sortby):
            special = _special(match, tokens, ended, transforms)
            if special is not None:
                found.append(special)
                break
    return found, complete


def _finders(transforms: ModuleType) -> tuple[Any, ...]:
    """The token transformers of IPython's `TransformerManager`, in its order."""
    return (transforms.MagicAssign, transforms.SystemAssign, transforms.EscapedCommand, transforms.HelpEnd)


def _special(
    match: Any, tokens: list[tokenize.TokenInfo], ended: list[str], transforms: ModuleType
) -> tuple[SpecialLine, int] | None:
    """The special line one of IPython's token transformers found, with the index after its last line."""
    row = match.start_line
    binds: tuple[str, ...] = ()
    if isinstance(match, transforms.HelpEnd):
        piece = "".join(ended[row : match.q_line + 1])[match.start_col :]
        if transforms._help_end_re.search(piece) is None:  # IPython's own test of a help target
            return None
        kind, end = "help request", match.q_line + 1
    else:
        end = transforms.find_end_of_continued_line(ended, row) + 1
        if isinstance(match, transforms.EscapedCommand):
            kind = ESCAPES[ended[row][match.start_col]]
        else:
            assign = transforms._find_assign_op(tokens)  # where IPython splits the assignment
            binds = tuple(token.string for token in tokens[:assign] if token.type == tokenize.NAME)
            kind = "IPython magic" if isinstance(match, transforms.MagicAssign) else "shell command"
    return SpecialLine(row + 1, kind, ended[row].strip(), binds), end


def _tokenized_to_the_end(tokens_by_line: list[list[tokenize.TokenInfo]]) -> bool:
    """Whether the tokenizer reached the end of the cell (IPython's grouping stops silently at an unclosed
    quote or bracket; a complete tokenization ends with ENDMARKER)."""
    return bool(tokens_by_line) and tokens_by_line[-1][-1].type == tokenize.ENDMARKER


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
