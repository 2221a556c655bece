"""Grading instrumented for bench/speed.py: where one problem's time goes, and a shared-child prototype.

`grade_serially` runs `grader.grading.execution.run_problem` problem by problem in this process with timers
around the sandbox's child start, its calls, the replay and the teardown, and records every call made.
`SharedChild` is a prototype that exists here only: it hands `run_problem` one sandbox child for every problem
of a submission. `leaky_orders` grades a submission with module-level state through it in both orders, to show
what a shared child would let flow from one problem into the next.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import TracebackType
from typing import Any

LEAKY_SUBMISSION = """\
import gym

played = []  # module-level state, as notebooks have (a global env, a Q-table, a list of results)


def _episode(env_id, policy):
    env = gym.make(env_id)
    observation, done, steps = env.reset(), False, 0
    while not done:
        observation, reward, done, info = env.step(policy(observation))
        steps += 1
    env.close()
    return steps


def cartpole():
    played.append("cartpole")
    print("calls made in this process so far:", len(played))
    return _episode("CartPole-v0", lambda observation: int(observation[2] > 0))


def car():
    played.append("car")
    print("calls made in this process so far:", len(played))
    return _episode("MountainCar-v0", lambda observation: 2 if observation[1] >= 0 else 0)
"""


@dataclass
class Buckets:
    """Time spent in the instrumented parts of one problem's grading."""

    ensure: float = 0.0
    call: float = 0.0
    replay: float = 0.0
    close: float = 0.0
    calls: list[tuple[str, tuple[Any, ...], dict[str, Any]]] = field(default_factory=list)


class Instruments:
    """Timers wrapped around the sandbox, the replay and the teardown of
    `grader.grading.execution.run_problem`."""

    def __init__(self) -> None:
        self.current = Buckets()
        self._in_call = False
        self._ensure_in_call = 0.0
        self._restore: list[tuple[Any, str, Any]] = []

    def __enter__(self) -> Instruments:
        import grader.grading.execution
        from grader.sandbox.runner import Sandbox

        self._wrap(Sandbox, "_ensure_child", self._timed_ensure)
        self._wrap(Sandbox, "call", self._timed_call)
        self._wrap(Sandbox, "close", self._timer("close"))
        self._wrap(grader.grading.execution, "replay_call", self._timer("replay"))
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, traceback: TracebackType | None
    ) -> None:
        for owner, name, original in reversed(self._restore):
            setattr(owner, name, original)

    def take(self) -> Buckets:
        """The buckets filled since the last take."""
        taken, self.current = self.current, Buckets()
        return taken

    def _wrap(self, owner: Any, name: str, make: Callable[[Any], Any]) -> None:
        original = getattr(owner, name, None)
        if original is None:
            print(f"note: {getattr(owner, '__name__', owner)}.{name} not found; its time counts as 'rest'")
            return
        self._restore.append((owner, name, original))
        setattr(owner, name, make(original))

    def _timer(self, bucket: str) -> Callable[[Any], Any]:
        def make(original: Any) -> Any:
            def timed(*args: Any, **kwargs: Any) -> Any:
                started = time.perf_counter()
                try:
                    return original(*args, **kwargs)
                finally:
                    setattr(
                        self.current, bucket, getattr(self.current, bucket) + time.perf_counter() - started
                    )

            return timed

        return make

    def _timed_ensure(self, original: Any) -> Any:
        def timed(sandbox: Any) -> Any:
            fresh = sandbox._child is None and sandbox._import_failure is None
            started = time.perf_counter()
            try:
                return original(sandbox)
            finally:
                if fresh:
                    elapsed = time.perf_counter() - started
                    self.current.ensure += elapsed
                    if self._in_call:
                        self._ensure_in_call += elapsed

        return timed

    def _timed_call(self, original: Any) -> Any:
        def timed(sandbox: Any, call: Any) -> Any:
            self.current.calls.append((call.function, tuple(call.args), dict(call.kwargs)))
            self._in_call, self._ensure_in_call = True, 0.0
            started = time.perf_counter()
            try:
                return original(sandbox, call)
            finally:
                self._in_call = False
                self.current.call += time.perf_counter() - started - self._ensure_in_call

        return timed


@dataclass
class ProblemCost:
    """Where one problem's grading time went (seconds)."""

    problem: str
    status: str
    wall: float
    start: float
    student: float
    transfer: float
    replay: float
    judge_rest: float
    close: float
    calls: int


def grade_serially(
    submission: Path, problems: Sequence[str], config: Any, seed: int, sandbox_factory: Any = None
) -> tuple[list[ProblemCost], list[Any], list[tuple[str, tuple[Any, ...], dict[str, Any]]]]:
    """Grade each problem in this process, one after the other, instrumented.

    Returns:
        Per-problem costs, the results, and every call made in order.
    """
    import grader.grading.execution
    from grader.sandbox import IsolationPolicy

    costs: list[ProblemCost] = []
    results: list[Any] = []
    calls: list[tuple[str, tuple[Any, ...], dict[str, Any]]] = []
    original_sandbox = grader.grading.execution.Sandbox
    if sandbox_factory is not None:
        grader.grading.execution.Sandbox = sandbox_factory
    try:
        with Instruments() as instruments:
            for problem in problems:
                started = time.perf_counter()
                run = grader.grading.execution.run_problem(
                    submission,
                    problem,
                    config=config,
                    grading_seed=seed,
                    policy=IsolationPolicy.REQUIRE_FULL,
                )
                wall = time.perf_counter() - started
                buckets = instruments.take()
                timings = run.result.timings
                student = timings.student_seconds if timings is not None else 0.0
                costs.append(
                    ProblemCost(
                        problem=problem,
                        status=run.result.status,
                        wall=wall,
                        start=buckets.ensure,
                        student=student,
                        transfer=max(buckets.call - student, 0.0),
                        replay=buckets.replay,
                        judge_rest=max(
                            wall - buckets.ensure - buckets.call - buckets.replay - buckets.close, 0
                        ),
                        close=buckets.close,
                        calls=len(buckets.calls),
                    )
                )
                results.append(run.result)
                calls += buckets.calls
    finally:
        grader.grading.execution.Sandbox = original_sandbox
    return costs, results, calls


class SharedChild:
    """Prototype: `run_problem` gets the same sandbox child for every problem (never closed in between).

    Each problem still gets its own seed stream (the sandbox's seed and call index are reset), and its own
    per-call time limit; the child, its imported module and every global it set carry over.
    """

    def __init__(self) -> None:
        self.sandbox: Any = None

    def __call__(
        self, submission: Path, *, seed: int, limits: Any, policy: Any
    ) -> contextlib.AbstractContextManager[Any]:
        from grader.sandbox.runner import Sandbox

        if self.sandbox is None:
            self.sandbox = Sandbox(submission, seed=seed, limits=limits, policy=policy)
        self.sandbox.seed = seed
        self.sandbox._next_index = 0
        self.sandbox.limits = limits
        return contextlib.nullcontext(self.sandbox)

    def close(self) -> None:
        """End the shared child."""
        if self.sandbox is not None:
            self.sandbox.close()


def graded(result: Any) -> dict[str, Any]:
    """A problem result without its timings: what must not depend on how the grading was scheduled."""
    data: dict[str, Any] = result.model_dump(exclude={"timings"})
    return data


def leaky_orders(directory: Path, config: Any, seed: int) -> dict[str, str]:
    """car's first output line when graded through a shared child after cartpole, and first."""
    submission = directory / "leaky.py"
    submission.write_text(LEAKY_SUBMISSION, encoding="utf-8")
    outputs = {}
    for order in (["cartpole", "car"], ["car", "cartpole"]):
        shared = SharedChild()
        try:
            _, results, _ = grade_serially(submission, order, config, seed, shared)
        finally:
            shared.close()
        car = next(result for result in results if result.id == "car")
        outputs[" then ".join(order)] = (car.output.splitlines() or [""])[0]
    return outputs
