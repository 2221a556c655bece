"""Which gym API a piece of code was written for, read from what the code does (pure, no I/O).

Two APIs share the name `gym`: classic gym (up to 0.25: `obs = env.reset()`, `obs, reward, done, info =
env.step(a)`) and gym 0.26 (`obs, info = env.reset()`, `obs, reward, terminated, truncated, info =
env.step(a)`). Code says which it expects by how it unpacks `reset()` and `step()`; that is strong
evidence. Weaker hints (`render_mode=`, names such as `terminated`, `env.seed()`, a `reset()` kept whole)
only decide when no strong evidence exists. Evidence is collected per function (innermost `def`), then
for the whole module: a function with its own evidence gets its own API, the others the module's.
"""

from __future__ import annotations

import ast
from collections.abc import Iterable
from dataclasses import dataclass, field
from enum import StrEnum


class Api(StrEnum):
    """A gym API the compat layer can serve."""

    CLASSIC = "classic"
    GYM026 = "gym026"

    @property
    def label(self) -> str:
        """How the report names the API."""
        return f"the {self.short} API ({4 if self is Api.CLASSIC else 5}-value step)"

    @property
    def short(self) -> str:
        """`classic gym` or `gym 0.26`."""
        return "classic gym" if self is Api.CLASSIC else "gym 0.26"


@dataclass(frozen=True)
class Evidence:
    """One line of code that shows which API it expects.

    Attributes:
        line: 1-based line number in the analysed source.
        api: the API this line expects.
        strong: whether it decides on its own (an unpacking) or only hints (a name, an argument).
        reason: what the line does, for the report ("step() unpacked into 5 values").
    """

    line: int
    api: Api
    strong: bool
    reason: str

    def describe(self) -> str:
        """`line 12: step() unpacked into 5 values`."""
        return f"line {self.line}: {self.reason}"


@dataclass(frozen=True)
class Decision:
    """The API a scope (a function or the module) expects, or why it cannot be told.

    Attributes:
        api: the API, or None when the evidence conflicts or there is none.
        evidence: the evidence that decided (or conflicts), in line order.
        conflict: True when lines of the scope expect different APIs.
    """

    api: Api | None
    evidence: tuple[Evidence, ...] = ()
    conflict: bool = False

    @property
    def strong(self) -> bool:
        """Whether an unpacking decided (not only hints)."""
        return bool(self.evidence) and self.evidence[0].strong

    def explain(self, limit: int = 3) -> str:
        """The lines that decided, for the report."""
        shown = [item.describe() for item in self.evidence[:limit]]
        more = len(self.evidence) - limit
        return "; ".join(shown) + (f" (and {more} more)" if more > 0 else "")


@dataclass(frozen=True)
class Scope:
    """A function definition (or the module) and the lines it spans.

    Attributes:
        name: qualified name (`cartpole`, `Agent.run`), or `<module>`.
        first_line: its first line (the `def`, or 1).
        last_line: its last line.
        decision: what its own lines say.
    """

    name: str
    first_line: int
    last_line: int
    decision: Decision


@dataclass(frozen=True)
class ApiDetection:
    """What a whole source file expects.

    Attributes:
        module: the decision from every line of the file.
        scopes: functions with evidence of their own, innermost last for nested functions.
        error: why the source could not be analysed (a syntax error), else "".
    """

    module: Decision
    scopes: tuple[Scope, ...] = ()
    error: str = ""

    def scope_at(self, line: int) -> Scope | None:
        """The innermost function with its own evidence that contains `line`, or None."""
        found = None
        for scope in self.scopes:
            if scope.first_line <= line <= scope.last_line and (
                found is None or scope.first_line >= found.first_line
            ):
                found = scope
        return found

    def decision_at(self, line: int) -> tuple[str, Decision]:
        """The scope name and decision that applies to code at `line`.

        A function whose own unpackings decide (or conflict) wins; then the module's unpackings; then the
        function's own hints; then the module's hints.
        """
        scope = self.scope_at(line)
        own = scope.decision if scope is not None else Decision(None)
        if scope is not None and own.strong:
            return scope.name, own
        if self.module.strong and self.module.api is not None:
            return "<module>", self.module
        if scope is not None and own.api is not None:
            return scope.name, own
        return "<module>", self.module


_RESET = "reset"
_STEP = "step"
_SEED_MODULES = frozenset({"random", "np", "numpy", "torch", "tf"})
_GYM026_NAMES = frozenset({"terminated", "truncated", "terminateds", "truncateds"})


def detect_api(source: str) -> ApiDetection:
    """Analyse `source` and decide which gym API each of its functions expects.

    Args:
        source: Python source text.

    Returns:
        The module's decision and every function that has evidence of its own. Source that does not
        parse gets an undecided detection whose `error` says why.
    """
    try:
        tree = ast.parse(source)
    except (SyntaxError, ValueError) as error:
        return ApiDetection(Decision(None), (), f"the source does not parse ({error})")
    collector = _Collector()
    collector.visit(tree)
    scopes = tuple(
        Scope(name, first, last, decide(items))
        for (name, first, last), items in collector.by_scope.items()
        if items and name != "<module>"
    )
    return ApiDetection(decide(collector.all_evidence), scopes)


def decide(evidence: Iterable[Evidence]) -> Decision:
    """Decide an API from evidence: strong evidence if any, else hints; disagreement is a conflict."""
    ordered = sorted(evidence, key=lambda item: item.line)
    for strength in (True, False):
        chosen = tuple(item for item in ordered if item.strong is strength)
        apis = {item.api for item in chosen}
        if len(apis) == 1:
            return Decision(apis.pop(), chosen)
        if len(apis) > 1:
            return Decision(None, chosen, conflict=True) if strength else Decision(None, chosen)
    return Decision(None)


def _call_name(node: ast.AST) -> str | None:
    """`reset`/`step`/... for `x.reset(...)`, also behind `[0]`; None for anything else."""
    if isinstance(node, ast.Subscript):
        node = node.value
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
        return node.func.attr
    return None


def _keywords(node: ast.Call) -> set[str]:
    return {keyword.arg for keyword in node.keywords if keyword.arg is not None}


def _unpacked_length(target: ast.AST) -> int | None:
    if isinstance(target, ast.Tuple | ast.List) and not any(
        isinstance(element, ast.Starred) for element in target.elts
    ):
        return len(target.elts)
    return None


@dataclass
class _Collector(ast.NodeVisitor):
    by_scope: dict[tuple[str, int, int], list[Evidence]] = field(default_factory=dict)
    all_evidence: list[Evidence] = field(default_factory=list)
    _stack: list[tuple[str, int, int]] = field(default_factory=lambda: [("<module>", 1, 1 << 30)])
    _named: set[tuple[int, str]] = field(default_factory=set)

    def _add(self, line: int, api: Api, strong: bool, reason: str) -> None:
        item = Evidence(line, api, strong, reason)
        self.all_evidence.append(item)
        self.by_scope.setdefault(self._stack[-1], []).append(item)

    def _function(self, node: ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef) -> None:
        outer = self._stack[-1][0]
        name = node.name if outer == "<module>" else f"{outer}.{node.name}"
        key = (name, node.lineno, node.end_lineno or node.lineno)
        self.by_scope.setdefault(key, [])
        self._stack.append(key)
        self.generic_visit(node)
        self._stack.pop()

    visit_FunctionDef = _function
    visit_AsyncFunctionDef = _function
    visit_ClassDef = _function

    def visit_Assign(self, node: ast.Assign) -> None:
        for target in node.targets:
            self._assignment(target, node.value, node.lineno)
        self.generic_visit(node)

    def visit_Name(self, node: ast.Name) -> None:
        if node.id in _GYM026_NAMES and (node.lineno, node.id) not in self._named:
            self._named.add((node.lineno, node.id))
            self._add(node.lineno, Api.GYM026, False, f"uses the name {node.id!r}")

    def _assignment(self, target: ast.AST, value: ast.AST, line: int) -> None:
        name = _call_name(value)
        if name not in (_RESET, _STEP):
            return
        call = value.value if isinstance(value, ast.Subscript) else value
        subscripted = isinstance(value, ast.Subscript)
        length = _unpacked_length(target)
        if name == _RESET:
            self._reset(call, target, length, subscripted, line)
        else:
            self._step(length, subscripted, line)

    def _reset(
        self, call: ast.AST, target: ast.AST, length: int | None, subscripted: bool, line: int
    ) -> None:
        classic_info = isinstance(call, ast.Call) and "return_info" in _keywords(call)
        if subscripted:
            self._add(line, Api.GYM026, True, "reset()[...] takes the observation out of (obs, info)")
        elif length == 2:
            if classic_info:
                self._add(line, Api.CLASSIC, True, "reset(return_info=True) unpacked into (obs, info)")
            else:
                self._add(line, Api.GYM026, True, "reset() unpacked into 2 values (obs, info)")
        elif isinstance(target, ast.Name):
            self._add(line, Api.CLASSIC, False, "reset() kept as one value (the observation)")

    def _step(self, length: int | None, subscripted: bool, line: int) -> None:
        if length == 4:
            self._add(line, Api.CLASSIC, True, "step() unpacked into 4 values (obs, reward, done, info)")
        elif length == 5:
            self._add(
                line,
                Api.GYM026,
                True,
                "step() unpacked into 5 values (obs, reward, terminated, truncated, info)",
            )

    def visit_Call(self, node: ast.Call) -> None:
        keywords = _keywords(node)
        if isinstance(node.func, ast.Attribute):
            if node.func.attr == "make" and "render_mode" in keywords:
                self._add(node.lineno, Api.GYM026, False, "make(..., render_mode=...)")
            elif (
                node.func.attr == "seed"
                and isinstance(node.func.value, ast.Name)
                and node.func.value.id not in _SEED_MODULES
            ):
                self._add(node.lineno, Api.CLASSIC, False, "env.seed() (classic seeding)")
        self.generic_visit(node)
