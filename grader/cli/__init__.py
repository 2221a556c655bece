"""The `gymgrade` command line: `check` one file (students), `grade` a batch (instructors), and plugins.

In detail:

- `grader/cli/__init__.py`: `gymgrade check`, `grade`, `gradescope-bundle`, `gradescope-run`,
  `gradescope-seed`, `doctor` and `similarity` (`grader/classroom/similarity/command.py`); other subcommands
  come from the entry-point group `gymgrade.commands` (each entry point is `add_command(subparsers) -> None`;
  the subparser sets `handler=callable(args) -> int`). The service registers `serve` and `worker` this way, so
  `grader` never imports `api`.
"""

from __future__ import annotations

import argparse
import io
import signal
import sys
from collections.abc import Callable, Sequence
from datetime import datetime
from importlib.metadata import entry_points
from pathlib import Path

from grader.errors import (
    EXIT_ERROR,
    EXIT_FULL_MARKS,
    EXIT_INTERRUPTED,
    EXIT_NOT_FULL,
    GraderError,
)
from grader.lab.editions import EDITIONS, all_problem_ids
from grader.lab.labs import LABS
from grader.render.progress import result_line
from grader.render.registry import FORMATS, format_help
from grader.report import ProblemResult
from grader.sandbox import IsolationPolicy
from grader.sandbox.errors import SandboxError
from grader.seeds import PRACTICE_SEED

COMMAND_GROUP = "gymgrade.commands"

Handler = Callable[[argparse.Namespace], int]


def _problem_ids(text: str) -> list[str]:
    """Problem ids of any edition (the chosen edition's plan then refuses those it does not grade)."""
    chosen = [name.strip() for name in text.split(",") if name.strip()]
    known = all_problem_ids()
    unknown = [name for name in chosen if name not in known]
    if unknown or not chosen:
        raise argparse.ArgumentTypeError(
            f"unknown problem {', '.join(unknown) or '(none)'}; expected ids among {', '.join(known)}"
        )
    return [problem for problem in known if problem in chosen]


def _positive(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive number of workers, found {value}")
    return value


def _seed(text: str) -> int:
    value = int(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected a non-negative seed, found {value}")
    return value


def _class_page(text: str) -> Path:
    page = Path(text)
    if page.suffix.lower() == ".json":
        raise argparse.ArgumentTypeError(
            f"expected an .html file name (the JSON summary is written beside it), found {text}; name the page e.g. class.html"  # noqa: E501
        )
    return page


def _add_common(parser: argparse.ArgumentParser, seed_help: str) -> None:
    parser.add_argument("--seed", type=_seed, default=None, help=seed_help)
    parser.add_argument(
        "--workers", type=_positive, default=None, help="parallel workers (default: all cores)"
    )
    parser.add_argument(
        "--only",
        type=_problem_ids,
        default=None,
        metavar="ID[,ID...]",
        help=f"grade only these problems ({', '.join(all_problem_ids())}; each edition grades its own)",
    )
    _add_lab(parser)
    parser.add_argument(
        "--edition",
        choices=tuple(EDITIONS),
        default=None,
        help="the edition of the lab graded (default: the configuration's `edition`, else detected from the file for check, else the --lab's current edition, else classic)",  # noqa: E501
    )
    parser.add_argument(
        "--config",
        type=Path,
        default=None,
        metavar="PATH",
        help="assignment configuration TOML (default: the bundled one)",
    )


def _add_lab(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--lab",
        choices=tuple(LABS),
        default=None,
        help="the lab graded: "
        + ", ".join(lab.label for lab in LABS.values())
        + " (default: the configuration's `lab`, else the --edition's lab, else detected from the file for check, else opengym); "  # noqa: E501
        "alone, its current edition",
    )


def _add_class_options(grade: argparse.ArgumentParser) -> None:
    from grader.classroom.gradebooks import GRADEBOOKS
    from grader.classroom.layouts import add_layout_option

    add_layout_option(grade)
    grade.add_argument(
        "--roster",
        type=Path,
        default=None,
        metavar="CSV",
        help="class roster (GitHub Classroom roster, Canvas gradebook export, or a CSV with id/name/email)",
    )
    grade.add_argument(
        "--gradebook",
        action="append",
        choices=tuple(GRADEBOOKS),
        default=[],
        help="also write this LMS's import CSV into --out (repeatable)",
    )
    grade.add_argument(
        "--assignment-title",
        default=None,
        help="the assignment's title in gradebooks (default: the lab's, e.g. 'OpenGym AI lab', 'Policy Function Iteration lab')",  # noqa: E501
    )
    grade.add_argument(
        "--assignment-id",
        default="",
        metavar="ID",
        help="the LMS's assignment id (needed by --gradebook canvas)",
    )
    grade.add_argument(
        "--overrides",
        type=Path,
        default=None,
        metavar="CSV",
        help="the instructor's overrides (student,problem,points,reason; problem an id or total), checked, then kept in --out for later runs",  # noqa: E501
    )
    grade.add_argument(
        "--submitted-at",
        type=Path,
        default=None,
        metavar="CSV",
        help="submission times the download lacks (student,submitted_at; a Canvas submissions CSV; Moodle's grading worksheet), for the [late] policy",  # noqa: E501
    )
    grade.add_argument(
        "--only-students",
        type=_students,
        default=None,
        metavar="ID[,ID...]",
        help="regrade only these students in an existing --out, at its recorded seed and configuration; nobody else's files change",  # noqa: E501
    )
    grade.add_argument(
        "--due",
        type=_moment,
        default=None,
        metavar="ISO-TIME",
        help="deadline (e.g. 2026-03-01T23:59-05:00): submissions whose source gives a time but no late mark are late after it",  # noqa: E501
    )


def _students(text: str) -> list[str]:
    chosen = [name.strip() for name in text.split(",") if name.strip()]
    if not chosen:
        raise argparse.ArgumentTypeError(
            f"expected students as grades.csv's student column names them, comma-separated; found {text!r}"
        )
    return chosen


def _moment(text: str) -> datetime:
    try:
        return datetime.fromisoformat(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r} is not an ISO 8601 time such as 2026-03-01T23:59-05:00"
        ) from None


def build_parser() -> argparse.ArgumentParser:
    """The argument parser, including subcommands registered under the `gymgrade.commands` entry points."""
    parser = argparse.ArgumentParser(prog="gymgrade", description="Grade OpenGym AI lab submissions.")
    subparsers = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    check = subparsers.add_parser("check", help="grade one file and explain every verdict (for students)")
    check.add_argument("file", type=Path, metavar="FILE")
    _add_common(
        check,
        f"seed of the starts (default: the practice seed {PRACTICE_SEED}; instructors grade on another)",
    )
    check.add_argument("--format", choices=tuple(FORMATS), default=next(iter(FORMATS)), help=format_help())
    check.add_argument("--json", action="store_true", help="same as --format json")
    check.add_argument(
        "--output", type=Path, default=None, metavar="PATH", help="also write the report JSON here"
    )
    check.add_argument(
        "--html",
        type=Path,
        default=None,
        metavar="PATH",
        help="also write a self-contained HTML report with plots and replays of your episodes",
    )
    check.set_defaults(handler=run_check)

    grade = subparsers.add_parser(
        "grade", help="grade many files: a report each and grades.csv (instructors)"
    )
    grade.add_argument("targets", type=Path, nargs="+", metavar="DIR|FILE")
    grade.add_argument(
        "--out", type=Path, required=True, metavar="DIR", help="directory for reports + grades.csv"
    )
    _add_common(
        grade,
        "grading seed (default: a fresh random one, printed and kept in every report and grades.csv; "
        "pass it again to regrade identically)",
    )
    grade.add_argument(
        "--allow-weak-isolation",
        action="store_true",
        help="grade even where the sandbox cannot enforce every isolation layer",
    )
    _add_class_options(grade)
    grade.add_argument(
        "--html",
        type=_class_page,
        default=None,
        metavar="PATH",
        help="also write a self-contained class report (scores, pass rates, common diagnoses, links to each report); "  # noqa: E501
        "its JSON summary goes beside it (class.html -> class.json)",
    )
    grade.add_argument(
        "--similarity",
        action="store_true",
        help="also rank pairs of students whose code is alike beyond the template into --out (similarity.csv/.html/.json, as `gymgrade similarity`; changes no grade)",  # noqa: E501
    )
    grade.add_argument(
        "--reference",
        type=Path,
        action="append",
        default=[],
        metavar="DIR",
        help="with --similarity: a folder of known solutions to compare against; may be repeated",
    )
    grade.set_defaults(handler=run_grade)

    bundle = subparsers.add_parser(
        "gradescope-bundle", help="build the Gradescope autograder zip (setup.sh, run_autograder, config)"
    )
    bundle.add_argument("--out", type=Path, default=Path("autograder.zip"), metavar="ZIP")
    bundle.add_argument("--config", type=Path, default=None, metavar="PATH", help="assignment configuration")
    _add_lab(bundle)
    bundle.add_argument(
        "--edition",
        choices=tuple(EDITIONS),
        default=None,
        help="the edition graded (default: the configuration's `edition`, else classic)",
    )
    bundle.set_defaults(handler=run_gradescope_bundle)

    gradescope_run = subparsers.add_parser(
        "gradescope-run", help="grade ROOT/submission into ROOT/results/results.json (run_autograder)"
    )
    gradescope_run.add_argument("--root", type=Path, default=None, metavar="DIR")
    gradescope_run.add_argument(
        "--secret-file",
        type=Path,
        default=None,
        metavar="PATH",
        help="the bundle's seed secret (the upload's seed derives from it and ROOT/submission_metadata.json)",
    )
    gradescope_run.add_argument(
        "--seed", type=_seed, default=None, help="grade on this seed instead (an instructor's regrade)"
    )
    gradescope_run.add_argument("--config", type=Path, default=None, metavar="PATH")
    gradescope_run.add_argument("--workers", type=_positive, default=None)
    gradescope_run.set_defaults(handler=run_gradescope_run)

    gradescope_seed = subparsers.add_parser(
        "gradescope-seed",
        help="an upload's grading seed from the autograder zip and its submission_metadata.json; "
        "with --submission, regrade it identically",
    )
    gradescope_seed.add_argument(
        "--bundle", type=Path, required=True, metavar="ZIP", help="the autograder zip"
    )
    gradescope_seed.add_argument(
        "--metadata", type=Path, required=True, metavar="JSON", help="the upload's submission_metadata.json"
    )
    gradescope_seed.add_argument(
        "--submission", type=Path, default=None, metavar="FILE|DIR", help="the upload's file(s): regrade them"
    )
    gradescope_seed.add_argument(
        "--out",
        type=Path,
        default=Path("results.json"),
        metavar="PATH",
        help="where the regrade's results go",
    )
    gradescope_seed.add_argument("--workers", type=_positive, default=None)
    gradescope_seed.set_defaults(handler=run_gradescope_seed)

    from grader.classroom.similarity.command import add_similarity_command

    add_similarity_command(subparsers)

    doctor = subparsers.add_parser(
        "doctor",
        help="show the interpreter, the sandbox's binds and layers, and the student modules (instructors)",
    )
    doctor.add_argument(
        "--config",
        type=Path,
        default=None,
        metavar="PATH",
        help="assignment configuration (its student_modules)",
    )
    doctor.set_defaults(handler=run_doctor)

    for entry_point in entry_points(group=COMMAND_GROUP):
        try:
            entry_point.load()(subparsers)
        except Exception as error:
            broken = subparsers.add_parser(entry_point.name, help=f"(unavailable: {type(error).__name__})")
            broken.set_defaults(handler=_unavailable(entry_point.name, error))
    return parser


def _unavailable(name: str, error: Exception) -> Handler:
    def handler(_args: argparse.Namespace) -> int:
        print(
            f"gymgrade {name}: the command could not be loaded ({type(error).__name__}: {error}); "
            "install the package providing it.",
            file=sys.stderr,
        )
        return EXIT_ERROR

    return handler


def main(argv: Sequence[str] | None = None) -> int:
    """Run `gymgrade` and return its exit code.

    0: full marks (check) or success (grade); 1: not full marks; 2: usage or grader error; 130: interrupted.
    """
    _utf8_output()
    args = build_parser().parse_args(argv)
    handler: Handler = args.handler
    # A terminated run unwinds like Ctrl-C, so the grading processes it started are ended too.
    previous = signal.signal(signal.SIGTERM, _interrupt)
    try:
        _choose_edition(args)
        return handler(args)
    except (GraderError, SandboxError, ValueError, OSError) as error:
        print(f"gymgrade {args.command}: {error}", file=sys.stderr)
        return EXIT_ERROR
    except KeyboardInterrupt:
        print(f"gymgrade {args.command}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    finally:
        signal.signal(signal.SIGTERM, previous)


def _utf8_output() -> None:
    """Writes UTF-8 to a pipe or file whatever the locale says (Windows' is cp1252 or the like), and never
    fails on a character a terminal's encoding lacks (it is shown as `?`)."""
    for stream in (sys.stdout, sys.stderr):
        if not isinstance(stream, io.TextIOWrapper):
            continue
        if stream.isatty():
            stream.reconfigure(errors="replace")
        else:
            stream.reconfigure(encoding="utf-8")


def _choose_edition(args: argparse.Namespace) -> None:
    """Resolve `--lab`/`--edition`, the configuration's lab/edition or detection into the configuration; say
    which lab and edition."""
    if args.command not in ("check", "grade", "gradescope-bundle"):
        return
    from grader.lab.editions.choice import choose_edition

    if args.command == "grade" and args.edition is None and args.config is None and args.lab is None:
        args.detect_editions = True  # per submission, once the class's files are known (run_grade)
        return
    submission = args.file if args.command == "check" and args.file.is_file() else None
    choice = choose_edition(args.edition, args.config, submission, args.lab)
    args.config = choice.config
    print(choice.lab_line, file=sys.stderr, flush=True)
    print(choice.line, file=sys.stderr, flush=True)


def _interrupt(signum: int, _frame: object) -> None:
    raise KeyboardInterrupt(signal.Signals(signum).name)


def run_doctor(args: argparse.Namespace) -> int:
    """`gymgrade doctor`: what the sandbox is made of here; exit 0 only when it is ready to grade."""
    from grader.lab.assignment import load_config
    from grader.sandbox.doctor import diagnose, render

    diagnosis = diagnose(load_config(args.config).sandbox.student_modules)
    print(render(diagnosis))
    return 0 if diagnosis.healthy else EXIT_ERROR


def run_check(args: argparse.Namespace) -> int:
    """`gymgrade check`: grade one file with live progress, summarise, exit 0 only at full marks."""
    from grader.grading.grade import grade_submission
    from grader.grading.plan import GradingPlan

    if not args.file.is_file():
        print(
            f"gymgrade check: {args.file} is not a file: pass the path of your .py or .ipynb file",
            file=sys.stderr,
        )
        return EXIT_ERROR
    plan = GradingPlan.load(args.config, args.only)
    output = FORMATS["json" if args.json else args.format]
    progress = sys.stdout if output.live_progress else sys.stderr
    seed = PRACTICE_SEED if args.seed is None else args.seed

    def show(result: ProblemResult) -> None:
        print(result_line(result), file=progress, flush=True)

    if output.live_progress:
        print(f"Checking {args.file.name} (practice seed {seed})...", flush=True)
    report = grade_submission(
        args.file,
        seed=seed,
        workers=args.workers,
        policy=IsolationPolicy.ALLOW_FALLBACK,
        on_progress=show,
        plan=plan,
    )
    if args.output is not None:
        args.output.write_text(FORMATS["json"].render(report, plan.assignment), encoding="utf-8")
    if args.html is not None:
        args.html.write_text(FORMATS["html"].render(report, plan.assignment), encoding="utf-8")
    sys.stdout.write(output.render(report, plan.assignment))
    if report.grader_errors:
        return EXIT_ERROR
    return EXIT_FULL_MARKS if report.full_marks else EXIT_NOT_FULL


def run_gradescope_bundle(args: argparse.Namespace) -> int:
    """`gymgrade gradescope-bundle`: write the autograder zip to upload to Gradescope."""
    from grader.cli.gradescope import bundle
    from grader.lab.assignment import load_config

    load_config(args.config)  # an invalid configuration fails here, not on Gradescope
    path = bundle(args.out, config=args.config)
    print(f"Wrote {path} ({path.stat().st_size:,} bytes): upload it as the assignment's autograder.")
    print(
        "Each upload is graded on its own seed, derived from a secret drawn now and kept in the zip (never shown to students). "  # noqa: E501
        "Keep the zip: `gymgrade gradescope-seed --bundle ZIP --metadata submission_metadata.json` recomputes an upload's seed and regrades it identically."  # noqa: E501
    )
    return 0


def run_gradescope_run(args: argparse.Namespace) -> int:
    """`gymgrade gradescope-run`: what the bundle's run_autograder calls; always writes results.json."""
    from grader.cli.gradescope import default_root, run_autograder
    from grader.submission.gradescope_upload import UploadSeed, seed_for_upload

    root = args.root or default_root()
    if args.seed is not None:
        upload = UploadSeed(args.seed, "given")
    elif args.secret_file is not None:
        upload = seed_for_upload(root, secret_file=args.secret_file)
    else:
        print(
            "gymgrade gradescope-run: expected --secret-file (the bundle's seed_secret, as run_autograder passes it) or --seed N; "  # noqa: E501
            "found neither",
            file=sys.stderr,
        )
        return EXIT_ERROR
    graded = run_autograder(root, upload=upload, config=args.config, workers=args.workers)
    print(f"Score: {graded.score:g}")
    return 0


def run_gradescope_seed(args: argparse.Namespace) -> int:
    """`gymgrade gradescope-seed`: an upload's seed; with ``--submission``, its results regraded."""
    from grader.cli.gradescope import regrade_upload, upload_seed_of

    upload = upload_seed_of(args.bundle, args.metadata)
    print(f"Grading seed {upload.seed} (upload {', '.join(upload.identity)})")
    if args.submission is None:
        return 0
    graded = regrade_upload(args.bundle, args.metadata, args.submission, args.out, workers=args.workers)
    print(f"Regraded {args.submission} on seed {upload.seed} into {args.out}: score {graded.score:g}")
    return 0


def run_grade(args: argparse.Namespace) -> int:
    """`gymgrade grade`: a class download graded into its gradebooks (`grader.classroom.command`)."""
    from grader.classroom.command import grade_class

    return grade_class(args)


if __name__ == "__main__":
    sys.exit(main())
