"""Exact values of the statistics in grader/lab/stats.py (closed forms, no scipy)."""

import math

import pytest

from grader.lab import stats

Z_975 = 1.959963984540054  # the 97.5% normal quantile to 15 digits


@pytest.mark.parametrize(
    ("z", "expected"),
    [(0.0, 0.5), (Z_975, 0.975), (-Z_975, 0.025), (1.0, 0.8413447460685429)],
    ids=["zero", "z975", "minus-z975", "one"],
)
def test_normal_cdf(z: float, expected: float) -> None:
    assert stats.normal_cdf(z) == pytest.approx(expected, abs=1e-14)


@pytest.mark.parametrize(
    ("z", "expected"),
    [(-5.0, 2.866515718791939e-07), (-5.326723886384500, 5e-8), (-10.0, 7.619853024160526e-24)],
    ids=["minus-5", "alpha-1e-7", "minus-10"],
)
def test_normal_cdf_keeps_its_relative_precision_far_in_the_lower_tail(z: float, expected: float) -> None:
    assert stats.normal_cdf(z) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize(
    ("probability", "expected"),
    [
        (0.975, Z_975),
        (0.025, -Z_975),
        (0.5, 0.0),
        (1 - 5e-7, 4.891638475698508),
        (5e-7, -4.891638475698589),
        (5e-10, -6.109410204869397),
    ],
    ids=["p975", "p025", "median", "two-sided-1e-6", "lower-1e-6", "lower-1e-9"],
)
def test_normal_quantile(probability: float, expected: float) -> None:
    assert stats.normal_quantile(probability) == pytest.approx(expected, abs=1e-10)


@pytest.mark.parametrize("probability", [0.0, 1.0, -0.1, 2.0], ids=["zero", "one", "negative", "above-one"])
def test_normal_quantile_rejects_non_probabilities(probability: float) -> None:
    with pytest.raises(ValueError, match="strictly between 0 and 1"):
        stats.normal_quantile(probability)


@pytest.mark.parametrize(
    ("k", "n", "p", "cdf"),
    [
        (1, 3, 0.5, 0.5),
        (0, 10, 0.5, 1 / 1024),
        (2, 10, 0.5, 56 / 1024),
        (5, 5, 0.3, 1.0),
        (-1, 5, 0.3, 0.0),
        (1, 4, 0.25, 0.75**4 + 4 * 0.25 * 0.75**3),
    ],
    ids=["n3-k1", "n10-k0", "n10-k2", "k-is-n", "k-negative", "n4-p25"],
)
def test_binomial_cdf(k: int, n: int, p: float, cdf: float) -> None:
    # lgamma-based probabilities carry ~1e-15 relative rounding per term.
    assert stats.binomial_cdf(k, n, p) == pytest.approx(cdf, abs=1e-13)


def test_binomial_acceptance_of_ten_fair_coins() -> None:
    # P(K <= 1) = 11/1024 <= 0.025 < P(K <= 2) = 56/1024, so the interval is 2..8.
    acceptance = stats.binomial_acceptance(10, 0.5, 0.05)
    assert (acceptance.low, acceptance.high) == (2, 8)
    assert acceptance.false_fail == pytest.approx(22 / 1024, abs=1e-15)
    assert acceptance.pass_probability(0.5) == pytest.approx(1 - 22 / 1024, abs=1e-13)
    assert acceptance.accepts(2) and acceptance.accepts(8)
    assert not acceptance.accepts(1) and not acceptance.accepts(9)


def test_binomial_acceptance_of_a_certain_outcome_never_fails() -> None:
    acceptance = stats.binomial_acceptance(100, 0.0, 1e-6)
    assert (acceptance.low, acceptance.high, acceptance.false_fail) == (0, 0, 0.0)


def test_binomial_acceptance_rejects_bad_arguments() -> None:
    with pytest.raises(ValueError, match="expected trials >= 1"):
        stats.binomial_acceptance(0, 0.5, 0.05)


@pytest.mark.parametrize(
    ("pmf", "alpha", "interval"),
    [
        ([0.25, 0.5, 0.25], 0.6, (1, 1, 0.5)),
        ([0.25, 0.5, 0.25], 0.4, (0, 2, 0.0)),
        ([0.1, 0.1, 0.8], 0.5, (2, 2, 0.2)),
        ([1.0], 0.5, (0, 0, 0.0)),
    ],
    ids=["both-tails-cut", "tails-too-heavy", "lower-tail-to-the-mode", "one-value"],
)
def test_central_interval_cuts_each_tail_up_to_half_alpha(
    pmf: list[float], alpha: float, interval: tuple[int, int, float]
) -> None:
    assert stats.central_interval(pmf, alpha) == interval


def test_mean_tolerance() -> None:
    tolerance = stats.mean_tolerance(expected=3.0, variance=4.0, samples=100, alpha=0.05)
    assert tolerance.half_width == pytest.approx(Z_975 * 0.2, abs=1e-8)
    assert tolerance.accepts(3.39) and not tolerance.accepts(3.4)
    assert tolerance.pass_probability(3.0) == pytest.approx(0.95, abs=1e-8)


def test_mean_tolerance_of_deterministic_observations() -> None:
    tolerance = stats.mean_tolerance(expected=7.5, variance=0.0, samples=10, alpha=1e-6)
    assert tolerance.accepts(7.5) and not tolerance.accepts(7.51)


@pytest.mark.parametrize(
    ("statistic", "df", "expected"),
    [
        (3.0, 2, math.exp(-1.5)),
        (10.0, 2, math.exp(-5.0)),
        (2.5, 1, math.erfc(math.sqrt(1.25))),
        (6.0, 4, math.exp(-3.0) * (1 + 3.0)),
        (40.0, 4, math.exp(-20.0) * (1 + 20.0)),
        (0.0, 3, 1.0),
    ],
    ids=["df2", "df2-tail", "df1", "df4", "df4-far-tail", "zero"],
)
def test_chi_square_sf(statistic: float, df: int, expected: float) -> None:
    assert stats.chi_square_sf(statistic, df) == pytest.approx(expected, rel=1e-10)


def test_goodness_of_fit() -> None:
    result = stats.goodness_of_fit([15, 5], [0.5, 0.5])
    assert (result.statistic, result.degrees_of_freedom) == (5.0, 1)
    assert result.p_value == pytest.approx(math.erfc(math.sqrt(2.5)), rel=1e-10)


def test_goodness_of_fit_rejects_mismatched_categories() -> None:
    with pytest.raises(ValueError, match="expected >= 2 categories"):
        stats.goodness_of_fit([1, 2, 3], [0.5, 0.5])


def test_grouped_binomial_fit() -> None:
    result = stats.grouped_binomial_fit([(50, 100), (60, 100), (0, 0)], 0.5)
    assert (result.statistic, result.degrees_of_freedom) == (4.0, 2)
    assert result.p_value == pytest.approx(math.exp(-2.0), rel=1e-10)


def test_grouped_binomial_fit_rejects_impossible_counts() -> None:
    with pytest.raises(ValueError, match="0 <= successes <= trials"):
        stats.grouped_binomial_fit([(5, 3)], 0.5)
