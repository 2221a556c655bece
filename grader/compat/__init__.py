"""The lab-compatibility layer: `gym` code of both lab versions (classic, gym 0.26) running on gymnasium 1.4.

Importing this package installs nothing: `import gym` works only in code run through the layer
(`activate()`, `run_script()`, `python -m grader.compat SCRIPT.py`, or a sandbox that puts
`shim_paths()` on `sys.path`). Self-contained: imports only the stdlib, numpy and gymnasium.
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
