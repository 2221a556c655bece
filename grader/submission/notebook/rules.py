"""Which top-level statements of a notebook may run at import: those that cannot call the student's code.

Every expression of a kept statement is judged by the kind of value it evaluates to (`Kind`): a literal,
an imported name and what library code returns for such values are ``SAFE`` (an operation on them runs
library code only); the student's own functions and classes (and anything that may hold one) are not, and
a kept statement may only *store* them (``policy = greedy``, a default argument, an annotation), never
operate on them: an attribute (a metaclass property), a subscript (``__class_getitem__``), an operator, a
comparison, a hash (a set or dict key), ``str.format``, iteration, truthiness and any call other than the
constructors in `CHEAP_CALLS` with safe arguments all run code the student wrote. An expression node this
module does not know is refused, so a new kind of Python expression cannot slip through.
"""

from __future__ import annotations

import ast
import builtins
import enum
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field


class Kind(enum.Enum):
    """What a name or expression holds, as far as running student code goes."""

    SAFE = "safe"
    """A literal, a module, a library object: operating on it runs library code only."""
    PLAIN_CLASS = "plain class"
    """A student class without hooks a subclass runs (``__init_subclass__``, a student metaclass)."""
    PROPERTY = "property"
    """A ``property`` made in a class body (``@name.setter`` reads its attribute)."""
    STUDENT = "student"
    """A student function or class, or a value that may hold one: store it, never operate on it."""


CHEAP_CALLS: frozenset[str] = frozenset(
    {
        "gym.make",
        "gymnasium.make",
        *(
            f"numpy.{name}"
            for name in ("array", "zeros", "ones", "full", "empty", "arange", "linspace", "eye", "asarray")
        ),
        *("range", "list", "tuple", "dict", "set", "frozenset", "int", "float", "str", "bool", "len"),
    }
)
"""Calls an assignment may make and still run at import: constructors that cost nothing and are how real
notebooks set up shared state (``env = gym.make("CartPole-v0")``, ``q = np.zeros((500, 6))``); their
arguments must be safe values."""
KEPT_DECORATORS: frozenset[str] = frozenset(
    {
        "staticmethod", "classmethod", "property", "functools.lru_cache", "functools.cache",
        "functools.cached_property", "functools.total_ordering", "functools.singledispatch",
        "dataclasses.dataclass", "abc.abstractmethod", "typing.overload", "typing.final", "numba.jit",
        "numba.njit",
    }
)  # fmt: skip
"""Library decorators that only wrap or register what they decorate; any other decorator is dropped (the
definition is graded undecorated), since applying it runs its code on the student's function at import
(``@timeit.timeit`` calls it; a student's own ``@timer`` is the student's code)."""
UNSAFE_MODULES = frozenset({"__main__", "submission"})
"""Modules whose import yields the student's own module (`grader.sandbox.child.importer.MODULE_NAME`,
which a test holds equal; importing the sandbox package here would cost the reading child half a second)."""
CLASS_HOOKS = frozenset({"__init_subclass__"})
"""Methods a class body may define that run when the class is subclassed."""
HOOKED_BASES = ("enum.",)
"""Library bases whose metaclass calls the class's own methods when it is created (Enum members)."""
_BUILTIN_NAMES = frozenset(dir(builtins))


@dataclass
class Scope:
    """The kinds of the names a module (or a class body, whose parent is the module) has bound so far."""

    kinds: dict[str, Kind] = field(default_factory=dict)
    aliases: dict[str, str] = field(default_factory=dict)
    parent: Scope | None = None

    def lookup(self, name: str) -> Kind | None:
        """The name's kind, None when nothing kept has bound it."""
        if name in self.kinds:
            return self.kinds[name]
        if self.parent is not None:
            return self.parent.lookup(name)
        return Kind.SAFE if name in _BUILTIN_NAMES else None

    def canonical(self, node: ast.expr) -> str | None:
        """``np.zeros`` -> ``numpy.zeros`` when the dotted name's head is an import or builtin kept as is."""
        dotted = dotted_name(node)
        if dotted is None:
            return None
        head, _, rest = dotted.partition(".")
        if self.lookup(head) is not Kind.SAFE:
            return None
        base = self._alias(head) or (head if head in _BUILTIN_NAMES and self._unbound_here(head) else None)
        if base is None:
            return None
        return f"{base}.{rest}" if rest else base

    def _alias(self, head: str) -> str | None:
        if head in self.kinds:
            return self.aliases.get(head)
        return self.parent._alias(head) if self.parent is not None else None

    def _unbound_here(self, head: str) -> bool:
        return head not in self.kinds and (self.parent is None or self.parent._unbound_here(head))

    def bind(self, name: str, kind: Kind, alias: str | None = None) -> None:
        """Record what a kept statement bound ``name`` to."""
        self.kinds[name] = kind
        if alias is None:
            self.aliases.pop(name, None)
        else:
            self.aliases[name] = alias


def dotted_name(node: ast.expr) -> str | None:
    """``a.b.c`` for a chain of attributes on a name, else None."""
    if isinstance(node, ast.Name):
        return node.id
    if isinstance(node, ast.Attribute):
        inner = dotted_name(node.value)
        return f"{inner}.{node.attr}" if inner else None
    return None


def join(kinds: Iterable[Kind]) -> Kind:
    """The kind of a value that may be any of ``kinds``: the same kind, or one that is only stored."""
    distinct = set(kinds)
    return distinct.pop() if len(distinct) == 1 else Kind.STUDENT


def evaluate(node: ast.expr, scope: Scope) -> Kind | None:
    """The kind of value ``node`` evaluates to, or None when evaluating it may run student code (or reads
    a name no kept statement set)."""
    kind = _evaluate(node, scope)
    return kind


def _safe(node: ast.expr | None, scope: Scope) -> bool:
    return node is None or _evaluate(node, scope) is Kind.SAFE


def _stored(node: ast.expr | None, scope: Scope) -> bool:
    return node is None or _evaluate(node, scope) is not None


def _evaluate(node: ast.expr, scope: Scope) -> Kind | None:
    match node:
        case ast.Constant():
            return Kind.SAFE
        case ast.Name():
            return scope.lookup(node.id)
        case ast.Attribute():
            value = _evaluate(node.value, scope)
            if value is Kind.PROPERTY and node.attr in ("setter", "getter", "deleter"):
                return Kind.SAFE
            return Kind.SAFE if value is Kind.SAFE else None
        case ast.Subscript():
            # The container is library code, but what it holds may be anything (sys.modules["submission"]).
            return Kind.STUDENT if _safe(node.value, scope) and _safe(node.slice, scope) else None
        case ast.Slice():
            return (
                Kind.SAFE if all(_safe(part, scope) for part in (node.lower, node.upper, node.step)) else None
            )
        case ast.BinOp():
            return Kind.SAFE if _safe(node.left, scope) and _safe(node.right, scope) else None
        case ast.UnaryOp():
            return Kind.SAFE if _safe(node.operand, scope) else None
        case ast.BoolOp():
            return Kind.SAFE if all(_safe(value, scope) for value in node.values) else None
        case ast.Compare():
            return Kind.SAFE if all(_safe(part, scope) for part in [node.left, *node.comparators]) else None
        case ast.IfExp():
            branches = [_evaluate(node.body, scope), _evaluate(node.orelse, scope)]
            if not _safe(node.test, scope) or None in branches:
                return None
            return join(kind for kind in branches if kind is not None)
        case ast.Tuple() | ast.List():
            return _sequence(node.elts, scope)
        case ast.Set():
            return Kind.SAFE if all(_safe(_unstarred(element), scope) for element in node.elts) else None
        case ast.Dict():
            if not all(_safe(key, scope) for key in node.keys):
                return None
            values = [_evaluate(value, scope) for value in node.values]
            unpacked = [value for key, value in zip(node.keys, node.values, strict=True) if key is None]
            if None in values or not all(_safe(value, scope) for value in unpacked):
                return None
            return join(kind for kind in values if kind is not None) if values else Kind.SAFE
        case ast.Call():
            return _call(node, scope)
        case ast.JoinedStr():
            return Kind.SAFE if all(_safe(value, scope) for value in node.values) else None
        case ast.FormattedValue():
            return Kind.SAFE if _safe(node.value, scope) and _safe(node.format_spec, scope) else None
        case ast.Lambda():
            defaults = [*node.args.defaults, *node.args.kw_defaults]
            return Kind.STUDENT if all(_stored(default, scope) for default in defaults) else None
        case ast.ListComp() | ast.SetComp() | ast.GeneratorExp() | ast.DictComp():
            return _comprehension(node, scope)
    return None  # NamedExpr, Await, Yield, YieldFrom, a bare Starred, and any kind not known here


def _unstarred(node: ast.expr) -> ast.expr:
    return node.value if isinstance(node, ast.Starred) else node


def _sequence(elements: Sequence[ast.expr], scope: Scope) -> Kind | None:
    kinds: list[Kind] = []
    for element in elements:
        if isinstance(element, ast.Starred):  # unpacking iterates the value
            if not _safe(element.value, scope):
                return None
            kinds.append(Kind.SAFE)
        else:
            kind = _evaluate(element, scope)
            if kind is None:
                return None
            kinds.append(kind)
    return Kind.SAFE if all(kind is Kind.SAFE for kind in kinds) else Kind.STUDENT


def _call(node: ast.Call, scope: Scope) -> Kind | None:
    if scope.canonical(node.func) not in CHEAP_CALLS:
        return None
    arguments = [_unstarred(argument) for argument in node.args] + [
        keyword.value for keyword in node.keywords
    ]
    return Kind.SAFE if all(_safe(argument, scope) for argument in arguments) else None


def _comprehension(
    node: ast.ListComp | ast.SetComp | ast.GeneratorExp | ast.DictComp, scope: Scope
) -> Kind | None:
    inner = Scope(parent=scope)
    for generator in node.generators:
        if generator.is_async or not _safe(generator.iter, inner):
            return None
        targets = list(ast.walk(generator.target))
        if not all(
            isinstance(target, ast.Name | ast.Tuple | ast.List | ast.expr_context) for target in targets
        ):
            return None  # a target such as `obj.attr` or `d[k]` assigns into an object
        for target in targets:
            if isinstance(target, ast.Name):
                inner.bind(target.id, Kind.SAFE)
        if not all(_safe(condition, inner) for condition in generator.ifs):
            return None
    parts = [node.key, node.value] if isinstance(node, ast.DictComp) else [node.elt]
    return Kind.SAFE if all(_safe(part, inner) for part in parts) else None


def decorator_kept(decorator: ast.expr, scope: Scope) -> bool:
    """True for a library decorator that only wraps (`KEPT_DECORATORS`, bare or called with safe
    arguments, or ``@name.setter`` of a property)."""
    if isinstance(decorator, ast.Attribute) and _evaluate(decorator.value, scope) is Kind.PROPERTY:
        return decorator.attr in ("setter", "getter", "deleter")
    target = decorator.func if isinstance(decorator, ast.Call) else decorator
    if scope.canonical(target) not in KEPT_DECORATORS:
        return False
    if isinstance(decorator, ast.Call):
        arguments = [_unstarred(a) for a in decorator.args] + [
            keyword.value for keyword in decorator.keywords
        ]
        return all(_safe(argument, scope) for argument in arguments)
    return True


def annotations_of(arguments: ast.arguments, returns: ast.expr | None) -> list[ast.expr]:
    """Every annotation of a signature (evaluated when the ``def`` runs, unless postponed)."""
    every = [*arguments.posonlyargs, *arguments.args, *arguments.kwonlyargs]
    every += [argument for argument in (arguments.vararg, arguments.kwarg) if argument is not None]
    return [annotation for annotation in [*(a.annotation for a in every), returns] if annotation is not None]


def stored_ok(node: ast.expr | None, scope: Scope) -> bool:
    """True when ``node`` may be evaluated to be stored (a default, an annotation, an assigned value)."""
    return _stored(node, scope)


def safe(node: ast.expr | None, scope: Scope) -> bool:
    """True when ``node`` may be evaluated and operated on (a test, a base, an iterated value)."""
    return _safe(node, scope)


def import_kind(module: str | None, level: int) -> Kind:
    """The kind of a name an import binds: the student's own module (or a relative import) is not safe."""
    if level or module is None or module.split(".")[0] in UNSAFE_MODULES:
        return Kind.STUDENT
    return Kind.SAFE


def hooked_base(base: ast.expr, scope: Scope) -> bool:
    """True for a library base whose metaclass runs the new class's own methods (Enum)."""
    name = scope.canonical(base) or ""
    return name.startswith(HOOKED_BASES)
