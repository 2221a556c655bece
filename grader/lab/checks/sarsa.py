"""Edition rl1, problem 7: `sarsa0(env, alpha, gamma, epsilon, N, decay)`, verified by replaying its updates.

The grader calls `sarsa0` twice with its own hyper-parameters and a small N (a constant epsilon, then
`decay=True`). `env` is the environment's name, `"Taxi-v3"`, as the course's template documents it
(`env (str): environment name`, first line `env = gym.make(env)`) and the notebook's cells call it; the env
the function makes by that name is recorded (with the time limit below). A sarsa0 changed to take an env
object fails on the name before it makes or plays anything: it is then called again with an env object the
child makes and records (`EnvArgument` of form `name_or_object`), and the feedback says which form was used.
Every step is replayed, so the grader knows each (s, a, r, s', a'); it recomputes SARSA(0) from the zero
table over those transitions and compares the returned table cell by cell (`grader.lab.checks.sarsa_updates`).
A mismatch names the first wrong update and the mistake that explains the whole table. The actions must be
epsilon-greedy on the table as it was when chosen: the count of non-greedy actions is tested against
epsilon (or, with `decay=True`, against the student's own `epsilon_decay(i, N)`, so a wrong decay is counted
only in problem 5) with Bernstein's inequality at a stated false-fail probability.

The env (made by name or passed) has no 200-step limit (its limit lies beyond the call's step budget), so
the lab's loop on `terminated` and a loop that also stops on `truncated` play exactly the same episodes:
both are honest.

How a learner is verified by replaying its updates:

- A call may pass an environment: `EnvArgument(env_id, max_episode_steps, form)`
  (`grader/sandbox/child/frames.py`) travels as `{"$env": ...}` in a call's arguments only (a returned value
  or an episode log holding the tag is refused). `form` says how it reaches the function
  (`grader.sandbox.child.calls`): `object`, the child makes it through the recorder's `gymnasium.make`;
  `name`, the function gets the id (a str) and the recorder gives an env made by that id (lab id or its
  gymnasium id, `Recorder.named_envs`) the argument's time limit when the function names none, so the env the
  student's `env = gym.make(env)` makes is logged and replayed like any other; `name_or_object` (sarsa0's, as
  the course's template passes a name), the name first and, when the call raised before making an env by that
  name or resetting or stepping any env, the call again with the env object (the recorder restarted with the
  call's seed), reported as a compat event `env_object`; when the object gets no further (no reset or step),
  the name's error stands. A lab id the grader names is resolved without a compat event.
- A call may bind the grader's own definitions in place of the submission's globals for its duration:
  `Call.provided` names them, `grader/sandbox/child/provided.py` (stdlib only) defines them (sarsa0 with the
  lab's `epsilon_decay`, `decay_schedule = "grader"`); the child restores the student's afterwards.
- `grader/lab/checks/sarsa.py` says which form was used (`env_form(records)`: the `env_object` event), in the
  feedback and the `env_form` measurement. `grader/simulated_students/simulation.py` passes env arguments as
  the child does (`Lab.passed`, the same retry), so the simulated learners are written as the template is.
- `grader/lab/checks/sarsa_updates.py` is the pure core: transitions from trusted replays, SARSA(0) and
  typical mistaken rules recomputed from the zero table, the greedy/non-greedy judgement of every action
  against the table as it was, Bernstein's bound. `grader/lab/checks/sarsa.py` plans the calls, validates the
  returned table
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
import numpy.typing as npt
from pydantic import Field

from grader.compat.events import ENV_OBJECT_PASSED
from grader.lab.checks.base import RESET_SLACK, CallRecord, Verdict, outcome_verdict, paused_gc
from grader.lab.checks.epsilon_decay import returned_number
from grader.lab.checks.integrity import Episode, integrity_problem, played_episodes
from grader.lab.checks.sarsa_updates import (
    RULES,
    EpisodeSteps,
    Precision,
    Recomputed,
    Transition,
    bernstein_half_width,
    first_mismatch,
    mismatched_cells,
    recompute,
)
from grader.lab.checks.values import as_number, describe
from grader.lab.games import TAXI, Game, GameRules
from grader.lab.settings import Probability, ProblemConfig
from grader.sandbox.limits import CallBudget
from grader.sandbox.outcome import (
    ENV_NAME_OR_OBJECT,
    PROVIDED,
    Call,
    EnvArgument,
    FunctionInfo,
    OutcomeStatus,
    PlainValue,
)

TAXI_SHAPE = (500, 6)
PENALTY_REWARD = -10.0


class SarsaConfig(ProblemConfig):
    """The settings of `sarsa0(env, alpha, gamma, epsilon, N, decay)` (edition rl1)."""

    alpha: float = Field(
        default=0.5, gt=0.0, lt=1.0, description="Learning rate passed (not 1: a missing alpha must show)."
    )
    gamma: float = Field(
        default=0.9, gt=0.0, lt=1.0, description="Discount passed (not 1: a missing gamma must show)."
    )
    epsilon: float = Field(
        default=0.2, gt=0.0, lt=1.0, description="Constant exploration rate of the first call."
    )
    episodes: int = Field(
        default=50,
        ge=1,
        le=10_000,
        description="N of the constant-epsilon call (the lab's 70 000 costs minutes).",
    )
    decay_episodes: int = Field(
        default=20,
        ge=0,
        le=10_000,
        description="N of the decay=True call, which explores with epsilon_decay(i, N); 0 = no decay call. "
        "Keep it small: the last episodes explore with about 1/N, and a nearly greedy learner on a poorly trained table can circle for a long time.",  # noqa: E501
    )
    max_steps: int = Field(
        default=400_000,
        ge=1_000,
        le=5_000_000,
        description="Steps one call may take (its budget); the env's time limit lies beyond it.",
    )
    decay_schedule: Literal["student", "grader"] = Field(
        default="student",
        description="Whose epsilon_decay the decay=True call uses: 'student' (the submission's own, read by calling it for i = 1..N, and the behaviour judged against its values) or 'grader' (the child binds the lab's formula in its place for that call). "  # noqa: E501
        "Either way a wrong decay counts in epsilon_decay only.",
    )
    table_tolerance: float = Field(
        default=1e-8,
        gt=0.0,
        lt=1e-2,
        description="Largest difference (absolute, and relative to the value) between a returned cell and the recomputed one.",  # noqa: E501
    )
    float32_table_tolerance: float = Field(
        default=1e-5,
        gt=0.0,
        lt=1e-2,
        description="The same for a table of float32 cells (np.zeros(..., dtype=np.float32)): it is recomputed in float32, where algebraically equal update formulas differ by up to about 1e-6.",  # noqa: E501
    )
    behaviour_alpha: Probability = Field(
        default=1e-6,
        description="False-fail probability of EACH call's test of the non-greedy action count (Bernstein's inequality).",  # noqa: E501
    )

    def game_rules(self) -> GameRules:
        """Taxi-v3 as made for the call (by the function from the name, or by the child): its time limit
        beyond the call's step budget."""
        return GameRules(TAXI.name, (_taxi_game(self.env_steps),))

    @property
    def env_steps(self) -> int:
        """The time limit of the env passed: never reached within the call's budget."""
        return self.max_steps + 1


def _taxi_game(limit: int) -> Game:
    return Game(
        TAXI.name,
        TAXI.gymnasium_ids,
        {**TAXI.rules, "max_episode_steps": limit},
        description=f"the {TAXI.name} env of the call (made from the name passed to sarsa0; time limit {limit})",  # noqa: E501
    )


def env_form(records: Sequence[CallRecord]) -> tuple[str, str]:
    """How sarsa0 got its env: ("name", ...) as the template has it, or ("object", ...) after failing on the
    name; the second item says so in a sentence."""
    for record in records:
        for event in record.outcome.compat_events:
            if event.kind == ENV_OBJECT_PASSED:
                return "object", (
                    f"The grader called sarsa0 with an environment object, gym.make({TAXI.name!r}): "
                    f"called with the name {TAXI.name!r}, as the template's `env = gym.make(env)` expects, it failed before making or playing it"  # noqa: E501
                )
    return "name", (
        f"The grader called sarsa0 with the environment's name, {TAXI.name!r}, as the template's `env = gym.make(env)` expects"  # noqa: E501
    )


@dataclass(frozen=True)
class Run:
    """One planned call of sarsa0."""

    episodes: int
    decay: bool

    @property
    def text(self) -> str:
        return (
            f"the decay=True call (N={self.episodes})"
            if self.decay
            else f"the call with epsilon constant (N={self.episodes})"
        )


def _runs(settings: SarsaConfig) -> list[Run]:
    runs = [Run(settings.episodes, False)]
    if settings.decay_episodes:
        runs.append(Run(settings.decay_episodes, True))
    return runs


@dataclass(frozen=True)
class SarsaCheck:
    """sarsa0 called with the grader's Taxi env and hyper-parameters; updates and exploration verified."""

    def plan(self, settings: SarsaConfig, functions: Mapping[str, FunctionInfo], seed: int) -> list[Call]:
        """The sarsa0 calls, then (for the decay call) the student's epsilon_decay(i, N) for i = 1..N.

        The decay schedule is read first: the decay call is judged against the student's own values.
        """
        calls = []
        for run in _runs(settings):
            if run.decay and settings.decay_schedule == "student":
                calls += [
                    Call("epsilon_decay", (episode, run.episodes), budget=CallBudget(0, 0))
                    for episode in range(1, run.episodes + 1)
                ]
            arguments = (
                EnvArgument(TAXI.name, settings.env_steps, ENV_NAME_OR_OBJECT),
                settings.alpha,
                settings.gamma,
                settings.epsilon,
                run.episodes,
                run.decay,
            )
            budget = CallBudget(2 * run.episodes + RESET_SLACK, settings.max_steps)
            provided = ("epsilon_decay",) if run.decay and settings.decay_schedule == "grader" else ()
            calls.append(Call("sarsa0", arguments, budget=budget, provided=provided))
        return calls

    @paused_gc
    def judge(self, settings: SarsaConfig, records: Sequence[CallRecord]) -> Verdict:
        """Verify each call's table update by update, its penalties, and its exploration."""
        sarsa_records = [record for record in records if record.outcome.call.function == "sarsa0"]
        decay_records = [record for record in records if record.outcome.call.function == "epsilon_decay"]
        schedule_note = ""
        if any(record.outcome.status is not OutcomeStatus.OK for record in decay_records):
            failed = next(r for r in decay_records if r.outcome.status is not OutcomeStatus.OK)
            schedule_note = (
                f" The decay=True call was not made: epsilon_decay{failed.outcome.call.args} did not return ({failed.outcome.message or failed.outcome.status.value}); "  # noqa: E501
                "it is graded in problem 5."
            )
        decay_run = next((run for run in _runs(settings) if run.decay), None)
        broken_schedule = (
            settings.decay_schedule == "student"
            and decay_run is not None
            and len(sarsa_records) == 2
            and _schedule(settings, decay_records, decay_run) is None
        )
        if broken_schedule and sarsa_records[1].outcome.status is not OutcomeStatus.OK:
            message = sarsa_records[1].outcome.message
            sarsa_records = sarsa_records[:1]
            schedule_note = (
                f" The decay=True call is not counted: your epsilon_decay returned something that is not a number and sarsa0 failed with it ({message}); "  # noqa: E501
                "epsilon_decay is graded in problem 5."
            )
        form_key, form = env_form(sarsa_records)
        early = outcome_verdict(sarsa_records)
        if early is not None and early.status == "missing":
            return early
        if early is not None:
            return Verdict(early.status, early.fraction, f"{early.feedback} ({form}.)", early.measurements)
        measurements: dict[str, PlainValue] = {"env_form": form_key}
        passes = []
        runs = _runs(settings)
        for run, record in zip(runs, sarsa_records, strict=False):
            schedule = _schedule(settings, decay_records, run) if run.decay else None
            verdict = _judge_run(settings, run, record, schedule, measurements)
            if verdict is not None:
                return Verdict(
                    verdict.status,
                    verdict.fraction,
                    f"{verdict.feedback}{schedule_note} ({form}.)",
                    measurements,
                )
            passes.append(run)
        explained = "; ".join(_passed_text(run, measurements) for run in passes)
        return Verdict(
            "passed",
            1.0,
            f"sarsa0: every update of your table is SARSA(0)'s on the transitions you played, and you explored as epsilon-greedy does ({explained}).{schedule_note} {form}.",  # noqa: E501
            measurements,
        )


def _schedule(settings: SarsaConfig, decay_records: Sequence[CallRecord], run: Run) -> list[float] | None:
    """The decay call's epsilon_decay(i, N) for i = 1..N, clipped to [0, 1]; None when any is no number.

    The grader's formula when it provided its own; else the student's values, read by calling it.
    """
    if settings.decay_schedule == "grader":
        lab_decay = PROVIDED["epsilon_decay"]
        return [lab_decay(episode, run.episodes) for episode in range(1, run.episodes + 1)]
    values = [returned_number(record.outcome.value) for record in decay_records]
    if len(values) != run.episodes or any(value is None for value in values):
        return None
    return [min(max(float(value), 0.0), 1.0) for value in values if value is not None]


def _passed_text(run: Run, measurements: Mapping[str, PlainValue]) -> str:
    key = "decay" if run.decay else "constant"
    return f"{run.text}: {measurements[f'{key}_updates']} updates, {measurements[f'{key}_non_greedy']} non-greedy actions where {float(measurements[f'{key}_expected_non_greedy']):.1f} ± {float(measurements[f'{key}_tolerance']):.1f} were expected"  # noqa: E501


def returned_table(value: PlainValue) -> tuple[npt.NDArray[np.float64] | None, PlainValue, str]:
    """(the table as a float64 array, the penalties or None, what was wrong) from what sarsa0 returned."""
    penalties: PlainValue = None
    candidate = value
    if isinstance(value, list | tuple) and len(value) == 2 and not isinstance(value[0], int | float):
        candidate, penalties = value
    found = describe(candidate)
    if isinstance(candidate, np.ndarray):
        if candidate.shape != TAXI_SHAPE or candidate.dtype.kind not in "iuf":
            return None, None, f"an array of shape {candidate.shape} and dtype {candidate.dtype}"
        table = candidate.astype(np.float64)
    elif isinstance(candidate, list) and len(candidate) == TAXI_SHAPE[0]:
        rows = [row for row in candidate if isinstance(row, list) and len(row) == TAXI_SHAPE[1]]
        numbers = [[as_number(item) for item in row] for row in rows]
        if len(rows) != TAXI_SHAPE[0] or any(item is None for row in numbers for item in row):
            return None, None, found
        table = np.asarray(numbers, dtype=np.float64)
    else:
        return None, None, found
    if not np.isfinite(table).all():
        return None, None, "a table with NaN or infinite values"
    return table, penalties, ""


def episode_steps(episode: Episode, epsilon: float) -> EpisodeSteps:
    """The trusted transitions of a played episode (states from the replay, actions from the log)."""
    length = episode.length
    observations = episode.replay.observations
    actions = [int(action) for action in episode.log.actions[:length]]
    rewards = episode.replay.rewards
    transitions = tuple(
        Transition(
            int(observations[step]),
            actions[step],
            float(rewards[step]),
            int(observations[step + 1]),
            actions[step + 1] if step + 1 < length else None,
        )
        for step in range(length)
    )
    return EpisodeSteps(transitions, epsilon)


def _judge_run(
    settings: SarsaConfig,
    run: Run,
    record: CallRecord,
    schedule: list[float] | None,
    measurements: dict[str, PlainValue],
) -> Verdict | None:
    """The failing verdict of one call, or None when it passes (its figures added to `measurements`)."""
    key = "decay" if run.decay else "constant"
    table, penalties, wrong = returned_table(record.outcome.value)
    if table is None:
        return _fail(
            f"sarsa0 must return the Q-table, a finite {TAXI_SHAPE[0]} x {TAXI_SHAPE[1]} array (one row per Taxi state), or (table, penalties); "  # noqa: E501
            f"{run.text} returned {wrong}."
        )
    episodes = played_episodes([record])
    problem = integrity_problem([record], episodes, settings.game_rules())
    if problem:
        return _fail(f"sarsa0, {run.text}: {problem}.")
    if len(episodes) != run.episodes:
        return _fail(
            f"sarsa0, {run.text}: you played {len(episodes)} episode(s); N={run.episodes} asks for {run.episodes} training episodes, each from env.reset() until it terminates."  # noqa: E501
        )
    if any(not episode.reached_terminal for episode in episodes):
        return _fail(
            f"sarsa0, {run.text}: an episode ended without delivering the passenger; play each episode until `terminated`."  # noqa: E501
        )
    rates = schedule if run.decay and schedule is not None else [settings.epsilon] * run.episodes
    played = [episode_steps(episode, rate) for episode, rate in zip(episodes, rates, strict=True)]
    precision, tolerance = _precision(settings, table)
    honest = recompute(played, TAXI_SHAPE, settings.alpha, settings.gamma, precision=precision)
    expected = honest.array()
    cells = mismatched_cells(table, expected, tolerance)
    updates = sum(len(episode.transitions) for episode in played)
    measurements[f"{key}_updates"] = updates
    if cells:
        measurements[f"{key}_mismatched_cells"] = len(cells)
        return _fail(_mismatch_text(settings, run, played, table, honest, cells, precision, tolerance))
    penalty_count = sum(
        1 for episode in played for step in episode.transitions if step.reward == PENALTY_REWARD
    )
    measurements[f"{key}_penalties"] = penalty_count
    if penalties is not None:
        counted = as_number(penalties)
        if counted is None or counted != penalty_count:
            return _fail(
                f"sarsa0, {run.text}: your table is right, but you returned {describe(penalties)} penalties; the episodes you played took {penalty_count} rewards of -10 (illegal pick-ups and drop-offs). Count `reward == -10` at every step."  # noqa: E501
            )
    if run.decay and schedule is None:
        measurements[f"{key}_non_greedy"] = honest.non_greedy
        measurements[f"{key}_expected_non_greedy"] = float("nan")
        measurements[f"{key}_tolerance"] = float("nan")
        return None
    half_width = bernstein_half_width(honest.variance, settings.behaviour_alpha)
    measurements[f"{key}_non_greedy"] = honest.non_greedy
    measurements[f"{key}_expected_non_greedy"] = honest.expected_non_greedy
    measurements[f"{key}_tolerance"] = half_width
    deviation = honest.non_greedy - honest.expected_non_greedy
    if abs(deviation) <= half_width:
        return None
    return _fail(_behaviour_text(settings, run, honest, half_width))


def _precision(settings: SarsaConfig, table: npt.NDArray[np.float64]) -> tuple[Precision, float]:
    """The cells' precision of a returned table and the tolerance it is compared with: float32 when every
    cell is a float32 number (a table made with dtype=np.float32, returned as an array or as lists; a
    float64 learner's table with gamma < 1 is not), else float64."""
    if bool(np.all(table.astype(np.float32) == table)):
        return np.float32, max(settings.table_tolerance, settings.float32_table_tolerance)
    return float, settings.table_tolerance


def _mismatch_text(
    settings: SarsaConfig,
    run: Run,
    played: Sequence[EpisodeSteps],
    table: npt.NDArray[np.float64],
    honest: Recomputed,
    cells: Sequence[tuple[int, int]],
    precision: Precision,
    tolerance: float,
) -> str:
    expected = honest.array()
    (state, action), where = first_mismatch(cells, honest.last_update)
    if where is None:
        place = f"Q[{state}, {action}] is {table[state, action]:.6g}, but no transition you played updates it, so SARSA(0) from the zero table leaves it at 0"  # noqa: E501
    else:
        episode, step = where
        place = (
            f"at episode {episode + 1}, step {step + 1} (the last update of that cell) your table's Q[{state}, {action}] is "  # noqa: E501
            f"{table[state, action]:.6g}; SARSA(0) from the transitions you played gives {expected[state, action]:.6g}"  # noqa: E501
        )
    for rule in RULES:
        variant = recompute(
            played, TAXI_SHAPE, settings.alpha, settings.gamma, rule, judge_actions=False, precision=precision
        )
        if not mismatched_cells(table, variant.array(), tolerance):
            return f"sarsa0, {run.text}: {place}; {rule.explanation}."
    return (
        f"sarsa0, {run.text}: {place} ({len(cells)} cells differ). Your table is not the one SARSA(0) computes from the zero table over the episodes this call played, "  # noqa: E501
        "nor any typical variant (Q-learning, a missing alpha or gamma, a skipped last update): return the table this call trained, "  # noqa: E501
        "starting from np.zeros, with Q[s, a] += alpha * (r + gamma * Q[s', a'] - Q[s, a]) at every step, a' being the next action you then play."  # noqa: E501
    )


def _behaviour_text(settings: SarsaConfig, run: Run, honest: Recomputed, tolerance: float) -> str:
    whose = "your own" if settings.decay_schedule == "student" else "the grader's"
    rate = f"epsilon_decay(i, N) of {whose} epsilon_decay" if run.decay else f"epsilon={settings.epsilon}"
    stated = (
        f"{honest.non_greedy} of your {honest.actions} actions were not a greedy action of the table as it was when you chose them; "  # noqa: E501
        f"epsilon-greedy with {rate} gives {honest.expected_non_greedy:.1f} ± {tolerance:.1f} (Bernstein's inequality, false-fail probability {settings.behaviour_alpha:g})"  # noqa: E501
    )
    if honest.non_greedy > honest.expected_non_greedy and honest.greedy_on_previous > honest.non_greedy // 2:
        cause = f"{honest.greedy_on_previous} of them were greedy on the previous state's row: choose the next action from next_state, not from state"  # noqa: E501
    elif honest.non_greedy > honest.expected_non_greedy:
        cause = "you explored more than epsilon asks (or chose actions on another table): explore with probability epsilon, else take a maximiser of q_table[state]"  # noqa: E501
    elif run.decay:
        cause = "you explored less than the decayed schedule asks: with decay=True episode i explores with epsilon_decay(i, N)"  # noqa: E501
    else:
        cause = "you explored less than epsilon asks: explore with probability epsilon (random.uniform(0, 1) < epsilon), using the epsilon passed in"  # noqa: E501
    return f"sarsa0, {run.text}: {stated}; {cause}."


def _fail(feedback: str) -> Verdict:
    return Verdict("failed", 0.0, feedback, {})
