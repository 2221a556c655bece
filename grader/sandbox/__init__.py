"""Untrusted execution of student code: isolated children, plain-data results, trusted replay.

The public names load their module on first use (PEP 562 `__getattr__`): every sandbox child imports this
package on its way to `grader.sandbox.child` and needs none of them (pydantic, the runner, the replay, the
isolation layers: about 0.3 s of each child's start, one child per problem). `_HOMES` says where each
name lives; the imports under `TYPE_CHECKING` are the same names for type checkers.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from grader.sandbox.episode_log import EpisodeLog
    from grader.sandbox.errors import IsolationUnavailable, SandboxClosedError, SandboxError
    from grader.sandbox.isolation import probe_isolation
    from grader.sandbox.isolation.layer import IsolationReport, LayerReport
    from grader.sandbox.limits import CallBudget, IsolationPolicy, Limits
    from grader.sandbox.outcome import (
        Call,
        CallOutcome,
        CompatEventRecord,
        FunctionInfo,
        OutcomeStatus,
        ParameterInfo,
        PlainValue,
    )
    from grader.sandbox.replay import Replay, replay_episode
    from grader.sandbox.runner import Sandbox, run_calls

_HOMES = {
    "grader.sandbox.episode_log": ("EpisodeLog",),
    "grader.sandbox.errors": ("IsolationUnavailable", "SandboxClosedError", "SandboxError"),
    "grader.sandbox.isolation": ("probe_isolation",),
    "grader.sandbox.isolation.layer": ("IsolationReport", "LayerReport"),
    "grader.sandbox.limits": ("CallBudget", "IsolationPolicy", "Limits"),
    "grader.sandbox.outcome": (
        "Call",
        "CallOutcome",
        "CompatEventRecord",
        "FunctionInfo",
        "OutcomeStatus",
        "ParameterInfo",
        "PlainValue",
    ),
    "grader.sandbox.replay": ("Replay", "replay_episode"),
    "grader.sandbox.runner": ("Sandbox", "run_calls"),
}
_MODULE_OF = {name: module for module, names in _HOMES.items() for name in names}

__all__ = [
    "Call",
    "CallBudget",
    "CallOutcome",
    "CompatEventRecord",
    "EpisodeLog",
    "FunctionInfo",
    "IsolationPolicy",
    "IsolationReport",
    "IsolationUnavailable",
    "LayerReport",
    "Limits",
    "OutcomeStatus",
    "ParameterInfo",
    "PlainValue",
    "Replay",
    "Sandbox",
    "SandboxClosedError",
    "SandboxError",
    "probe_isolation",
    "replay_episode",
    "run_calls",
]

if set(__all__) != set(_MODULE_OF):
    raise ImportError(
        f"grader.sandbox: __all__ and _HOMES disagree on {sorted(set(__all__) ^ set(_MODULE_OF))}"
    )


def __getattr__(name: str) -> Any:
    """A public name, imported from its module on first use (then kept in this module's namespace)."""
    module = _MODULE_OF.get(name)
    if module is None:
        raise AttributeError(f"module 'grader.sandbox' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted([*globals(), *__all__])
