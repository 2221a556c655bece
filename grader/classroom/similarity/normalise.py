"""Python source to renaming-proof token streams, one per function, through Python's own parser.

Each top-level function (and each method) is one *unit*; the module's other statements form one more.
Fingerprints never cross units, so reordering functions changes nothing. Within a unit the tree is
cleaned of what a disguise adds or changes without changing the program: docstrings and bare strings,
``pass``, output calls (``print``, ``clear_output``, ``display``, ``plt.*``), branches on a constant
(``if False:``), statements after ``return``/``raise``/``break``/``continue``, imports, and assignments
to names nothing reads. The remaining tree is written out in pre-order as tokens: every name the file
binds (variables, parameters, its own functions, import aliases resolve to their module) becomes ``ID``;
names it does not bind (``range``, ``np``, attributes such as ``env.step``) are kept; literals are bucketed
(``0``, ``1``, ``-1``, ``True``, ``None`` kept; other ints ``INT``, floats ``FLOAT``, strings ``STR``).
"""

from __future__ import annotations

import ast
import hashlib
import io
import re
import tokenize
from dataclasses import dataclass, field

from grader import parsing

MAX_TOKENS_PER_FILE = 200_000
"""A lab solution is a few thousand tokens; beyond this a file is padding and is cut (and says so)."""
OUTPUT_CALLS = frozenset({"print", "clear_output", "display", "pprint"})
OUTPUT_MODULES = frozenset({"plt", "pyplot", "display", "IPython"})
KEPT_LITERALS = frozenset({0, 1, -1, None})
MODULE_UNIT = "<module>"
MIN_REMARK_CHARS = 12
"""Shorter comments and strings (``# reset``, ``"Taxi-v3"``) are what everyone writes: not evidence."""


@dataclass(frozen=True)
class Unit:
    """One function's (or the module code's) normalised tokens.

    Attributes:
        name: The function's name as written (``Class.method`` for methods, ``<module>`` otherwise).
        shape: A digest of the token stream: equal for two functions that differ only in names, literal
            values of the same bucket, comments, docstrings and dead code.
        tokens: The tokens.
        lines: For each token, the source line (1-based) it comes from.
    """

    name: str
    shape: str
    tokens: tuple[str, ...]
    lines: tuple[int, ...]


@dataclass(frozen=True)
class Remark:
    """A comment or string literal kept as evidence (identical comments and typos rarely arise independently).

    Attributes:
        key: The text lowercased with whitespace collapsed (what two files must share).
        text: The text as written (shown to the reader).
        line: Where it is.
    """

    key: str
    text: str
    line: int


@dataclass
class NormalisedSource:
    """Everything the comparison keeps of one file.

    Attributes:
        units: One per function, method and the module's code.
        remarks: Comments and longer string literals (docstrings included).
        constants: Numeric literals with their line, as written (``0.0173``).
        truncated: True when the file held more than ``MAX_TOKENS_PER_FILE`` tokens and was cut.
    """

    units: list[Unit] = field(default_factory=list)
    remarks: list[Remark] = field(default_factory=list)
    constants: list[tuple[str, int]] = field(default_factory=list)
    truncated: bool = False


def normalise(source: str) -> NormalisedSource:
    """Parse ``source`` (never executing it) and return its units, comments and constants.

    Raises:
        SyntaxError: When it is not Python (also for nesting too deep for the parser).
    """
    try:
        tree = parsing.parse(source)
    except (ValueError, RecursionError, MemoryError) as error:
        raise SyntaxError(f"the parser gave up ({type(error).__name__})") from None
    facts = _facts(tree)
    read = frozenset(facts.read)  # a store nothing in the file reads is dead, whatever function it is in
    result = NormalisedSource(remarks=_remarks(source, facts.strings), constants=facts.constants)
    budget = MAX_TOKENS_PER_FILE
    renameable, attributes = frozenset(facts.bound - facts.aliases.keys()), frozenset(facts.attributes)
    for name, statements in _units(tree):
        cleaned = _clean_block(statements, read)
        if not cleaned:
            continue
        writer = _TokenWriter(renameable, facts.aliases, attributes)
        for statement in cleaned:
            writer.write(statement)
        tokens, lines = writer.tokens[:budget], writer.lines[:budget]
        budget -= len(tokens)
        if tokens:
            result.units.append(Unit(name, _digest(tokens), tuple(tokens), tuple(lines)))
        if budget <= 0:
            result.truncated = True
            break
    return result


def _digest(tokens: list[str]) -> str:
    return hashlib.blake2b("\0".join(tokens).encode(), digest_size=16).hexdigest()


def _units(tree: ast.Module) -> list[tuple[str, list[ast.stmt]]]:
    units: list[tuple[str, list[ast.stmt]]] = []
    module_code: list[ast.stmt] = []
    for statement in tree.body:
        if isinstance(statement, (ast.FunctionDef, ast.AsyncFunctionDef)):
            units.append((statement.name, [statement]))
        elif isinstance(statement, ast.ClassDef):
            methods = [
                node for node in statement.body if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))
            ]
            units.extend((f"{statement.name}.{method.name}", [method]) for method in methods)
            module_code.extend(node for node in statement.body if node not in methods)
        else:
            module_code.append(statement)
    if module_code:
        units.append((MODULE_UNIT, module_code))
    return units


@dataclass
class _Facts:
    """What one walk of the whole tree finds (one walk: the tree is walked once, not once per question)."""

    bound: set[str] = field(default_factory=set)
    read: set[str] = field(default_factory=set)
    aliases: dict[str, str] = field(default_factory=dict)
    attributes: set[str] = field(default_factory=set)
    strings: list[tuple[str, int]] = field(default_factory=list)
    constants: list[tuple[str, int]] = field(default_factory=list)


_CANONICAL_MODULES = {"numpy": "np", "gymnasium": "gym", "matplotlib.pyplot": "plt", "pyplot": "plt"}


_FACT_NODES = frozenset(
    {
        ast.Name,
        ast.Constant,
        ast.Attribute,
        ast.arg,
        ast.FunctionDef,
        ast.AsyncFunctionDef,
        ast.ClassDef,
        ast.Import,
        ast.ImportFrom,
        ast.ExceptHandler,
        ast.Global,
        ast.Nonlocal,
    }
)


def _facts(tree: ast.Module) -> _Facts:
    """Names the file binds (a disguise can rename them), import aliases (``import numpy as npy`` reads as
    ``np``), attributes it assigns or defines as methods (renameable too), its strings and numbers."""
    facts = _Facts(aliases={"numpy": "np", "gymnasium": "gym"})
    for node in ast.walk(tree):
        if type(node) not in _FACT_NODES:
            continue
        if isinstance(node, ast.Name):
            if isinstance(node.ctx, ast.Load):
                facts.read.add(node.id)
            else:
                facts.bound.add(node.id)
        elif isinstance(node, ast.Constant):
            value = node.value
            if isinstance(value, str):
                if len(value.strip()) >= MIN_REMARK_CHARS:
                    facts.strings.append((value, node.lineno))
            elif isinstance(value, (int, float)) and not isinstance(value, bool):
                facts.constants.append((repr(value), node.lineno))
        elif isinstance(node, ast.Attribute):
            if isinstance(node.ctx, ast.Store):
                facts.attributes.add(node.attr)
        elif isinstance(node, ast.arg):
            facts.bound.add(node.arg)
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            facts.bound.add(node.name)
        elif isinstance(node, ast.ClassDef):
            facts.bound.add(node.name)
            facts.attributes.update(
                item.name for item in node.body if isinstance(item, (ast.FunctionDef, ast.AsyncFunctionDef))
            )
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            for alias in node.names:
                if alias.asname:
                    module = alias.name.split(".")[-1] if isinstance(node, ast.ImportFrom) else alias.name
                    facts.aliases[alias.asname] = module
        elif isinstance(node, ast.ExceptHandler) and node.name:
            facts.bound.add(node.name)
        elif isinstance(node, (ast.Global, ast.Nonlocal)):
            facts.bound.update(node.names)
            facts.read.update(node.names)
    facts.aliases = {name: _CANONICAL_MODULES.get(module, module) for name, module in facts.aliases.items()}
    return facts


def _clean_block(statements: list[ast.stmt], read: frozenset[str]) -> list[ast.stmt]:
    """The statements of a block without the ones that cannot change what the program computes."""
    kept: list[ast.stmt] = []
    for statement in statements:
        if _is_noise(statement):
            continue
        if isinstance(statement, (ast.If, ast.While)) and _constant_truth(statement.test) is not None:
            taken = _constant_truth(statement.test)
            if isinstance(statement, ast.While) and not taken:
                continue
            if isinstance(statement, ast.If):
                kept.extend(_clean_block(statement.body if taken else statement.orelse, read))
                continue
        _clean_children(statement, read)
        kept.append(statement)
        if isinstance(statement, (ast.Return, ast.Raise, ast.Break, ast.Continue)):
            break
    return _without_dead_stores(kept, read)


def _clean_children(statement: ast.stmt, read: frozenset[str]) -> None:
    for name in ("body", "orelse", "finalbody"):
        block = getattr(statement, name, None)
        if isinstance(block, list) and block and isinstance(block[0], ast.stmt):
            setattr(statement, name, _clean_block(block, read))
    if isinstance(statement, ast.Try):
        for handler in statement.handlers:
            handler.body = _clean_block(handler.body, read)
    if isinstance(statement, ast.Match):
        for case in statement.cases:
            case.body = _clean_block(case.body, read)


def _is_noise(statement: ast.stmt) -> bool:
    if isinstance(statement, (ast.Pass, ast.Import, ast.ImportFrom)):
        return True
    if isinstance(statement, ast.Expr):
        value = statement.value
        if isinstance(value, ast.Constant):
            return True
        if isinstance(value, ast.Call):
            return _is_output_call(value.func)
    return False


def _is_output_call(function: ast.expr) -> bool:
    if isinstance(function, ast.Name):
        return function.id in OUTPUT_CALLS
    root = function
    while isinstance(root, ast.Attribute):
        root = root.value
    return isinstance(root, ast.Name) and root.id in OUTPUT_MODULES


def _constant_truth(test: ast.expr) -> bool | None:
    if isinstance(test, ast.Constant):
        return bool(test.value)
    if (
        isinstance(test, ast.UnaryOp)
        and isinstance(test.op, ast.Not)
        and isinstance(test.operand, ast.Constant)
    ):
        return not test.operand.value
    return None


def _without_dead_stores(statements: list[ast.stmt], read: frozenset[str]) -> list[ast.stmt]:
    """Drop assignments to plain names that nothing in the unit reads (``x = 5`` padding)."""
    kept: list[ast.stmt] = []
    for statement in statements:
        targets: list[ast.expr] = []
        if isinstance(statement, ast.Assign):
            targets = statement.targets
        elif isinstance(statement, (ast.AnnAssign, ast.AugAssign)):
            targets = [statement.target]
        names = [target.id for target in targets if isinstance(target, ast.Name)]
        if targets and len(names) == len(targets) and not read.intersection(names):
            continue
        kept.append(statement)
    return kept


_SKIPPED_FIELDS = frozenset({"ctx", "decorator_list", "type_comment"})
"""Load/Store contexts say nothing a token does not; decorators are the same on every copy of a function."""


class _TokenWriter:
    def __init__(self, bound: frozenset[str], aliases: dict[str, str], attributes: frozenset[str]) -> None:
        self.bound = bound
        self.aliases = aliases
        self.attributes = attributes
        self.tokens: list[str] = []
        self.lines: list[int] = []
        self.line = 1

    def write(self, node: ast.AST) -> None:
        stack: list[ast.AST] = [node]
        while stack:
            current = stack.pop()
            self.line = getattr(current, "lineno", self.line)
            self._emit(current)
            if isinstance(current, (ast.Constant, ast.JoinedStr)):
                continue
            children: list[ast.AST] = []
            for name in current._fields:
                if name in _SKIPPED_FIELDS:
                    continue
                value = getattr(current, name, None)
                if isinstance(value, ast.AST):
                    children.append(value)
                elif isinstance(value, list):
                    children.extend(item for item in value if isinstance(item, ast.AST))
            stack.extend(reversed(children))

    def _emit(self, node: ast.AST) -> None:
        kind = type(node).__name__
        if isinstance(node, ast.Name):
            token = "ID" if node.id in self.bound else self.aliases.get(node.id, node.id)
        elif isinstance(node, ast.Attribute):
            token = "." + ("ID" if node.attr in self.attributes else node.attr)
        elif isinstance(node, ast.arg):
            token = "arg"
        elif isinstance(node, ast.Constant):
            token = _literal(node.value)
        elif isinstance(node, (ast.operator, ast.boolop, ast.cmpop, ast.unaryop)):
            token = kind
        elif isinstance(node, ast.keyword):
            token = f"kw={node.arg}" if node.arg is not None and node.arg not in self.bound else "kw"
        else:
            token = kind
        self.tokens.append(token)
        self.lines.append(self.line)


def _literal(value: object) -> str:
    if isinstance(value, bool) or value is None or value is Ellipsis:
        return repr(value)
    if isinstance(value, int):
        return repr(value) if value in KEPT_LITERALS else "INT"
    if isinstance(value, float):
        return "1" if value == 1.0 else "0" if value == 0.0 else "FLOAT"
    if isinstance(value, complex):
        return "COMPLEX"
    return "STR"


_SPACE = re.compile(r"\s+")


def _key(text: str) -> str:
    return _SPACE.sub(" ", text.strip().lower())


def _remarks(source: str, strings: list[tuple[str, int]]) -> list[Remark]:
    remarks: list[Remark] = []
    try:
        tokens = tokenize.generate_tokens(io.StringIO(source).readline) if "#" in source else iter(())
        for token in tokens:
            if token.type == tokenize.COMMENT:
                text = token.string.lstrip("#").strip()
                if len(text) >= MIN_REMARK_CHARS:
                    remarks.append(Remark(_key(text), text, token.start[0]))
    except (tokenize.TokenError, SyntaxError):
        pass  # the tree parsed, so only exotic tokenizer disagreements land here; comments are optional
    for value, line_number in strings:
        for offset, line in enumerate(value.splitlines()):
            if len(line.strip()) >= MIN_REMARK_CHARS:
                remarks.append(Remark(_key(line), line.strip()[:200], line_number + offset))
    return remarks
