"""The second lab, "Policy Function Iteration" ("Reinforcement Learning 2: Markov Decision Process" since
2024), graded as packs beside the OpenGym lab's: nothing in the grader's core is specific to it.

How its parts fit:

- `grader/lab/rl2/editions.py` declares every fact about its editions once: the shared problem declarations
  (`Problem`s whose ids are the lab's function names), the five `Edition`s (`v2018`, `v2019`, `v2023`,
  `v2024`, `v2026`, `lab="rl2"`) with their registries, template functions, templates and references
  (`submissions/rl2/`), default configurations (`grader/lab/rl2/<edition>.toml`) and what is not graded yet.
  `grader.lab.editions.EDITIONS` lists them after the OpenGym lab's, so `--edition v2024` and
  `edition = "v2024"` work through the same machinery; the acceptance modules
  `grader/grading/cases/test_<id>.py` look their problem up in a registry that has it.
- `grader/lab/rl2/checks/`: one module per pure problem (`value_iteration`, `improvement`, `evaluation`,
  `policy_iteration`: settings model + check), sharing `mdp_calls` (the grader's MDPs from
  `reference.oracles.mdps.grading_cases()`, the call of one function on one MDP, how returned values are read,
  the tolerance `tol` earns). Exact oracles: `reference.oracles.mdp`. And one module per played problem
  (`run_simulation`, `frozen_lake`, `model_comparison`), whose episodes are replayed in the grader's envs
  (`grader.lab.games`: the FrozenLake games) as the first lab's are.
- The MDP reaches the student's function as `grader.sandbox.outcome.MdpArgument` (declared by the child in
  `grader/sandbox/child/frames.py`): plain lists on the wire, a fresh `{s: {a: [(p, s', r, done), ...]}}` at
  every call. `policy_iteration` and `frozen_lake` are judged with the student's own functions first and,
  only when that does not pass, again with the grader's own steps bound in their place
  (`grader/sandbox/child/provided.py`; `grader.lab.checks.base.SecondReading`), the better verdict kept.
- What each check calls and how it judges: `grader/lab/rl2/ASSIGNMENT.md`.
"""
