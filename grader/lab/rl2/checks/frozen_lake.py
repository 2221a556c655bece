"""The second lab's `frozen_lake(basic_case=True, M=1000, render=False)` (2018: `frozenlake(basic_case, M)`).

The grader calls it twice, `basic_case=True` (4x4) and `False` (8x8), with a small `M` (`episodes`, 100 by
default: 2 x 2 x 100 episodes and the student's own solvers on both lakes, a few seconds), `render=False`
in third place where the signature has it. It returns five results (2018-2023: `vi_policy,
vi_total_rewards, pi_value_func, pi_policy, pi_total_rewards`) or six (2024 on: `vi_value_func` first).
Judged on the lake the lab means, slippery FrozenLake of the asked size:

- the episodes: exactly 2M played in that lake from the grader's seeds (the first lab's integrity rules),
  the first M with `vi_policy` (every action `vi_policy[state]`) and the next M with `pi_policy`, or the two
  alternating (one loop playing one episode with each policy per pass, as many real files do; `ORDERS`);
- each returned mean: exactly the mean of its M replayed returns (beta = 1, the lab's default), read either
  way the lab's gyms allow: each episode up to its first end (`terminated or truncated`, gym.make's time
  limit of 100 or 200 steps included), or each to its terminal state past the time limit (classic
  `gym.make(id).env`, or a loop on `terminated` only; replayed by `replay_past_time_limit`);
- each policy by its exact value (`reference.oracles.mdp.judge_policy`, ties allowed), the value functions
  against the exact optimal values (within `value_tolerance`: the lab's own value iteration at tol = 1e-8
  stops within 7e-7 of them on both lakes);
- each policy's replayed mean up to the time limit actually played against its exact finite-horizon mean
  (`return_moments(steps=limit)`; the limit cannot make a correct policy fail): Bernstein's inequality for
  returns in [0, 1], false-fail probability `mean_alpha` per test, 4 tests.

A mistake counts once, in the problem that made it: when a policy or value function is not the optimum,
the grader compares it with what the student's own `value_iteration` (its greedy policy) and
`policy_iteration` return on the same lake (called in the same sandbox); when they agree, frozen_lake wired
the lab's steps right and passes, the feedback saying which reading was used (the mistake is graded in
value_iteration or policy_iteration).

A second reading (`grader.lab.checks.base.SecondReading`): only when that verdict is not a pass, both lakes'
frozen_lake calls are made again with the grader's own `value_iteration`, `policy_iteration`,
`run_simulation` and improvement and evaluation steps (`grader.sandbox.child.provided`) bound in place of the
student's, and the better verdict is kept, the feedback saying which reading gave it: a frozen_lake that
wires the lab's steps right is not failed for a mistake (or a missing function) graded in another problem.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from functools import cache
from typing import Literal

import numpy as np
from pydantic import Field

from grader.lab.checks.base import CallRecord, Verdict, better_reading, outcome_verdict, paused_gc
from grader.lab.checks.integrity import (
    NO_EPISODES,
    Episode,
    games_budget,
    integrity_problem,
    played_episodes,
)
from grader.lab.checks.values import as_number, describe
from grader.lab.games import FROZEN_LAKE_4X4, FROZEN_LAKE_8X8, Game
from grader.lab.rl2.checks.mdp_calls import as_policy, as_vector, describe_values, mdp_argument
from grader.lab.settings import PlayedProblemConfig, Probability
from grader.sandbox.outcome import Call, FunctionInfo, OutcomeStatus, PlainValue
from grader.sandbox.replay import replay_past_time_limit, time_limit_of
from reference.oracles.mdp import Mdp, greedy_gaps, judge_policy, optimal_solution, return_moments
from reference.oracles.mdps import frozen_lake as lake_mdp

Shape = Literal["five", "six"]
STEPS_PROVIDED = (
    "value_iteration",
    "policy_iteration",
    "run_simulation",
    "extract_policy",
    "compute_policy_v",
    "policy_improvement",
    "iter_policy_eval",
)
"""What the second reading binds: the functions frozen_lake calls, under every edition's names."""
GRADERS_READING = "frozen_lake was called with the grader's own value_iteration, policy_iteration, run_simulation and improvement and evaluation steps (the lab's algorithms) in place of yours, so a mistake in those counts only in their own problems."  # noqa: E501
LAKE_STEPS = 200
"""Steps per episode the budget allows for (gym.make's limit on 8x8; longer episodes are played by `.env`
users and loops on `terminated` only, and the budget's slack covers them)."""
EPISODE_SLACK = 40
"""The budget's steps per episode: an episode continued past the time limit rarely lasts 40 times it."""


class FrozenLakeConfig(PlayedProblemConfig):
    """The settings of `frozen_lake(basic_case, M, render)` / 2018's `frozenlake(basic_case, M)`."""

    episodes: int = Field(
        default=100,
        ge=10,
        le=10_000,
        description="M passed (the lab's 1 000): each call plays 2M episodes; the returned means are checked exactly against them.",  # noqa: E501
    )
    value_tolerance: float = Field(
        default=1e-5,
        gt=0.0,
        lt=0.1,
        description="Largest difference between a returned value function and the exact optimal values (the lab's value iteration at tol = 1e-8 stops within 7e-7 of them).",  # noqa: E501
    )
    mean_alpha: Probability = Field(
        default=1e-6,
        description="False-fail probability of EACH Bernstein test of a policy's replayed mean against its exact finite-horizon mean (4 tests).",  # noqa: E501
    )


@dataclass(frozen=True)
class Lake:
    """One call's lake: the map asked for, its game and exact MDP."""

    basic_case: bool
    game: Game

    @property
    def map_name(self) -> str:
        return "4x4" if self.basic_case else "8x8"

    @property
    def mdp(self) -> Mdp:
        return _mdp(self.map_name)


@cache
def _mdp(map_name: str) -> Mdp:
    return lake_mdp(map_name, slippery=True)


LAKES = (Lake(True, FROZEN_LAKE_4X4), Lake(False, FROZEN_LAKE_8X8))


@dataclass(frozen=True)
class Returned:
    """One call's results, read."""

    vi_values: np.ndarray | None
    vi_policy: np.ndarray
    vi_mean: float
    pi_values: np.ndarray
    pi_policy: np.ndarray
    pi_mean: float


@dataclass(frozen=True)
class FrozenLakeCheck:
    """frozen_lake on both lakes: episodes replayed, means exact, policies and values against exact DP.

    Attributes:
        function: The edition's name (`frozen_lake`, 2018's `frozenlake`).
        shape: `five` (2018-2023) or `six` results (2024 on).
    """

    function: str = "frozen_lake"
    shape: Shape = "six"

    def plan(
        self, settings: FrozenLakeConfig, functions: Mapping[str, FunctionInfo], seed: int
    ) -> list[Call]:
        """Both lakes' frozen_lake calls, then the student's own solvers on each lake (pure calls)."""
        info = functions.get(self.function)
        names = [parameter.name for parameter in info.parameters] if info is not None else []
        calls = []
        for lake in LAKES:
            args: tuple[PlainValue, ...] = (lake.basic_case, settings.episodes)
            if len(names) >= 3 and names[2] == "render":
                args = (*args, False)
            budget = games_budget(2 * settings.episodes, LAKE_STEPS * EPISODE_SLACK // 4)
            calls.append(Call(self.function, args, budget=budget))
        for lake in LAKES:
            table = mdp_argument(lake.mdp)
            size = (lake.mdp.n_states, lake.mdp.n_actions)
            calls.append(Call("value_iteration", (table, *size), budget=NO_EPISODES))
            calls.append(Call("policy_iteration", (table, *size), budget=NO_EPISODES))
        return calls

    def second_plan(
        self, settings: FrozenLakeConfig, first: Verdict, functions: Mapping[str, FunctionInfo], seed: int
    ) -> list[Call]:
        """Both lakes' frozen_lake calls again, the grader's steps bound, when the first did not pass."""
        if first.status == "passed":
            return []
        played = self.plan(settings, functions, seed)[: len(LAKES)]
        return [replace(call, provided=STEPS_PROVIDED) for call in played]

    def keep(self, settings: FrozenLakeConfig, first: Verdict, second: Verdict) -> Verdict:
        """The better of the two readings, the student's own on a tie."""
        return better_reading(first, second)

    @paused_gc
    def judge(self, settings: FrozenLakeConfig, records: Sequence[CallRecord]) -> Verdict:
        """Judge both calls; the solver calls only explain a non-optimal answer (the own reading)."""
        verdict = self._judged(settings, records)
        if any(record.outcome.call.provided for record in records):
            feedback = f"{verdict.feedback} {GRADERS_READING}"
            return Verdict(verdict.status, verdict.fraction, feedback, verdict.measurements)
        return verdict

    def _judged(self, settings: FrozenLakeConfig, records: Sequence[CallRecord]) -> Verdict:
        played = [record for record in records if record.outcome.call.function == self.function]
        own = [record for record in records if record.outcome.call.function != self.function]
        early = outcome_verdict(played)
        if early is not None:
            return early
        measurements: dict[str, PlainValue] = {}
        readings: list[str] = []
        for number, (lake, record) in enumerate(zip(LAKES, played, strict=False)):
            verdict = self._judge_call(settings, lake, record, number, own, measurements, readings)
            if verdict is not None:
                return verdict
        reading = (
            " " + " ".join(dict.fromkeys(readings))
            if readings
            else " Every policy and value function is the exact optimum (exact reading)."
        )
        means = sorted({str(value) for key, value in measurements.items() if key.endswith("_reading")})
        reading += f" Your means count each episode {' and '.join(means)}."
        if ORDERS[1] in measurements.values():
            reading += " " + ALTERNATING_READING
        return Verdict(
            "passed",
            1.0,
            f"{self.function}: on the slippery 4x4 and 8x8 lakes you played M={settings.episodes} episodes with each policy, every action the policy's, and returned the exact means of the replayed returns; each policy's mean is within Bernstein's bound of its exact value under the time limit played (false-fail probability {settings.mean_alpha:g} each).{reading}",  # noqa: E501
            measurements,
        )

    def _judge_call(
        self,
        settings: FrozenLakeConfig,
        lake: Lake,
        record: CallRecord,
        number: int,
        own: Sequence[CallRecord],
        measurements: dict[str, PlainValue],
        readings: list[str],
    ) -> Verdict | None:
        call = f"{self.function}(basic_case={lake.basic_case}, M={settings.episodes})"
        returned = self._read(record.outcome.value, lake.mdp)
        if isinstance(returned, str):
            return _fail(f"{call} returned {describe(record.outcome.value)}; {returned}")
        episodes = played_episodes([record])
        problem = integrity_problem([record], episodes, settings.game_rules())
        if problem:
            return _fail(f"{call}: {problem}.")
        wrong_lake = next((e for e in episodes if lake.game.mismatch(e.log) is not None), None)
        if wrong_lake is not None:
            return _fail(
                f"{call}: your episodes were played in {wrong_lake.log.requested_id!r} with {wrong_lake.log.env_kwargs}; basic_case={lake.basic_case} asks for the slippery {lake.map_name} lake (gym.make('FrozenLake-v1', map_name={lake.map_name!r}, is_slippery=True))."  # noqa: E501
            )
        m = settings.episodes
        if len(episodes) != 2 * m:
            return _fail(
                f"{call}: you played {len(episodes)} episodes; M={m} asks for M episodes with the value-iteration policy, then M with the policy-iteration policy."  # noqa: E501
            )
        problems: list[Verdict] = []
        for order in ORDERS:
            found: dict[str, PlainValue] = {}
            order_problem = _order_problem(settings, call, lake, returned, order, episodes, found)
            if order_problem is None:
                measurements.update(found)
                measurements[f"{lake.map_name}_order"] = order
                break
            problems.append(order_problem)
        else:  # no order explains the episodes: the first order's problem is the one told
            measurements.update(problems[0].measurements)
            return Verdict(problems[0].status, problems[0].fraction, problems[0].feedback, measurements)
        answer = self._answer_problem(settings, lake, returned, own, readings)
        return _fail(f"{call}: {answer}") if answer else None

    def _read(self, value: PlainValue, mdp: Mdp) -> Returned | str:
        size = 6 if self.shape == "six" else 5
        if not isinstance(value, list | tuple) or len(value) != size:
            names = (
                "(vi_value_func, vi_policy, vi_avg_disct_rewards, pi_value_func, pi_policy, pi_avg_disct_rewards)"  # noqa: E501
                if size == 6
                else "(vi_policy, vi_total_rewards, pi_value_func, pi_policy, pi_total_rewards)"
            )
            return f"expected {size} results {names}."
        items = list(value) if size == 6 else [None, *value]
        vi_values = None if size == 5 else as_vector(items[0], mdp.n_states)
        policies = [as_policy(items[1], mdp), as_policy(items[4], mdp)]
        means = [as_number(items[2]), as_number(items[5])]
        pi_values = as_vector(items[3], mdp.n_states)
        if (size == 6 and vi_values is None) or pi_values is None:
            return f"the value functions must be {mdp.n_states} numbers each (one per state)."
        if policies[0] is None or policies[1] is None:
            return f"the policies must be {mdp.n_states} actions each (whole numbers 0-3)."
        if means[0] is None or means[1] is None:
            return "the mean rewards must be numbers."
        return Returned(vi_values, policies[0], float(means[0]), pi_values, policies[1], float(means[1]))

    def _answer_problem(
        self,
        settings: FrozenLakeConfig,
        lake: Lake,
        returned: Returned,
        own: Sequence[CallRecord],
        readings: list[str],
    ) -> str | None:
        """Why the returned policies and value functions are neither optimal nor the own solvers' answers."""
        mdp = lake.mdp
        optimum = optimal_solution(mdp, 1.0).values
        wrong: list[str] = []
        for name, policy in (("vi_policy", returned.vi_policy), ("pi_policy", returned.pi_policy)):
            judged = judge_policy(mdp, policy, 1.0)
            if not judged.optimal:
                worst = int(np.argmax(judged.shortfall))
                wrong.append(
                    f"{name} is not optimal: its exact value in state {worst} is {judged.values[worst]:.6g}, the optimum {optimum[worst]:.6g}"  # noqa: E501
                )
        for name, values in (("vi_value_func", returned.vi_values), ("pi_value_func", returned.pi_values)):
            if values is not None and np.max(np.abs(values - optimum)) > settings.value_tolerance:
                worst = int(np.argmax(np.abs(values - optimum)))
                wrong.append(
                    f"{name} is {describe_values(values)}, not the optimal values {describe_values(optimum)} (state {worst}: {values[worst]:.6g} against {optimum[worst]:.6g})"  # noqa: E501
                )
        if not wrong:
            return None
        explained = self._own_reading(lake, returned, own)
        if explained:
            readings.append(explained)
            return None
        return (
            "; ".join(wrong)
            + ". frozen_lake solves the slippery lake with your value_iteration and policy_iteration at beta = 1 and returns their results."  # noqa: E501
        )

    def _own_reading(self, lake: Lake, returned: Returned, own: Sequence[CallRecord]) -> str | None:
        """The own-solver reading when it explains every returned answer, else None."""
        index = 0 if lake.basic_case else 1
        pair = own[2 * index : 2 * index + 2]
        if len(pair) < 2 or any(record.outcome.status is not OutcomeStatus.OK for record in pair):
            return None
        mdp = lake.mdp
        vi_value = pair[0].outcome.value
        vi_v = as_vector(
            vi_value[0] if isinstance(vi_value, list | tuple) and vi_value else None, mdp.n_states
        )
        pi_value = pair[1].outcome.value
        if vi_v is None or not isinstance(pi_value, list | tuple) or len(pi_value) < 2:
            return None
        pi_v, pi_p = as_vector(pi_value[0], mdp.n_states), as_policy(pi_value[1], mdp)
        if pi_v is None or pi_p is None:
            return None
        greedy = bool(np.all(greedy_gaps(mdp, vi_v, returned.vi_policy, 1.0) <= 1e-9 * (1 + np.abs(vi_v))))
        same_vi = returned.vi_values is None or bool(np.allclose(returned.vi_values, vi_v, atol=1e-9))
        same_pi = bool(np.array_equal(returned.pi_policy, pi_p)) and bool(
            np.allclose(returned.pi_values, pi_v, atol=1e-9)
        )
        if greedy and same_vi and same_pi:
            return (
                f"On the {lake.map_name} lake your answers are not the exact optimum, but they are what your own value_iteration and policy_iteration return there "  # noqa: E501
                "(own-solver reading): the mistake is graded in those problems, not here."
            )
        return None


WHOLE = "to the end, past the time limit"
"""The reading of the time limit that counts each episode to its terminal state (`_mean_problem`)."""
ORDERS = ("one after the other", "alternating")
"""How frozen_lake's 2M episodes may be ordered: the M value-iteration episodes then the M policy-iteration
ones (two loops, or two list comprehensions), or alternating, one with each policy per pass of one loop
(`for _ in range(M): vi += run_simulation(env, vi_policy); pi += run_simulation(env, pi_policy)`, a common
form in real files). On FrozenLake both policies are usually the same, so the actions cannot tell the orders
apart: each is tried, the first order under which every episode follows its policy and both means are the
replayed ones counts; when none does, the first order's problem is reported."""
ALTERNATING_READING = (
    "Your episodes alternate between the two policies (one with each per pass of your loop); "
    "each mean was compared with the replayed episodes of its own policy."
)


def _groups(episodes: Sequence[Episode], order: str) -> tuple[Sequence[Episode], Sequence[Episode]]:
    """The (vi, pi) episodes under one of `ORDERS`."""
    if order == ORDERS[0]:
        m = len(episodes) // 2
        return episodes[:m], episodes[m:]
    return episodes[0::2], episodes[1::2]


def _order_problem(
    settings: FrozenLakeConfig,
    call: str,
    lake: Lake,
    returned: Returned,
    order: str,
    episodes: Sequence[Episode],
    measurements: dict[str, PlainValue],
) -> Verdict | None:
    """Why the episodes, grouped by `order`, are not the returned policies' play and means, or None."""
    halves = (("vi", returned.vi_policy, returned.vi_mean), ("pi", returned.pi_policy, returned.pi_mean))
    for index, ((name, policy, mean), group) in enumerate(zip(halves, _groups(episodes, order), strict=True)):
        off = _off_policy(group, policy)
        if off:
            which = (
                ("first" if index == 0 else "second") + " M episodes"
                if order == ORDERS[0]
                else ("odd" if index == 0 else "even") + "-numbered episodes"
            )
            return _fail(f"{call}: {off} (the {which} play {name}_policy).", measurements)
        key = f"{lake.map_name}_{name}"
        verdict = _mean_problem(settings, call, name, group, mean, measurements, key)
        if verdict is not None:
            return verdict
        off = _off_policy_past_limit(group, policy) if measurements[f"{key}_reading"] == WHOLE else None
        if off:
            return _fail(f"{call}: {off}; your {name} mean counts those steps.", measurements)
        test = _bernstein(settings, lake, group, policy, measurements, key)
        if test is not None:
            return _fail(f"{call}: {test}", measurements)
    return None


def _off_policy(episodes: Sequence[Episode], policy: np.ndarray) -> str | None:
    for number, episode in enumerate(episodes):
        for step, (state, action) in enumerate(episode.decisions()):
            if int(action) != int(policy[int(state)]):
                return f"episode {number + 1}, step {step + 1}: action {action} in state {int(state)}, but the policy you returned has {int(policy[int(state)])} there"  # noqa: E501
    return None


def _off_policy_past_limit(episodes: Sequence[Episode], policy: np.ndarray) -> str | None:
    """The first action off `policy` among the steps played past gym.make's time limit, or None.

    Those steps count in the reading "to the end, past the time limit", so they are judged as the steps
    before the limit are (`_off_policy`): replayed to the episode's end, every action the policy's.
    """
    for number, episode in enumerate(episodes):
        if episode.reached_terminal or not episode.replay.truncated[-1]:
            continue
        whole = replay_past_time_limit(episode.log)
        decisions = zip(whole.observations[: whole.length], episode.log.actions[: whole.length], strict=True)
        for step, (state, action) in enumerate(decisions):
            if step >= episode.length and int(action) != int(policy[int(state)]):
                return f"episode {number + 1}, step {step + 1} (past gym.make's time limit): action {action} in state {int(state)}, but the policy you returned has {int(policy[int(state)])} there"  # noqa: E501
    return None


def _mean_problem(
    settings: FrozenLakeConfig,
    call: str,
    name: str,
    episodes: Sequence[Episode],
    mean: float,
    measurements: dict[str, PlainValue],
    key: str,
) -> Verdict | None:
    """None when `mean` is the replayed mean under either reading of the time limit (the reading noted)."""
    cut = math.fsum(episode.total_reward for episode in episodes) / len(episodes)
    whole = whole_mean(episodes)
    measurements[f"{key}_returned_mean"] = mean
    measurements[f"{key}_replayed_mean"] = cut
    for reading, value in (("up to the time limit", cut), (WHOLE, whole)):
        if value is not None and abs(mean - value) <= 1e-9 * max(1.0, abs(value)):
            measurements[f"{key}_reading"] = reading
            return None
    beyond = (
        ""
        if whole is None or whole == cut
        else f" ({whole:.6g} counting each episode to its end past gym.make's time limit)"
    )
    return _fail(
        f"{call}: you returned {mean:.6g} as the {name} mean reward, but your M={settings.episodes} replayed {name} episodes average {cut:.6g}{beyond}. "  # noqa: E501
        "Return the mean of run_simulation's returns over exactly the M episodes played with that policy.",
        measurements,
    )


def whole_mean(episodes: Sequence[Episode]) -> float | None:
    """The mean return with every episode the time limit cut replayed to its terminal state, or None when an
    episode was not continued to its end (then only the cut reading exists)."""
    totals = []
    for episode in episodes:
        if episode.reached_terminal or not episode.replay.truncated[-1]:
            totals.append(episode.total_reward)
            continue
        whole = replay_past_time_limit(episode.log)
        if whole.mismatch is not None or not whole.terminated or not whole.terminated[whole.length - 1]:
            return None
        totals.append(whole.total_reward)
    return math.fsum(totals) / len(totals)


def bernstein_half_width(variance: float, samples: int, alpha: float, value_range: float = 1.0) -> float:
    """Bernstein: P(|mean - mu| >= t) <= alpha for `samples` returns within `value_range` of their mean."""
    log_term = math.log(2.0 / alpha)
    return math.sqrt(2.0 * variance * log_term / samples) + value_range * log_term / (3.0 * samples)


def _bernstein(
    settings: FrozenLakeConfig,
    lake: Lake,
    episodes: Sequence[Episode],
    policy: np.ndarray,
    measurements: dict[str, PlainValue],
    key: str,
) -> str | None:
    """Why the policy's replayed mean up to the time limit played is off its exact finite-horizon mean."""
    limits = {time_limit_of(episode.log) for episode in episodes}
    if len(limits) != 1:
        return "your episodes were played under different time limits; play every episode in one env."
    limit = limits.pop()
    moments = return_moments(lake.mdp, policy, 1.0, steps=limit)
    mu, variance = float(moments.mean[0]), float(moments.variance[0])
    mean = math.fsum(episode.total_reward for episode in episodes) / len(episodes)
    half = bernstein_half_width(variance, len(episodes), settings.mean_alpha)
    measurements[f"{key}_exact_mean"] = mu
    measurements[f"{key}_tolerance"] = half
    if abs(mean - mu) <= half:
        return None
    horizon = f"within gym.make's {limit}-step limit" if limit else "without a time limit"
    return f"the {len(episodes)} episodes played with this policy average {mean:.4f}, but its exact mean {horizon} is {mu:.4f} ± {half:.4f} (Bernstein's inequality, false-fail probability {settings.mean_alpha:g}): the episodes are not a fair sample of the policy's play."  # noqa: E501


def _fail(feedback: str, measurements: dict[str, PlainValue] | None = None) -> Verdict:
    return Verdict("failed", 0.0, feedback, measurements or {})
