"""Curves found in measurements are drawn as inline SVG with their labels escaped."""

from __future__ import annotations

from typing import Any

import pytest

from api.plots import find_curves, problem_plots, render_svg

POINTS = [{"n": n, "student": 0.1 * n, "exact": 0.1 * n + 0.01} for n in range(4)]


@pytest.mark.parametrize(
    ("measurements", "expected"),
    [
        ({"curve": POINTS}, [("curve", "n", ["student", "exact"], 4)]),
        (
            {
                "exact_curve": {str(n): 0.01 * n for n in range(22)},
                "curve": {"12": 0.4, "20": 0.15},
                "best": 13,
            },
            [("exact_curve and curve", "n", ["exact_curve", "curve"], 22)],
        ),
        ({"curve": {"12": 0.4, "20": 0.15}}, []),
        ({"by_name": {"a": 1, "b": 2, "c": 3}}, []),
        ({"by_n": {"n": [1, 2, 3], "win": [0.1, 0.2, None]}}, [("by_n", "n", ["win"], 3)]),
        ({"mean": 0.4, "runs": [1, 2, 3], "label": "x"}, []),
        ({"short": POINTS[:2]}, []),
        ({"mismatched": {"n": [1, 2, 3], "win": [0.1]}}, []),
        ({"flags": [{"n": True, "ok": False}] * 3}, []),
    ],
    ids=[
        "list-of-points",
        "keyed-blackjack-curves",
        "keyed-too-few",
        "keyed-not-numeric",
        "columns",
        "scalars-and-plain-lists",
        "too-few-points",
        "unequal-columns",
        "booleans",
    ],
)
def test_curves_are_recognised(
    measurements: dict[str, Any], expected: list[tuple[str, str, list[str], int]]
) -> None:
    found = [(c.title, c.x_label, list(c.series), len(c.x)) for c in find_curves(measurements)]
    assert found == expected


def test_svg_escapes_labels_and_draws_one_line_per_series() -> None:
    svg = str(render_svg(find_curves({"<script>": [{"<n>": n, "a&b": n * n} for n in range(3)]})[0]))
    assert svg.startswith("<svg") and svg.endswith("</svg>")
    assert "<script>" not in svg and "&lt;script&gt;" in svg and "a&amp;b" in svg
    assert svg.count("<polyline") == 1


def test_a_flat_curve_is_drawn_without_dividing_by_zero() -> None:
    assert problem_plots({"flat": {"n": [1, 1, 1], "y": [2, 2, 2]}})[0].count("<polyline") == 1


def test_keyed_series_share_the_x_axis_and_sparse_points_are_marked() -> None:
    measurements = {"exact_curve": {str(n): 0.4 for n in range(10, 15)}, "curve": {"12": 0.41}}
    (curve,) = find_curves(measurements)
    assert curve.series["curve"] == [None, None, 0.41, None, None]
    svg = str(render_svg(curve))
    assert svg.count("<polyline") == 1, "the sparse series is drawn as points, not joined up"
    assert svg.count("<circle") == 6
