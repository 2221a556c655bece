"""Which edition of the second lab (Policy Function Iteration / Reinforcement Learning 2) a file's marks show.

A file shows the lab when it defines one of the lab's functions (`FUNCTIONS`: the problem ids of every
edition, names no other lab uses) or carries one of its file names (`policy_iteration.py`, the 2026 template's
`policy_function_iteration.py`) and defines no other lab's function. Its edition, first rule that applies,
each with the reason printed:

1. `model_comparison`, or `import model_free_RL` (the 2024 template's helper import): `v2024`;
2. `frozenlake` (2018's name; later editions write `frozen_lake`): `v2018`;
3. `run_simulation` with a `render` parameter (2019-2022): `v2019`;
4. `policy_improvement` / `iter_policy_eval` (the 2024 names) without the above, or the file name
   `policy_function_iteration.py`: `v2026`;
5. `extract_policy` / `compute_policy_v` (the 2018-2023 names) with `import gymnasium`: `v2023`; with
   `import gym`: `v2019`;
6. otherwise the lab but no edition (`shown` False): taken as the lab's current edition, counted by no class.

Editions are looked up by name in `grader.lab.editions.EDITIONS` when a rule applies.
"""

from __future__ import annotations

from grader.lab.editions import EDITIONS
from grader.lab.editions.marks import Detection, Marks

LAB = "rl2"
FUNCTIONS = (
    "value_iteration",
    "extract_policy",
    "compute_policy_v",
    "policy_improvement",
    "iter_policy_eval",
    "policy_iteration",
    "frozenlake",
    "frozen_lake",
    "run_simulation",
    "model_comparison",
)
"""Every function some edition of the lab asks for (tests check it against the packs)."""
FILE_NAMES = ("policy_iteration", "policy_function_iteration")
"""The lab's file names (without suffix): every edition's text, and the 2026 template's."""
CURRENT = "v2026"
"""The lab's current edition (the 2026 template)."""


def rl2_edition(marks: Marks) -> Detection | None:
    """The second lab's edition the marks show, or None when they show nothing of the second lab."""
    defined = [marks.functions[name] for name in FUNCTIONS if name in marks.functions]
    stem = marks.name.rsplit(".", 1)[0]
    if not defined and (stem not in FILE_NAMES or _another_labs(marks)):
        return None  # a name is weaker than what the file defines: another lab's functions decide
    functions = marks.functions
    shows = (
        f"it defines {', '.join(function.name for function in defined)}"
        if defined
        else f"it is named {marks.name}"
    )
    if "model_comparison" in functions:
        return _edition(
            "v2024", f"it defines {functions['model_comparison'].text}, which only the 2024 edition asks for"
        )
    if "model_free_RL" in marks.imports:
        return _edition("v2024", "it imports model_free_RL, the helper only the 2024 template imports")
    if "frozenlake" in functions:
        return _edition(
            "v2018", f"it defines {functions['frozenlake'].text}, the 2018 name (later: frozen_lake)"
        )
    simulation = functions.get("run_simulation")
    if simulation is not None and "render" in simulation.parameters:
        return _edition(
            "v2019", f"its {simulation.text} takes a render flag, as the 2019-2022 editions write it"
        )
    renamed = [name for name in ("policy_improvement", "iter_policy_eval") if name in functions]
    if renamed:
        return _edition(
            "v2026",
            f"it defines {' and '.join(renamed)} (the names since 2024) and no model_comparison, as the 2026 template",  # noqa: E501
        )
    if stem == "policy_function_iteration":
        return _edition("v2026", f"it is named {marks.name}, as the 2026 template names the file")
    old = [name for name in ("extract_policy", "compute_policy_v") if name in functions]
    if old and "gymnasium" in marks.imports:
        return _edition(
            "v2023", f"it defines {' and '.join(old)} (the 2018-2023 names) and imports gymnasium"
        )
    if old and "gym" in marks.imports:
        return _edition("v2019", f"it defines {' and '.join(old)} (the 2018-2023 names) and imports gym")
    current = EDITIONS[CURRENT]
    return Detection(
        current,
        f"{shows}, so it was written for the Policy Function Iteration lab, but it shows none of an edition's marks",  # noqa: E501
        shown=False,
    )


def _another_labs(marks: Marks) -> bool:
    """Whether the file defines a function some other lab's edition asks for."""
    return any(
        edition.function(name)
        for edition in EDITIONS.values()
        if edition.lab != LAB
        for name in marks.functions
    )


def _edition(name: str, reason: str) -> Detection:
    return Detection(EDITIONS[name], reason)
