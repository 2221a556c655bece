"""The assignment configuration: the bundled file, its validation errors, and the power analysis behind it."""

from pathlib import Path

import pytest
from fake_problem import WITH_ECHO, WITH_OPTIONAL_ECHO, EchoConfig
from pydantic import BaseModel

from grader.errors import PlanError, UnknownProblem
from grader.lab import assignment as config_module
from grader.lab.assignment import AssignmentConfig, ConfigError, load_config
from grader.lab.checks.blackjack import BlackjackConfig
from grader.lab.problems import PROBLEM_IDS, PROBLEMS, problem
from grader.lab.registry import Registry
from grader.lab.settings import ProblemConfig
from grader.lab.stats import binomial_acceptance, mean_tolerance
from grader.sandbox.limits import Limits
from reference.oracles import random_policy_outcome, random_policy_return, threshold_policy_outcome

LAB_REQUIRED = [problem.id for problem in PROBLEMS if problem.enabled]
BUNDLED = config_module.DEFAULT_CONFIG_PATH.read_text(encoding="utf-8")


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "assignment.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_bundled_configuration_loads_with_every_problem() -> None:
    config = load_config()
    assert tuple(config.problems) == PROBLEM_IDS
    assert {config.problems[problem].points for problem in PROBLEM_IDS[:5]} == {1.0}
    assert config.problems["find_qvalues"].points == 0.0


def _models() -> list[type[BaseModel]]:
    file_model = config_module.assignment_file_model(PROBLEMS)
    return [
        AssignmentConfig,
        file_model,
        file_model.model_fields["problems"].annotation,
        config_module.SandboxConfig,
        *(entry.config for entry in PROBLEMS),
    ]


@pytest.mark.parametrize("model", _models(), ids=lambda model: model.__name__)
def test_every_field_is_described(model: type[BaseModel]) -> None:
    undescribed = [name for name, field in model.model_fields.items() if not field.description]
    assert undescribed == []


@pytest.mark.parametrize(
    ("registry", "required"), [(WITH_ECHO, [*LAB_REQUIRED, "echo"]), (WITH_OPTIONAL_ECHO, LAB_REQUIRED)]
)
def test_the_file_has_a_table_per_registered_problem_in_registry_order(
    registry: Registry, required: list[str]
) -> None:
    schema = config_module.assignment_file_model(registry).model_json_schema()
    tables = schema["$defs"]["ProblemTable"]
    assert (list(tables["properties"]), tables["required"]) == ([*PROBLEM_IDS, "echo"], required)
    assert tables["properties"]["echo"]["description"].startswith("Problem E: echo. `echo(n)`: every field")


def test_titles_points_and_enabled_default_to_the_registry(tmp_path: Path) -> None:
    config = load_config()
    assert [config.problem(entry.id).title for entry in PROBLEMS] == [entry.title for entry in PROBLEMS]
    assert [config.problem(entry.id).points for entry in PROBLEMS] == [entry.points for entry in PROBLEMS]
    unscored = BUNDLED.replace("points = 1.0\nenabled = true\n", "", 1)
    assert load_config(_write(tmp_path, unscored)).problem("random_blackjack").points == 1.0


def test_a_title_in_the_file_still_overrides_the_registry(tmp_path: Path) -> None:
    renamed = BUNDLED.replace("[problems.car]\n", '[problems.car]\ntitle = "Aufgabe 4: MountainCar"\n', 1)
    assert load_config(_write(tmp_path, renamed)).problem("car").title == "Aufgabe 4: MountainCar"


def test_the_digest_covers_every_problem_s_own_settings(tmp_path: Path) -> None:
    """The config_sha256 of reports hashes model_dump_json(): a changed threshold must change it."""
    changed = BUNDLED.replace("thresholds = [12, 13, 14, 20]", "thresholds = [12, 13, 14, 19]", 1)
    dumped, other = load_config().model_dump_json(), load_config(_write(tmp_path, changed)).model_dump_json()
    assert '"thresholds":[12,13,14,20]' in dumped
    assert dumped != other


def test_a_problem_disabled_by_default_may_be_left_out() -> None:
    config = load_config(registry=WITH_OPTIONAL_ECHO)
    echo = WITH_OPTIONAL_ECHO.problem("echo").settings(config)
    assert isinstance(echo, EchoConfig)
    assert (echo.enabled, echo.title, echo.points, echo.answer) == (False, "Problem E: echo", 2.0, 42)
    assert tuple(config.problems) == (*PROBLEM_IDS, "echo")
    assert config.registry is WITH_OPTIONAL_ECHO


def test_a_problem_enabled_by_default_may_not_be_left_out() -> None:
    with pytest.raises(ConfigError, match=r"problems\.echo: Field required \(add it to the file\)"):
        load_config(registry=WITH_ECHO)


def test_settings_are_typed_by_the_registry_and_bound_to_their_problem() -> None:
    config = load_config()
    settings = problem("blackjack").settings(config)
    assert isinstance(settings, BlackjackConfig)
    assert settings.problem_id == "blackjack"
    assert [game.name for game in settings.game_rules().games] == ["Blackjack-v0", "Blackjack-v1"]
    assert config.problem("find_qvalues").game_rules() is None


def test_settings_of_another_registry_are_refused_with_what_to_do(tmp_path: Path) -> None:
    echo_table = "[problems.echo]\nanswer = 7\n"
    config = load_config(_write(tmp_path, BUNDLED + echo_table), registry=WITH_ECHO)
    assert WITH_ECHO.problem("echo").settings(config).answer == 7
    with pytest.raises(UnknownProblem, match="unknown problem echo; expected ids among random_blackjack, "):
        load_config().problem("echo")
    foreign = config.model_copy(update={"problems": {**config.problems, "car": config.problem("echo")}})
    with pytest.raises(
        PlanError, match="expected CarConfig settings for problem car, found EchoConfig: load"
    ):
        problem("car").settings(foreign)


def test_settings_built_by_hand_say_how_to_bind_them() -> None:
    loose = ProblemConfig(title="t", points=1.0, call_seconds=1.0, expected_seconds=1.0)
    with pytest.raises(
        PlanError, match=r"unbound settings: load them with grader\.lab\.assignment\.load_config"
    ):
        _ = loose.problem_id
    assert loose.for_problem("car").problem_id == "car"


def test_accepted_envs_restrict_the_games(tmp_path: Path) -> None:
    assert problem("blackjack").settings(load_config()).accepted_envs is None
    restricted = BUNDLED.replace(
        "games_per_call = 10000", 'games_per_call = 10000\naccepted_envs = ["Blackjack-v1"]'
    )
    settings = problem("blackjack").settings(load_config(_write(tmp_path, restricted)))
    assert settings.accepted_envs == ["Blackjack-v1"]
    assert [game.name for game in settings.game_rules().games] == ["Blackjack-v1"]


def test_sandbox_settings_become_limits() -> None:
    limits = load_config().sandbox.to_limits(12.5)
    assert isinstance(limits, Limits)
    assert limits.call_seconds == 12.5
    assert limits.memory_bytes == 2 * 2**30


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        (
            "points = 1.0\nenabled = true\ncall_seconds = 60.0\nexpected_seconds = 2.0",
            "points = -1.0\nenabled = true\ncall_seconds = 60.0\nexpected_seconds = 2.0",
            "problems.random_blackjack.points: Input should be greater than or equal to 0 (found -1.0)",
        ),
        (
            "thresholds = [12, 13, 14, 20]",
            "thresholds = [12, 22]",
            "problems.blackjack.thresholds.1: Input should be less than or equal to 21 (found 22)",
        ),
        (
            "thresholds = [12, 13, 14, 20]",
            "thresholds = [12, 12]",
            "problems.blackjack.thresholds: Value error, expected distinct values of n, found [12, 12]",
        ),
        (
            "min_steps = 120",
            "min_steps = 120\nlaps = 3",
            "problems.cartpole.laps: Extra inputs are not permitted (found 3)",
        ),
        (
            "win_rate_alpha = 1e-6",
            "win_rate_alpha = 1.5",
            "problems.random_blackjack.win_rate_alpha: Input should be less than 1 (found 1.5)",
        ),
        (
            "memory_bytes = 2147483648",
            "memory_bytes = 1048576",
            "sandbox.memory_bytes: Input should be greater than or equal to 1610612736 (found 1048576)",
        ),
        (
            "[problems.find_qvalues]",
            "[problems.find_q]",
            "problems.find_qvalues: Field required (add it to the file)",
        ),
        (
            "min_steps = 120",
            'min_steps = 120\nvisibility = "secret"',
            "problems.cartpole.visibility: Input should be 'visible', 'after_due_date' or 'hidden' "
            "(found 'secret')",
        ),
        (
            "min_steps = 120",
            'min_steps = 120\nvisibility = "after_published"',
            "problems.cartpole.visibility: Input should be 'visible', 'after_due_date' or 'hidden' "
            "(found 'after_published')",
        ),
        (
            "uncounted_steps_deduction = 0.0\n\n[problems.car]",
            'uncounted_steps_deduction = 0.0\naccepted_envs = ["CartPole-v2"]\n\n[problems.car]',
            "problems.cartpole: Value error, accepted_envs must be a non-empty list of CartPole-v0, "
            "CartPole-v1; found ['CartPole-v2']",
        ),
        (
            "uncounted_steps_deduction = 0.0\n\n[problems.taxi]",
            "uncounted_steps_deduction = 1.5\n\n[problems.taxi]",
            "problems.car.uncounted_steps_deduction: Input should be less than or equal to 1 (found 1.5)",
        ),
        (
            'run = "when_scored"',
            'run = "sometimes"',
            "problems.find_qvalues.run: Input should be 'when_scored' or 'always' (found 'sometimes')",
        ),
    ],
    ids=[
        "negative-points",
        "threshold-above-21",
        "duplicate-thresholds",
        "unknown-field",
        "alpha-above-one",
        "memory-too-small",
        "missing-problem",
        "unknown-visibility",
        "gradescope-only-visibility",
        "unknown-game",
        "deduction-above-one",
        "unknown-find-qvalues-run",
    ],
)
def test_invalid_fields_are_named_with_what_was_found(
    tmp_path: Path, old: str, new: str, message: str
) -> None:
    assert old in BUNDLED
    with pytest.raises(ConfigError) as raised:
        load_config(_write(tmp_path, BUNDLED.replace(old, new, 1)))
    assert message in str(raised.value)
    assert "invalid assignment configuration" in str(raised.value)


def test_visibility_defaults_to_visible_and_can_be_set_per_problem(tmp_path: Path) -> None:
    assert {problem.visibility for problem in load_config().problems.values()} == {"visible"}
    text = BUNDLED.replace("min_steps = 120", 'min_steps = 120\nvisibility = "hidden"', 1).replace(
        "max_mean_steps = 180.0", 'max_mean_steps = 180.0\nvisibility = "after_due_date"', 1
    )
    config = load_config(_write(tmp_path, text))
    assert {problem: settings.visibility for problem, settings in config.problems.items()} == {
        "random_blackjack": "visible",
        "blackjack": "visible",
        "cartpole": "hidden",
        "car": "after_due_date",
        "taxi": "visible",
        "find_qvalues": "visible",
        "guessing_game": "visible",
    }


def test_no_points_at_all_is_refused(tmp_path: Path) -> None:
    text = BUNDLED.replace("points = 1.0", "points = 0.0")
    with pytest.raises(ConfigError, match="expected at least one enabled problem worth points; found none"):
        load_config(_write(tmp_path, text))


def test_missing_file_says_so(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match=r"nothing\.toml not found: pass an existing TOML file"):
        load_config(tmp_path / "nothing.toml")


def test_not_toml_says_so(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="is not valid UTF-8 TOML"):
        load_config(_write(tmp_path, "[problems\n"))


def test_an_unreadable_path_says_so(tmp_path: Path) -> None:
    with pytest.raises(
        ConfigError, match=r"cannot read the assignment configuration .* pass a readable TOML file"
    ):
        load_config(tmp_path)


# The power analysis of grader/lab/ASSIGNMENT.md, pinned: exact binomial probabilities and exact Taxi moments.


def test_random_blackjack_sample_size_detects_a_shifted_win_rate() -> None:
    settings = problem("random_blackjack").settings(load_config())
    exact = random_policy_outcome().win
    acceptance = binomial_acceptance(settings.games, exact, settings.win_rate_alpha)
    assert acceptance.false_fail <= 1e-6
    assert acceptance.pass_probability(exact - 0.04) < 1e-3
    assert acceptance.pass_probability(exact + 0.04) < 1e-3


def test_random_blackjack_hit_test_detects_a_biased_coin() -> None:
    settings = problem("random_blackjack").settings(load_config())
    # At least 1.3 decisions per game (measured 1.37): every game has one, and half of the first draws go on.
    decisions = int(1.3 * settings.games)
    tolerance = mean_tolerance(0.5, 0.25, decisions, settings.action_alpha)
    assert tolerance.pass_probability(0.45) < 1e-3
    assert tolerance.pass_probability(0.55) < 1e-3


def test_blackjack_thresholds_include_the_best_n_and_both_its_sides() -> None:
    thresholds = problem("blackjack").settings(load_config()).thresholds
    wins = {n: threshold_policy_outcome(n).win for n in range(22)}
    best = max(wins, key=wins.__getitem__)
    assert {best - 1, best, best + 1} <= set(thresholds)
    # n = 21 (always draw) never wins; among the others `<` versus `<=` matters most at:
    largest_gap = max(range(1, 21), key=lambda n: abs(wins[n] - wins[n - 1]))
    assert largest_gap in thresholds


def test_taxi_random_mean_tolerance() -> None:
    settings = problem("taxi").settings(load_config())
    moments = random_policy_return()
    tolerance = mean_tolerance(
        moments.mean,
        moments.variance,
        settings.episodes_per_scenario,
        settings.mean_alpha,
    )
    assert tolerance.half_width < 5.0
    assert tolerance.pass_probability(moments.mean + 10.0) < 1e-6


def test_the_optional_guessing_game_is_off_by_default_and_may_be_left_out(tmp_path: Path) -> None:
    assert not load_config().problems["guessing_game"].enabled
    table = BUNDLED[BUNDLED.index("[problems.guessing_game]") : BUNDLED.index("[sandbox]")]
    config = load_config(_write(tmp_path, BUNDLED.replace(table, "")))
    assert not config.problems["guessing_game"].enabled
    assert config.problems["guessing_game"] == load_config().problems["guessing_game"]
    enabled = load_config(_write(tmp_path, BUNDLED.replace("enabled = false", "enabled = true")))
    assert enabled.problems["guessing_game"].enabled
