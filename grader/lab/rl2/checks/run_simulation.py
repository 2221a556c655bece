"""The second lab's `run_simulation(env, policy, beta=1.0)`: one episode's discounted return, replayed.

The grader passes its own envs and policies (`CASES`): deterministic lakes (4x4 at beta 0.8 and 1, 8x8 at
0.9), slippery lakes (4x4 with an optimal and a deliberately poor policy, 8x8 at discount 1) and Taxi (a
reward on every step, so a return of the last reward only shows). Each env is made by the child with
`gym.make` (`EnvArgument`, form `gym_object`: behind the compatibility layer, which serves each edition's
code the API it expects) with a time limit of `time_limit` steps (2 000: every grader policy ends its
episodes long before it, the chance of a cut is below 1e-20 per episode, so a loop on `terminated` only
and one on `terminated or truncated` play the same episodes). 2019-2022's `run_simulation(env, policy,
render=True, beta=1.0)` is called as the template orders it, `render=False` in third place.

Verdict, call by call: the one episode played in the env passed (the grader's seeds; the integrity rules
of the first lab: its game, no options, finished, replayed exactly), every action `policy[state]`, and the
returned number equal to `sum beta**k * r_k` from k = 0 over the replayed rewards (within `tolerance`). On
a deterministic lake that sum is `beta**(steps - 1)` exactly; on a slippery one each returned value is
compared with its own replayed episode, so nothing is statistical. A value that misses is explained by the
typical mistake that reproduces every call (discount from k = 1, never applied, `beta *= beta`, the last
reward only). Closing the env passed is named too (`env_closed`, the lab says the function does not).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from functools import cache

import numpy as np
import numpy.typing as npt
from pydantic import Field

from grader.compat.events import ENV_CLOSED, STEP_BEFORE_RESET
from grader.lab.checks.base import CallRecord, Verdict, outcome_verdict, paused_gc
from grader.lab.checks.integrity import Episode, games_budget, integrity_problem, played_episodes
from grader.lab.checks.values import as_number, describe
from grader.lab.games import (
    FROZEN_LAKE_4X4,
    FROZEN_LAKE_4X4_STILL,
    FROZEN_LAKE_8X8,
    FROZEN_LAKE_8X8_STILL,
    TAXI,
    Game,
)
from grader.lab.settings import PlayedProblemConfig, Share
from grader.sandbox.child.frames import ENV_GYM_OBJECT
from grader.sandbox.outcome import Call, EnvArgument, FunctionInfo, OutcomeStatus, PlainValue
from reference.oracles import optimal_q_table
from reference.oracles.mdp import optimal_solution
from reference.oracles.mdps import DOWN, frozen_lake

FUNCTION = "run_simulation"
TAXI_STEPS = 200
"""Taxi keeps its registered limit (an optimal policy delivers within 20 steps)."""


class RunSimulationConfig(PlayedProblemConfig):
    """The settings of `run_simulation(env, policy, beta)` (every edition of the second lab)."""

    slippery_calls: int = Field(
        default=10,
        ge=1,
        le=200,
        description="Calls (one episode each) on each of the three slippery cases; each returned value is checked exactly against its own replayed episode.",  # noqa: E501
    )
    time_limit: int = Field(
        default=2000,
        ge=100,
        le=100_000,
        description="max_episode_steps of the lakes the grader passes: far beyond any episode of its policies (a cut has probability below 1e-20 per episode), so stopping on `terminated` alone and on `terminated or truncated` play the same episodes.",  # noqa: E501
    )
    tolerance: float = Field(
        default=1e-10,
        gt=0.0,
        lt=1e-3,
        description="Largest difference (absolute, and relative to the value) between a returned value and the replayed episode's discounted return.",  # noqa: E501
    )
    closing_fraction: Share = Field(
        default=0.5,
        description="Share of the points a run_simulation that returns every value right but closes the env it is given keeps (status failed).",  # noqa: E501
    )


@dataclass(frozen=True)
class Case:
    """One env, policy and discount the grader passes.

    Attributes:
        key: Short name (measurements).
        game: The env's game.
        env_id: The id the child makes.
        kwargs: Its constructor arguments.
        policy: A function giving the policy (one action per state).
        beta: The discount passed.
        slippery: Whether the case is called `slippery_calls` times (else once).
        text: How the feedback names it.
    """

    key: str
    game: Game
    env_id: str
    kwargs: tuple[tuple[str, str | bool | int], ...]
    policy: Callable[[], npt.NDArray[np.int64]]
    beta: float
    slippery: bool
    text: str


@cache
def _lake_policy(map_name: str, slippery: bool, beta: float) -> npt.NDArray[np.int64]:
    return optimal_solution(frozen_lake(map_name, slippery=slippery), beta).policy


@cache
def _always_down() -> npt.NDArray[np.int64]:
    return np.full(16, DOWN, dtype=np.int64)


@cache
def _taxi_policy() -> npt.NDArray[np.int64]:
    table = optimal_q_table(0.9) - 1e-6 * np.arange(6)  # tie-free: any argmax plays the same
    policy: npt.NDArray[np.int64] = np.argmax(table, axis=1).astype(np.int64)
    return policy


def _lake(map_name: str, slippery: bool) -> tuple[tuple[str, str | bool | int], ...]:
    return (("is_slippery", slippery), ("map_name", map_name))


CASES = (
    Case(
        "still4_0.8",
        FROZEN_LAKE_4X4_STILL,
        "FrozenLake-v1",
        _lake("4x4", False),
        lambda: _lake_policy("4x4", False, 0.8),
        0.8,
        False,
        "the deterministic 4x4 lake, an optimal policy, beta=0.8",
    ),
    Case(
        "still4_1",
        FROZEN_LAKE_4X4_STILL,
        "FrozenLake-v1",
        _lake("4x4", False),
        lambda: _lake_policy("4x4", False, 0.8),
        1.0,
        False,
        "the deterministic 4x4 lake, an optimal policy, beta=1",
    ),
    Case(
        "still8_0.9",
        FROZEN_LAKE_8X8_STILL,
        "FrozenLake-v1",
        _lake("8x8", False),
        lambda: _lake_policy("8x8", False, 0.9),
        0.9,
        False,
        "the deterministic 8x8 lake, an optimal policy, beta=0.9",
    ),
    Case(
        "lake4_0.9",
        FROZEN_LAKE_4X4,
        "FrozenLake-v1",
        _lake("4x4", True),
        lambda: _lake_policy("4x4", True, 1.0),
        0.9,
        True,
        "the slippery 4x4 lake, an optimal policy, beta=0.9",
    ),
    Case(
        "lake4_down_0.95",
        FROZEN_LAKE_4X4,
        "FrozenLake-v1",
        _lake("4x4", True),
        _always_down,
        0.95,
        True,
        "the slippery 4x4 lake, a poor policy (always down), beta=0.95",
    ),
    Case(
        "lake8_1",
        FROZEN_LAKE_8X8,
        "FrozenLake-v1",
        _lake("8x8", True),
        lambda: _lake_policy("8x8", True, 0.9),
        1.0,
        True,
        "the slippery 8x8 lake, a policy optimal at 0.9, beta=1",
    ),
    Case("taxi_0.9", TAXI, "Taxi-v3", (), _taxi_policy, 0.9, False, "Taxi-v3, an optimal policy, beta=0.9"),
)
"""Every case the grader passes, in call order (deterministic first: they name a mistake exactly)."""


def planned_cases(settings: RunSimulationConfig) -> list[Case]:
    """One case per planned call, in call order."""
    return [case for case in CASES for _ in range(settings.slippery_calls if case.slippery else 1)]


def _limit(case: Case, settings: RunSimulationConfig) -> int | None:
    """The time limit of the env passed: `time_limit` for the lakes; Taxi keeps its registered 200 steps."""
    return None if case.game is TAXI else settings.time_limit


def _arguments(
    case: Case, settings: RunSimulationConfig, info: FunctionInfo | None
) -> tuple[tuple[PlainValue, ...], dict[str, PlainValue]]:
    """(args, kwargs) as the student's signature orders them: 2019-2022's `render` gets False."""
    env = EnvArgument(case.env_id, _limit(case, settings), ENV_GYM_OBJECT, case.kwargs)
    policy = case.policy()
    names = [parameter.name for parameter in info.parameters] if info is not None else []
    if len(names) >= 4 and names[2] == "render":
        return (env, policy, False, case.beta), {}
    if "render" in names:
        return (env, policy), {"beta": case.beta, "render": False}
    return (env, policy, case.beta), {}


MISTAKES: tuple[tuple[str, Callable[[Sequence[float], float], float]], ...] = (
    (
        "you discount from k = 1 (beta**(k + 1), or the weight multiplied by beta before the reward is added): the first step's reward is weighted by beta**0 = 1, the next by beta, and so on",  # noqa: E501
        lambda rewards, beta: math.fsum(beta ** (k + 1) * r for k, r in enumerate(rewards)),
    ),
    (
        "you never applied the discount (or returned the last reward only): the return is sum beta**k * r_k, each reward weighted by beta to the power of its step",  # noqa: E501
        lambda rewards, beta: math.fsum(rewards),
    ),
    (
        "you square the discount after every step (`beta *= beta`): the weight of step k is beta**k, so multiply a running weight by beta, never beta by itself",  # noqa: E501
        lambda rewards, beta: math.fsum(
            r * (1.0 if k == 0 else beta ** (2**k)) for k, r in enumerate(rewards)
        ),
    ),
    (
        "you square the discount after every step (`beta *= beta`): the weight of step k is beta**k, so multiply a running weight by beta, never beta by itself",  # noqa: E501
        lambda rewards, beta: math.fsum(
            r * (1.0 if k == 0 else beta ** (2 ** (k - 1))) for k, r in enumerate(rewards)
        ),
    ),
    (
        "you return the last reward only: the return adds every step's reward, sum beta**k * r_k",
        lambda rewards, beta: rewards[-1] if rewards else 0.0,
    ),
    (
        "you return the last reward only, discounted: the return adds every step's reward, sum beta**k * r_k",
        lambda rewards, beta: beta ** (len(rewards) - 1) * rewards[-1] if rewards else 0.0,
    ),
)
"""Typical mistaken returns, computed from the replayed rewards; the first that explains every call names
the mistake (the two readings of `beta *= beta` are the same mistake). On FrozenLake the only reward is the
last, so the last reward only and a discount never applied coincide there; Taxi tells them apart."""


def discounted_return(rewards: Sequence[float], beta: float) -> float:
    """`sum beta**k * r_k` from k = 0: what run_simulation returns for an episode."""
    return math.fsum(beta**k * reward for k, reward in enumerate(rewards))


@dataclass(frozen=True)
class RunSimulationCheck:
    """run_simulation on the grader's envs and policies: one replayed episode per call, its return exact."""

    def plan(
        self, settings: RunSimulationConfig, functions: Mapping[str, FunctionInfo], seed: int
    ) -> list[Call]:
        """One call per case (`slippery_calls` per slippery case), arguments in the student's order."""
        info = functions.get(FUNCTION)
        calls = []
        for case in planned_cases(settings):
            args, kwargs = _arguments(case, settings, info)
            steps = _limit(case, settings) or TAXI_STEPS
            calls.append(Call(FUNCTION, args, kwargs, budget=games_budget(1, steps)))
        return calls

    @paused_gc
    def judge(self, settings: RunSimulationConfig, records: Sequence[CallRecord]) -> Verdict:
        """Each call's one episode replayed, its actions the policy's, its return exact; mistakes named."""
        unreset = _not_reset(records)
        if unreset is not None:
            return _fail(unreset)
        early = outcome_verdict(records)
        if early is not None:
            return early
        cases = planned_cases(settings)[: len(records)]
        values = [as_number(record.outcome.value) for record in records]
        wrong_type = next((i for i, value in enumerate(values) if value is None), None)
        if wrong_type is not None:
            return _fail(
                f"run_simulation on {cases[wrong_type].text} returned {describe(records[wrong_type].outcome.value)}; expected one number, the episode's discounted return."  # noqa: E501
            )
        episodes = played_episodes(records)
        problem = integrity_problem(records, episodes, settings.game_rules())
        if problem:
            return _fail(f"run_simulation: {problem}.")
        by_call: list[list[Episode]] = [[] for _ in records]
        for episode in episodes:
            by_call[episode.call_index].append(episode)
        played: list[Episode] = []
        for number, (case, own) in enumerate(zip(cases, by_call, strict=True)):
            wrong = _episode_problem(case, own, number, _limit(case, settings))
            if wrong:
                return _fail(f"run_simulation on {case.text}: {wrong}")
            played.append(own[0])
        measurements: dict[str, PlainValue] = {"calls": len(records), "episodes_replayed": len(played)}
        misses = []
        for number, (case, episode, value) in enumerate(zip(cases, played, values, strict=True)):
            expected = discounted_return(episode.rewards, case.beta)
            if not _close(float(value), expected, settings.tolerance):  # type: ignore[arg-type]
                misses.append((number, case, episode, float(value), expected))  # type: ignore[arg-type]
        measurements["calls_with_the_replayed_return"] = len(records) - len(misses)
        if misses:
            return _fail(_miss_text(settings, cases, played, values, misses[0]), measurements)
        closed = [n for n, record in enumerate(records) if _closed(record)]
        if closed:
            return Verdict(
                "failed",
                settings.closing_fraction,
                f"run_simulation returned every episode's discounted return exactly, but it closed the env it was given (call {closed[0] + 1}, {cases[closed[0]].text}): "  # noqa: E501
                "the lab's run_simulation resets the env itself and leaves it open, since its caller made it and closes it (frozen_lake plays M episodes in one env). Remove env.close() from run_simulation.",  # noqa: E501
                measurements,
            )
        kinds = list(dict.fromkeys(case.text for case in cases))
        return Verdict(
            "passed",
            1.0,
            f"run_simulation: in all {len(records)} calls you played one episode in the env passed, followed the policy, and returned sum beta**k * r_k from k = 0 of the replayed episode exactly ({'; '.join(kinds)}).",  # noqa: E501
            measurements,
        )


def _not_reset(records: Sequence[CallRecord]) -> str | None:
    """Why a call stepped the env it was given without resetting it first, or None."""
    for record in records:
        outcome = record.outcome
        skipped = any(event.kind == STEP_BEFORE_RESET for event in outcome.compat_events)
        refused = outcome.status is OutcomeStatus.EXCEPTION and "ResetNeeded" in outcome.message
        if skipped or refused:
            return "run_simulation stepped the env it was given before resetting it: the lab's run_simulation resets the env itself (obs = env.reset(), or obs, info = env.reset() with gymnasium) and then plays one episode from there."  # noqa: E501
    return None


def _closed(record: CallRecord) -> bool:
    return any(event.kind == ENV_CLOSED for event in record.outcome.compat_events)


def _episode_problem(case: Case, episodes: Sequence[Episode], number: int, limit: int | None) -> str | None:
    """Why a call's episodes are not one episode of the env passed, played with the policy passed.

    The env is recognised by what makes the game: its id, map, slipperiness and time limit (an env made
    anew with all of them equal plays the same game from the grader's seeds, and is not told apart).
    """
    if not episodes:
        return (
            f"call {number + 1} returned a value without playing an episode in the env it was given. "
            "Play one episode in `env` (reset it, then step it with policy[state] until the episode ends) and return its discounted return."  # noqa: E501
        )
    if len(episodes) > 1:
        return f"call {number + 1} played {len(episodes)} episodes; run_simulation plays ONE episode and returns its discounted return."  # noqa: E501
    episode = episodes[0]
    made = {name: episode.log.env_kwargs.get(name) for name in (*dict(case.kwargs), "max_episode_steps")}
    passed = {**dict(case.kwargs), "max_episode_steps": limit}
    if episode.log.env_id not in case.game.gymnasium_ids or made != passed:
        arguments = ", ".join(f"{name}={value!r}" for name, value in made.items() if value is not None)
        return (
            f"call {number + 1} played its episode in an environment it made itself ({episode.log.requested_id!r}{', ' if arguments else ''}{arguments}), not in the env it was given. "  # noqa: E501
            "Play the env passed as the first argument: the caller chooses the lake and its time limit."
        )
    policy = case.policy()
    for step, (state, action) in enumerate(episode.decisions()):
        if int(action) != int(policy[int(state)]):
            return (
                f"call {number + 1}, step {step + 1}: in state {int(state)} you took action {action}, but the policy passed has policy[{int(state)}] = {int(policy[int(state)])}. "  # noqa: E501
                "Step with the action the given policy assigns to the current state."
            )
    return None


def _close(returned: float, expected: float, tolerance: float) -> bool:
    return abs(returned - expected) <= tolerance * max(1.0, abs(expected))


def _miss_text(
    settings: RunSimulationConfig,
    cases: Sequence[Case],
    played: Sequence[Episode],
    values: Sequence[float | None],
    miss: tuple[int, Case, Episode, float, float],
) -> str:
    number, case, episode, value, expected = miss
    where = (
        f"call {number + 1} on {case.text} played an episode of {episode.length} steps (rewards {describe(episode.rewards)}); "  # noqa: E501
        f"its discounted return sum beta**k * r_k from k = 0 is {expected:.10g}, and you returned {value:.10g}"  # noqa: E501
    )
    for cause, mistaken in MISTAKES:
        if all(
            _close(float(returned), mistaken(one.rewards, one_case.beta), settings.tolerance)  # type: ignore[arg-type]
            for one_case, one, returned in zip(cases, played, values, strict=True)
        ):
            return f"run_simulation: {where}: {cause}."
    return f"run_simulation: {where}. Return the sum over the episode's steps of beta**k times the step's reward, k counted from 0 at the first step."  # noqa: E501


def _fail(feedback: str, measurements: dict[str, PlainValue] | None = None) -> Verdict:
    return Verdict("failed", 0.0, feedback, measurements or {})
