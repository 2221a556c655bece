"""The editions of the lab as assignment packs: one module per edition, `EDITIONS` lists them.

The contract is `grader.lab.editions.pack.Edition`; `edition_of(name)` finds a pack, `DEFAULT_EDITION` is the
one every configuration that names none grades (the first, so existing configurations and reports keep their
meaning). Detection from a submission is `grader.lab.editions.detection`; the command line's choice between
`--edition`, a configuration's `edition = "..."` and detection is `grader.lab.editions.choice`.

How an edition is carried, chosen and shown:

- **The edition travels inside the configuration.** A TOML's top-level `edition = "NAME"` (default
  `classic`) picks the registry `load_config` validates its tables with (`AssignmentConfig.edition`,
  `.registry`); `GradingPlan.load` loads it once and the plan carries it to every xdist worker
  (`plugin.GradingSession`); a batch, Gradescope and the service load the same file, so nothing else
  carries an edition. Problem ids are unique within an edition;
  an acceptance module `test_<id>.py` looks its problem up in its edition's registry
  (`RL1.registry.acceptance_problem(__name__)`), and `--only` accepts every edition's ids
  (`grader.lab.editions.all_problem_ids()`), the plan refusing those its edition does not grade.
- **Choosing** (`grader/lab/editions/choice.py`, called once by `gymgrade check`/`grade`/`gradescope-bundle`
  before their handlers): `--lab NAME` chooses the lab (`grader.lab.labs`; an edition named with it must be
  one of its editions, else `LabConflict` names both), `--edition NAME` the edition (with no `--config`: the
  pack's default configuration; with one: it must grade the same problems, else `EditionConflict` says what
  to write), else the configuration's `edition` (or its `lab`'s current edition), else `--lab`'s edition the
  file shows (`check`) or its current edition, else detection (`check`: the file; `grade`: each file, below),
  else `classic`. The command prints `Lab: NAME (...)` and `Edition: NAME (title): why` on stderr. What a
  student is graded on is the instructor's choice: detection alone chooses only for a student's own
  `check`; `service_edition(GYMGRADE_EDITION, GYMGRADE_LAB)` for the service (both unset: `classic`, never
  the upload's).
- **Detection** (`grader/lab/editions/detection.py`) reads the submission's marks (`marks.py`) in the
  parent (without following links) with `ast` only, within bounds (1 MB of source; a notebook's code cells
  come from the bounded reader, `grader.submission.notebook.read_notebook`, so its JSON is never parsed in
  the parent; a file that cannot be read or parsed shows no mark), and asks each lab's rules, the second
  lab's first (`rl2_marks.py`: its functions or file names, then its edition). The first lab's
  (`opengym_marks.py`): a function only `rl1` asks for (`epsilon_decay`, `qlearn`, `sarsa0`,
  `compare`) or a two-table `taxi` -> `rl1`; a `render` flag on `cartpole`/`car` or `import gymnasium` ->
  `volume2`; `gym_toytext` or gym 0.26's five-value `step` / two-value `reset` -> `gym026`; `import gym` ->
  `classic`; else the file shows no edition (`Detection.shown` False: taken as `classic`, counted by no
  class). Each reason names what it saw. `detect_source(bytes, name)` reads source already read;
  `edition_note(graded, detection)` is what a report says (`Report.edition_note`) to a file written for
  another lab or other problems than the edition graded: `grader.grading.grade` computes it for every graded
  file (a notebook from the module built of its cells), so `check --edition`, `grade`, Gradescope and the
  service all tell it.

- **The edition is in the report** (`Report.edition`; a report without it, written before editions, reads
  as `classic`, `grader.report.FIRST_EDITION`), and so is its lab (`Report.lab`, absent: `opengym`). The
  text summary, the HTML report, the Gradescope output and the service's page show both
  (`grader.render.text.edition_name`: `rl1 (Reinforcement Learning 1: Gymnasium)`; `lab_name`);
  figures are drawn with the report's edition's configuration (`grader.lab.editions.choice.edition_config`).
- **A class without `--lab`, `--edition` or a configuration** (`gymgrade grade`,
  `grader/lab/editions/per_submission.py`): every graded file is detected; files showing different labs stop
  the class (exit 2, naming each lab and whose files are behind it); files showing no edition are left
  out; when the others all ask the same problems the class is graded as their edition (of several names, the
  most common, a tie to the newer; none: `classic`), so its gradebook has one set of columns; `Edition: ...`
  then one line per submission (`identity: edition: reason`). When they ask different problems,
  `ClassEditions.disagreement` names each edition and whose files are behind it and `grade` stops before
  grading (exit 2): a majority never decides. When the class's edition asks other functions than the first
  edition's, the graded files are chosen again by its functions from the download already read
  (`submissions_of_all`, nothing extracted again).
- **The service** grades each upload as `GYMGRADE_EDITION` (validated when the settings load; unset: the
  first edition), chosen in the grading child `api/jobs/child.py` (`service_edition`, which logs the
  `Edition:` line); an upload's own edition is never used, its report's `edition_note` tells it. A batch
  job carries its configuration as before.

The four editions of this lab: `classic` (1, the lab text; its registry is `grader.lab.problems.PROBLEMS`, so
every configuration and report that names no edition keeps its meaning), `gym026` (2) and `volume2` (3) (the
same problems: the compatibility layer runs their APIs; `cartpole()`/`car()` are called without arguments, so
`render=False` keeps its default), and `rl1` (4, the current one: problems 1-4 are `PROBLEMS`' own
declarations, reused, plus `epsilon_decay` and the two-table `taxi` (the same id as edition 1's `taxi`,
another `Problem`: ids are unique within an edition), `sarsa0` and `compare()` (the grader's tables bound
to the globals it reads, by default); `qlearn` is a provided function, listed in `not_graded`). Templates are
`submissions/template.py` (classic) and `submissions/templates/<edition>.py`; references are
`submissions/*_complete.py` and `submissions/editions/rl1_complete.py`; `rl1`'s default configuration is
`grader/lab/editions/rl1.toml` (the others use the bundled `grader/lab/assignment.toml`).

The second lab's five editions (`v2018`, `v2019`, `v2023`, `v2024`, `v2026`; `Edition.lab` "rl2") are declared
in `grader/lab/rl2/editions.py` and listed here after the first lab's; their configurations are
`grader/lab/rl2/<edition>.toml`.
"""

from grader.lab.editions.classic import CLASSIC
from grader.lab.editions.errors import UnknownEdition
from grader.lab.editions.gym026 import GYM026
from grader.lab.editions.pack import Edition, ExpectedFunction
from grader.lab.editions.rl1 import RL1
from grader.lab.editions.volume2 import VOLUME2
from grader.lab.ids import ProblemId
from grader.lab.rl2.editions import EDITIONS as RL2_EDITIONS

__all__ = [
    "DEFAULT_EDITION",
    "EDITIONS",
    "Edition",
    "ExpectedFunction",
    "all_problem_ids",
    "edition_label",
    "edition_of",
]

EDITIONS: dict[str, Edition] = {
    edition.name: edition for edition in (CLASSIC, GYM026, VOLUME2, RL1, *RL2_EDITIONS)
}
"""Every edition pack: the OpenGym lab's, oldest first, then the second lab's (`grader.lab.rl2`), oldest
first. Names are unique across labs (`Edition.lab` says whose)."""
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
