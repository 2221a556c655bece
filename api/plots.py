"""Inline SVG line charts of the curves in a problem's measurements (e.g. blackjack's win rate against n)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from markupsafe import Markup, escape

WIDTH, HEIGHT = 480, 260
MARGIN_LEFT, MARGIN_RIGHT, MARGIN_TOP, MARGIN_BOTTOM = 52, 16, 28, 40
LEGEND_STEP = 140
COLOURS = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e")
MIN_POINTS = 3


@dataclass(frozen=True)
class Curve:
    """Series sharing one x axis: ``series`` maps a label to y values (None where missing)."""

    title: str
    x_label: str
    x: list[float]
    series: dict[str, list[float | None]]


def find_curves(measurements: Mapping[str, Any]) -> list[Curve]:
    """Find plottable curves in measurements.

    Three shapes are recognised: objects mapping numeric keys to numbers (``{"12": 0.41, "13": 0.42}``,
    e.g. the blackjack check's ``exact_curve`` and the student's ``curve``), all drawn together on one
    chart; a list of at least three points that are objects sharing numeric fields (the first field is
    x); and an object of equally long numeric lists (the first list is x).

    Args:
        measurements: A problem's measurements from the report.

    Returns:
        The curves: the keyed series first, then the others in the order of the measurements.
    """
    curves = []
    keyed = _keyed_curve(measurements)
    if keyed is not None:
        curves.append(keyed)
    for name, value in measurements.items():
        curve = _points_curve(name, value) or _columns_curve(name, value)
        if curve is not None:
            curves.append(curve)
    return curves


def _keyed_series(value: object) -> dict[float, float] | None:
    if not isinstance(value, Mapping) or not value:
        return None
    series = {}
    for key, item in value.items():
        try:
            x = float(key)
        except (TypeError, ValueError):
            return None
        if not _is_number(item) or not math.isfinite(x):
            return None
        series[x] = float(item)
    return series


def _keyed_curve(measurements: Mapping[str, Any]) -> Curve | None:
    found = {name: series for name, value in measurements.items() if (series := _keyed_series(value))}
    if not found or max(len(series) for series in found.values()) < MIN_POINTS:
        return None
    x = sorted({point for series in found.values() for point in series})
    return Curve(
        title=" and ".join(found),
        x_label="n",
        x=x,
        series={name: [series.get(point) for point in x] for name, series in found.items()},
    )


def _is_number(value: object) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def _points_curve(name: str, value: object) -> Curve | None:
    if not isinstance(value, Sequence) or isinstance(value, str) or len(value) < MIN_POINTS:
        return None
    if not all(isinstance(point, Mapping) for point in value):
        return None
    keys = [key for key, item in value[0].items() if _is_number(item)]
    if len(keys) < 2 or not all(_is_number(point.get(keys[0])) for point in value):
        return None
    series = {
        key: [float(point[key]) if _is_number(point.get(key)) else None for point in value]
        for key in keys[1:]
    }
    return Curve(name, keys[0], [float(point[keys[0]]) for point in value], series)


def _columns_curve(name: str, value: object) -> Curve | None:
    if not isinstance(value, Mapping) or len(value) < 2:
        return None
    columns = list(value.items())
    x_label, x = columns[0]
    if (
        not isinstance(x, Sequence)
        or isinstance(x, str)
        or len(x) < MIN_POINTS
        or not all(map(_is_number, x))
    ):
        return None
    series: dict[str, list[float | None]] = {}
    for label, ys in columns[1:]:
        if isinstance(ys, Sequence) and not isinstance(ys, str) and len(ys) == len(x):
            series[str(label)] = [float(y) if _is_number(y) else None for y in ys]
    if not series:
        return None
    return Curve(name, str(x_label), [float(item) for item in x], series)


def render_svg(curve: Curve) -> Markup:
    """Draw a curve as an accessible inline SVG (labels escaped, no scripts, no inline styles)."""
    ys = [y for values in curve.series.values() for y in values if y is not None]
    x_low, x_high = min(curve.x), max(curve.x)
    y_low, y_high = (min(ys), max(ys)) if ys else (0.0, 1.0)
    if y_high == y_low:
        y_low, y_high = y_low - 0.5, y_high + 0.5
    if x_high == x_low:
        x_low, x_high = x_low - 0.5, x_high + 0.5
    plot_w, plot_h = WIDTH - MARGIN_LEFT - MARGIN_RIGHT, HEIGHT - MARGIN_TOP - MARGIN_BOTTOM

    def px(x: float) -> float:
        return MARGIN_LEFT + (x - x_low) / (x_high - x_low) * plot_w

    def py(y: float) -> float:
        return MARGIN_TOP + (1 - (y - y_low) / (y_high - y_low)) * plot_h

    parts = [
        f'<svg class="plot" role="img" viewBox="0 0 {WIDTH} {HEIGHT}" width="{WIDTH}" height="{HEIGHT}" '
        f'xmlns="http://www.w3.org/2000/svg"><title>{escape(curve.title)}</title>',
        f'<rect x="{MARGIN_LEFT}" y="{MARGIN_TOP}" width="{plot_w}" height="{plot_h}" '
        'fill="none" stroke="#999"/>',
    ]
    for fraction in (0.0, 0.5, 1.0):
        y_value = y_low + fraction * (y_high - y_low)
        parts.append(
            f'<text x="{MARGIN_LEFT - 6}" y="{py(y_value) + 4:.1f}" text-anchor="end" font-size="11">'
            f"{y_value:.3g}</text>"
        )
        x_value = x_low + fraction * (x_high - x_low)
        parts.append(
            f'<text x="{px(x_value):.1f}" y="{HEIGHT - MARGIN_BOTTOM + 16}" '
            'text-anchor="middle" font-size="11">'
            f"{x_value:.3g}</text>"
        )
    parts.append(
        f'<text x="{MARGIN_LEFT + plot_w / 2}" y="{HEIGHT - 6}" text-anchor="middle" font-size="12">'
        f"{escape(curve.x_label)}</text>"
    )
    for index, (label, values) in enumerate(curve.series.items()):
        colour = COLOURS[index % len(COLOURS)]
        drawn = [(px(x), py(y)) for x, y in zip(curve.x, values, strict=True) if y is not None]
        if len(drawn) == len(values):  # a line only through a complete series: gaps are not joined up
            points = " ".join(f"{x:.1f},{y:.1f}" for x, y in drawn)
            parts.append(f'<polyline fill="none" stroke="{colour}" stroke-width="2" points="{points}"/>')
        parts.extend(f'<circle cx="{x:.1f}" cy="{y:.1f}" r="3.5" fill="{colour}"/>' for x, y in drawn)
        parts.append(
            f'<text x="{MARGIN_LEFT + LEGEND_STEP * index}" y="{MARGIN_TOP - 8}" '
            f'fill="{colour}" font-size="12">'
            f"● {escape(label.replace('_', ' '))}</text>"
        )
    parts.append("</svg>")
    return Markup("".join(parts))


def problem_plots(measurements: Mapping[str, Any] | None) -> list[Markup]:
    """Every curve in a problem's measurements, drawn (what the report template calls)."""
    return [render_svg(curve) for curve in find_curves(measurements or {})]
