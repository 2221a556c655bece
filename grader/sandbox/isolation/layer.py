"""The isolation layer plug-in contract (`Layer`: probe, then apply), what a layer reports, and the report."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:  # launch.py reads the layer list, whose modules implement this protocol
    from grader.sandbox.isolation.launch import LaunchSpec


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
