"""What this operating system offers gymgrade: the one module that reads the platform.

The check path runs wherever CPython 3.11+ runs (Linux, macOS, Windows). Everything POSIX- or Linux-only
it uses (the `resource`, `pwd` modules; `fork`, sessions and process groups, `SIGKILL`; `/proc`,
cgroups, namespaces, seccomp, Landlock; CPU affinity) is reached through the facts declared here, each
found by asking for the capability itself (not by the platform's name), so that a Python lacking one
is served the same way whatever it calls itself. An isolation layer names the features it needs
(`needs`); the probe reports a layer whose features are missing as "not available on this system"
without running it. How a child process is started and ended follows from the same facts
(`grader.sandbox.process_model`).

In detail:

- `grader/sandbox/host.py` is the one place that reads the platform: `HOST.system` ("Linux", "macOS",
  "Windows") and `HOST.features`, each found by asking for the capability (`POSIX_PROCESSES`: fork,
  killpg, setsid, SIGKILL; `RESOURCE_LIMITS`; `USER_IDS`: geteuid and pwd; `LINUX_KERNEL`: Linux with
  POSIX processes; `CPU_AFFINITY`; `WINDOWS_HANDLES`: msvcrt and _winapi; `FILE_LOCKS`: fcntl's flock,
  which proves who owns a job's cgroup or harness tree, `grader.sandbox.isolation.ownership`), plus
  `usable_cpus()` and `signal_number(name)` (None where a signal does not exist). Nothing else under
  `grader/` tests `sys.platform` or imports `resource`/`pwd` at module level.
- Each layer declares `needs: tuple[Feature, ...]` (cgroup, bubblewrap, seccomp, Landlock: `LINUX_KERNEL`;
  privileges: `USER_IDS`; rlimits: `RESOURCE_LIMITS`) and `guards` (what it enforces); `probe_isolation`
  reports a layer whose needs are missing as "not available on this system (<system> without
  <feature>): <guards> not enforced" without probing it. The
  bootstrap imports `resource` only for an rlimit step and sets no-new-privileges only when the parent
  asks (`BootstrapSteps.no_new_privileges`, `rlimits_may_fail`: off Linux a refused limit is named on
  the child's stderr).
- `grader/sandbox/process_model.py` decides how a child is started, read and ended (`MODEL`): `posix`
  (`pass_fds`, a new session, `killpg(SIGKILL)`, pipes waited on with `selectors`), `windows` (the
  pipes as inheritable handles in `STARTUPINFO`'s handle list, `--handles` on the harness's command
  line, `Popen.kill()`, pipes polled with PeekNamedPipe) and `inherited` (no `pass_fds` and no handles:
  inheritable descriptors with `close_fds=False`, `Popen.kill()`; the Windows-shaped test runs use it).
  `ChildProcess` (`process.py`) calls `start`, `end`, `read_available` and `pipe_selector` only;
  `exists(pid)` asks, where there are no file locks, whether a grader that left a harness tree still
  runs (Windows' `os.kill(pid, 0)` would end it). On Windows the request pipe is written blocking
  (frames are sent to an idle child). The
  child's environment adds `PYTHONUTF8=1` (and, on Windows, `SYSTEMROOT` and the like), so a student's
  text is UTF-8 whatever the locale. The wall-clock limit per call is the parent's and holds on every
  system; memory and CPU limits hold where the rlimits or cgroup layer is active, and the report's
  isolation lines say when they are not.
- `tests/grader/test_portable.py` runs `check` under interpreters shaped like Windows' and macOS'
  CPython (`tests/grader/shaped_python/`) and compares statuses, scores and measurements with this
  machine's; `.github/workflows/portable.yml` runs the same on real Windows and macOS runners.
"""

from __future__ import annotations

import importlib.util
import os
import signal
import sys
from dataclasses import dataclass
from enum import StrEnum


class Feature(StrEnum):
    """Something of the operating system a part of the sandbox needs; the value says it to a person."""

    POSIX_PROCESSES = "POSIX processes (fork, inherited descriptors, sessions, SIGKILL)"
    RESOURCE_LIMITS = "resource limits (the resource module)"
    USER_IDS = "user ids (os.geteuid, the pwd module)"
    LINUX_KERNEL = "Linux kernel features (/proc, cgroups, namespaces, seccomp, Landlock)"
    CPU_AFFINITY = "CPU affinity (os.sched_getaffinity)"
    WINDOWS_HANDLES = "Windows handles (msvcrt, _winapi)"
    FILE_LOCKS = "file locks (fcntl.flock)"


def _importable(name: str) -> bool:
    try:
        return importlib.util.find_spec(name) is not None
    except (ImportError, ValueError):
        return False


def _detect() -> frozenset[Feature]:
    found: set[Feature] = set()
    process_calls = ("fork", "killpg", "setsid", "getpgid", "set_blocking")
    if os.name == "posix" and all(hasattr(os, name) for name in process_calls) and hasattr(signal, "SIGKILL"):
        found.add(Feature.POSIX_PROCESSES)
    if _importable("resource"):
        found.add(Feature.RESOURCE_LIMITS)
    if hasattr(os, "geteuid") and _importable("pwd"):
        found.add(Feature.USER_IDS)
    if sys.platform.startswith("linux") and Feature.POSIX_PROCESSES in found:
        found.add(Feature.LINUX_KERNEL)
    if hasattr(os, "sched_getaffinity"):
        found.add(Feature.CPU_AFFINITY)
    if _importable("msvcrt") and _importable("_winapi"):
        found.add(Feature.WINDOWS_HANDLES)
    if _importable("fcntl"):
        found.add(Feature.FILE_LOCKS)
    return frozenset(found)


def _system_name() -> str:
    if sys.platform.startswith("linux"):
        return "Linux"
    return {"darwin": "macOS", "win32": "Windows"}.get(sys.platform, sys.platform)


@dataclass(frozen=True)
class Host:
    """The operating system this process runs on, as far as gymgrade is concerned.

    Attributes:
        system: "Linux", "macOS", "Windows", or `sys.platform` for another.
        features: What it offers of `Feature`.
    """

    system: str
    features: frozenset[Feature]

    def has(self, feature: Feature) -> bool:
        """Whether this system offers `feature`."""
        return feature in self.features

    def lacking(self, needs: tuple[Feature, ...]) -> tuple[Feature, ...]:
        """The features of `needs` this system does not offer, in the order given."""
        return tuple(feature for feature in needs if feature not in self.features)

    def unavailable_detail(self, needs: tuple[Feature, ...]) -> str:
        """The report's line for a layer whose features are missing here."""
        missing = "; ".join(feature.value for feature in self.lacking(needs))
        return f"not available on this system ({self.system} without {missing})"


HOST = Host(_system_name(), _detect())
"""This process's system, read once at import."""


def usable_cpus() -> int:
    """The CPUs this process may run on (its affinity where the system has one), at least 1."""
    if HOST.has(Feature.CPU_AFFINITY):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1


def signal_number(name: str) -> int | None:
    """The number of the signal called `name` ("SIGXCPU"), or None where the system has no such signal."""
    value = getattr(signal, name, None)
    return int(value) if value is not None else None
