"""Isolation layers for sandboxed children: probed into an `IsolationReport`, applied by `build_launch`."""

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
