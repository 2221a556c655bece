"""The isolation layers' contract: `Layer` (probe, then apply), what a layer reports and the report, and
the `LaunchSpec` every active layer adds its part to, composed into a `Launch`.

`launch.py` composes a child's start from the layers listed in `registry.py`; each layer's module imports
this contract only, never the composer.

Besides `Layer`, `LayerReport` and `IsolationReport`, the contract holds the `LaunchSpec`/`BootstrapSteps`/
`Launch` a layer adds its part to, and `ChildJob`, what a launch needs of the cgroup layer's job. The
grading's scope (`scope.py`) knows no layer: it runs the cleanups layers register for what they record
(`register_cleanup(kind, cleanup)`).
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol

from grader.sandbox import process_model
from grader.sandbox.host import HOST, Feature
from grader.sandbox.isolation.filesystem import ChildView, PythonPaths, host_view, remove_host_scratch
from grader.sandbox.limits import Limits


@dataclass(frozen=True)
class LayerReport:
    """Whether one layer of isolation is enforced on this machine.

    Attributes:
        name: The layer ("cgroup", "privileges", "bubblewrap", "seccomp", "rlimits", "landlock").
        active: Whether the layer is applied to every child.
        detail: What the layer enforces, or why it cannot.
        remedy: How to make an inactive layer available (empty when active or not applicable).
        required: Whether `IsolationPolicy.REQUIRE_FULL` needs this layer active.
    """

    name: str
    active: bool
    detail: str
    remedy: str = ""
    required: bool = True


class Layer(Protocol):
    """One isolation layer: probed on this machine, then applied to the start of every child while active.

    Implementations are listed once, outermost first, in `grader.sandbox.isolation.registry.LAYERS`.
    """

    name: str
    needs: tuple[Feature, ...]
    """What the layer needs of the operating system; where any is missing it is reported as not available
    on this system without being probed (`grader.sandbox.host`)."""
    guards: str
    """What the layer enforces, as the report names it when the layer cannot run here ("... not
    enforced")."""

    def probe(self, outer: IsolationReport) -> LayerReport:
        """What the layer can enforce here and, when nothing, the remedy (no side effects left behind).

        Args:
            outer: The reports of the layers listed before this one, already switched off as the caller
                asked (a layer that depends on another reads it here). Costly machine checks are cached.
        """
        ...

    def apply(self, spec: LaunchSpec) -> None:
        """Adds the layer's part to one child's start (called only while the layer is active).

        Raises:
            OSError: when the layer, probed as active, cannot be applied now.
        """
        ...


@dataclass(frozen=True)
class IsolationReport:
    """Which layers of isolation protect the children of one `Sandbox`.

    Attributes:
        layers: One report per layer, in the order they wrap the child (outermost first).
    """

    layers: tuple[LayerReport, ...]

    @property
    def full(self) -> bool:
        """True when every required layer is active."""
        return not self.missing

    @property
    def missing(self) -> tuple[LayerReport, ...]:
        """The required layers that are not active."""
        return tuple(layer for layer in self.layers if layer.required and not layer.active)

    def layer(self, name: str) -> LayerReport:
        """The report of the layer called `name` (KeyError when there is no such layer)."""
        for layer in self.layers:
            if layer.name == name:
                return layer
        raise KeyError(name)

    def is_active(self, name: str) -> bool:
        """Whether the layer called `name` is active."""
        return self.layer(name).active

    def summary(self) -> str:
        """One line per layer: `[x] name: detail` or `[ ] name: detail (remedy)`."""
        lines = []
        for layer in self.layers:
            mark = "x" if layer.active else " "
            remedy = f" -- {layer.remedy}" if layer.remedy and not layer.active else ""
            lines.append(f"[{mark}] {layer.name}: {layer.detail}{remedy}")
        return "\n".join(lines)

    def to_dict(self) -> dict[str, object]:
        """Plain data for reports and the HTTP service."""
        return {
            "full": self.full,
            "layers": [
                {
                    "name": layer.name,
                    "active": layer.active,
                    "required": layer.required,
                    "detail": layer.detail,
                    "remedy": layer.remedy,
                }
                for layer in self.layers
            ],
        }


class ChildJob(Protocol):
    """What a launch needs of the group a layer puts the child's whole process tree in (the cgroup layer's
    `JobCgroup`)."""

    def oom_kills(self) -> int:
        """How many processes the kernel killed for exceeding the memory limit."""
        ...

    def kill(self, timeout: float = 2.0) -> bool:
        """SIGKILLs every process in the job until it is empty; False when some survived `timeout`."""
        ...

    def remove(self) -> bool:
        """Kills what is left and removes the job; False when something stayed behind."""
        ...


Wrapper = Callable[["LaunchSpec"], list[str]]
"""A command prefix (ending in its own ``--``), built from the finished spec when the launch is composed."""


@dataclass
class Launch:
    """Everything needed to start one child and to clean up after it.

    Attributes:
        argv: The full command.
        env: The environment given to the first process of `argv`.
        pass_fds: Descriptors the first process inherits (besides the request/result pipes).
        cgroup: The child's job cgroup, when the cgroup layer is active.
        scratch: The host directory used as scratch when no layer gives the child a private one.
        signals_in_exit_status: Whether the outermost wrapper exits with 128 + N when the child was
            killed by signal N (bubblewrap does).
        cwd: The working directory of the first process (the scratch without bubblewrap).
    """

    argv: list[str]
    env: dict[str, str]
    pass_fds: list[int] = field(default_factory=list)
    cgroup: ChildJob | None = None
    scratch: Path | None = None
    signals_in_exit_status: bool = False
    cwd: str | None = None

    def close_descriptors(self) -> None:
        """Closes the descriptors only the child needed (call once the child has started)."""
        for descriptor in self.pass_fds:
            with contextlib.suppress(OSError):
                os.close(descriptor)
        self.pass_fds = []

    def cleanup(self) -> bool:
        """Kills whatever is left in the cgroup and removes it and the scratch; False if anything stayed."""
        self.close_descriptors()
        clean = self.cgroup.remove() if self.cgroup is not None else True
        if self.scratch is not None:
            remove_host_scratch(self.scratch)
        return clean


@dataclass
class BootstrapSteps:
    """The child-side steps bootstrap.py knows, run in this order before the harness; off until set.

    Attributes:
        no_new_privileges: Whether the child sets Linux's no-new-privileges first (on for every child where
            the kernel has it).
        rlimits: (name, soft, hard) resource limits the child sets on itself.
        rlimits_may_fail: Whether a limit the system refuses is only named on stderr (outside Linux, where
            not every limit exists in every kernel) instead of stopping the child.
        landlock: Landlock rules ({"read": [...], "write": [...]}) the child restricts itself to.
        seccomp_fd: A descriptor holding a BPF program the child installs.
    """

    no_new_privileges: bool = field(default_factory=lambda: HOST.has(Feature.LINUX_KERNEL))
    rlimits: list[tuple[str, int, int]] = field(default_factory=list)
    rlimits_may_fail: bool = field(default_factory=lambda: not HOST.has(Feature.LINUX_KERNEL))
    landlock: dict[str, list[str]] | None = None
    seccomp_fd: int | None = None


@dataclass
class LaunchSpec:
    """One child's start while the active layers add their parts, outermost layer first.

    Layers read the first six attributes and add to the others.

    Attributes:
        isolation: The probed layers (a layer that depends on another asks `isolation.is_active`).
        limits: The limits in force.
        paths: The interpreter and its directories (`python_paths()`).
        tree: The harness tree on the host (`harness_tree()`).
        submission: The submission's bytes.
        submission_name: The submission's file name as the child sees it.
        wrappers: Command prefixes, outermost first (cgroup join, bwrap, setpriv), built when composed.
        environment: Variables the layers add to the child's environment.
        bootstrap: The child-side steps bootstrap.py runs before the harness (a wrapper that performs
            one itself, earlier, takes it from here).
        view: The child's file system as chosen by a layer (`child_view()` falls back to the host's).
        process_env: The first process's environment when a wrapper sets the child's own (None: the
            child's environment itself).
        launch: The resources to release afterwards (descriptors, cgroup, scratch) and the result.
    """

    isolation: IsolationReport
    limits: Limits
    paths: PythonPaths
    tree: Path
    submission: bytes
    submission_name: str
    wrappers: list[Wrapper] = field(default_factory=list)
    environment: dict[str, str] = field(default_factory=dict)
    bootstrap: BootstrapSteps = field(default_factory=BootstrapSteps)
    view: ChildView | None = None
    process_env: dict[str, str] | None = None
    launch: Launch = field(default_factory=lambda: Launch(argv=[], env={}))

    def provide_view(self, view: ChildView) -> None:
        """Gives the child a private file system (one layer may; before any layer reads `child_view()`)."""
        if self.view is not None:
            raise RuntimeError(
                f"a second view of the file system was provided ({view.scratch}) after {self.view.scratch}; "
                "only one layer may give the child its file system, listed before the layers reading it"
            )
        self.view = view

    def child_view(self) -> ChildView:
        """The child's file system: the one a layer provided, else (made on first use) the host's."""
        if self.view is None:
            self.view = host_view(self.tree, self.submission, self.submission_name)
            self.launch.scratch = self.view.host_scratch
        return self.view

    def child_environment(self) -> dict[str, str]:
        """The whole environment of the child: the base for its scratch, then what layers added."""
        scratch = self.child_view().scratch
        return {
            "PATH": "/usr/bin:/bin",
            "HOME": scratch,
            "TMPDIR": scratch,
            "LANG": "C.UTF-8",
            "PYTHONHASHSEED": "0",
            "PYTHONDONTWRITEBYTECODE": "1",
            "PYTHONUTF8": "1",
            "MPLCONFIGDIR": f"{scratch}/.matplotlib",
            **process_model.system_environment(),
            **self.environment,
        }

    def compose(self, harness_argv: list[str]) -> Launch:
        """The finished launch: the wrappers (built first: they may take steps), then the interpreter
        running the bootstrap with the remaining steps and the harness's arguments."""
        view = self.child_view()
        prefix = [argument for wrapper in self.wrappers for argument in wrapper(self)]
        config = {
            "sys_path": [f"{view.harness}/lib", *self.paths.stdlib, *self.paths.site_dirs],
            **dataclasses.asdict(self.bootstrap),
            "harness_argv": harness_argv,
        }
        inner = [str(self.paths.executable), "-S", "-B", f"{view.harness}/bootstrap.py", json.dumps(config)]
        self.launch.argv = [*prefix, *inner]
        self.launch.env = self.child_environment() if self.process_env is None else self.process_env
        self.launch.cwd = view.cwd
        return self.launch
