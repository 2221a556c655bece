"""Which edition of the first lab (OpenGym AI / Reinforcement Learning 1) a file's marks show.

The rules, newest edition first, each with the reason the command line prints:

1. a function only the current edition asks for (`epsilon_decay`, `qlearn`, `sarsa0`, `compare`), or a
   `taxi` with two required parameters: `rl1`;
2. `cartpole`/`car` with a `render` parameter, or `import gymnasium`: `volume2`;
3. `import gym_toytext`, or gym 0.26's five-value `step` / two-value `reset` unpacking: `gym026`;
4. `import gym` with none of the above: `classic`;
5. a function of the lab's (`blackjack`, ...) with none of the above: the lab, but no edition (`shown` False:
   taken as `classic`, counted by no class);
6. nothing of the lab: None (the file shows no lab).

Editions 1-3 grade the same problems (the compatibility layer runs every gym API), so telling them apart only
names the edition; rule 1 changes what is graded.
"""

from __future__ import annotations

from grader.lab.editions.classic import CLASSIC
from grader.lab.editions.gym026 import GYM026
from grader.lab.editions.marks import Detection, Marks
from grader.lab.editions.rl1 import RL1
from grader.lab.editions.volume2 import VOLUME2

_EDITIONS = (CLASSIC, GYM026, VOLUME2, RL1)


def opengym_edition(marks: Marks) -> Detection | None:
    """The first lab's edition the marks show, or None when they show nothing of the first lab."""
    functions = marks.functions
    other_names = {function.name for edition in (CLASSIC, GYM026, VOLUME2) for function in edition.functions}
    only_rl1 = [
        function for name, function in functions.items() if name not in other_names and RL1.function(name)
    ]
    if only_rl1:
        names = ", ".join(function.text for function in only_rl1)
        return Detection(RL1, f"it defines {names}, which only edition {RL1.number} ({RL1.title}) asks for")
    taxi = functions.get("taxi")
    if taxi is not None and taxi.required >= 2:
        return Detection(
            RL1, f"its taxi({', '.join(taxi.parameters)}) takes two tables, as only edition {RL1.number} asks"
        )
    rendered = [
        name for name in ("cartpole", "car") if name in functions and "render" in functions[name].parameters
    ]
    if rendered:
        return Detection(
            VOLUME2,
            f"its {' and '.join(f'{name}(render=...)' for name in rendered)} take a render flag, as editions "
            f"{VOLUME2.number} and {RL1.number} write them, and it defines none of edition {RL1.number}'s new functions",  # noqa: E501
        )
    imports = marks.imports
    if "gymnasium" in imports:
        return Detection(VOLUME2, "it imports gymnasium and defines none of edition 4's new functions")
    if "gym_toytext" in imports:
        return Detection(GYM026, "it imports gym_toytext, as the gym 0.26 notebook does")
    if "gym" in imports and marks.new_gym_api:
        return Detection(
            GYM026, "it imports gym and unpacks the five values of gym 0.26's step (or reset's two)"
        )
    if "gym" in imports:
        return Detection(
            CLASSIC,
            "it imports gym and shows no mark of a later edition (their functions, render flags or APIs)",
        )
    if any(edition.function(name) for edition in _EDITIONS for name in functions):
        return Detection(
            CLASSIC,
            "it shows no edition: it imports no gym and defines none of a later edition's functions or render flags",  # noqa: E501
            shown=False,
        )
    return None
