"""Which lab and edition a command grades: `--lab`/`--edition`, else the configuration's `lab`/`edition`, else
detection.

The choice ends in an assignment configuration path: the edition (and through it the lab) travels inside it
(its `edition` key picks the pack's registry wherever the configuration is loaded: the plan, every xdist
worker, a batch), so nothing downstream of the command line needs another argument.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from grader.lab.assignment import configured_edition as edition_of_data
from grader.lab.assignment import read_config_file
from grader.lab.editions import DEFAULT_EDITION, EDITIONS, edition_of
from grader.lab.editions.detection import detect_edition
from grader.lab.editions.errors import EditionConflict
from grader.lab.editions.pack import BUNDLED_CONFIG, Edition
from grader.lab.editions.rl1 import RL1
from grader.lab.labs import Lab, edition_in_lab, lab_of, lab_of_edition


@dataclass(frozen=True)
class EditionChoice:
    """The edition graded, the configuration that grades it (None: the bundled one) and why it was chosen."""

    edition: Edition
    config: Path | None
    reason: str

    @property
    def lab(self) -> Lab:
        """The lab of the edition."""
        return lab_of_edition(self.edition)

    @property
    def line(self) -> str:
        """What the command line prints: the edition and why (after `lab_line`)."""
        return f"Edition: {self.edition.name} ({self.edition.title}): {self.reason}."

    @property
    def lab_line(self) -> str:
        """What the command line prints first: the lab."""
        return f"Lab: {self.lab.label}."


def configured_edition(config: Path) -> str:
    """The edition a configuration file grades (`edition = "..."`, else its `lab = "..."`'s current edition,
    else the first edition).

    Raises:
        ConfigError: The file cannot be read as TOML (the loader says the same when grading), or names an
            unknown lab or edition, or an edition of another lab than its `lab`.
    """
    return edition_of_data(read_config_file(config), where=str(config)).name


def choose_edition(
    flag: str | None, config: Path | None, submission: Path | None, lab: str | None = None
) -> EditionChoice:
    """The edition to grade and the configuration to grade it with.

    Args:
        flag: `--edition NAME`, or None.
        config: `--config PATH`, or None.
        submission: The one file graded (`check`), read statically for detection; None for a batch.
        lab: `--lab NAME`, or None: an edition named must be one of its editions; named alone, its current
            edition is graded (for `check`, the edition of the lab the file shows, if it shows one).

    Raises:
        UnknownLab, UnknownEdition: The flag or the configuration names no lab or edition.
        LabConflict: The edition named (flag or configuration) is not an edition of `--lab`.
        EditionConflict: The flag's edition grades other problems than the configuration given with it.
        ConfigError: The configuration cannot be read.
    """
    named_lab = None if lab is None else lab_of(lab, where="--lab")
    within = "" if named_lab is None else f" within --lab {named_lab.name}"
    if flag is not None:
        chosen = edition_of(flag, where="--edition")
        if named_lab is not None:
            edition_in_lab(
                named_lab,
                chosen,
                lab_named=f"--lab {lab}",
                edition_named=f"--edition {flag}",
                remedy="or drop --lab",
            )
        if config is None:
            return EditionChoice(chosen, default_config(chosen), f"chosen with --edition{within}")
        named = edition_of(configured_edition(config))
        if named.registry is not chosen.registry:
            graded, configured = ", ".join(chosen.registry.ids), ", ".join(named.registry.ids)
            raise EditionConflict(
                f"--edition {chosen.name} grades {graded}, but {config} configures edition {named.name} ({configured}): "  # noqa: E501
                f'write edition = "{chosen.name}" and its tables in {config} (start from {chosen.default_config}), or drop --edition'  # noqa: E501
            )
        return EditionChoice(chosen, config, f"chosen with --edition{within}, configured by {config}")
    if config is not None:
        edition = EDITIONS[configured_edition(config)]
        if named_lab is not None:
            edition_in_lab(
                named_lab,
                edition,
                lab_named=f"--lab {lab}",
                edition_named=f"{config} (edition {edition.name})",
                remedy=f"pass a configuration of lab {named_lab.name} (start from {named_lab.current_edition.default_config}), or drop --lab",  # noqa: E501
            )
        return EditionChoice(edition, config, f"named by {config}")
    if named_lab is not None:
        return _lab_alone(named_lab, submission)
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


def _lab_alone(lab: Lab, submission: Path | None) -> EditionChoice:
    """`--lab NAME` without an edition: the edition of that lab the file shows (`check`), else the lab's
    current edition."""
    current = lab.current_edition
    if submission is None:
        return EditionChoice(current, default_config(current), f"--lab {lab.name}: its current edition")
    detected = detect_edition(submission)
    if detected.shown and detected.edition.lab == lab.name:
        reason = f"--lab {lab.name}, detected from {submission.name}: {detected.reason}"
        return EditionChoice(detected.edition, default_config(detected.edition), reason)
    return EditionChoice(
        current,
        default_config(current),
        f"--lab {lab.name}: its current edition ({submission.name} shows none of its editions' marks)",
    )


def service_edition(name: str | None, lab: str | None = None) -> EditionChoice:
    """The edition every upload to the service is graded as: `GYMGRADE_EDITION` (an edition of
    `GYMGRADE_LAB` when both are set), else `GYMGRADE_LAB`'s current edition, else the first edition (as every
    configuration naming none). Never detected from an upload: a student does not choose what they are
    graded on.

    Raises:
        UnknownEdition, UnknownLab: A setting names no edition or lab.
        LabConflict: `GYMGRADE_EDITION` is not an edition of `GYMGRADE_LAB`.
    """
    named_lab = None if lab is None else lab_of(lab, where="GYMGRADE_LAB")
    if name is None and named_lab is None:
        first = EDITIONS[DEFAULT_EDITION]
        reason = f"GYMGRADE_LAB and GYMGRADE_EDITION are unset: the first edition (GYMGRADE_EDITION={RL1.name} grades today's)"  # noqa: E501
        return EditionChoice(first, default_config(first), reason)
    if name is None and named_lab is not None:
        current = named_lab.current_edition
        return EditionChoice(
            current, default_config(current), f"GYMGRADE_LAB={named_lab.name}: its current edition"
        )
    chosen = edition_of(name, where="GYMGRADE_EDITION")
    if named_lab is None:
        return EditionChoice(chosen, default_config(chosen), f"GYMGRADE_EDITION={chosen.name}")
    edition_in_lab(
        named_lab,
        chosen,
        lab_named=f"GYMGRADE_LAB={named_lab.name}",
        edition_named=f"GYMGRADE_EDITION={chosen.name}",
        remedy="or unset GYMGRADE_LAB",
    )
    return EditionChoice(
        chosen, default_config(chosen), f"GYMGRADE_LAB={named_lab.name}, GYMGRADE_EDITION={chosen.name}"
    )


def default_config(edition: Edition) -> Path | None:
    """The configuration an edition is graded with when none is given (None: the bundled one)."""
    return None if edition.default_config == BUNDLED_CONFIG else edition.default_config


def edition_config(name: str) -> Path | None:
    """The default configuration of the edition a report names (None: the bundled one), to draw its
    figures with; a name no pack has (a report from a newer gymgrade) gets the first edition's."""
    found = EDITIONS.get(name)
    return None if found is None else default_config(found)
