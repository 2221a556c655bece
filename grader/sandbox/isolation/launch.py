"""One child's start: the active layers each add their part to a `LaunchSpec`, composed into a `Launch`."""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from grader.sandbox.isolation import registry
from grader.sandbox.isolation.cgroup import JobCgroup
from grader.sandbox.isolation.filesystem import (
    ChildView,
    PythonPaths,
    harness_tree,
    host_view,
    python_paths,
    remove_host_scratch,
)
from grader.sandbox.isolation.layer import IsolationReport
from grader.sandbox.limits import Limits

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
    cgroup: JobCgroup | None = None
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
        rlimits: (name, soft, hard) resource limits the child sets on itself.
        landlock: Landlock rules ({"read": [...], "write": [...]}) the child restricts itself to.
        seccomp_fd: A descriptor holding a BPF program the child installs.
    """

    rlimits: list[tuple[str, int, int]] = field(default_factory=list)
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
            "MPLCONFIGDIR": f"{scratch}/.matplotlib",
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


def build_launch(
    report: IsolationReport,
    limits: Limits,
    *,
    submission: bytes,
    submission_name: str,
    requests_fd: int,
    results_fd: int,
    import_seed: int,
) -> Launch:
    """The command starting one child: every active layer of `report` applied in order, outermost first.

    Raises:
        OSError: when a layer that was probed as active fails now (the caller reports a sandbox error).
    """
    spec = LaunchSpec(report, limits, python_paths(), harness_tree(), submission, submission_name)
    active = {layer.name for layer in report.layers if layer.active}
    try:
        for layer in registry.LAYERS:
            if layer.name in active:
                layer.apply(spec)
        harness_argv = [
            "--submission",
            spec.child_view().submission,
            "--requests",
            str(requests_fd),
            "--results",
            str(results_fd),
            "--max-frame",
            str(limits.frame_bytes),
            "--seed",
            str(import_seed),
        ]
        return spec.compose(harness_argv)
    except BaseException:
        spec.launch.cleanup()
        raise
