"""`from IPython.display import clear_output` in the child without importing IPython, until more is used.

The lab's notebooks import `clear_output` (or `display`) from `IPython.display`. Importing IPython costs
about 0.35 s of CPU (prompt_toolkit, the terminal shell), more than the rest of a child's start, and a
grading starts a child per problem. Outside a running IPython shell, which the child never is, those two
functions only print: `clear_output` writes the terminal's clear-line sequence twice and `display`
prints its objects. `LightIPython`, first on `sys.meta_path`, serves `IPython` and `IPython.display` as
small modules with exactly that behaviour. Anything else (`IPython.display.HTML`, `IPython.get_ipython`,
`import IPython.core...`) loads the real IPython at that moment, which from then on answers for both
modules: the student's code sees IPython's own objects for everything but the two functions.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import sys
from collections.abc import Sequence
from importlib.machinery import ModuleSpec
from types import ModuleType
from typing import Any

PACKAGE = "IPython"
DISPLAY = "IPython.display"
_CLEAR_LINE = "\033[2K\r"


def clear_output(wait: bool = False) -> None:
    """What `IPython.display.clear_output` does outside an IPython shell (IPython 8: it prints the
    terminal's clear-line sequence twice, flushing stdout and stderr)."""
    print(_CLEAR_LINE, end="")
    sys.stdout.flush()
    print(_CLEAR_LINE, end="")
    sys.stderr.flush()


def display(*objs: Any, **kwargs: Any) -> None:
    """What `IPython.display.display` does outside an IPython shell: print the objects, return None."""
    print(*objs)


class LightIPython(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Serves the light `IPython` and `IPython.display` until something else of IPython is wanted.

    It serves nothing when IPython is not installed (the compat layer's stand-in answers then) or when
    `IPython` on `sys.path` is not IPython's package (a student's own `IPython.py`), and nothing once the
    real IPython is loaded. It stays on `sys.meta_path` either way: the import system iterates that very
    list while asking it, so removing an entry there would skip the next finder.
    """

    def __init__(self) -> None:
        real = importlib.machinery.PathFinder.find_spec(PACKAGE)
        # Only IPython's package: a module of the student's own named IPython is theirs to import.
        self._locations = list(real.submodule_search_locations or []) if real is not None else []
        self.light = bool(self._locations)

    def find_spec(
        self, fullname: str, path: Sequence[str] | None, target: ModuleType | None = None
    ) -> ModuleSpec | None:
        if not self.light or not (fullname == PACKAGE or fullname.startswith(PACKAGE + ".")):
            return None
        if fullname in (PACKAGE, DISPLAY):
            return importlib.machinery.ModuleSpec(fullname, self, is_package=fullname == PACKAGE)
        self.load_real()  # another part of IPython is imported: the real IPython from now on
        # IPython's own import may have loaded the module already. Left in sys.modules, the import system
        # would load it a second time; handed over by `_AlreadyLoaded`, it stays the one module.
        module = sys.modules.pop(fullname, None)
        if module is None:
            return None  # the path finder, next on `sys.meta_path`, finds it in IPython's directory
        return importlib.machinery.ModuleSpec(
            fullname, _AlreadyLoaded(module), is_package=hasattr(module, "__path__")
        )

    def create_module(self, spec: ModuleSpec) -> ModuleType:
        module = ModuleType(spec.name)
        module.__getattr__ = self._forward(spec.name)  # type: ignore[method-assign]
        if spec.name == PACKAGE:
            module.__path__ = list(self._locations)
        else:
            module.clear_output = clear_output  # type: ignore[attr-defined]
            module.display = display  # type: ignore[attr-defined]
        return module

    def exec_module(self, module: ModuleType) -> None:
        if module.__name__ == PACKAGE:
            module.display = importlib.import_module(DISPLAY)  # type: ignore[attr-defined]

    def load_real(self) -> None:
        """Import the real IPython (once): from now on `sys.modules` holds its modules."""
        if not self.light:
            return
        self.light = False
        for name in (DISPLAY, PACKAGE):
            if getattr(sys.modules.get(name), "__loader__", None) is self:
                del sys.modules[name]
        importlib.import_module(PACKAGE)
        importlib.import_module(DISPLAY)

    def _forward(self, name: str) -> Any:
        def forward(attribute: str) -> Any:
            if attribute in _NOT_FORWARDED:
                raise AttributeError(f"module {name!r} has no attribute {attribute!r}")
            self.load_real()
            real = sys.modules[name]
            if attribute == "__all__" and not hasattr(real, "__all__"):
                # `import *` of a module without `__all__` takes its public names: the real module's.
                return [public for public in vars(real) if not public.startswith("_")]
            return getattr(real, attribute)

        return forward


_NOT_FORWARDED = frozenset({"__path__", "__file__", "__cached__", "__wrapped__"})
"""Names the import system and introspection probe on any module: answered without loading IPython."""


class _AlreadyLoaded(importlib.abc.Loader):
    """Hands the import system a module IPython's own import loaded already, as it is."""

    def __init__(self, module: ModuleType) -> None:
        self._module = module
        self._spec = module.__spec__

    def create_module(self, spec: ModuleSpec) -> ModuleType:
        return self._module

    def exec_module(self, module: ModuleType) -> None:
        module.__spec__ = self._spec  # the import system set ours on it
