"""Untrusted execution of student code: isolated children, plain-data results, trusted replay."""

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
