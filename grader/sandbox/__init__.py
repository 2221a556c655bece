"""Untrusted execution of student code: isolated children, plain-data results, trusted replay.

The public names load their module on first use (PEP 562 `__getattr__`): every sandbox child imports this
package on its way to `grader.sandbox.child` and needs none of them (pydantic, the runner, the replay, the
isolation layers: about 0.3 s of each child's start, one child per problem). `_HOMES` says where each
name lives; the imports under `TYPE_CHECKING` are the same names for type checkers.

The sandbox's contract, beyond the types the code declares:

- **Budgets and bounded frames.** A call's `CallBudget` travels in its request; the child's recorder
  counts every `reset` (also one with a seed it does not log) and every step of a recording call, stops
  recording once either count exceeds the budget, and the call ends `EPISODE_LIMIT` with a message
  naming the count, the limit and what to do. The same budget bounds the call's result frame
  (`grader/sandbox/child/budget.py`, used by both sides): bytes = 4 MiB + 1 024 x max_episodes +
  64 x max_steps and structural characters (`,` `[` `{`, an upper bound on JSON values) = 500 000 +
  64 x max_episodes + 8 x min(max_steps, 250 000), each capped by `Limits.frame_bytes` and 8 000 000
  (those caps alone apply with no budget; a non-recording call may send `MAX_NODES` + 500 000). The
  parent refuses a header announcing more bytes without reading the body, and a frame over either
  limit before `json.loads`; `episodes_from_plain(data, budget)` refuses more episodes or steps than the
  budget from the shapes the log's arrays announce before decoding any, and array data is checked
  against its shape before base64 decoding. The `ready` frame is bounded likewise (16 MiB, 200 000).
  Over a limit is a forged frame (`INVALID_VALUE`), never a grader error; the child checks its own frame
  against the same limits and reports an honest overflow as `OUTPUT_TOO_LARGE`.
- **Declared boundaries.** Everything the child sends is validated by declared pydantic models in strict mode
  with no undeclared fields (`grader/sandbox/boundary.py`: `STRICT`, `one_of` for unions that fail with one
  sentence, `at_most(n)` refusing a longer list or dict before any entry is validated,
  `problem(ValidationError, where)` -> "the episode log: envs[0].env_kwargs: should be a valid dictionary,
  found list [1]"). `grader/sandbox/messages.py`: `ReadyMessage` (function table, at most `MAX_LISTED_NAMES` x
  `MAX_LISTED_PARAMETERS`), `ImportErrorMessage`, `ResultMessage` (`ChildStatus`, `compat_events:
  list[CompatEventRecord]`, `wall_time` in [0, 1e9)), whose string fields are cleaned as they validate;
  `value` is decoded by `decode_value`, `episodes` by `episodes_from_plain` (the episodes' wire format:
  `grader.sandbox.child.log_block`). A failed validation is a forged frame (`INVALID_VALUE`) with that
  sentence. pydantic was chosen over msgspec by `bench/boundaries.py` (bench/RESULTS.md; the bench measured
  the per-episode layout and was retired with it: run it at commit 78f5685).
- **Strings from the child** are cleaned once where they enter the parent (`grader/sandbox/text.py`:
  `clean_text(text, limit)` replaces lone surrogates and NULs with U+FFFD and caps with a note;
  `clean_plain` for values, env arguments and reset options): messages and tracebacks 20 000
  characters, compat event fields 500, function and parameter names 200, output at `output_bytes`.
  Every string of a `CallOutcome` encodes as UTF-8.
- Each call's randomness is derived from `(seed, call index)` only, so restarting the child, running
  under xdist or alone gives identical outcomes. Calls never share RNG state.
- The child harness (`grader/sandbox/child/`, stdlib + numpy + gymnasium + `grader.compat` only) starts as
  `python -I -B <root>/grader/sandbox/child/__main__.py --submission P --requests FD --results FD
  [--max-frame BYTES] [--seed IMPORT_SEED] [--max-recorded-steps N] [--name SHOWN]` (or `runpy.run_module(
  "grader.sandbox.child", run_name="__main__")` with `sys.path` prepared); frames and plain-data
  encoding are `grader/sandbox/child/frames.py`, used by both sides. The harness tree the child imports
  from (`filesystem.harness_tree()`, one per grader process, read-only in the child) carries the bytecode
  of its copies, compiled by the grader (the child runs `-B` and would otherwise compile the harness and
  `grader.compat` at every start); after the runner closes its requests the child flushes its streams and
  ends with `os._exit` (the interpreter's finalisation was 25-50 ms of CPU nothing reads).
- Children are spawned, one per problem, through the layers' wrappers (cgroup join, bwrap, setpriv, the
  bootstrap). A per-worker fork server that imports numpy and gymnasium once (about 0.17 s of a child's
  0.25 s start) was measured and not built (issue 31, bench/RESULTS.md `## Class throughput`): those
  imports run after bwrap and setpriv have exec'd, so a process forked after them would live in its
  zygote's namespaces, file system view and cgroup, not in a fresh set of its own.
- Before the submission is imported, `harness.prepare_process` puts two finders first on
  `sys.meta_path`: `_QuietPyplot` (pyplot's `show`/`pause` return at once) and
  `light_ipython.LightIPython`, which serves `IPython` and `IPython.display` as small modules whose
  `clear_output` and `display` print exactly what IPython's print outside a shell, and loads the real
  IPython (once, in place) the moment anything else of it is used (`HTML`, `get_ipython`, `import
  IPython.core...`, `import *`). IPython's import was 0.35 s of CPU in every child, more than the rest of
  its start (`tests/grader/sandbox/test_light_ipython.py`).
- `IsolationPolicy.REQUIRE_FULL` (instructor grading, the service) fails closed with
  `grader.sandbox.errors.IsolationUnavailable`; `ALLOW_FALLBACK` (a student's `gymgrade check`) runs
  with the strongest available layers and says so in `IsolationReport`.

The interpreter inside the sandbox:

- `grader/sandbox/isolation/filesystem.py` `python_paths()`: the interpreter's directories (prefixes,
  executable's directory, stdlib entries from `sysconfig`, existing site directories), resolved, each once;
  the child's `sys.path` uses the same resolved strings. `bubblewrap.interpreter_binds(roots, system,
  masked)` (pure) decides which to bind and in what order: ancestors first, none that a read-only bind
  already shows (anything inside `/usr` but outside the `/usr/local` mask), so the mask stays a mount point
  that bwrap can remount read-only; a directory containing a system directory raises `SandboxLayoutError`.
  `file_system_argv` is shared by the children and the bubblewrap probe, which starts the interpreter in
  that file system and reports bwrap's message (paths without `/newroot`) when it cannot.
- `grader/sandbox/doctor.py`: `diagnose(student_modules) -> Diagnosis` (probe, binds, one sandbox child
  importing each module, timings) and `render(diagnosis)`; `gymgrade doctor [--config]` prints it (exit 0 =
  ready).
- `grader.lab.assignment.STUDENT_MODULES` / `[sandbox] student_modules`: the modules students may import
  beyond the stdlib, numpy and gym (installed by `pyproject.toml`'s dependencies); not part of `Limits`.
- `grader/sandbox/process.py` `CappedOutput`: a line rewritten with `\\r` keeps its last state (progress
  bars, `clear_output`), before the `output_bytes` cap.
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
