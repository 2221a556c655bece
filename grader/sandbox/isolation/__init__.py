"""Isolation layers for sandboxed children: probed into an `IsolationReport`, applied by `build_launch`.

How layers plug in:

- **Isolation layers are plug-ins** (`grader/sandbox/isolation/`). Each layer is one module with a class
  implementing `layer.Layer` (the contract, with `LaunchSpec`, in `layer.py`): `name`, `probe(outer:
  IsolationReport) -> LayerReport` (what it enforces here, or why not and the remedy; `outer` holds the
  reports of the layers listed before it, already switched off as `disable` asks: privileges and Landlock read
  bubblewrap there; costly machine checks are cached per process) and `apply(spec: LaunchSpec)` (called only
  while active). `registry.LAYERS` is the one ordered list, outermost first: cgroup, bubblewrap, seccomp,
  privileges, rlimits, landlock; `probe_isolation(disable)` and `launch.build_launch` are loops over it, so
  the report's order and each child's wrapping follow it. A layer adds its part to the `LaunchSpec`:
  `wrappers` (command prefixes ending in `--`, built from the finished spec when composed: the cgroup join
  shell, bwrap, setpriv), `environment` (added to the child's), `bootstrap` (the child-side steps
  `bootstrap.py` runs before the harness: rlimits, Landlock rules, a seccomp descriptor), `launch.pass_fds`,
  `launch.cgroup` (placement, OOM counts, killing the tree), `launch.signals_in_exit_status`, and at most one
  private file system (`provide_view`; otherwise `child_view()` makes a scratch directory on the host).
  Bubblewrap sets the child's environment with `--setenv` and installs the seccomp program itself
  (`--seccomp`), taking that step from the bootstrap. Adding a layer is one module and one line in
  `registry.LAYERS` (`tests/grader/sandbox/marker_layer.py` is such a layer, in the tests); only a new *kind*
  of child-side step also needs code in `bootstrap.py` (stdlib only, run before the harness).
"""

from __future__ import annotations

from grader.sandbox.host import HOST
from grader.sandbox.isolation import registry
from grader.sandbox.isolation.layer import IsolationReport, Layer, LayerReport

__all__ = ["IsolationReport", "Layer", "LayerReport", "probe_isolation"]


def _not_on_this_system(layer: Layer) -> LayerReport:
    """A layer this system cannot run at all: reported, never probed (its probe may need what is missing)."""
    return LayerReport(
        layer.name,
        False,
        f"{HOST.unavailable_detail(layer.needs)}: {layer.guards} not enforced",
        "none needed to check your own code: each call still stops at its time limit",
    )


def _switched_off(report: LayerReport) -> LayerReport:
    return LayerReport(
        report.name,
        False,
        f"switched off by the caller ({report.detail})",
        "do not switch this layer off",
        report.required,
    )


def probe_isolation(disable: frozenset[str] = frozenset()) -> IsolationReport:
    """Probes every layer of `registry.LAYERS` and reports what can be enforced, outermost first.

    Each layer sees the reports of the layers before it, already switched off as asked, so the layers
    depending on another (privileges and Landlock on bubblewrap) are derived accordingly. Costly checks
    run once per process.

    Args:
        disable: Layers to leave off although available (to test or compare fallbacks).

    Raises:
        ValueError: `disable` names an unknown layer.
    """
    names = [layer.name for layer in registry.LAYERS]
    unknown = set(disable) - set(names)
    if unknown:
        raise ValueError(f"unknown isolation layers {sorted(unknown)}; expected some of {names}")
    reports: list[LayerReport] = []
    for layer in registry.LAYERS:
        if HOST.lacking(layer.needs):
            reports.append(_not_on_this_system(layer))
            continue
        report = layer.probe(IsolationReport(tuple(reports)))
        reports.append(_switched_off(report) if layer.name in disable and report.active else report)
    return IsolationReport(tuple(reports))
