"""`gymgrade doctor`: the interpreter, the sandbox's binds and layers and the student modules on this machine.

An instructor runs it before a deadline: each missing layer comes with why and what to install, each
student module is imported inside a real sandbox child (as student code would), and a child's start time
is measured.
"""

from __future__ import annotations

import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from grader.sandbox import Call, IsolationPolicy, IsolationReport, OutcomeStatus, Sandbox, probe_isolation
from grader.sandbox.errors import SandboxLayoutError
from grader.sandbox.isolation.bubblewrap import MASKED_DIRS, interpreter_binds
from grader.sandbox.isolation.filesystem import SYSTEM_DIRS, PythonPaths, python_paths

_PROBE_SOURCE = """
import importlib


def student_modules(names):
    found = {}
    for name in names:
        try:
            module = importlib.import_module(name)
        except Exception as error:
            first_line = "".join(str(error).splitlines()[:1])[:300]
            found[name] = "! " + first_line + " (" + type(error).__name__ + ")"
        else:
            found[name] = str(getattr(module, "__version__", "")) or "importable"
    return found
"""
"""The child's side of the module check: each name, imported as a student's file would."""


@dataclass(frozen=True)
class ModuleCheck:
    """Whether one student module imports inside the sandbox.

    Attributes:
        name: The top-level module.
        version: Its `__version__` ("importable" without one); None when it cannot be imported.
        problem: Why it cannot be imported (empty when it can).
    """

    name: str
    version: str | None
    problem: str = ""


@dataclass(frozen=True)
class Diagnosis:
    """What `gymgrade doctor` found.

    Attributes:
        paths: The interpreter and its directories.
        binds: The directories bubblewrap binds for the interpreter, or why they cannot be bound.
        isolation: The layers, probed.
        modules: Each student module, checked in a sandbox child.
        child_seconds: Wall-clock seconds to start one child and import an empty file in it.
        import_seconds: Wall-clock seconds of that child importing every student module.
        sandbox_problem: Why the check could not run in a child (empty when it ran).
    """

    paths: PythonPaths
    binds: tuple[Path, ...] | str
    isolation: IsolationReport
    modules: tuple[ModuleCheck, ...]
    child_seconds: float
    import_seconds: float
    sandbox_problem: str = ""

    @property
    def healthy(self) -> bool:
        """True when every layer is active and every student module imports."""
        modules_ok = all(module.version is not None for module in self.modules)
        return self.isolation.full and modules_ok and not self.sandbox_problem


def _binds(paths: PythonPaths) -> tuple[Path, ...] | str:
    system = tuple(Path(d) for d in SYSTEM_DIRS if Path(d).is_dir() and not Path(d).is_symlink())
    try:
        return interpreter_binds(paths.roots, system, tuple(map(Path, MASKED_DIRS)))
    except SandboxLayoutError as error:
        return str(error)


def diagnose(student_modules: Sequence[str]) -> Diagnosis:
    """Probes the layers and checks `student_modules` in one sandbox child (the strongest available).

    Args:
        student_modules: Top-level module names (an assignment's `[sandbox] student_modules`).
    """
    paths = python_paths()
    isolation = probe_isolation()
    modules: tuple[ModuleCheck, ...] = ()
    child_seconds = import_seconds = 0.0
    problem = ""
    with tempfile.TemporaryDirectory(prefix="gymgrade-doctor-") as directory:
        probe = Path(directory) / "doctor_probe.py"
        probe.write_text(_PROBE_SOURCE, encoding="utf-8")
        with Sandbox(probe, seed=0, policy=IsolationPolicy.ALLOW_FALLBACK, isolation=isolation) as sandbox:
            started = time.perf_counter()
            ready = "student_modules" in sandbox.functions
            child_seconds = time.perf_counter() - started
            outcome = sandbox.call(Call("student_modules", (list(student_modules),), record_episodes=False))
            import_seconds = outcome.wall_time
    if not ready or outcome.status is not OutcomeStatus.OK or not isinstance(outcome.value, dict):
        problem = f"a sandbox child could not run the check ({outcome.status}): {outcome.message}"
    else:
        modules = tuple(
            ModuleCheck(name, None, str(found)[2:])
            if str(found).startswith("! ")
            else ModuleCheck(name, str(found))
            for name, found in outcome.value.items()
        )
    return Diagnosis(paths, _binds(paths), isolation, modules, child_seconds, import_seconds, problem)


def render(diagnosis: Diagnosis) -> str:
    """The diagnosis as the lines `gymgrade doctor` prints."""
    paths = diagnosis.paths
    lines = [
        f"Interpreter: {paths.executable} (Python {sys.version.split()[0]}, prefix {sys.prefix}, "
        f"base prefix {sys.base_prefix})",
        "Child's sys.path (stdlib, then site directories):",
        *(f"  {entry}" for entry in (*paths.stdlib, *paths.site_dirs)),
        f"Bound read-only by bubblewrap besides {', '.join(SYSTEM_DIRS)} (without {MASKED_DIRS[0]}):",
    ]
    if isinstance(diagnosis.binds, str):
        lines.append(f"  cannot bind: {diagnosis.binds}")
    else:
        lines += [f"  {bind}" for bind in diagnosis.binds] or ["  (nothing more: /usr holds the interpreter)"]
    lines += ["Hidden from the child (import hooks, installed copies of the project):"]
    lines += [f"  {hidden}" for hidden in paths.hidden] or ["  (none)"]
    lines += ["Isolation layers ([x] active, [ ] missing -- why and what to do):"]
    lines += [f"  {line}" for line in diagnosis.isolation.summary().splitlines()]
    if diagnosis.sandbox_problem:
        lines.append(f"Student modules: not checked: {diagnosis.sandbox_problem}")
    else:
        timing = f"start {diagnosis.child_seconds:.2f} s, imports {diagnosis.import_seconds:.2f} s"
        lines.append(f"Student modules, imported inside a sandbox child ({timing}):")
        for module in diagnosis.modules:
            if module.version is not None:
                lines.append(f"  [x] {module.name} {module.version}")
            else:
                remedy = f"install it into the environment of {paths.executable} (pyproject.toml's dependencies; `bash scripts/setup.sh`)"  # noqa: E501
                lines.append(f"  [ ] {module.name}: {module.problem} -- {remedy}")
    verdict = "ready to grade" if diagnosis.healthy else "NOT ready: fix what is marked [ ] above"
    lines.append(f"Verdict: {verdict}")
    return "\n".join(lines)
