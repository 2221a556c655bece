"""What this operating system offers gymgrade: the one module that reads the platform.

The check path runs wherever CPython 3.11+ runs (Linux, macOS, Windows). Everything POSIX- or Linux-only
it uses (the `resource`, `pwd` modules; `fork`, sessions and process groups, `SIGKILL`; `/proc`,
cgroups, namespaces, seccomp, Landlock; CPU affinity) is reached through the facts declared here, each
found by asking for the capability itself (not by the platform's name), so that a Python lacking one
is served the same way whatever it calls itself. An isolation layer names the features it needs
(`needs`); the probe reports a layer whose features are missing as "not available on this system"
without running it. How a child process is started and ended follows from the same facts
(`grader.sandbox.process_model`).
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
