"""The lab-compatibility layer: `gym` code of both lab versions (classic, gym 0.26) running on gymnasium 1.4.

Importing this package installs nothing: `import gym` works only in code run through the layer
(`activate()`, `run_script()`, `python -m grader.compat SCRIPT.py`, or a sandbox that puts
`shim_paths()` on `sys.path`). Self-contained: imports only the stdlib, numpy and gymnasium.

The layer's contract:

- `grader.compat.resolve_env_id(env_id: str) -> EnvTarget` (`EnvTarget(gymnasium_id: str, kwargs: dict)`),
  raises `grader.compat.errors.UnknownEnvironmentError` whose message names the lab's id (`Taxi-v2` -> use
  `Taxi-v3`). The parent's replay uses the same function, so ids resolve identically on both sides.
- `grader.compat.register_envs()` registers `NChain-v0` and `GuessingGame-v0` with gymnasium (idempotent).
- `grader.compat.shim_paths() -> ShimPaths(first: Path, fallback: Path)`: directories to put at the
  front (`gym`) and the back (`IPython` fallback providing `IPython.display.clear_output`) of `sys.path`.
  Only code run through the layer sees `gym`; importing `grader` or `reference` never installs it.
- The `gym` shim calls `gymnasium.make` looked up **at call time** (`gymnasium.make(...)`, never
  `from gymnasium import make`), so the sandbox's recorder, which wraps `gymnasium.make`, sees every env.
- `grader.compat.events.drain() -> list[CompatEvent]` (`CompatEvent(kind: str, env_id: str, detail: str)`,
  kinds: `step_before_reset`, `step_after_done`, `numpy_action`, `render_without_mode`, `legacy_seed_call`,
  `renamed_id`, `seed_replaced`, `api_detected`): what the layer had to tolerate. Repeats are counted, not
  stored: one event per (kind, env_id) per drain, its detail ending in "(N times)".
- `python -m grader.compat SCRIPT.py` runs a script with the layer active.
- **Both gym APIs**: `grader.compat.detection.detect_api(source) -> ApiDetection` (pure, `ast`)
  decides per function, then per module, whether code expects classic gym (`Api.CLASSIC`: `obs = reset()`,
  4-value `step`) or gym 0.26 (`Api.GYM026`: `obs, info = reset()`, 5-value `step`). Strong evidence is
  how `reset()`/`step()` results are unpacked (`reset(return_info=True)` unpacked into two is classic);
  hints (`render_mode=`, the names `terminated`/`truncated`, `env.seed()`, `obs = env.reset()`) decide only
  without it. `grader.compat.dialect.caller_api(env_id)` finds the calling code on the stack (first frame
  outside `grader/compat` and gymnasium), analyses its file once (`linecache`), and returns the API of the
  innermost function with evidence, else of the module; a function without evidence in a module that
  mixes both follows the nearest caller with evidence; code with no evidence (and no deciding caller) gets
  classic gym, and the event says so. A function (or module-level code) whose own lines expect both raises
  `grader.compat.errors.AmbiguousApiError` naming the lines.
  `ClassicEnv(env, requested_id, api=None)` asks at every `reset()`/`step()` (cached per call site).
  Event kind `api_detected` (env_id `"<id> in <function>()"`, one per scope and drain) says which API and
  the lines that decided; `events.generation()` counts drains.
- **`gym_toytext`** (shim package) registers `GuessingGame-v0`, `HotterColder-v0`, `KellyCoinflip-v0`,
  `KellyCoinflipGeneralized-v0`, `NChain-v0`, `Roulette-v0` (`grader.compat.envs.TOY_TEXT_IDS`, the
  registrations of gym_toytext 0.25) and exposes its class names; `gym.envs.toy_text` gives gymnasium's
  `BlackjackEnv`, `CliffWalkingEnv`, `FrozenLakeEnv`, `TaxiEnv` and their modules, and classic gym's
  `nchain`, `guessing_game`, `hotter_colder`, `roulette`, `kellycoinflip` modules.
- `EnvTarget.note` (why a lab id maps elsewhere; `""` if not) and
  `EnvTarget.merged_kwargs(student_kwargs)` (student wins); `grader.compat.activate()` (shim dirs on
  `sys.path`, `register_envs()`, headless SDL); `grader.compat.make(env_id, **kwargs) -> ClassicEnv`
  (what `gym.make` is). The recorder relies on `gymnasium.make` being called directly from
  `grader.compat.make.make`, whose local `env_id` is the requested id (pinned by a test).
- **gym.make's wrapper chain** (`grader.compat.chain`): what each gym's `gym.make` built (TimeLimit over the
  env in gym 0.10-0.21, OrderEnforcing below it from 0.22, PassiveEnvChecker below that from 0.24 and in
  gymnasium), and `SERVED_CHAIN`, the chain served to code of every edition: `gym.make(id).env`,
  `.env.env` and `.env.env.env` (the raw env, which has no `env`) are levels of one chain,
  each stepping the one env at its top (the sandbox's recorder), below the time limit without its
  truncation, forwarding public attribute reads (`env.P`, `env.nS`) as gym 0.12.1 to gymnasium 0.29 did.
  `ClassicEnv` serves it with the gym API; `served_levels(top, stepper)` serves gymnasium's own chain below
  `top` to `import gymnasium` code (the recorder's `RecordingEnv.env`); `time_limit_of(env)` finds the real
  `TimeLimit` through served levels.
- Beyond the lab's ids the table maps `FrozenLake-v0`/`FrozenLake8x8-v0` -> `-v1` (same transitions) and
  `Pendulum-v0` -> `Pendulum-v1`, which is **not** identical (v0 advanced the angle with the unclipped
  velocity); its `note`, and so its `renamed_id` event, says so.
"""

from . import events
from .activation import ShimPaths, activate, format_summary, run_script, shim_paths
from .adapter import ClassicEnv
from .detection import Api, ApiDetection, detect_api
from .envs import GuessingGameEnv, NChainEnv, register_envs
from .errors import (
    AmbiguousApiError,
    CompatError,
    InvalidActionError,
    RetiredEnvironmentError,
    UnknownEnvironmentError,
    UnsupportedRenderModeError,
)
from .events import CompatEvent
from .ids import EnvTarget, lab_ids, resolve_env_id
from .make import make

__all__ = [
    "AmbiguousApiError",
    "Api",
    "ApiDetection",
    "ClassicEnv",
    "CompatError",
    "CompatEvent",
    "EnvTarget",
    "GuessingGameEnv",
    "InvalidActionError",
    "NChainEnv",
    "RetiredEnvironmentError",
    "ShimPaths",
    "UnknownEnvironmentError",
    "UnsupportedRenderModeError",
    "activate",
    "detect_api",
    "events",
    "format_summary",
    "lab_ids",
    "make",
    "register_envs",
    "resolve_env_id",
    "run_script",
    "shim_paths",
]
