"""A fake extra isolation layer, as a new layer module would be: probed, reported and applied by the loops.

It enforces nothing; it sets `MARKER_VARIABLE` in the child's environment so a test can see it applied.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from grader.sandbox.host import Feature
from grader.sandbox.isolation.layer import IsolationReport, LaunchSpec, LayerReport

MARKER_VARIABLE = "GYMGRADE_MARKER"


@dataclass
class MarkerLayer:
    """Available when `available`; records the outer layers it was probed with and how often it applied."""

    available: bool = True
    name: str = "marker"
    needs: tuple[Feature, ...] = ()
    guards: str = "the marker"
    outer_seen: list[tuple[str, ...]] = field(default_factory=list)
    applied: int = 0

    def probe(self, outer: IsolationReport) -> LayerReport:
        """Active when `available`, with a remedy otherwise."""
        self.outer_seen.append(tuple(report.name for report in outer.layers))
        if not self.available:
            return LayerReport(self.name, False, "no marker here", "install a marker")
        return LayerReport(self.name, True, "marks the child's environment")

    def apply(self, spec: LaunchSpec) -> None:
        """Adds `MARKER_VARIABLE` to the child's environment."""
        self.applied += 1
        spec.environment[MARKER_VARIABLE] = "applied"
