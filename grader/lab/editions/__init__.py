"""The editions of the lab as assignment packs: one module per edition, `EDITIONS` lists them.

The contract is `grader.lab.editions.pack.Edition`; `edition_of(name)` finds a pack, `DEFAULT_EDITION` is the
one every configuration that names none grades (the first, so existing configurations and reports keep their
meaning). Detection from a submission is `grader.lab.editions.detection`; the command line's choice between
`--edition`, a configuration's `edition = "..."` and detection is `grader.lab.editions.choice`.
"""

from grader.lab.editions.classic import CLASSIC
from grader.lab.editions.errors import UnknownEdition
from grader.lab.editions.gym026 import GYM026
from grader.lab.editions.pack import Edition, ExpectedFunction
from grader.lab.editions.rl1 import RL1
from grader.lab.editions.volume2 import VOLUME2
from grader.lab.ids import ProblemId

__all__ = [
    "DEFAULT_EDITION",
    "EDITIONS",
    "Edition",
    "ExpectedFunction",
    "all_problem_ids",
    "edition_label",
    "edition_of",
]

EDITIONS: dict[str, Edition] = {edition.name: edition for edition in (CLASSIC, GYM026, VOLUME2, RL1)}
"""Every edition pack, oldest first."""
DEFAULT_EDITION = CLASSIC.name


def edition_of(name: object, *, where: str = "edition") -> Edition:
    """The pack of an edition name.

    Raises:
        UnknownEdition: No pack has this name (the message lists them; `where` says who named it).
    """
    found = EDITIONS.get(name) if isinstance(name, str) else None
    if found is None:
        raise UnknownEdition(
            f"{where}: unknown edition {name!r}; expected one of {', '.join(EDITIONS)} (grader/lab/editions/)"
        )
    return found


def all_problem_ids() -> tuple[ProblemId, ...]:
    """Every problem id some edition grades, each once, oldest edition's first (what `--only` accepts)."""
    ids = (problem for edition in EDITIONS.values() for problem in edition.registry.ids)
    return tuple(dict.fromkeys(ids))


def edition_label(name: str) -> str:
    """How a report names its edition to a person: `rl1 (Reinforcement Learning 1: Gymnasium)`.

    A name no pack has (a report from a newer gymgrade) is shown as it is.
    """
    found = EDITIONS.get(name)
    return name if found is None else f"{found.name} ({found.title})"
