"""Serve each `reset()`/`step()` call the gym API its call site was written for.

The code calling an environment is found on the stack (the first frame outside this package and
gymnasium); its file is analysed once (`grader.compat.detection`) and the line decides. A function
without evidence of its own follows its module, or, when the module mixes both APIs, the nearest caller
that has evidence. Code with no evidence at all (or none decided by a caller) gets classic gym, the API
the lab was written for.
Every decision is reported once per drain of the events (`api_detected`), with the lines that decided.
"""

from __future__ import annotations

import linecache
import sys
from functools import cache
from pathlib import Path
from types import CodeType, FrameType

import gymnasium

from . import events
from .detection import Api, ApiDetection, Decision, detect_api
from .errors import AmbiguousApiError

DEFAULT_API = Api.CLASSIC
"""Served when no line of the calling code shows which API it expects (the lab's own API)."""

_SKIPPED_DIRECTORIES = (
    str(Path(__file__).resolve().parent),
    str(Path(gymnasium.__file__).resolve().parent),
)

# (code, line) of a call site whose own frame decided -> API, valid for one drain of the events.
_served: dict[tuple[CodeType, int], Api] = {}
_announced: set[tuple[str, str]] = set()
_served_generation = -1
# A file's path -> its own name as the grader shows it (`show_file_as`); its file name when not listed.
_shown_names: dict[str, str] = {}


def show_file_as(filename: str, name: str) -> None:
    """Name the file at ``filename`` ``name`` in what the layer says (events, errors): the sandbox imports a
    copy whose name may be numbered or made safe, while a person reads the file's own name (`--name`)."""
    _shown_names[filename] = name


def _shown(filename: str) -> str:
    return _shown_names.get(filename) or Path(filename).name


def caller_api(env_id: str, depth: int = 2) -> Api:
    """The API to serve the code that called the environment method calling this function.

    Args:
        env_id: the id the environment was made as (names the `api_detected` event).
        depth: frames between this function and the student's call (2: the env method's caller).

    Raises:
        AmbiguousApiError: the calling function's own lines (or module-level code) expect both APIs; the
            message names the lines. A function without evidence in a file that uses both, called by no
            function with evidence, gets `DEFAULT_API` and an event saying so.
    """
    global _served_generation
    frame = sys._getframe(depth)
    if _served_generation != events.generation():
        _served.clear()
        _announced.clear()
        _served_generation = events.generation()
    site = (frame.f_code, frame.f_lineno)
    served = _served.get(site)
    if served is not None:
        return served
    return _resolve(frame, site, env_id)


def _resolve(frame: FrameType | None, site: tuple[CodeType, int], env_id: str) -> Api:
    first: tuple[str, str, Decision] | None = None
    origin = frame
    while frame is not None:
        filename = frame.f_code.co_filename
        detection = None if filename.startswith(_SKIPPED_DIRECTORIES) else _detection(filename)
        if detection is not None:
            scope, decision = detection.decision_at(frame.f_lineno)
            calling = first is None
            if calling:
                first = (filename, scope, decision)
            if decision.api is not None:
                if frame is origin:
                    _served[site] = decision.api
                _announce(env_id, filename, scope, decision.api, decision)
                return decision.api
            # Lines of one function, or module-level code calling the env, that expect both cannot be served.
            module_code = calling and frame.f_code.co_name == "<module>"
            if decision.conflict and (scope != "<module>" or module_code):
                raise _ambiguous(filename, scope, decision)
        frame = frame.f_back
    _served[site] = DEFAULT_API
    where = _shown(first[0]) if first is not None else "the calling code"
    if (where, "") in _announced:
        return DEFAULT_API
    _announced.add((where, ""))
    if first is not None and first[2].conflict:
        reason = f"the calling function shows no API of its own and its file uses both ({first[2].explain(limit=2)}), so it got {DEFAULT_API.label}, the lab's API"  # noqa: E501
    else:
        reason = f"no line shows which gym API it expects (no reset() or step() result unpacked), so it got {DEFAULT_API.label}, the lab's API"  # noqa: E501
    events.record(events.API_DETECTED, env_id, f"{where}: {reason}")
    return DEFAULT_API


@cache
def _detection(filename: str) -> ApiDetection | None:
    lines = linecache.getlines(filename)
    if not lines:
        return None
    return detect_api("".join(lines))


def _announce(env_id: str, filename: str, scope: str, api: Api, decision: Decision) -> None:
    if (filename, scope) in _announced:
        return
    _announced.add((filename, scope))
    where = _shown(filename) if scope == "<module>" else f"{scope}() in {_shown(filename)}"
    # One event per scope: the key of an event is its (kind, env_id), and one env can serve several scopes.
    label = env_id if scope == "<module>" else f"{env_id} in {scope}()"
    events.record(events.API_DETECTED, label, f"{where} was served {api.label}: {decision.explain()}")


def _ambiguous(filename: str, scope: str, decision: Decision) -> AmbiguousApiError:
    where = "this file" if scope == "<module>" else f"{scope}()"
    lines = "; ".join(f"{item.describe()} ({item.api.short})" for item in decision.evidence[:6])
    return AmbiguousApiError(
        f"gymgrade cannot tell which gym API {where} in {_shown(filename)} expects: {lines}. "
        "Classic gym's reset() returns the observation and step() 4 values (obs, reward, done, info); "
        "gym 0.26's reset() returns (obs, info) and step() 5 values (obs, reward, terminated, truncated, info). "  # noqa: E501
        "Make these lines follow one of them."
    )
