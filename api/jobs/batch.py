"""`gymgrade grade` on the cluster: each file is a Celery task, each report comes back on a Redis list.

The batch core (``grader.grading.batch``) decides what to grade and keeps every report as it arrives, so a
distributed batch resumes exactly like a local one. This module only ships files to the workers and
hands their reports back. It is found through the ``gymgrade.executors`` entry point, so ``grader``
never imports ``api``.
"""

from __future__ import annotations

import base64
import json
import logging
import time
import tomllib
import uuid
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from api.settings import BrokerSettings
from grader.errors import ConfigError, ExecutorUnavailable
from grader.grading.grade import READ_LIMIT, grade_files
from grader.grading.outcomes import GradingListener, Outcomes, Silent, Submission
from grader.grading.plan import GradingPlan
from grader.lab.assignment import config_from_data
from grader.report import Report
from grader.sandbox import IsolationPolicy
from grader.submission.untrusted_file import UnsafeFile, read_untrusted

logger = logging.getLogger(__name__)

REPLY_PREFIX = "gymgrade:batch:"
_WAIT_SECONDS = 1
_RECONNECT_SECONDS = 1.0


def executor_from_environment(policy: IsolationPolicy) -> CeleryExecutor | None:
    """The ``gymgrade.executors`` entry point: the cluster when GYMGRADE_BROKER_URL is set, else None.

    Celery and Redis are imported only when the setting is there, so a local batch never needs them.

    Raises:
        grader.errors.ExecutorUnavailable: The setting is invalid or the broker does not answer.
    """
    try:
        settings = BrokerSettings()
    except ValidationError as error:
        raise ExecutorUnavailable(f"GYMGRADE_BROKER_URL is not usable: {error.errors()[0]['msg']}") from error
    if settings.broker_url is None:
        return None
    from api.jobs.distributed import broker_problem

    problem = broker_problem(settings)
    if problem is not None:
        raise ExecutorUnavailable(problem + "; or unset GYMGRADE_BROKER_URL to grade on this machine")
    return CeleryExecutor(settings, policy)


def configuration_text(plan: GradingPlan) -> str | None:
    """The text of the plan's configuration file, which every worker reads, checked to be the plan's.

    The workers are sent the file's text; the plan was made from the same file when the batch started. A
    file edited in between would grade the cluster's files with another configuration than the one the
    batch checked and records, so that is refused.

    Raises:
        ConfigError: The file cannot be read any more, or now says something else than the plan.
    """
    if plan.config is None:
        return None
    where = str(plan.config)
    try:
        text = plan.config.read_text(encoding="utf-8")
        now = config_from_data(tomllib.loads(text), where=where)
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as error:
        raise ConfigError(
            f"cannot read the assignment configuration {where} again to send it to the workers ({error}): "
            "keep the file in place until the batch has been sent, then grade again"
        ) from None
    if (
        GradingPlan(assignment=now, problems=plan.problems, config=plan.config).config_sha256
        != plan.config_sha256
    ):
        raise ConfigError(
            f"the assignment configuration {where} changed after the batch read it: the workers would grade "
            "with a configuration other than the one checked; grade the batch again"
        )
    return text


@dataclass(frozen=True)
class CeleryExecutor:
    """A :class:`grader.grading.batch.BatchExecutor` that grades on the cluster's workers.

    Attributes:
        settings: The broker settings.
        policy: ``ALLOW_FALLBACK`` lets workers configured with GYMGRADE_ALLOW_WEAK_ISOLATION use it.
    """

    settings: BrokerSettings
    policy: IsolationPolicy = IsolationPolicy.REQUIRE_FULL

    def __str__(self) -> str:
        from api.jobs.distributed import describe

        return describe(self.settings)

    def grade(
        self,
        paths: Sequence[Path],
        plan: GradingPlan,
        *,
        seed: int,
        listener: GradingListener,
        file_names: Mapping[Path, str] | None = None,
    ) -> None:
        """Send every file to the cluster and hand each report over as it arrives.

        ``file_names`` (each file's own name as shown, ``path.name`` without one) goes with each file as
        the request's ``name``: the worker's messages and the report's ``submission`` say what a local
        grading says, while the worker writes the file under a safe grading name of its own.

        A broker restart during the batch loses its queued tasks: once the broker answers again, every
        file still outstanding is sent again (a report that arrives twice is taken once).

        Raises:
            KeyboardInterrupt: Interrupted; the outstanding tasks are revoked.
        """
        import redis

        from api.jobs.distributed import make_celery, redis_client

        app = make_celery(self.settings)
        client = redis_client(self.settings)
        reply_to = REPLY_PREFIX + uuid.uuid4().hex
        config_toml = configuration_text(plan)
        requests: dict[str, dict[str, Any]] = {}
        shown = {path: (file_names or {}).get(path) or path.name for path in paths}
        contents: dict[str, bytes] = {}
        pending: dict[str, Path] = {}
        for index, path in enumerate(paths):
            try:
                data = read_untrusted(path, limit=READ_LIMIT)
            except UnsafeFile:  # a link or unreadable: refused without any grading, no need for the cluster
                grade_files(
                    [path],
                    plan,
                    seed=seed,
                    workers=1,
                    policy=self.policy,
                    listener=listener,
                    names=file_names,
                )
                continue
            key = str(index)
            contents[key], pending[key] = data, path
            requests[key] = {
                "key": key,
                "reply_to": reply_to,
                "filename": path.name,
                "name": shown[path],
                "content": base64.b64encode(data).decode("ascii"),
                "seed": seed,
                "only": list(plan.problems),
                "config_toml": config_toml,
                "allow_weak_isolation": self.policy is IsolationPolicy.ALLOW_FALLBACK,
            }
        task_ids = {key: self._send(app, request) for key, request in requests.items()}
        broker_lost = False
        try:
            while pending:
                try:
                    item = client.blpop([reply_to], timeout=_WAIT_SECONDS)
                    if broker_lost:
                        logger.warning(
                            "the broker is back; sending the %d outstanding files again", len(pending)
                        )
                        task_ids.update({key: self._send(app, requests[key]) for key in pending})
                        broker_lost = False
                except redis.ConnectionError:
                    broker_lost = True
                    time.sleep(_RECONNECT_SECONDS)
                    continue
                if item is None:
                    continue
                message = json.loads(item[1])
                key = str(message.get("key"))
                if key not in pending:
                    continue  # a duplicate delivery's report, already taken
                path = pending.pop(key)
                report = _report(path, contents[key], message, plan, seed, shown[path])
                for result in report.problems:
                    listener.result(path, result)
                listener.report(path, report)
            client.delete(reply_to)
        except KeyboardInterrupt:
            app.control.revoke([task_ids[key] for key in pending])
            raise
        finally:
            client.close()
            app.close()

    @staticmethod
    def _send(app: Any, request: dict[str, Any]) -> str:
        from api.jobs.distributed import GRADE_FILE, QUEUE

        task_id: str = app.send_task(GRADE_FILE, args=[request], queue=QUEUE).id
        return task_id


def _report(
    path: Path, data: bytes, message: dict[str, Any], plan: GradingPlan, seed: int, name: str = ""
) -> Report:
    """The report a worker sent, its ``submission`` the file's name as shown (``name``, ``path.name`` when
    empty: what this side read, whatever the worker says); a grading that failed becomes a grader error."""
    if "report" in message:
        report = Report.model_validate(message["report"])
        return report.model_copy(update={"submission": name or path.name})
    reason = str(message.get("error", "the worker sent no report"))
    collector = Outcomes(plan, seed=seed, workers=0, listener=Silent())
    collector.expect(Submission(path, data, path, name=name))
    collector.close(f"the cluster could not grade it: {reason}")
    return collector.reports[path]
