"""The `gymgrade serve` and `gymgrade worker` subcommands (entry points of the group gymgrade.commands)."""

from __future__ import annotations

import argparse
import logging
import signal
import sys
from types import FrameType
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from api.settings import Settings

DEFAULT_HOST = "127.0.0.1"
DEFAULT_PORT = 8000


def add_serve_command(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``gymgrade serve [--host HOST] [--port PORT]``."""
    parser = subparsers.add_parser(
        "serve",
        help="run the HTTP submission service (settings from GYMGRADE_* variables)",
        description="Run the HTTP submission service with uvicorn. "
        "Configure it with GYMGRADE_* environment variables; "
        "GYMGRADE_OPERATOR_TOKEN (or GYMGRADE_INSTRUCTOR_TOKEN, its single-course name) is required.",
    )
    parser.add_argument("--host", default=DEFAULT_HOST, help=f"address to listen on (default {DEFAULT_HOST})")
    parser.add_argument(
        "--port", type=int, default=DEFAULT_PORT, help=f"port to listen on (default {DEFAULT_PORT})"
    )
    parser.set_defaults(handler=serve)


def add_worker_command(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``gymgrade worker [--workers N]``."""
    parser = subparsers.add_parser(
        "worker",
        help="grade queued submissions in this process (a Celery worker when GYMGRADE_BROKER_URL is set)",
        description="Grade queued submissions until Ctrl-C or SIGTERM: "
        "from the service's database next to `gymgrade serve` with GYMGRADE_WORKERS=0, or, with GYMGRADE_BROKER_URL=redis://HOST:PORT/N, as a Celery worker of the cluster (it needs the broker, the database and full isolation).",  # noqa: E501
    )
    parser.add_argument(
        "--workers",
        type=int,
        default=None,
        help="gradings run at once (default: one per core with GYMGRADE_BROKER_URL, else GYMGRADE_WORKERS; at least 1)",  # noqa: E501
    )
    parser.set_defaults(handler=work)


def _settings_or_none() -> Settings | None:
    # Imported here: every `gymgrade` command builds this parser, and the settings' imports
    # (pydantic-settings, the service's errors) cost a `gymgrade check` about 45 ms before its grading starts.
    from pydantic import ValidationError

    from api.errors import GraderUnavailable
    from api.grader_adapter import check_grader_target
    from api.settings import load_settings

    try:
        settings = load_settings()
        check_grader_target(settings.grader)
        return settings
    except GraderUnavailable as error:
        print(f"gymgrade: {error}", file=sys.stderr)
        return None
    except ValidationError as error:
        for problem in error.errors():
            message = str(problem["msg"]).removeprefix("Value error, ")
            field = ".".join(str(part) for part in problem["loc"])
            if field:
                message = f"GYMGRADE_{field.upper()}: {message}, found {problem['input']!r}"
            print(f"gymgrade: {message}", file=sys.stderr)
        return None


def serve(args: argparse.Namespace) -> int:
    """Run uvicorn with the service until interrupted; 2 when the settings are refused."""
    import uvicorn

    from api.main import create_app

    settings = _settings_or_none()
    if settings is None:
        return 2
    uvicorn.run(create_app(settings), host=args.host, port=args.port, log_level="info")
    return 0


def work(args: argparse.Namespace) -> int:
    """Run a worker pool until SIGINT or SIGTERM; 2 when the settings are refused."""
    from api.context import ServiceContext

    settings = _settings_or_none()
    if settings is None:
        return 2
    if args.workers is not None and args.workers < 1:
        print(f"gymgrade worker: --workers must be at least 1, found {args.workers}", file=sys.stderr)
        return 2
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(levelname)s %(name)s: %(message)s")
    if settings.broker_url is not None:
        from api.jobs.celery_worker import run_worker, startup_problem

        problem = startup_problem(settings)
        if problem is not None:
            print(f"gymgrade worker: {problem}", file=sys.stderr)
            return 2
        return run_worker(settings, args.workers)
    context = ServiceContext.open(settings, pool_size=args.workers or max(settings.workers, 1), publish=False)
    pool = context.pool
    if pool is None:
        raise RuntimeError("ServiceContext.open started no pool for a pool size of at least 1")

    def stop(_signum: int, _frame: FrameType | None) -> None:
        pool.stop(timeout=0)

    signal.signal(signal.SIGINT, stop)
    signal.signal(signal.SIGTERM, stop)
    pool.wait()
    context.close()
    return 0
