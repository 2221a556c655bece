"""Settings refuse to start the service without a strong instructor token, outside development."""

from __future__ import annotations

from datetime import UTC, datetime, timedelta

import pytest
from pydantic import ValidationError

from api.settings import GradebookPolicy, SeedPolicy, Settings, token_weakness

STRONG = "Zq3-vK9_pL2xR7mN4tB8wY6c"


@pytest.mark.parametrize(
    ("environment", "message"),
    [
        (
            {},
            "GYMGRADE_OPERATOR_TOKEN (or GYMGRADE_INSTRUCTOR_TOKEN) is not set; expected a long random token",
        ),
        (
            {"GYMGRADE_INSTRUCTOR_TOKEN": "secret"},
            "GYMGRADE_INSTRUCTOR_TOKEN is weak: expected at least 24 "
            "characters, found 6; generate a random one",
        ),
        (
            {"GYMGRADE_INSTRUCTOR_TOKEN": "ab" * 20},
            "GYMGRADE_INSTRUCTOR_TOKEN is weak: expected at least 10 "
            "distinct characters, found 2; generate a random one",
        ),
        (
            {"GYMGRADE_OPERATOR_TOKEN": "secret"},
            "GYMGRADE_OPERATOR_TOKEN is weak: expected at least 24 characters, found 6",
        ),
        (
            {"GYMGRADE_OPERATOR_TOKEN": STRONG, "GYMGRADE_INSTRUCTOR_TOKEN": STRONG[::-1]},
            "GYMGRADE_OPERATOR_TOKEN and GYMGRADE_INSTRUCTOR_TOKEN are both set, to different tokens: "
            "expected one operator token",
        ),
    ],
    ids=["missing", "short", "repetitive", "operator-short", "two-different"],
)
def test_unsafe_tokens_are_refused_outside_development(
    monkeypatch: pytest.MonkeyPatch, environment: dict[str, str], message: str
) -> None:
    monkeypatch.delenv("GYMGRADE_INSTRUCTOR_TOKEN", raising=False)
    monkeypatch.delenv("GYMGRADE_OPERATOR_TOKEN", raising=False)
    monkeypatch.delenv("GYMGRADE_DEVELOPMENT", raising=False)
    for name, value in environment.items():
        monkeypatch.setenv(name, value)
    with pytest.raises(ValidationError) as raised:
        Settings()
    assert message in str(raised.value)


@pytest.mark.parametrize("token", [None, "dev"], ids=["missing", "weak"])
def test_development_allows_a_missing_or_weak_token(
    monkeypatch: pytest.MonkeyPatch, token: str | None
) -> None:
    monkeypatch.setenv("GYMGRADE_DEVELOPMENT", "1")
    if token is None:
        monkeypatch.delenv("GYMGRADE_INSTRUCTOR_TOKEN", raising=False)
    else:
        monkeypatch.setenv("GYMGRADE_INSTRUCTOR_TOKEN", token)
    assert Settings().development


def test_environment_variables_are_read_with_the_prefix(
    monkeypatch: pytest.MonkeyPatch, tmp_path: object
) -> None:
    monkeypatch.setenv("GYMGRADE_INSTRUCTOR_TOKEN", STRONG)
    monkeypatch.setenv("GYMGRADE_DATA_DIR", str(tmp_path))
    monkeypatch.setenv("GYMGRADE_MAX_UPLOAD_BYTES", "1000")
    monkeypatch.setenv("GYMGRADE_GRADEBOOK_POLICY", "best")
    monkeypatch.setenv("GYMGRADE_SEED_POLICY", "random")
    monkeypatch.setenv("GYMGRADE_ALLOW_WEAK_ISOLATION", "true")
    settings = Settings()
    assert settings.instructor_token is not None and settings.instructor_token.get_secret_value() == STRONG
    assert (settings.max_upload_bytes, settings.gradebook_policy, settings.seed_policy) == (
        1000,
        GradebookPolicy.BEST,
        SeedPolicy.RANDOM,
    )
    assert settings.allow_weak_isolation
    assert settings.sqlalchemy_url == f"sqlite:///{tmp_path}/gymgrade.sqlite3"


@pytest.mark.parametrize(
    "names",
    [
        ("GYMGRADE_OPERATOR_TOKEN",),
        ("GYMGRADE_INSTRUCTOR_TOKEN",),
        ("GYMGRADE_OPERATOR_TOKEN", "GYMGRADE_INSTRUCTOR_TOKEN"),
    ],
    ids=["operator", "instructor", "both-alike"],
)
def test_the_operator_token_is_read_under_either_name(
    monkeypatch: pytest.MonkeyPatch, names: tuple[str, ...]
) -> None:
    for name in ("GYMGRADE_OPERATOR_TOKEN", "GYMGRADE_INSTRUCTOR_TOKEN", "GYMGRADE_DEVELOPMENT"):
        monkeypatch.delenv(name, raising=False)
    for name in names:
        monkeypatch.setenv(name, STRONG)
    operator = Settings().operator
    assert operator is not None and operator.get_secret_value() == STRONG


def test_database_url_takes_precedence(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("GYMGRADE_INSTRUCTOR_TOKEN", STRONG)
    monkeypatch.setenv("GYMGRADE_DATABASE_URL", "postgresql+psycopg://u@127.0.0.1/db")
    assert Settings().sqlalchemy_url == "postgresql+psycopg://u@127.0.0.1/db"


def test_isolation_is_strict_by_default(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("GYMGRADE_INSTRUCTOR_TOKEN", STRONG)
    monkeypatch.delenv("GYMGRADE_ALLOW_WEAK_ISOLATION", raising=False)
    assert not Settings().allow_weak_isolation


def test_a_generated_token_is_strong() -> None:
    assert token_weakness(STRONG) is None


def test_each_submission_gets_a_held_out_seed_by_default(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("GYMGRADE_INSTRUCTOR_TOKEN", STRONG)
    monkeypatch.delenv("GYMGRADE_SEED_POLICY", raising=False)
    settings = Settings()
    assert (settings.seed_policy, settings.release_seeds, settings.due_date) == (
        SeedPolicy.RANDOM,
        False,
        None,
    )


def test_the_public_practice_seed_is_refused_as_a_fixed_grading_seed(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("GYMGRADE_INSTRUCTOR_TOKEN", STRONG)
    monkeypatch.delenv("GYMGRADE_DEVELOPMENT", raising=False)
    monkeypatch.setenv("GYMGRADE_SEED_POLICY", "fixed")
    with pytest.raises(ValidationError) as raised:
        Settings()
    assert (
        "GYMGRADE_SEED_POLICY=fixed with GYMGRADE_SEED=0: that is the public practice seed of `gymgrade "
        "check`, so a file could memorise every start" in str(raised.value)
    )
    monkeypatch.setenv("GYMGRADE_SEED", "8675309")
    assert Settings().seed == 8675309
    monkeypatch.delenv("GYMGRADE_SEED")
    monkeypatch.setenv("GYMGRADE_DEVELOPMENT", "1")
    assert Settings().seed == 0, "development may grade on the practice seed"


@pytest.mark.parametrize(
    ("value", "expected"),
    [
        ("2026-12-01T12:00:00", datetime(2026, 12, 1, 12, 0, tzinfo=UTC)),
        ("2026-12-01T13:00:00+01:00", datetime(2026, 12, 1, 12, 0, tzinfo=UTC)),
    ],
    ids=["naive-is-utc", "offset-converted"],
)
def test_the_due_date_is_held_in_utc(monkeypatch: pytest.MonkeyPatch, value: str, expected: datetime) -> None:
    monkeypatch.setenv("GYMGRADE_INSTRUCTOR_TOKEN", STRONG)
    monkeypatch.setenv("GYMGRADE_DUE_DATE", value)
    due_date = Settings().due_date
    assert due_date == expected and due_date is not None and due_date.utcoffset() == timedelta(0)


def test_a_due_date_that_is_not_a_date_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("GYMGRADE_INSTRUCTOR_TOKEN", STRONG)
    monkeypatch.setenv("GYMGRADE_DUE_DATE", "next friday")
    with pytest.raises(ValidationError, match="due_date"):
        Settings()


@pytest.mark.parametrize(
    ("environment", "message"),
    [
        (
            {"GYMGRADE_BROKER_URL": "amqp://127.0.0.1:5672//"},
            "expected a Redis URL such as redis://127.0.0.1:6379/0",
        ),
        (
            {"GYMGRADE_BROKER_URL": "redis://127.0.0.1:6379/0", "GYMGRADE_VISIBILITY_TIMEOUT_SECONDS": "600"},
            "GYMGRADE_VISIBILITY_TIMEOUT_SECONDS must exceed GYMGRADE_GRADING_TIMEOUT_SECONDS (1800), "
            "found 600",
        ),
    ],
    ids=["not-redis", "visibility-shorter-than-a-grading"],
)
def test_unsafe_broker_settings_are_refused(
    monkeypatch: pytest.MonkeyPatch, environment: dict[str, str], message: str
) -> None:
    monkeypatch.setenv("GYMGRADE_DEVELOPMENT", "1")
    for name, value in environment.items():
        monkeypatch.setenv(name, value)
    with pytest.raises(ValidationError) as raised:
        Settings()
    assert message in str(raised.value)


def test_without_a_broker_url_nothing_distributed_is_configured(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("GYMGRADE_DEVELOPMENT", "1")
    monkeypatch.setenv("GYMGRADE_BROKER_URL", "")
    assert Settings().broker_url is None


def test_an_edition_no_pack_has_is_refused_when_the_service_starts(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("GYMGRADE_INSTRUCTOR_TOKEN", STRONG)
    monkeypatch.setenv("GYMGRADE_EDITION", "rl9")
    with pytest.raises(ValidationError) as raised:
        Settings()
    assert "GYMGRADE_EDITION: unknown edition 'rl9'; expected one of classic, gym026, volume2, rl1" in str(
        raised.value
    )
    monkeypatch.setenv("GYMGRADE_EDITION", "rl1")
    assert Settings().edition == "rl1"


@pytest.mark.parametrize(
    ("lab", "edition", "message"),
    [
        (
            "nonsense",
            None,
            "GYMGRADE_LAB: unknown lab 'nonsense'; expected one of opengym (OpenGym AI / Reinforcement Learning 1), rl2 (Policy Function Iteration / Reinforcement Learning 2)",  # noqa: E501
        ),
        (
            "rl2",
            "rl1",
            "GYMGRADE_EDITION=rl1 is an edition of lab opengym (OpenGym AI / Reinforcement Learning 1), but GYMGRADE_LAB=rl2 names lab rl2 (Policy Function Iteration / Reinforcement Learning 2): name one of rl2's editions (v2018, v2019, v2023, v2024, v2026), or unset GYMGRADE_LAB",  # noqa: E501
        ),
    ],
    ids=["unknown-lab", "edition-of-another-lab"],
)
def test_a_lab_the_service_cannot_grade_is_refused_when_it_starts(
    monkeypatch: pytest.MonkeyPatch, lab: str, edition: str | None, message: str
) -> None:
    monkeypatch.setenv("GYMGRADE_INSTRUCTOR_TOKEN", STRONG)
    monkeypatch.setenv("GYMGRADE_LAB", lab)
    if edition is not None:
        monkeypatch.setenv("GYMGRADE_EDITION", edition)
    with pytest.raises(ValidationError) as raised:
        Settings()
    assert message in str(raised.value)


def test_a_lab_and_one_of_its_editions_are_accepted(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("GYMGRADE_INSTRUCTOR_TOKEN", STRONG)
    monkeypatch.setenv("GYMGRADE_LAB", "rl2")
    assert (Settings().lab, Settings().edition) == ("rl2", None)
    monkeypatch.setenv("GYMGRADE_EDITION", "v2019")
    assert (Settings().lab, Settings().edition) == ("rl2", "v2019")
