"""What every isolation layer reports at start-up, and the report assembled from all of them."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol


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
    """One isolation layer: probed once per process, then applied to every child it starts."""

    name: str

    def probe(self) -> LayerReport:
        """Checks on this machine whether the layer can be enforced (without side effects left behind)."""
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
