"""What names a problem: the lowest layer of the problem stack, standard library only.

Everything about problems imports its id type from here (the checks, the settings models, the games, the
registry, the edition packs), so no module below the registry needs the registry itself.
"""

from typing import TypeAlias

ProblemId: TypeAlias = str
"""A registered problem's id: a Python identifier that names the student's function, the `[problems.<id>]`
table and the acceptance module `grader/grading/cases/test_<id>.py`. Checked where it enters
(`Registry.problem`, `Registry.select`, the configuration loader)."""


def acceptance_module_name(problem_id: ProblemId) -> str:
    """The name of a problem's acceptance module in `grader/grading/cases/` (one test per submission)."""
    return f"test_{problem_id}"
