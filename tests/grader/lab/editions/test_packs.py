"""Every edition is a complete pack; an assignment configuration's `edition` picks its problems."""

from pathlib import Path

import pytest

from grader.errors import ConfigError
from grader.lab.assignment import load_config
from grader.lab.editions import DEFAULT_EDITION, EDITIONS, all_problem_ids, edition_of
from grader.lab.editions.choice import choose_edition
from grader.lab.editions.errors import EditionConflict, UnknownEdition
from grader.lab.problems import PROBLEMS


@pytest.mark.parametrize("name", list(EDITIONS))
def test_each_pack_is_complete(name: str) -> None:
    edition = EDITIONS[name]
    assert edition.template.is_file() and edition.reference.is_file()
    graded = set(edition.registry.ids) - {"guessing_game"}  # the optional problem is the lab text's own
    declared = {function.name for function in edition.functions}
    assert graded <= declared
    config = load_config(edition.default_config)
    assert config.registry is edition.registry
    same_lab = [other.number for other in EDITIONS.values() if other.lab == edition.lab]
    assert same_lab == list(range(1, len(same_lab) + 1)), "numbers count within a lab, oldest first"


def test_the_labs_and_their_editions() -> None:
    labs = {name: edition.lab for name, edition in EDITIONS.items()}
    assert labs == {
        "classic": "opengym", "gym026": "opengym", "volume2": "opengym", "rl1": "opengym",
        "v2018": "rl2", "v2019": "rl2", "v2023": "rl2", "v2024": "rl2", "v2026": "rl2",
    }  # fmt: skip
    assert EDITIONS["v2018"].registry.ids == (
        "value_iteration",
        "extract_policy",
        "compute_policy_v",
        "policy_iteration",
        "frozenlake",
        "run_simulation",
    )
    assert EDITIONS["v2024"].registry.ids == (
        "value_iteration", "policy_improvement", "iter_policy_eval", "policy_iteration", "frozen_lake",
        "run_simulation", "model_comparison",
    )  # fmt: skip
    assert EDITIONS["v2026"].registry.ids[4:] == ("run_simulation", "frozen_lake")
    for name in ("v2018", "v2019", "v2023", "v2024", "v2026"):
        edition = EDITIONS[name]
        template = {f.name for f in edition.functions}
        assert {function for function, _ in edition.not_graded} | set(edition.registry.ids) == template


def test_the_first_edition_is_the_default_and_grades_the_lab_registry() -> None:
    assert DEFAULT_EDITION == "classic"
    config = load_config()
    assert (config.edition, config.registry) == ("classic", PROBLEMS)


def test_rl1_grades_the_shared_problems_and_its_own() -> None:
    rl1 = edition_of("rl1")
    assert rl1.registry.ids == (
        "random_blackjack", "blackjack", "cartpole", "car", "epsilon_decay", "taxi", "sarsa0", "compare"
    )  # fmt: skip
    for shared in ("random_blackjack", "blackjack", "cartpole", "car"):
        assert rl1.registry.problem(shared) is PROBLEMS.problem(shared)
    assert rl1.registry.problem("taxi") is not PROBLEMS.problem("taxi")  # the two-table taxi, same id
    assert {name for name, _ in rl1.not_graded} == {"qlearn"}
    assert "epsilon_decay" in all_problem_ids() and "taxi" in all_problem_ids()


def test_an_unknown_edition_in_a_configuration_is_a_config_error(tmp_path: Path) -> None:
    path = tmp_path / "assignment.toml"
    path.write_text('edition = "rl9"\n', encoding="utf-8")
    with pytest.raises(
        UnknownEdition, match=r"unknown edition 'rl9'; expected one of classic, gym026, volume2, rl1"
    ):
        load_config(path)
    assert issubclass(UnknownEdition, ConfigError)


def test_a_configuration_without_the_editions_tables_names_them(tmp_path: Path) -> None:
    path = tmp_path / "assignment.toml"
    path.write_text(
        Path(EDITIONS["classic"].default_config)
        .read_text(encoding="utf-8")
        .replace("[problems.random_blackjack]", 'edition = "rl1"\n[problems.random_blackjack]', 1),
        encoding="utf-8",
    )
    with pytest.raises(ConfigError, match=r"problems\.epsilon_decay"):
        load_config(path)


def test_choice_flag_config_detection(tmp_path: Path) -> None:
    rl1 = EDITIONS["rl1"]
    chosen = choose_edition("rl1", None, None)
    assert (chosen.edition, chosen.config) == (rl1, rl1.default_config)
    assert choose_edition("volume2", None, None).config is None  # the bundled configuration
    named = choose_edition(None, rl1.default_config, None)
    assert named.edition is rl1 and "named by" in named.reason
    detected = choose_edition(None, None, rl1.template)
    assert detected.edition is rl1 and detected.config == rl1.default_config
    assert detected.line.startswith(
        "Edition: rl1 (Reinforcement Learning 1: Gymnasium): detected from rl1.py: "
    )
    assert choose_edition(None, None, None).edition.name == "classic"
    # Editions 1-3 grade the same problems: the bundled configuration serves each.
    assert choose_edition("gym026", EDITIONS["classic"].default_config, None).edition.name == "gym026"


def test_a_flag_that_contradicts_the_configuration_says_what_to_do() -> None:
    with pytest.raises(
        EditionConflict, match=r'--edition rl1 grades .* configures edition classic .* write edition = "rl1"'
    ):
        choose_edition("rl1", EDITIONS["classic"].default_config, None)
    with pytest.raises(UnknownEdition, match="--edition: unknown edition 'x'"):
        choose_edition("x", None, None)
