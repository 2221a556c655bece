"""Per-step cost of recording in the sandbox child: the lab's Taxi loop with and without the recorder.

    python bench/recorder_cost.py [--steps 400000] [--rounds 5] [--api classic|gymnasium]
                                  [--game taxi|blackjack]

Each variant runs in a fresh interpreter, alternated A/B, B/A, ... for `--rounds` rounds:

- plain: `grader.compat.activate()`, then the lab's random Taxi play (`gym.make("Taxi-v3")`, reset, random
  actions until done, `--steps` steps in all), as the plain run of `bench/speed.py` does;
- recorded: the same after the child's set-up (`Recorder`, `install`, `begin_call(record=True)` with a
  budget, as `grader.sandbox.child.calls.run_call` does), then `finish_call` and the call's wire block
  (`log_block`: the log as sent, before JSON encoding).

Prints the median CPU per step of each and the median of the rounds' differences: what the recorder costs
per step. `--baseline TREE` adds a third variant, the recorder of another tree (a worktree of `main`), in
the same rounds: a before/after on the same load.
`--api gymnasium` plays through `gymnasium.make` directly (no compat wrapper); `--game blackjack` plays the
lab's Blackjack (one or two steps a game, so the cost of a reset dominates).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]


def play(steps: int, api: str, game: str) -> int:
    """Random play as the lab writes it; returns the steps taken (at least `steps`)."""
    if api == "classic":
        return play_classic(steps, "Taxi-v3" if game == "taxi" else "Blackjack-v0")
    return play_gymnasium(steps, "Taxi-v4" if game == "taxi" else "Blackjack-v1")


def play_classic(steps: int, env_id: str) -> int:
    """The lab's loop on the classic API (one function per API: the compat layer reads the call site)."""
    import random

    import gym

    env = gym.make(env_id)
    actions = env.action_space.n
    taken = 0
    while taken < steps:
        env.reset()
        done = False
        while not done:
            _, _, done, _ = env.step(random.randrange(actions))
            taken += 1
    return taken


def play_gymnasium(steps: int, env_id: str) -> int:
    """The same loop on gymnasium's API, through `gymnasium.make`."""
    import random

    import gymnasium

    env = gymnasium.make(env_id)
    actions = int(env.action_space.n)
    taken = 0
    while taken < steps:
        env.reset()
        terminated = truncated = False
        while not (terminated or truncated):
            _, _, terminated, truncated, _ = env.step(random.randrange(actions))
            taken += 1
    return taken


def play_block(env: Any, steps: int, actions: int) -> int:
    """`steps` steps or more of the lab's classic loop on `env` (whole episodes)."""
    import random

    taken = 0
    while taken < steps:
        env.reset()
        done = False
        while not done:
            _, _, done, _ = env.step(random.randrange(actions))
            taken += 1
    return taken


def interleaved(steps: int, game: str, blocks: int) -> dict[str, float]:
    """Median CPU per step of three variants in this one process, block by block in turn.

    - bare: the compat `ClassicEnv` straight on gymnasium's env, as the plain run has it (made before the
      recorder is installed, so gymnasium's own class, not the child's cheaper twin);
    - wrapped: through the recorder's wrapper (and the child's env) while the call does not record;
    - recording: through the wrapper while the call records (then `finish_call` and `log_block`).
    Interleaving the blocks in one process cancels most of the load's drift between variants.
    """
    import random

    import grader.compat

    grader.compat.activate()
    import gym

    from grader.compat.adapter import ClassicEnv
    from grader.sandbox.child.budget import WireBudget
    from grader.sandbox.child.recorder import Recorder, install

    env_id = "Taxi-v3" if game == "taxi" else "Blackjack-v0"
    bare = gym.make(env_id)  # made before `install`: gymnasium's own game, as the plain run plays it
    assert isinstance(bare, ClassicEnv)
    recorder = Recorder(0)
    install(recorder)
    wrapped = gym.make(env_id)
    actions = int(wrapped.action_space.n)
    random.seed(0)
    times: dict[str, list[float]] = {"bare": [], "wrapped": [], "recording": []}
    budget = WireBudget(max_episodes=10**6, max_steps=10**8)
    for block in range(blocks):
        for name in ("bare", "wrapped", "recording") if block % 2 == 0 else ("recording", "wrapped", "bare"):
            recorder.begin_call(block, record=name == "recording", budget=budget)
            started = time.process_time()
            taken = play_block(bare if name == "bare" else wrapped, steps, actions)
            if name == "recording":
                wire_log(recorder.finish_call())
            else:
                recorder.finish_call()
            times[name].append((time.process_time() - started) / taken * 1e6)
    return {name: statistics.median(values) for name, values in times.items()}


def wire_log(episodes: list[Any]) -> Any:
    """The call's episodes as the child puts them on the wire (per episode in a tree older than the
    columnar block, which an A/B baseline may be)."""
    try:
        from grader.sandbox.child.log_block import log_block
    except ImportError:
        return [episode.to_plain() for episode in episodes]
    return log_block(episodes)


def child(variant: str, steps: int, api: str, game: str) -> None:
    """One measurement in this process; prints `{"cpu": seconds, "steps": n}`."""
    os.environ.update({"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"})
    import grader.compat

    grader.compat.activate()
    recorder = None
    if variant == "recorded":
        from grader.sandbox.child.budget import WireBudget
        from grader.sandbox.child.recorder import Recorder, install

        recorder = Recorder(0)
        install(recorder)
        recorder.begin_call(1, record=True, budget=WireBudget(max_episodes=10**6, max_steps=10**8))
    import random

    random.seed(0)
    started = time.process_time()
    taken = play(steps, api, game)
    if recorder is not None:
        episodes = recorder.finish_call()
        plain = wire_log(episodes)
        assert sum(len(episode.actions) for episode in episodes) == taken, "every step logged"
        del plain
    print(json.dumps({"cpu": time.process_time() - started, "steps": taken}))


def run(variant: str, steps: int, api: str, game: str, tree: Path) -> dict[str, float]:
    """One measurement in a fresh interpreter, with the grader of `tree`."""
    environment = dict(
        os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(tree), os.environ.get("PYTHONPATH")]))
    )
    command = [
        sys.executable,
        __file__,
        "--child",
        variant,
        "--steps",
        str(steps),
        "--api",
        api,
        "--game",
        game,
    ]
    done = subprocess.run(command, capture_output=True, text=True, env=environment, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])  # type: ignore[no-any-return]


def interleaved_main(args: argparse.Namespace) -> int:
    """`--interleaved BLOCKS`: one process per tree (this one, then `--baseline`), variants block by block."""
    trees = {"this tree": ROOT} | ({} if args.baseline is None else {"baseline": args.baseline.resolve()})
    load = os.getloadavg()[0]
    print(
        f"{args.game}, classic API, {args.interleaved} blocks of {args.steps:,} steps per variant, "
        f"interleaved in one process per tree; load average {load:.1f} before"
    )
    for label, tree in trees.items():
        environment = dict(
            os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(tree), os.environ.get("PYTHONPATH")]))
        )
        command = [sys.executable, __file__, "--child", "interleaved", "--steps", str(args.steps)]
        command += ["--game", args.game, "--blocks", str(args.interleaved)]
        done = subprocess.run(command, capture_output=True, text=True, env=environment, check=True)
        figures = json.loads(done.stdout.strip().splitlines()[-1])
        bare = figures["bare"]
        print(
            f"  {label} ({tree}): bare {bare:.2f}, wrapped {figures['wrapped']:.2f}, recording "
            f"{figures['recording']:.2f} us/step (medians); the wrapper's frame "
            f"{figures['wrapped'] - bare:+.2f}, recording {figures['recording'] - bare:+.2f} us/step "
            f"({(figures['recording'] - bare) / bare:+.0%} of the bare step)"
        )
    print(f"load average {os.getloadavg()[0]:.1f} after")
    return 0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, default=400_000)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--api", choices=("classic", "gymnasium"), default="classic")
    parser.add_argument("--game", choices=("taxi", "blackjack"), default="taxi")
    parser.add_argument(
        "--baseline",
        type=Path,
        default=None,
        help="also measure the recorder of this tree (a worktree of main, say), in the same rounds",
    )
    parser.add_argument(
        "--interleaved",
        type=int,
        default=0,
        metavar="BLOCKS",
        help="measure in one process per tree instead: BLOCKS blocks of --steps steps per variant, in turn",
    )
    parser.add_argument("--blocks", type=int, default=0, help=argparse.SUPPRESS)
    parser.add_argument("--child", choices=("plain", "recorded", "interleaved"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child == "interleaved":
        print(json.dumps(interleaved(args.steps, args.game, args.blocks)))
        return 0
    if args.child:
        child(args.child, args.steps, args.api, args.game)
        return 0
    if args.interleaved:
        return interleaved_main(args)
    trees = {"this tree": ROOT} | ({} if args.baseline is None else {"baseline": args.baseline.resolve()})
    variants = [("plain", "plain", ROOT)] + [
        (f"recorded, {label}", "recorded", tree) for label, tree in trees.items()
    ]
    per_step: dict[str, list[float]] = {label: [] for label, _, _ in variants}
    load = [os.getloadavg()[0]]
    for index in range(args.rounds):
        for label, variant, tree in variants if index % 2 == 0 else variants[::-1]:
            figures = run(variant, args.steps, args.api, args.game, tree)
            per_step[label].append(figures["cpu"] / figures["steps"] * 1e6)
    load.append(os.getloadavg()[0])
    print(
        f"{args.game} random play, {args.api} API, {args.steps:,} steps per run, {args.rounds} rounds, "
        f"variants alternated; load average {load[0]:.1f} before, {load[1]:.1f} after"
    )
    for label, values in per_step.items():
        each = ", ".join(f"{value:.2f}" for value in values)
        print(f"  {label:22s} {statistics.median(values):7.2f} us/step CPU (median; each: {each})")
    for label, tree in trees.items():
        paired = [
            recorded - plain
            for recorded, plain in zip(per_step[f"recorded, {label}"], per_step["plain"], strict=True)
        ]
        share = statistics.median(paired) / statistics.median(per_step["plain"])
        print(
            f"  recorder of {label} ({tree}): {statistics.median(paired):.2f} us/step "
            f"(median of the rounds' differences; {share:.0%} of the plain step)"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
