"""The lab graded: its problems and their settings, the checks that decide each verdict, the editions, and
the assignment configuration that chooses among them (`assignment.toml`, documented in ASSIGNMENT.md).

How the lab's parts fit:

- `grader/lab/stats.py` pure statistics.
- Problems: `grader/lab/problems.py` is the first edition's registry, the only list of its problems (later
  editions declare theirs in `grader/lab/editions/`, reusing these entries): `PROBLEMS` (a
  `grader.lab.registry.Registry` of `Problem[ConfigT]`: id, title, default points, default `enabled`, settings
  model, check; in lab order), `PROBLEM_IDS`, `problem(id)`. `ProblemId` is a `str` checked where it
  enters (`Registry.problem`/`select` raise `grader.errors.UnknownProblem` with "unknown problem X;
  expected ids among ..."). Derived from it: the configuration's tables, `--only` (choices, help, message),
  the acceptance modules (`test_<id>.py`, `PROBLEM = PROBLEMS.acceptance_problem(__name__)`) and the
  report's titles and points.
  `tests/grader/lab/test_problems.py` fails on any other source that lists every id.
- `grader/lab/assignment.py` loads `grader/lab/assignment.toml` for a registry (`load_config(path,
  registry=PROBLEMS)`): `assignment_file_model(registry)` has one `[problems.<id>]` table per problem, parsed
  with its settings model, whose `title`, `points` and `enabled` default to the registry's; a problem disabled
  by default may be left out (built from its model's defaults). Each loaded settings object is bound to its
  problem (`settings.problem_id`; `settings.game_rules()` is `allowed_games(problem.games, accepted_envs)` for
  played problems, None otherwise). `AssignmentConfig.problem(id)` gives the settings as `ProblemConfig`;
  `registry.problem(id).settings(assignment)` gives them typed (`Problem.settings`, the one narrowing;
  `PlanError` for another registry's). `config.registry` is the registry it was loaded with, and
  `model_dump_json()` (the report's `config_sha256`) includes every problem's own fields.
- `grader/lab/games.py`: the environments problems may be played in, each declared once (`Game`s:
  `Blackjack-v0` = gymnasium `Blackjack-v1` with `sab=False`, `Blackjack-v1` with `sab=True` (`natural`
  free for both: it never changes a win), `CartPole-v0`, `CartPole-v1`, `MountainCar-v0`, `Taxi-v3`,
  `GuessingGame-v0`; the second lab's FrozenLake lakes, `frozen_lake_game(map_name, slippery=)`; the labs'
  `*_GAMES` tuples); which a problem accepts is its declaration's `games`
  (the loader binds them to its settings), and `allowed_games(games, names=None, *, problem) -> GameRules`
  with `problem_with(log) -> str | None` (why an episode's env is none of them), `game_of(log)`,
  `played_game(logs) -> Game | str` (one game per problem). A problem's `accepted_envs` in the
  configuration restricts the list. Checks pick their exact oracles by the game played (`Game.sab`).
- **Optional problems.** `guessing_game` (the lab's midpoint search on `GuessingGame-v0`) is a full
  problem (a `PROBLEMS` entry with `enabled=False`; `GuessingGameConfig` and `GuessingGameCheck` in
  `grader/lab/checks/guessing_game.py`; acceptance module, samples) that is off unless the configuration says
  `enabled = true`; its settings fields all have defaults, so a file without its table loads (and leaves
  it off). Its check judges each guess against the midpoint of the interval the
  replayed observations leave and the total of guesses with an exact test
  (`checks.guessing_game.total_acceptance`: the n-fold convolution of the oracle's distribution).
- `grader/lab/checks/` pure per-problem verdict logic; `grader/grading/cases/` one pytest module per problem
  (`test_<id>.py` with `PROBLEM` and `test_<id>(problem_case, grade)`), run by pytest-xdist through the plugin
  `grader/grading/plugin.py` in one **acceptance session per grading, in the calling process**
  (`grader/grading/session.py`; see `grader.grading`). `grader/lab/checks/base.py` is the contract:
  `CallRecord(outcome, replays)`, `Verdict(status, fraction, feedback, measurements)`, `ProblemCheck[ConfigT]`
  with `.plan(settings: ConfigT, functions, seed) -> list[Call]` (the problem's seed) /
  `.judge(settings: ConfigT, records) -> Verdict`
  (a check never narrows its settings; the games its episodes must be played in are `settings.game_rules()`),
  and the shared outcome mapping. Every planned `Call` carries a `CallBudget`
  (`grader.lab.checks.integrity.games_budget`). `grader.grading.execution.run_problem` looks the problem up in
  `config.registry`, makes the calls one by one; each outcome becomes a record through
  `integrity.replay_call(outcome, settings.game_rules())`, which checks env ids, arguments and reset options
  **before** anything is replayed (refused logs get `replay.not_replayed(reason)` replays); after each record
  `integrity.settled_by(record, games)` says whether the verdict can still change, and if not the remaining
  calls are not made (the verdict's feedback and `calls_planned`/`calls_made` measurements say so). The
  integrity rules (the grader's seeds, the lab's game, no options, played starts a fair sample of the dealt
  ones, real and finished games) are `integrity_problem`; the selection test on dealt starts is
  `grader/lab/checks/starts.py` (it values every start with `reference.oracles` or the reference policy and
  needs every call, so unplayed resets never settle a verdict early); steps after a game ended are a note
  (`integrity.noting_post_terminal_steps` on each played check's `judge`), and a call beyond its `CallBudget`
  is a described `failed` (`base.outcome_verdict`). All are stated in `grader/lab/ASSIGNMENT.md`. The numbers
  behind every check are explained in `grader/lab/ASSIGNMENT.md`.

**Where an edition's problems sit (no import circle, type-only imports included).** From the bottom:
`grader/lab/ids.py` (`ProblemId`, standard library only) <- `grader/lab/games.py` (the `Game`s and the lab's
`*_GAMES` tuples) <- `grader/lab/settings.py` (settings models; a loaded model is bound to its problem's id
and games) <- `grader/lab/checks/*` <- `grader/lab/showcase.py` (`ShowcaseRule`s) and `grader/lab/plots.py`
(plotters; matplotlib imported when a plot is drawn) <- `grader/lab/registry.py` (`Problem`, `Registry`; it
reads settings through the `SettingsSource` protocol, never `grader.lab.assignment`) <-
`grader/lab/problems.py` and the packs in `grader/lab/editions/` <- `grader/lab/assignment.py` <- everything
that grades or renders. A problem's declaration holds everything about it: `Problem(id, title, points, config,
check, enabled, games, showcase, plot)`; nothing outside it is keyed by problem id (`grader.render.figures`
asks `config.registry.problem(id).plot`, `grader.grading.execution` passes `problem.showcase`, the loader
binds `problem.games`).
"""
