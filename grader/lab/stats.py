"""Pure statistics behind the checks: exact binomial tests, z-tests with known variance, chi-square tests."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache
from statistics import NormalDist

_SQRT2 = math.sqrt(2.0)
_STANDARD_NORMAL = NormalDist()


def normal_cdf(z: float) -> float:
    """P(Z <= z) for a standard normal Z, to full relative precision far in the lower tail.

    By hand from `math.erfc` rather than `NormalDist().cdf`, which computes 0.5 * (1 + erf(z / sqrt 2))
    and so loses the lower tail to cancellation (measured: 1.8% off at z = -8, 0 instead of 7.6e-24
    at z = -10); calibration reports lower-tail false-fail probabilities with it.
    """
    return 0.5 * math.erfc(-z / _SQRT2)


def normal_quantile(probability: float) -> float:
    """The z with P(Z <= z) = probability (`NormalDist.inv_cdf`, Wichura's AS241, ~1e-16 relative).

    Args:
        probability: In (0, 1).

    Raises:
        ValueError: probability is not strictly between 0 and 1.
    """
    if not 0.0 < probability < 1.0:
        raise ValueError(f"expected a probability strictly between 0 and 1, found {probability}")
    return _STANDARD_NORMAL.inv_cdf(probability)


def binomial_log_pmf(k: int, n: int, p: float) -> float:
    """log P(K = k) for K ~ Binomial(n, p); -inf outside the support."""
    if not 0 <= k <= n:
        return -math.inf
    if p in (0.0, 1.0):
        return 0.0 if k == (0 if p == 0.0 else n) else -math.inf
    log_choose = math.lgamma(n + 1) - math.lgamma(k + 1) - math.lgamma(n - k + 1)
    return log_choose + k * math.log(p) + (n - k) * math.log1p(-p)


def binomial_cdf(k: int, n: int, p: float) -> float:
    """P(K <= k) for K ~ Binomial(n, p), by exact summation."""
    if k < 0:
        return 0.0
    if k >= n:
        return 1.0
    return math.fsum(math.exp(binomial_log_pmf(i, n, p)) for i in range(0, k + 1))


@dataclass(frozen=True)
class BinomialAcceptance:
    """The counts a correct solution may produce: accept k when `low <= k <= high`.

    Attributes:
        trials: Number of Bernoulli trials n.
        probability: Success probability p of a correct solution.
        low: Smallest accepted count.
        high: Largest accepted count.
        false_fail: Exact P(K < low) + P(K > high) under Binomial(n, p).
    """

    trials: int
    probability: float
    low: int
    high: int
    false_fail: float

    def accepts(self, count: int) -> bool:
        """Whether a count lies in the acceptance interval."""
        return self.low <= count <= self.high

    def pass_probability(self, probability: float) -> float:
        """Exact probability that a solution whose true success probability is `probability` is accepted."""
        return binomial_cdf(self.high, self.trials, probability) - binomial_cdf(
            self.low - 1, self.trials, probability
        )


@cache
def binomial_acceptance(trials: int, probability: float, alpha: float) -> BinomialAcceptance:
    """The narrowest central interval of counts whose two tails each hold at most alpha / 2.

    Args:
        trials: Number of Bernoulli trials (n >= 1).
        probability: Success probability of a correct solution, in [0, 1].
        alpha: Largest acceptable false-fail probability, in (0, 1).

    Returns:
        The acceptance interval and its exact false-fail probability (<= alpha).

    Raises:
        ValueError: An argument is out of range.
    """
    if trials < 1 or not 0.0 <= probability <= 1.0 or not 0.0 < alpha < 1.0:
        raise ValueError(
            f"expected trials >= 1, probability in [0, 1], alpha in (0, 1); "
            f"found {trials}, {probability}, {alpha}"
        )
    pmf = [math.exp(binomial_log_pmf(k, trials, probability)) for k in range(trials + 1)]
    return BinomialAcceptance(trials, probability, *central_interval(pmf, alpha))


def central_interval(pmf: Sequence[float], alpha: float) -> tuple[int, int, float]:
    """The narrowest central interval of a law on 0 .. len(pmf) - 1 whose tails each hold at most alpha / 2.

    Written out because scipy's `interval` gives quantiles, not the exact tail sums a false-fail
    probability states; shared by every acceptance interval of an exact discrete law.

    Args:
        pmf: The probability of each value 0, 1, ..., len(pmf) - 1 (at least one).
        alpha: Largest acceptable false-fail probability, in (0, 1).

    Returns:
        `(low, high, false_fail)`: accept `low <= k <= high`; `false_fail` is P(k < low) + P(k > high).
    """
    last = len(pmf) - 1
    low, lower_tail = 0, 0.0
    while low < last and lower_tail + pmf[low] <= alpha / 2:
        lower_tail += pmf[low]
        low += 1
    high, upper_tail = last, 0.0
    while high > low and upper_tail + pmf[high] <= alpha / 2:
        upper_tail += pmf[high]
        high -= 1
    return low, high, math.fsum([lower_tail, upper_tail])


@dataclass(frozen=True)
class MeanTolerance:
    """A two-sided z-test of a sample mean whose variance is known exactly.

    Attributes:
        expected: The exact expectation of one observation.
        variance: The exact variance of one observation.
        samples: Number of independent observations averaged.
        alpha: Stated false-fail probability (normal approximation of the mean).
        half_width: Accept a mean within expected ± half_width.
    """

    expected: float
    variance: float
    samples: int
    alpha: float
    half_width: float

    def accepts(self, mean: float) -> bool:
        """Whether a sample mean is within the tolerance."""
        return abs(mean - self.expected) <= self.half_width

    def pass_probability(self, true_mean: float) -> float:
        """Normal-approximation probability of acceptance when the true mean is `true_mean`."""
        standard_error = math.sqrt(self.variance / self.samples)
        if standard_error == 0:
            return 1.0 if abs(true_mean - self.expected) <= self.half_width else 0.0
        upper = (self.expected + self.half_width - true_mean) / standard_error
        lower = (self.expected - self.half_width - true_mean) / standard_error
        return normal_cdf(upper) - normal_cdf(lower)


def mean_tolerance(expected: float, variance: float, samples: int, alpha: float) -> MeanTolerance:
    """The z-test tolerance of a mean of `samples` observations with known variance.

    Args:
        expected: Exact expectation of one observation.
        variance: Exact variance of one observation (>= 0).
        samples: Number of observations (>= 1).
        alpha: Two-sided false-fail probability, in (0, 1).

    Raises:
        ValueError: An argument is out of range.
    """
    if samples < 1 or variance < 0 or not 0.0 < alpha < 1.0:
        raise ValueError(
            f"expected samples >= 1, variance >= 0, alpha in (0, 1); found {samples}, {variance}, {alpha}"
        )
    z = normal_quantile(1.0 - alpha / 2)
    # A floor of 1e-9 absorbs float rounding in means of deterministic observations.
    half_width = z * math.sqrt(variance / samples) + 1e-9
    return MeanTolerance(expected, variance, samples, alpha, half_width)


def _regularized_gamma_q(shape: float, x: float) -> float:
    """Q(a, x) = Gamma(a, x) / Gamma(a): series for x < a + 1, continued fraction otherwise."""
    if x <= 0:
        return 1.0
    log_prefix = shape * math.log(x) - x - math.lgamma(shape)
    if x < shape + 1:
        term = total = 1.0 / shape
        denominator = shape
        for _ in range(10_000):
            denominator += 1
            term *= x / denominator
            total += term
            if abs(term) < abs(total) * 1e-16:
                break
        return max(0.0, 1.0 - total * math.exp(log_prefix))
    tiny = 1e-300
    b = x + 1 - shape
    c = 1 / tiny
    d = 1 / b
    fraction = d
    for i in range(1, 10_000):
        an = -i * (i - shape)
        b += 2
        d = an * d + b
        d = tiny if abs(d) < tiny else d
        c = b + an / c
        c = tiny if abs(c) < tiny else c
        d = 1 / d
        delta = d * c
        fraction *= delta
        if abs(delta - 1) < 1e-16:
            break
    return math.exp(log_prefix) * fraction


def chi_square_sf(statistic: float, degrees_of_freedom: int) -> float:
    """P(X >= statistic) for X ~ chi-square(degrees_of_freedom)."""
    if degrees_of_freedom < 1:
        raise ValueError(f"expected at least 1 degree of freedom, found {degrees_of_freedom}")
    return _regularized_gamma_q(degrees_of_freedom / 2, statistic / 2)


@dataclass(frozen=True)
class ChiSquareResult:
    """A chi-square test's outcome.

    Attributes:
        statistic: Pearson's statistic.
        degrees_of_freedom: Its degrees of freedom.
        p_value: P(X >= statistic) under the null (asymptotic chi-square approximation).
    """

    statistic: float
    degrees_of_freedom: int
    p_value: float


def goodness_of_fit(observed: Sequence[int], probabilities: Sequence[float]) -> ChiSquareResult:
    """Pearson's test that counts follow known category probabilities (df = categories - 1).

    Raises:
        ValueError: Lengths differ, fewer than 2 categories, or no observations.
    """
    total = sum(observed)
    if len(observed) != len(probabilities) or len(observed) < 2 or total == 0:
        raise ValueError(
            f"expected >= 2 categories with matching probabilities and some observations; "
            f"found {len(observed)} counts, {len(probabilities)} probabilities, total {total}"
        )
    statistic = math.fsum(
        (count - total * probability) ** 2 / (total * probability)
        for count, probability in zip(observed, probabilities, strict=True)
    )
    degrees = len(observed) - 1
    return ChiSquareResult(statistic, degrees, chi_square_sf(statistic, degrees))


def grouped_binomial_fit(groups: Sequence[tuple[int, int]], probability: float) -> ChiSquareResult:
    """Pearson's test that every group's successes have the known probability (df = non-empty groups).

    With fair coins flipped whatever the history (random actions), each group's successes minus
    trials x probability is a martingale, so the statistic is asymptotically chi-square even though the
    number of trials in a group depends on earlier flips.

    Args:
        groups: Per group, (successes, trials).
        probability: The success probability under the null, in (0, 1).

    Raises:
        ValueError: probability outside (0, 1), successes outside 0..trials, or no trials at all.
    """
    if not 0.0 < probability < 1.0:
        raise ValueError(f"expected a probability strictly between 0 and 1, found {probability}")
    used = [(successes, trials) for successes, trials in groups if trials > 0]
    if not used or any(not 0 <= successes <= trials for successes, trials in used):
        raise ValueError(
            f"expected groups of (successes, trials) with 0 <= successes <= trials, found {groups}"
        )
    statistic = math.fsum(
        (successes - trials * probability) ** 2 / (trials * probability * (1 - probability))
        for successes, trials in used
    )
    return ChiSquareResult(statistic, len(used), chi_square_sf(statistic, len(used)))
