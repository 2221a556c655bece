"""Which edition a command grades: `--edition NAME`, else the configuration's `edition`, else detection.

The choice ends in an assignment configuration path: the edition travels inside it (its `edition` key picks
the pack's registry wherever the configuration is loaded: the plan, every xdist worker, a batch), so nothing
downstream of the command line needs another argument.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from grader.lab.assignment import read_config_file
from grader.lab.editions import DEFAULT_EDITION, EDITIONS, edition_of
from grader.lab.editions.detection import detect_edition
from grader.lab.editions.errors import EditionConflict
from grader.lab.editions.pack import BUNDLED_CONFIG, Edition
from grader.lab.editions.rl1 import RL1


@dataclass(frozen=True)
class EditionChoice:
    """The edition graded, the configuration that grades it (None: the bundled one) and why it was chosen."""

    edition: Edition
    config: Path | None
    reason: str

    @property
    def line(self) -> str:
        """What the command line prints."""
        return f"Edition: {self.edition.name} ({self.edition.title}): {self.reason}."


def configured_edition(config: Path) -> str:
    """The edition a configuration file names (`edition = "..."`), the first edition when it names none.

    Raises:
        ConfigError: The file cannot be read as TOML (the loader says the same when grading).
    """
    name = read_config_file(config).get("edition", DEFAULT_EDITION)
    edition_of(name, where=f"{config}: edition")
    return str(name)


def choose_edition(flag: str | None, config: Path | None, submission: Path | None) -> EditionChoice:
    """The edition to grade and the configuration to grade it with.

    Args:
        flag: `--edition NAME`, or None.
        config: `--config PATH`, or None.
        submission: The one file graded (`check`), read statically for detection; None for a batch.

    Raises:
        UnknownEdition: The flag or the configuration names no edition.
        EditionConflict: The flag's edition grades other problems than the configuration given with it.
        ConfigError: The configuration cannot be read.
    """
    if flag is not None:
        chosen = edition_of(flag, where="--edition")
        if config is None:
            return EditionChoice(chosen, default_config(chosen), "chosen with --edition")
        named = edition_of(configured_edition(config))
        if named.registry is not chosen.registry:
            graded, configured = ", ".join(chosen.registry.ids), ", ".join(named.registry.ids)
            raise EditionConflict(
                f"--edition {chosen.name} grades {graded}, but {config} configures edition {named.name} ({configured}): "  # noqa: E501
                f'write edition = "{chosen.name}" and its tables in {config} (start from {chosen.default_config}), or drop --edition'  # noqa: E501
            )
        return EditionChoice(chosen, config, f"chosen with --edition, configured by {config}")
    if config is not None:
        name = configured_edition(config)
        return EditionChoice(EDITIONS[name], config, f"named by {config}")
    if submission is None:
        first = EDITIONS[DEFAULT_EDITION]
        reason = f"no --edition and no configuration: the first edition (--edition {RL1.name} grades today's)"
        return EditionChoice(first, None, reason)
    detected = detect_edition(submission)
    return EditionChoice(
        detected.edition,
        default_config(detected.edition),
        f"detected from {submission.name}: {detected.reason}",
    )


def service_edition(name: str | None) -> EditionChoice:
    """The edition every upload to the service is graded as: `GYMGRADE_EDITION`, else the first edition
    (as every configuration naming none). Never detected from an upload: a student does not choose what
    they are graded on.

    Raises:
        UnknownEdition: The setting names no edition.
    """
    if name is None:
        first = EDITIONS[DEFAULT_EDITION]
        reason = f"GYMGRADE_EDITION is unset: the first edition (GYMGRADE_EDITION={RL1.name} grades today's)"
        return EditionChoice(first, default_config(first), reason)
    chosen = edition_of(name, where="GYMGRADE_EDITION")
    return EditionChoice(chosen, default_config(chosen), f"GYMGRADE_EDITION={chosen.name}")


def default_config(edition: Edition) -> Path | None:
    """The configuration an edition is graded with when none is given (None: the bundled one)."""
    return None if edition.default_config == BUNDLED_CONFIG else edition.default_config


def edition_config(name: str) -> Path | None:
    """The default configuration of the edition a report names (None: the bundled one), to draw its
    figures with; a name no pack has (a report from a newer gymgrade) gets the first edition's."""
    found = EDITIONS.get(name)
    return None if found is None else default_config(found)
