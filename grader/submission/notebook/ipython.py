"""Read a cell the way IPython does before Python sees it: its input transformations, done by hand.

IPython's ``IPython.core.inputtransformer2.TransformerManager`` (and, for one-line cells, the prefilter's
automagic) turns ``%magic``, ``%%cell magic``, ``!shell``, ``x = !cmd``, ``obj?``, ``,autocall``, prompts
pasted from a console and a bare ``pip install gym`` into Python that calls ``get_ipython()``. The grader
runs none of those commands, so each such line becomes ``pass`` (same indentation, same line numbers) and
is listed as skipped. IPython is not a dependency of the trusted parent, hence this copy of its rules;
IPython re-tokenizes the cell after every transformation, this finds every special line in a few passes
of one tokenization each, so a cell costs time linear in its size.
"""

from __future__ import annotations

import ast
import builtins
import io
import keyword
import re
import tokenize
from collections.abc import Container
from dataclasses import dataclass, field

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
_CLASSIC_FIRST = re.compile(r"^>>>( |$)")
_CLASSIC_ANY = re.compile(r"^(>>>|\.\.\.)( |$)")
_IPYTHON_PROMPT = re.compile(r"^(((\[nav\]|\[ins\])?\ )?In\ \[\d+\]:\ |\s*\.{3,}:\ ?)")
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
    lines = _dedented(lines, first)
    lines = _without_prompts(lines, first)
    result = TransformedCell("")
    if lines and lines[first].startswith("%%"):
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


def _dedented(lines: list[str], first: int) -> list[str]:
    indent = _INDENT.match(lines[first]) if lines else None
    if indent is None:
        return lines
    space = indent.group(0)
    return [line[len(space) :] if line.startswith(space) else line for line in lines]


def _without_prompts(lines: list[str], first: int) -> list[str]:
    rest = lines[first:]
    if rest and _CLASSIC_FIRST.match(rest[0]):
        return [_CLASSIC_ANY.sub("", line, count=1) for line in lines]
    if rest and (_IPYTHON_PROMPT.match(rest[0]) or (len(rest) > 1 and _IPYTHON_PROMPT.match(rest[1]))):
        return [_IPYTHON_PROMPT.sub("", line, count=1) for line in lines]
    return lines


def _parsed(lines: list[str]) -> ast.Module | None:
    """The cell's syntax tree when it parses as it is: then no token transformation applies (each one's
    trigger, a line starting with ``!``, ``%``, ``?``, ``,``, ``;`` or ``/``, ``= !``, ``= %name`` or a
    trailing ``?``, is a syntax error in Python), and the tokenizer, pure Python and slow, need not run."""
    try:
        return ast.parse("\n".join(lines))
    except (SyntaxError, ValueError, MemoryError, RecursionError):
        return None


def _logical_lines(lines: list[str]) -> tuple[list[list[tokenize.TokenInfo]], bool]:
    """Tokens grouped by logical line, as IPython's ``make_tokens_by_line`` groups them, and whether the
    tokenizer reached the end."""
    by_line: list[list[tokenize.TokenInfo]] = [[]]
    depth = 0
    text = "".join(line + "\n" for line in lines)
    try:
        for token in tokenize.generate_tokens(io.StringIO(text).readline):
            by_line[-1].append(token)
            if token.type == tokenize.NEWLINE or (token.type == tokenize.NL and depth <= 0):
                by_line.append([])
            elif token.string in "([{" and token.type == tokenize.OP:
                depth += 1
            elif token.string in ")]}" and token.type == tokenize.OP and depth > 0:
                depth -= 1
    except (tokenize.TokenError, SyntaxError):  # an unclosed string or bracket: IPython stops there too
        return [tokens for tokens in by_line if tokens], False
    return [tokens for tokens in by_line if tokens], True


def _special_lines(lines: list[str]) -> tuple[list[tuple[SpecialLine, int]], bool]:
    """Each special line of the cell with the index after its last (backslash-continued) line, and whether
    the whole cell was tokenized."""
    found: list[tuple[SpecialLine, int]] = []
    logical, complete = _logical_lines(lines)
    for tokens in logical:
        body = [token for token in tokens if token.type not in (tokenize.INDENT, tokenize.DEDENT)]
        meaningful = [
            token
            for token in body
            if token.type not in (tokenize.NEWLINE, tokenize.NL, tokenize.COMMENT)
            and not token.string.isspace()
        ]
        if not meaningful:
            continue
        start = meaningful[0]
        row = start.start[0]
        binds: tuple[str, ...] = ()
        kind = ESCAPES.get(start.string[:1]) if start.string not in ("%=", "/=") else None
        if kind is None:
            assigned = _assigned_command(meaningful)
            if assigned is not None:
                kind, binds, row = assigned
            elif meaningful[-1].string == "?":
                kind = "help request"
        if kind is None:
            continue
        end = row
        while end < len(lines) and lines[end - 1].endswith("\\"):
            end += 1
        code = lines[start.start[0] - 1].strip()
        found.append((SpecialLine(start.start[0], kind, code, binds), end))
    return found, complete


def _assigned_command(tokens: list[tokenize.TokenInfo]) -> tuple[str, tuple[str, ...], int] | None:
    """``x = %magic`` / ``files = !ls`` (IPython's MagicAssign and SystemAssign)."""
    depth = 0
    for index, token in enumerate(tokens):
        if token.type == tokenize.OP and token.string in "([{":
            depth += 1
        elif token.type == tokenize.OP and token.string in ")]}":
            depth -= 1
        elif depth == 0 and token.type == tokenize.OP and token.string == "=":
            following = [t for t in tokens[index + 1 : index + 4] if not t.string.isspace()][:2]
            names = tuple(t.string for t in tokens[:index] if t.type == tokenize.NAME)
            if following and following[0].string == "!":
                return "shell command", names, token.start[0]
            if len(following) == 2 and following[0].string == "%" and following[1].type == tokenize.NAME:
                return "IPython magic", names, token.start[0]
            return None
    return None


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
