"""Per-problem checks: each module declares a problem's settings model and its check (pure, no I/O).

`grader.lab.problems` pairs each with its problem id; `base.py` is the contract they follow. A check module
(the second lab's, in `grader/lab/rl2/checks/`, are built the same way) holds:

- its settings model, a `grader.lab.settings.ProblemConfig` (`PlayedProblemConfig` when its calls play
  episodes), every field with a description (ASSIGNMENT.md explains the numbers; an optional problem,
  `enabled=False` in the registry, gives every field a default);
- its check: `plan(settings, functions, seed) -> list[Call]`, each call with its `CallBudget`
  (`integrity.games_budget` for played episodes), and `judge(settings, records) -> Verdict` on the replays
  (`episodes.played_episodes`), applying the integrity rules (`integrity.integrity_problem` or
  `played_games_problem` with `settings.game_rules()`) before any verdict of its own. `judge` runs under
  `@paused_gc`; one that needs every call to have returned takes `@judged_when_all_returned` (a call that did
  not return is then judged by `base.outcome_verdict`); the first lab's played problems note steps taken
  after a game ended (`@integrity.noting_post_terminal_steps`).

Its tests (`tests/grader/lab/checks/test_<id>.py`) grade simulated students: the reference passes, each
typical mistake is named, every verdict branch fails a sample of its own.
"""
