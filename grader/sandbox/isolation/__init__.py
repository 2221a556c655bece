"""Isolation layers for sandboxed children, probed once per process into an `IsolationReport`."""

from __future__ import annotations

import functools
import os

from grader.sandbox.isolation import landlock
from grader.sandbox.isolation.bubblewrap import BubblewrapLayer
from grader.sandbox.isolation.cgroup import CgroupLayer
from grader.sandbox.isolation.filesystem import python_paths
from grader.sandbox.isolation.layer import IsolationReport, Layer, LayerReport
from grader.sandbox.isolation.privileges import PrivilegesLayer, running_as_root
from grader.sandbox.isolation.rlimits import RlimitsLayer
from grader.sandbox.isolation.seccomp import SeccompLayer

__all__ = ["LAYER_NAMES", "IsolationReport", "Layer", "LayerReport", "probe_isolation"]


def _landlock_report(bubblewrap_active: bool) -> LayerReport:
    if bubblewrap_active:
        return LayerReport(
            "landlock", False, "not needed: bubblewrap already hides the file system", required=False
        )
    abi = landlock.abi_version()
    if abi < 1:
        return LayerReport(
            "landlock",
            False,
            "unavailable: the file system is NOT hidden from student code",
            "use Linux >= 5.13 with Landlock enabled, or install bubblewrap",
            required=False,
        )
    network = "and TCP" if abi >= 4 else "(network NOT restricted: Landlock ABI < 4)"
    return LayerReport(
        "landlock",
        True,
        f"fallback (ABI {abi}): "
        f"reads limited to the interpreter and libraries, writes to the scratch directory, {network}",
        required=False,
    )


def _interpreter_readable_by_others() -> bool:
    return all(
        os.stat(root).st_mode & 0o005 == 0o005
        and all(os.stat(parent).st_mode & 0o001 for parent in root.parents)
        for root in python_paths().roots
    )


def _privileges_report(report: LayerReport, bubblewrap_active: bool) -> LayerReport:
    unreachable = not bubblewrap_active and not _interpreter_readable_by_others()
    if report.active and running_as_root() and unreachable:
        return LayerReport(
            "privileges",
            False,
            "running as root without bubblewrap, and the interpreter is not readable by an unprivileged uid: "
            "the child keeps root",
            "install bubblewrap, or install Python where every user can read it",
        )
    return report


LAYER_NAMES = ("cgroup", "bubblewrap", "seccomp", "privileges", "rlimits", "landlock")


@functools.cache
def _probed() -> tuple[LayerReport, ...]:
    layers: tuple[Layer, ...] = (
        CgroupLayer(),
        BubblewrapLayer(),
        SeccompLayer(),
        PrivilegesLayer(),
        RlimitsLayer(),
    )
    return tuple(layer.probe() for layer in layers)


def _switched_off(report: LayerReport) -> LayerReport:
    return LayerReport(
        report.name,
        False,
        f"switched off by the caller ({report.detail})",
        "do not switch this layer off",
        report.required,
    )


def probe_isolation(disable: frozenset[str] = frozenset()) -> IsolationReport:
    """Probes every layer (once per process) and reports what can be enforced, outermost first.

    Args:
        disable: Layers to leave off although available (to test or compare fallbacks); the layers that
            depend on them (privileges and Landlock depend on bubblewrap) are derived accordingly.

    Raises:
        ValueError: `disable` names an unknown layer.
    """
    unknown = set(disable) - set(LAYER_NAMES)
    if unknown:
        raise ValueError(f"unknown isolation layers {sorted(unknown)}; expected some of {list(LAYER_NAMES)}")
    probed = {report.name: report for report in _probed()}
    bubblewrap_active = probed["bubblewrap"].active and "bubblewrap" not in disable
    probed["privileges"] = _privileges_report(probed["privileges"], bubblewrap_active)
    probed["landlock"] = _landlock_report(bubblewrap_active)
    return IsolationReport(
        tuple(
            _switched_off(probed[name]) if name in disable and probed[name].active else probed[name]
            for name in LAYER_NAMES
        )
    )
