"""The service's view of the grader: the adapter that calls the configured grader (``GYMGRADE_GRADER``)."""

from __future__ import annotations

import importlib
import importlib.util
import inspect
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from api.errors import GraderFailed, GraderUnavailable

JsonObject = dict[str, Any]
ProgressCallback = Callable[[JsonObject], None]


@dataclass(frozen=True)
class ImportedGrader:
    """Calls a function with the signature of ``grader.grading.grade.grade_submission``, imported by name.

    Attributes:
        target: ``module:function``, e.g. ``grader.grading.grade:grade_submission``.
        workers: Processes one grading may use (None: all cores).
        allow_weak_isolation: Grade with the strongest available isolation instead of failing closed.
    """

    target: str
    workers: int | None = None
    allow_weak_isolation: bool = False

    def __call__(
        self,
        path: Path,
        *,
        seed: int,
        on_progress: ProgressCallback,
        only: Sequence[str] | None = None,
        config: Path | None = None,
        name: str | None = None,
    ) -> JsonObject:
        """Grade the file at ``path`` with ``seed``; call ``on_progress`` with each finished problem (JSON).

        ``only`` and ``config`` (a distributed batch's --only and --config) default to every enabled
        problem of the bundled configuration. ``name`` is the file's own name as its messages and report
        show it when its copy here has a safe grading name instead (an upload named ``my lab.py``, a
        class's ``smith-1.py``); ``path.name`` when None. Returns the report as JSON data.
        """
        grade_submission = load_function(self.target)
        from grader.sandbox import IsolationPolicy  # the grader is heavy: import it only where grading runs

        policy = IsolationPolicy.ALLOW_FALLBACK if self.allow_weak_isolation else IsolationPolicy.REQUIRE_FULL
        selection: dict[str, Any] = {}
        if only is not None:
            selection["only"] = only
        if config is not None:  # passed only when set, so graders without the parameter still work
            selection["config"] = config
        if name is not None and accepts(grade_submission, "name"):  # a grader without it shows its file's
            selection["name"] = name
        report = grade_submission(
            path,
            seed=seed,
            workers=self.workers,
            policy=policy,
            on_progress=lambda result: on_progress(result.model_dump(mode="json")),
            **selection,
        )
        if report.grader_errors:
            failures = "; ".join(report.grader_errors)
            raise GraderFailed(f"the grader failed on this submission (not the student's fault): {failures}")
        dumped: JsonObject = report.model_dump(mode="json")
        return dumped


def accepts(function: Callable[..., Any], parameter: str) -> bool:
    """Whether ``function`` takes the keyword ``parameter`` (or any keyword); False when it cannot be told."""
    try:
        parameters = inspect.signature(function).parameters
    except (TypeError, ValueError):
        return False
    return parameter in parameters or any(
        item.kind is inspect.Parameter.VAR_KEYWORD for item in parameters.values()
    )


def check_grader_target(target: str) -> None:
    """Check that ``module:function`` names an importable module without importing it (cheap, at start-up).

    Raises:
        GraderUnavailable: The target is malformed or its module cannot be found.
    """
    module_name, _, function_name = target.partition(":")
    if not module_name or not function_name:
        raise GraderUnavailable(f"GYMGRADE_GRADER must look like module:function, found {target!r}")
    try:
        found = importlib.util.find_spec(module_name) is not None
    except (ImportError, ValueError):
        found = False
    if not found:
        raise GraderUnavailable(
            f"GYMGRADE_GRADER names module {module_name!r}, which is not installed; "
            "expected e.g. grader.grading.grade:grade_submission"
        )


def load_function(target: str) -> Callable[..., Any]:
    """Import ``module:function``.

    Raises:
        GraderUnavailable: The target is malformed, or the module or function does not exist.
    """
    module_name, _, function_name = target.partition(":")
    if not module_name or not function_name:
        raise GraderUnavailable(f"GYMGRADE_GRADER must look like module:function, found {target!r}")
    try:
        module = importlib.import_module(module_name)
    except ImportError as error:
        raise GraderUnavailable(
            f"GYMGRADE_GRADER names module {module_name!r}, which cannot be imported: {error}"
        ) from error
    function = getattr(module, function_name, None)
    if not callable(function):
        raise GraderUnavailable(
            f"GYMGRADE_GRADER names {target!r}, but {module_name} has no function {function_name}"
        )
    return function  # type: ignore[no-any-return]
