"""Edition rl1, problem 5: `epsilon_decay(episode, N, epsilon_start=1.0, epsilon_end=1e-6)`, a pure function.

Graded exactly over a grid of arguments (first and last episodes, the defaults, non-default starts and ends,
a large N), each a sandboxed call like any other. A wrong value is compared with the typical mistakes
(`MISTAKES`), and the one that explains every returned value is named. The optional `decay_type="exp"` is
graded only when the configuration enables it (`grade_exp`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

from pydantic import Field

from grader.lab.checks.base import CallRecord, Verdict, outcome_verdict, paused_gc
from grader.lab.checks.integrity import NO_EPISODES
from grader.lab.checks.values import describe
from grader.lab.settings import ProblemConfig, Share
from grader.sandbox.outcome import Call, FunctionInfo, PlainValue

DEFAULT_START, DEFAULT_END = 1.0, 1e-6
"""The signature's defaults, `epsilon_start=1.0, epsilon_end=1e-6`."""


@dataclass(frozen=True)
class DecayPoint:
    """One graded argument set; `start`/`end` None: the call leaves them to the student's defaults."""

    episode: int
    n: int
    start: float | None = None
    end: float | None = None

    def args(self) -> tuple[PlainValue, ...]:
        """Positional arguments, so a student who renamed a parameter is still called correctly."""
        if self.start is None or self.end is None:
            return (self.episode, self.n)
        return (self.episode, self.n, self.start, self.end)

    @property
    def bounds(self) -> tuple[float, float]:
        """(epsilon_start, epsilon_end) this call means."""
        if self.start is None or self.end is None:
            return (DEFAULT_START, DEFAULT_END)
        return (self.start, self.end)

    def text(self, exp: bool = False) -> str:
        arguments = ", ".join(repr(arg) for arg in self.args())
        return f"epsilon_decay({arguments}{', decay_type=' + repr('exp') if exp else ''})"


GRID: tuple[DecayPoint, ...] = (
    DecayPoint(1, 100),
    DecayPoint(2, 100),
    DecayPoint(50, 100),
    DecayPoint(100, 100),
    DecayPoint(1, 70_000),
    DecayPoint(35_000, 70_000),
    DecayPoint(70_000, 70_000),
    DecayPoint(1, 10, 0.5, 0.1),
    DecayPoint(7, 10, 0.5, 0.1),
    DecayPoint(10, 10, 0.5, 0.1),
    DecayPoint(3, 4, 0.9, 0.05),
    DecayPoint(4, 4, 0.9, 0.05),
    DecayPoint(1_000_000, 1_000_000, 0.3, 0.001),
)
"""First, middle and last episodes; the defaults; non-default starts and ends; large N. N >= 2 everywhere,
so the `N - 1` mistake returns numbers (and is named) instead of dividing by zero."""

Formula = Callable[[int, int, float, float], float]


def linear(episode: int, n: int, start: float, end: float) -> float:
    """The lab's decay: episode i (1-based) gets `start - (i - 1) * (start - end) / N`."""
    return start - (episode - 1) * (start - end) / n


def exponential(episode: int, n: int, start: float, end: float) -> float:
    """The optional `decay_type="exp"`: `start * (end / start) ** (episode / N)`."""
    return float(start * (end / start) ** (episode / n))


MISTAKES: tuple[tuple[str, Formula], ...] = (
    (
        "your values are those of 0-based episodes (episode i gets start - i * delta); the lab numbers episodes from 1, so episode 1 must get epsilon_start exactly",  # noqa: E501
        lambda i, n, s, e: s - i * (s - e) / n,
    ),
    (
        "your values divide by N - 1 (delta = (epsilon_start - epsilon_end) / (N - 1)); the lab's delta divides by N, so the last episode gets epsilon_start - (N - 1) * delta, not epsilon_end",  # noqa: E501
        lambda i, n, s, e: s - (i - 1) * (s - e) / (n - 1),
    ),
    (
        "your values are right except at the last episode, where you return epsilon_end; the formula gives the last episode epsilon_start - (N - 1) * delta, which is not epsilon_end",  # noqa: E501
        lambda i, n, s, e: e if i == n else linear(i, n, s, e),
    ),
    (
        "your values ignore the epsilon_start and epsilon_end passed in (they are those of 1.0 and 1e-6); use the parameters, not constants",  # noqa: E501
        lambda i, n, s, e: linear(i, n, DEFAULT_START, DEFAULT_END),
    ),
    (
        "your values decay to 0 rather than to epsilon_end (delta = epsilon_start / N); subtract epsilon_end: delta = (epsilon_start - epsilon_end) / N",  # noqa: E501
        lambda i, n, s, e: s - (i - 1) * s / n,
    ),
    (
        "your values decay exponentially; the default decay is linear",
        exponential,
    ),
)
"""Typical mistakes: (what the feedback says, the values it gives). Named when it explains every value."""


class EpsilonDecayConfig(ProblemConfig):
    """The settings of `epsilon_decay(episode, N, epsilon_start=1.0, epsilon_end=1e-6)` (edition rl1)."""

    grade_exp: bool = Field(
        default=False,
        description="Also grade the optional decay_type='exp' (the additional-materials exercise).",
    )
    exp_share: Share = Field(
        default=0.5, description="Share of the points for decay_type='exp' when grade_exp is true."
    )
    relative_tolerance: float = Field(
        default=1e-9,
        gt=0.0,
        lt=1e-3,
        description="Floating-point tolerance of an exact answer (the same formula written another way, or applied episode by episode), relative to the value or to epsilon_start's scale.",  # noqa: E501
    )


def returned_number(value: PlainValue) -> float | None:
    """A returned value as a float, or None when it is no finite real number (bools are not numbers)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        item = getattr(value, "item", None)
        value = item() if callable(item) and getattr(value, "shape", None) == () else None
        if isinstance(value, bool) or not isinstance(value, int | float):
            return None
    number = float(value)
    return number if math.isfinite(number) else None


@dataclass(frozen=True)
class EpsilonDecayCheck:
    """Every grid point called once (linear), plus once with decay_type='exp' when enabled."""

    def plan(
        self, settings: EpsilonDecayConfig, functions: Mapping[str, FunctionInfo], seed: int
    ) -> list[Call]:
        """One unrecorded call per grid point (and per grid point again with decay_type='exp')."""
        calls = [
            Call("epsilon_decay", point.args(), record_episodes=False, budget=NO_EPISODES) for point in GRID
        ]
        if settings.grade_exp:
            calls += [
                Call(
                    "epsilon_decay",
                    point.args(),
                    {"decay_type": "exp"},
                    record_episodes=False,
                    budget=NO_EPISODES,
                )
                for point in GRID
            ]
        return calls

    @paused_gc
    def judge(self, settings: EpsilonDecayConfig, records: Sequence[CallRecord]) -> Verdict:
        """Compare each returned value with the formula; name the mistake that explains them all."""
        early = outcome_verdict(records[: len(GRID)])
        if early is not None:
            return early
        tolerance = settings.relative_tolerance
        values = [returned_number(record.outcome.value) for record in records]
        linear_problem = _mismatch(values[: len(GRID)], linear, tolerance, exp=False)
        measurements: dict[str, PlainValue] = {
            "points_graded": len(GRID),
            "linear_correct": linear_problem is None,
        }
        parts = [(1.0, linear_problem)]
        if settings.grade_exp:
            exp_early = outcome_verdict(records[len(GRID) :])
            exp_problem = (
                exp_early.feedback
                if exp_early is not None
                else _mismatch(values[len(GRID) :], exponential, tolerance, exp=True)
            )
            measurements["exp_correct"] = exp_problem is None
            parts = [(1.0 - settings.exp_share, linear_problem), (settings.exp_share, exp_problem)]
        fraction = sum(share for share, problem in parts if problem is None)
        problems = [problem for _, problem in parts if problem is not None]
        graded = f"{len(GRID)} argument sets" + (" for each decay type" if settings.grade_exp else "")
        if not problems:
            return Verdict("passed", 1.0, f"epsilon_decay: every value is exact over {graded}.", measurements)
        return Verdict("failed", fraction, " ".join(problems), measurements)


def _mismatch(values: Sequence[float | None], formula: Formula, tolerance: float, *, exp: bool) -> str | None:
    """What is wrong with the values against `formula` over the grid, or None when all are exact."""
    expected = [formula(point.episode, point.n, *point.bounds) for point in GRID]
    wrong = [
        index
        for index, (value, want, point) in enumerate(zip(values, expected, GRID, strict=True))
        if not _same(value, want, point, tolerance)
    ]
    if not wrong:
        return None
    first = wrong[0]
    point = GRID[first]
    found = values[first]
    start, end = point.bounds
    rule = (
        f"epsilon_start * (epsilon_end / epsilon_start) ** (episode / N) = {expected[first]!r}"
        if exp
        else f"epsilon_start - (episode - 1) * delta with delta = ({start!r} - {end!r}) / {point.n} = {expected[first]!r}"  # noqa: E501
    )
    returned = "no finite number" if found is None else describe(found)
    message = f"{point.text(exp)} returned {returned}; expected {rule} ({len(wrong)} of {len(GRID)} argument sets wrong)."  # noqa: E501
    if found is None:
        return message + " Return a float."
    if not exp:
        for cause, mistake in MISTAKES:
            guesses = [mistake(p.episode, p.n, *p.bounds) for p in GRID]
            if all(
                _same(value, guess, point, tolerance)
                for value, guess, point in zip(values, guesses, GRID, strict=True)
            ):
                return f"{message} Likely cause: {cause}."
    return message


def _same(value: float | None, want: float, point: DecayPoint, tolerance: float) -> bool:
    """Equal up to rounding: relative to the value, or to the scale of epsilon_start for values near 0.

    Subtracting delta once per episode (a loop) accumulates up to N roundings of epsilon_start's scale:
    about 1e-10 of it at N = 1 000 000, far below the smallest difference a mistake makes (delta, 3e-7 there).
    """
    scale = max(abs(bound) for bound in point.bounds)
    return value is not None and math.isclose(value, want, rel_tol=tolerance, abs_tol=tolerance * scale)
