"""The service's settings, read from ``GYMGRADE_*`` environment variables and validated once."""

from __future__ import annotations

import ipaddress
from datetime import UTC, datetime
from enum import StrEnum
from pathlib import Path
from urllib.parse import urlsplit

from pydantic import Field, SecretStr, field_validator, model_validator
from pydantic_settings import BaseSettings, SettingsConfigDict

from grader.seeds import PRACTICE_SEED

MIN_TOKEN_LENGTH = 24
MIN_TOKEN_DISTINCT_CHARACTERS = 10


class SeedPolicy(StrEnum):
    """How the grading seed of a submission is chosen."""

    FIXED = "fixed"
    RANDOM = "random"


class GradebookPolicy(StrEnum):
    """Which of a student's graded submissions the gradebook shows."""

    LATEST = "latest"
    BEST = "best"


class BrokerSettings(BaseSettings):
    """The distributed engine's settings: all `gymgrade grade` on a cluster needs (no token, no database)."""

    model_config = SettingsConfigDict(env_prefix="GYMGRADE_", extra="ignore", frozen=True)

    broker_url: str | None = Field(
        default=None,
        description="redis://HOST:PORT/N of the Celery broker: "
        "`serve` enqueues gradings there, `worker` runs a Celery worker, `grade` sends batches to the cluster. "  # noqa: E501
        "Unset: the embedded database queue.",
    )
    visibility_timeout_seconds: float = Field(
        default=3600.0,
        gt=0,
        description="A task taken by a worker that vanished is delivered again after this long; "
        "must exceed GRADING_TIMEOUT_SECONDS (the longest grading).",
    )
    reconcile_seconds: float = Field(
        default=30.0,
        gt=0,
        description="How often the server re-enqueues queued jobs whose task is gone (broker restart or flush) and running jobs whose worker stopped renewing its lease.",  # noqa: E501
    )

    @field_validator("broker_url")
    @classmethod
    def _redis_url(cls, url: str | None) -> str | None:
        if url is None or url == "":
            return None
        if urlsplit(url).scheme not in ("redis", "rediss"):
            raise ValueError("expected a Redis URL such as redis://127.0.0.1:6379/0")
        return url


class Settings(BrokerSettings):
    """Everything the service and its workers can be configured with (environment prefix ``GYMGRADE_``)."""

    model_config = SettingsConfigDict(env_prefix="GYMGRADE_", extra="ignore", frozen=True)

    data_dir: Path = Field(
        default=Path("gymgrade-data"),
        description="Directory holding the SQLite database (nothing executable is ever written there).",
    )
    database_url: str | None = Field(
        default=None,
        description="URL of a PostgreSQL database (postgresql+psycopg://...); unset: SQLite in DATA_DIR.",
    )
    operator_token: SecretStr | None = Field(
        default=None,
        description="Bearer token of the operator, who creates courses and their staff and acts as every course's instructor; "  # noqa: E501
        "required (or INSTRUCTOR_TOKEN, its name for a single course) unless DEVELOPMENT is set.",
    )
    instructor_token: SecretStr | None = Field(
        default=None,
        description="The operator's token under its single-course name (the default course's instructor): "
        "the same as OPERATOR_TOKEN; set one of the two (both only with the same value).",
    )
    development: bool = Field(
        default=False, description="Development mode: allows a missing or weak operator token."
    )
    max_upload_bytes: int = Field(default=256 * 1024, gt=0, description="Largest accepted submission file.")
    rate_limit_per_minute: int = Field(
        default=6, gt=0, description="Uploads one student may make in any 60 seconds."
    )
    workers: int = Field(
        default=1,
        ge=0,
        description="Gradings the server's worker pool runs at once (0: leave them to `gymgrade worker`); "
        "ignored by the server when BROKER_URL is set (Celery workers grade).",
    )
    grading_workers: int | None = Field(
        default=None, gt=0, description="Processes one grading spreads its checks over (default: all cores)."
    )
    seed_policy: SeedPolicy = Field(
        default=SeedPolicy.RANDOM,
        description="random: a fresh held-out seed per submission, stored in its row (an instructor regrades with it); "  # noqa: E501
        "fixed: every submission graded with SEED (never the public practice seed 0).",
    )
    seed: int = Field(default=0, ge=0, description="The grading seed under the fixed seed policy.")
    release_seeds: bool = Field(
        default=False,
        description="Show students the grading seed and per-problem seeds of their reports (instructors always see them); "  # noqa: E501
        "false keeps the starts unforeseeable.",
    )
    due_date: datetime | None = Field(
        default=None,
        description="The assignment's due date (ISO 8601; UTC when no offset is given): "
        "students see problems marked after_due_date from then on; unset, never.",
    )
    late_policy: Path | None = Field(
        default=None,
        description="A TOML file with a [late] table, as the assignment configuration has it (due, penalty_per_day, max_penalty, grace_minutes, [late.extensions] by student name): "  # noqa: E501
        "the gradebook takes late penalties by upload time; unset, none.",
    )
    gradebook_policy: GradebookPolicy = Field(
        default=GradebookPolicy.LATEST, description="latest or best graded submission per student."
    )
    allow_weak_isolation: bool = Field(
        default=False,
        description="Grade even when the sandbox cannot enforce full isolation (never for real students).",
    )
    grader: str = Field(
        default="grader.grading.grade:grade_submission",
        description="module:function with grade_submission's signature that grades one file.",
    )
    edition: str | None = Field(
        default=None,
        pattern=r"^[a-z][a-z0-9_]*$",
        description="The course's edition of the lab, set once per course: every upload is graded as it (grader/lab/editions/: classic, gym026, volume2, rl1; rl1 for today's). "  # noqa: E501
        "Unset: the first edition, classic. "
        "Never detected from an upload; a file written for another edition's problems is told so in its report.",  # noqa: E501
    )
    lab: str | None = Field(
        default=None,
        pattern=r"^[a-z][a-z0-9_]*$",
        description="The course's lab, set once per assignment's service (grader/lab/labs.py: opengym, rl2): every upload is graded as its current edition, or as GYMGRADE_EDITION, which must then be one of its editions. "  # noqa: E501
        "Unset: the lab of GYMGRADE_EDITION, else the first lab, opengym. Never detected from an upload.",
    )
    nice: int = Field(default=10, ge=0, le=19, description="Niceness added to grading processes.")
    lease_seconds: float = Field(
        default=60.0,
        gt=0,
        description="A running job whose worker stopped renewing it for this long is retried.",
    )
    poll_seconds: float = Field(
        default=1.0, gt=0, description="How often an idle worker looks for queued jobs."
    )
    max_attempts: int = Field(
        default=3, gt=0, description="Times a job is started before it is marked failed."
    )
    grading_timeout_seconds: float = Field(
        default=1800.0,
        gt=0,
        description="A grading still running after this long is stopped and marked failed.",
    )

    public_url: str | None = Field(
        default=None,
        description="The service's address as browsers and LMS platforms reach it (https://gymgrade.example.edu): "  # noqa: E501
        "the LTI login, launch and JWKS URLs are made from it; unset, from each request's own address.",
    )
    lti_key_grace_seconds: float = Field(
        default=2 * 24 * 3600.0,
        gt=0,
        description="A rotated LTI signing key stays published and accepted this long (platforms cache the JWKS; launches in flight).",  # noqa: E501
    )
    lti_session_seconds: float = Field(
        default=8 * 3600.0, gt=0, description="How long an LTI launch keeps its browser signed in."
    )
    lti_publish_seconds: float = Field(
        default=2.0, gt=0, description="How often the server publishes new scores to the LMS (LTI AGS)."
    )
    lti_publish_concurrency: int = Field(
        default=8,
        ge=1,
        le=32,
        description="The most scores the server sends to one LMS at once (each waits for the LMS's answer).",
    )
    lti_publish_attempts: int = Field(
        default=8,
        gt=0,
        description="Times a score is sent to an LMS that refuses it before it is shown as failed to the instructor.",  # noqa: E501
    )
    lti_retry_seconds: float = Field(
        default=2.0,
        gt=0,
        description="The first wait before sending a refused score again; each retry doubles it (at most 10 minutes).",  # noqa: E501
    )
    lti_allow_http: bool = Field(
        default=False,
        description="Let the tool talk to platforms over plain http and accept http endpoints in registrations: for tests on loopback only (LMSs need https).",  # noqa: E501
    )
    lti_allowed_networks: str = Field(
        default="",
        description="Comma-separated networks (CIDR, e.g. 10.20.0.0/16) the tool may reach for a platform although they are loopback, link-local or private (an LMS on the campus network); unset: public addresses only.",  # noqa: E501
    )
    lti_service_hosts: str = Field(
        default="",
        description="Comma-separated host names (or *.example.edu for subdomains) where a platform's endpoints and service URLs may be besides the platform's own hosts (Canvas cloud: sso.canvaslms.com,*.instructure.com).",  # noqa: E501
    )
    lti_max_response_bytes: int = Field(
        default=1_000_000,
        gt=0,
        description="The largest answer the tool reads from a platform (JWKS, configuration, token, roster page).",  # noqa: E501
    )
    lti_request_seconds: float = Field(
        default=15.0,
        gt=0,
        description="The longest a request to a platform may take in total (connection, sending, the whole answer).",  # noqa: E501
    )
    lti_registration_ticket_seconds: float = Field(
        default=1800.0,
        gt=0,
        le=7 * 24 * 3600.0,
        description="How long a dynamic registration URL stays usable (it is used once).",
    )
    key_encryption_key: SecretStr | None = Field(
        default=None,
        description="The key (Fernet: 32 random bytes, URL-safe base64) encrypting the LTI signing keys in the database; required to use LTI outside development. NEW,OLD: encrypt with NEW, read OLD too (keys are encrypted again with NEW at start-up).",  # noqa: E501
    )

    @field_validator("lti_allowed_networks")
    @classmethod
    def _networks(cls, value: str) -> str:
        for item in _listed(value):
            try:
                ipaddress.ip_network(item, strict=False)
            except ValueError:
                raise ValueError(
                    f"GYMGRADE_LTI_ALLOWED_NETWORKS holds {item!r}, which is not a network; "
                    "expected comma-separated CIDR networks such as 10.20.0.0/16,127.0.0.1/32"
                ) from None
        return value

    @field_validator("key_encryption_key")
    @classmethod
    def _fernet_key(cls, value: SecretStr | None) -> SecretStr | None:
        if value is None or not value.get_secret_value():
            return None
        from cryptography.fernet import Fernet

        try:
            for key in value.get_secret_value().split(","):
                Fernet(key.strip())
        except (ValueError, TypeError):
            raise ValueError(
                "GYMGRADE_KEY_ENCRYPTION_KEY is not a Fernet key; "
                "expected 32 random bytes in URL-safe base64 (`python -c 'from cryptography.fernet import Fernet; print(Fernet.generate_key().decode())'`)"  # noqa: E501
            ) from None
        return value

    @property
    def lti_networks(self) -> tuple[ipaddress.IPv4Network | ipaddress.IPv6Network, ...]:
        """GYMGRADE_LTI_ALLOWED_NETWORKS, parsed."""
        return tuple(ipaddress.ip_network(item, strict=False) for item in _listed(self.lti_allowed_networks))

    @property
    def lti_hosts(self) -> tuple[str, ...]:
        """GYMGRADE_LTI_SERVICE_HOSTS, parsed (lower case)."""
        return tuple(item.lower() for item in _listed(self.lti_service_hosts))

    @field_validator("edition")
    @classmethod
    def _known_edition(cls, edition: str | None) -> str | None:
        if edition is None:
            return None
        from grader.lab.editions import edition_of  # the packs import the checks: only when an edition is set
        from grader.lab.editions.errors import UnknownEdition

        try:
            edition_of(edition, where="GYMGRADE_EDITION")
        except UnknownEdition as error:
            raise ValueError(str(error)) from None
        return edition

    @field_validator("lab")
    @classmethod
    def _known_lab(cls, lab: str | None) -> str | None:
        if lab is None:
            return None
        from grader.lab.editions.errors import UnknownLab
        from grader.lab.labs import lab_of  # the packs import the checks: only when a lab is set

        try:
            lab_of(lab, where="GYMGRADE_LAB")
        except UnknownLab as error:
            raise ValueError(str(error)) from None
        return lab

    @model_validator(mode="after")
    def _edition_of_the_lab(self) -> Settings:
        if self.lab is None or self.edition is None:
            return self
        from grader.lab.editions.choice import service_edition
        from grader.lab.editions.errors import LabConflict

        try:
            service_edition(self.edition, self.lab)
        except LabConflict as error:
            raise ValueError(str(error)) from None
        return self

    @field_validator("late_policy")
    @classmethod
    def _readable_late_policy(cls, path: Path | None) -> Path | None:
        if path is None:
            return None
        from grader.classroom.late import read_late_policy
        from grader.errors import GraderError

        try:
            found = read_late_policy(path)
        except GraderError as error:
            raise ValueError(str(error)) from None
        if found is None:
            raise ValueError(
                f"GYMGRADE_LATE_POLICY={path} has no [late] table: add one (due, penalty_per_day, ...) or unset it"  # noqa: E501
            )
        return path

    @field_validator("due_date")
    @classmethod
    def _in_utc(cls, due_date: datetime | None) -> datetime | None:
        if due_date is None:
            return None
        return due_date.replace(tzinfo=UTC) if due_date.tzinfo is None else due_date.astimezone(UTC)

    @model_validator(mode="after")
    def _refuse_unsafe_values(self) -> Settings:
        if self.broker_url is not None and self.visibility_timeout_seconds <= self.grading_timeout_seconds:
            raise ValueError(
                f"GYMGRADE_VISIBILITY_TIMEOUT_SECONDS must exceed GYMGRADE_GRADING_TIMEOUT_SECONDS ({self.grading_timeout_seconds:g}), found {self.visibility_timeout_seconds:g}: "  # noqa: E501
                "a task would be delivered to a second worker while the first is still grading it"
            )
        if (
            self.operator_token is not None
            and self.instructor_token is not None
            and self.operator_token.get_secret_value() != self.instructor_token.get_secret_value()
        ):
            raise ValueError(
                "GYMGRADE_OPERATOR_TOKEN and GYMGRADE_INSTRUCTOR_TOKEN are both set, to different tokens: "
                "expected one operator token; unset GYMGRADE_INSTRUCTOR_TOKEN (its single-course name) or give both the same value"  # noqa: E501
            )
        if self.development:
            return self
        if self.seed_policy is SeedPolicy.FIXED and self.seed == PRACTICE_SEED:
            raise ValueError(
                f"GYMGRADE_SEED_POLICY=fixed with GYMGRADE_SEED={PRACTICE_SEED}: "
                "that is the public practice seed of `gymgrade check`, so a file could memorise every start; "
                "expected the random policy (the default) or a secret GYMGRADE_SEED (e.g. `python -c 'import secrets; print(secrets.randbelow(2**31))'`)"  # noqa: E501
            )
        operator = self.operator
        if operator is None:
            raise ValueError(
                "GYMGRADE_OPERATOR_TOKEN (or GYMGRADE_INSTRUCTOR_TOKEN) is not set; "
                "expected a long random token (e.g. `python -c 'import secrets; print(secrets.token_urlsafe(32))'`), or GYMGRADE_DEVELOPMENT=1 for local development"  # noqa: E501
            )
        problem = token_weakness(operator.get_secret_value())
        if problem is not None:
            name = (
                "GYMGRADE_OPERATOR_TOKEN" if self.operator_token is not None else "GYMGRADE_INSTRUCTOR_TOKEN"
            )
            raise ValueError(f"{name} is weak: {problem}")
        return self

    @property
    def operator(self) -> SecretStr | None:
        """The operator's token: OPERATOR_TOKEN, else INSTRUCTOR_TOKEN (its single-course name), else None."""
        return self.operator_token if self.operator_token is not None else self.instructor_token

    @property
    def sqlalchemy_url(self) -> str:
        """The database URL in force: DATABASE_URL, or the SQLite file in DATA_DIR."""
        if self.database_url:
            return self.database_url
        return f"sqlite:///{(self.data_dir / 'gymgrade.sqlite3').resolve()}"


def _listed(value: str) -> list[str]:
    return [item.strip() for item in value.split(",") if item.strip()]


def token_weakness(token: str) -> str | None:
    """Say why a token is too weak to guard the instructor's endpoints, or None when it is strong enough.

    Args:
        token: The candidate token.

    Returns:
        A sentence naming what was expected and what was found, or None.
    """
    if len(token) < MIN_TOKEN_LENGTH:
        return f"expected at least {MIN_TOKEN_LENGTH} characters, found {len(token)}; generate a random one"
    distinct = len(set(token))
    if distinct < MIN_TOKEN_DISTINCT_CHARACTERS:
        return (
            f"expected at least {MIN_TOKEN_DISTINCT_CHARACTERS} distinct characters, found {distinct}; "
            "generate a random one"
        )
    return None


def load_settings() -> Settings:
    """Read the settings from the environment (raises pydantic.ValidationError on unsafe values)."""
    return Settings()
