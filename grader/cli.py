"""The `gymgrade` command line: `check` one file (students), `grade` a batch (instructors), and plugins."""

from __future__ import annotations

import argparse
import io
import signal
import sys
import tempfile
from collections.abc import Callable, Sequence
from datetime import datetime
from importlib.metadata import entry_points
from pathlib import Path
from typing import TYPE_CHECKING

from grader.editions import EDITIONS, all_problem_ids
from grader.errors import BatchInterrupted, ExecutorUnavailable, GraderError
from grader.progress import ProgressBar, result_line
from grader.render.registry import FORMATS, format_help
from grader.report import ProblemResult
from grader.sandbox import IsolationPolicy
from grader.sandbox.errors import SandboxError
from grader.seeds import PRACTICE_SEED, held_out_seed

if TYPE_CHECKING:
    from grader.batch import BatchExecutor
    from grader.classroom.kept import InstructorData
    from grader.classroom.model import ClassDownload
    from grader.classroom.output import ClassGradebook
    from grader.classroom.roster import Roster
    from grader.plan import GradingPlan

COMMAND_GROUP = "gymgrade.commands"
EXECUTOR_GROUP = "gymgrade.executors"
"""Entry points ``factory(policy) -> BatchExecutor | None`` that `gymgrade grade` asks, in order, for an
executor; one that is not configured (e.g. no GYMGRADE_BROKER_URL) returns None, and the batch is local."""
EXIT_FULL_MARKS, EXIT_NOT_FULL, EXIT_ERROR = 0, 1, 2
EXIT_INTERRUPTED = 130

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
    parser.add_argument(
        "--edition",
        choices=tuple(EDITIONS),
        default=None,
        help="the edition of the lab graded (default: the configuration's `edition`, else detected from the file for check, else classic)",  # noqa: E501
    )
    parser.add_argument(
        "--config",
        type=Path,
        default=None,
        metavar="PATH",
        help="assignment configuration TOML (default: the bundled one)",
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
        "--assignment-title", default="OpenGym AI lab", help="the assignment's title in gradebooks"
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

    from grader.similarity.command import add_similarity_command

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
    """Resolve `--edition`, the configuration's edition or detection into the configuration; say which."""
    if args.command not in ("check", "grade", "gradescope-bundle"):
        return
    from grader.editions.choice import choose_edition

    if args.command == "grade" and args.edition is None and args.config is None:
        args.detect_editions = True  # per submission, once the class's files are known (run_grade)
        return
    submission = args.file if args.command == "check" and args.file.is_file() else None
    choice = choose_edition(args.edition, args.config, submission)
    args.config = choice.config
    print(choice.line, file=sys.stderr, flush=True)


def _interrupt(signum: int, _frame: object) -> None:
    raise KeyboardInterrupt(signal.Signals(signum).name)


def run_doctor(args: argparse.Namespace) -> int:
    """`gymgrade doctor`: what the sandbox is made of here; exit 0 only when it is ready to grade."""
    from grader.config import load_config
    from grader.doctor import diagnose, render

    diagnosis = diagnose(load_config(args.config).sandbox.student_modules)
    print(render(diagnosis))
    return 0 if diagnosis.healthy else EXIT_ERROR


def run_check(args: argparse.Namespace) -> int:
    """`gymgrade check`: grade one file with live progress, summarise, exit 0 only at full marks."""
    from grader.grading import grade_submission
    from grader.plan import GradingPlan

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


def choose_seed(given: int | None, out_dir: Path) -> int:
    """The batch's grading seed, announced on stderr: ``--seed``, else the one an earlier (interrupted)
    batch recorded in ``out_dir``, so that re-running the same command resumes it, else a fresh held-out
    seed."""
    from grader.batch import recorded_seed

    recorded = recorded_seed(out_dir) if given is None else None
    if given is not None:
        seed, origin = given, "given"
    elif recorded is not None:
        seed, origin = recorded, f"recorded in {out_dir / 'grades.csv'}; pass --seed for another"
    else:
        seed, origin = held_out_seed(), "held out, drawn at random"
    print(
        f"Grading seed {seed} ({origin}; regrade identically with --seed {seed})", file=sys.stderr, flush=True
    )
    return seed


def run_gradescope_bundle(args: argparse.Namespace) -> int:
    """`gymgrade gradescope-bundle`: write the autograder zip to upload to Gradescope."""
    from grader.config import load_config
    from grader.gradescope import bundle

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
    from grader.gradescope import default_root, run_autograder
    from grader.gradescope_upload import UploadSeed, seed_for_upload

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
    from grader.gradescope import regrade_upload, upload_seed_of

    upload = upload_seed_of(args.bundle, args.metadata)
    print(f"Grading seed {upload.seed} (upload {', '.join(upload.identity)})")
    if args.submission is None:
        return 0
    graded = regrade_upload(args.bundle, args.metadata, args.submission, args.out, workers=args.workers)
    print(f"Regraded {args.submission} on seed {upload.seed} into {args.out}: score {graded.score:g}")
    return 0


def run_grade(args: argparse.Namespace) -> int:
    """`gymgrade grade`: recognise the class download, grade each student's file not yet graded in --out
    (reports named by identity), keep each report and the gradebooks as they are done."""
    from grader.classroom import GradedFileRule, read_all, submissions_of_all
    from grader.classroom.errors import GradebookError
    from grader.classroom.gradebooks import Assignment
    from grader.classroom.kept import chosen_submissions
    from grader.classroom.output import ClassGradebook
    from grader.classroom.roster import read_roster
    from grader.plan import GradingPlan

    roster = read_roster(args.roster) if args.roster is not None else None
    assignment = Assignment(title=args.assignment_title, lms_id=args.assignment_id)
    if "canvas" in args.gradebook and not assignment.lms_id:
        raise GradebookError(
            "--gradebook canvas needs --assignment-id ID (the number in the assignment's Canvas URL .../assignments/ID), so Canvas puts the scores in that assignment's column"  # noqa: E501
        )
    with tempfile.TemporaryDirectory(prefix="gymgrade-class-") as scratch:
        # Every enabled problem, not just --only's: the graded file must not change with --only.
        functions = GradingPlan.load(args.config, None).problems
        # Read once, within one budget for every target; files are grouped again without reading anything.
        reads = read_all(args.targets, layout=args.layout, sections=args.sections, scratch=Path(scratch))
        download = submissions_of_all(reads, rule=GradedFileRule(functions=functions), due=args.due)
        if getattr(args, "detect_editions", False):
            asked = _detect_class_edition(args, download)
            if asked is None:
                return EXIT_ERROR
            if asked != functions:  # the class's edition asks other functions: choose each file by them
                download = submissions_of_all(reads, rule=GradedFileRule(functions=asked), due=args.due)
        plan = GradingPlan.load(args.config, args.only)
        print(class_summary(download), file=sys.stderr, flush=True)
        graded = [submission for submission in download.submissions if submission.graded_file is not None]
        if not download.submissions and roster is None:
            print("gymgrade grade: no submissions found in the given targets", file=sys.stderr)
            return EXIT_ERROR
        identities = {
            submission.graded_file.path: submission.identity
            for submission in graded
            if submission.graded_file
        }
        if args.html is not None:
            clash = class_page_clash(args.html, list(identities.values()), args.out)
            if clash is not None:
                print(f"gymgrade grade: {clash}", file=sys.stderr)
                return EXIT_ERROR
        if args.reference and not args.similarity:
            print(
                "gymgrade grade: --reference is used by the similarity check; add --similarity (or leave out --reference)",  # noqa: E501
                file=sys.stderr,
            )
            return EXIT_ERROR
        if args.similarity:
            clash = similarity_clash(list(identities.values()), args.out, args.html)
            if clash is not None:
                print(f"gymgrade grade: {clash}", file=sys.stderr)
                return EXIT_ERROR
        instructor = _instructor_data(args, download, roster, plan)
        regrade = None
        if args.only_students is not None:
            chosen = chosen_submissions(download, args.only_students)
            regrade = {path for path, identity in identities.items() if identity in chosen}
        gradebook = ClassGradebook(
            download,
            identities,
            plan.problems,
            roster,
            args.gradebook,
            assignment,
            decisions=instructor.decisions,
        )
        code = _grade_class(args, list(identities), identities, gradebook, regrade, instructor)
        if args.similarity and code != EXIT_INTERRUPTED:
            return _similarity_beside_grading(args, download) or code
        return code


def _instructor_data(
    args: argparse.Namespace, download: ClassDownload, roster: Roster | None, plan: GradingPlan
) -> InstructorData:
    """The instructor's overrides, late policy and given times for this class (kept in --out from earlier
    runs unless given again), each line about them printed."""
    from grader.class_report.text import terminal_line
    from grader.classroom.gradebooks import class_rows
    from grader.classroom.kept import load_instructor_data

    students = sorted({row.member.identity for row in class_rows(download, {}, roster)})
    data = load_instructor_data(
        out_dir=args.out,
        config=args.config,
        overrides=args.overrides,
        submitted_at=args.submitted_at,
        students=students,
        maxima=plan.points,
    )
    for line in data.lines:
        print(terminal_line(line), file=sys.stderr, flush=True)
    return data


def _detect_class_edition(args: argparse.Namespace, download: ClassDownload) -> tuple[str, ...] | None:
    """Detect each submission's edition and grade the class as the edition every file showing one asks the
    problems of (into ``args.config``), print which and why; return the functions of its enabled problems.
    None (after saying which editions were found and whose files are behind each) when the files disagree:
    the instructor names the assignment's edition, a majority of files never does."""
    from grader.class_report.text import terminal_line
    from grader.editions.per_submission import class_editions
    from grader.plan import GradingPlan

    files = {
        submission.identity: submission.graded_file.path
        for submission in download.submissions
        if submission.graded_file is not None
    }
    editions = class_editions(files)
    if editions.disagreement is not None:
        for line in editions.lines()[1:]:  # each file's edition and why
            print(terminal_line(line), file=sys.stderr, flush=True)
        print(terminal_line(f"gymgrade grade: {editions.disagreement}"), file=sys.stderr, flush=True)
        return None
    for line in editions.lines():
        print(terminal_line(line), file=sys.stderr, flush=True)
    args.config = editions.choice.config
    return GradingPlan.load(args.config, None).problems


def similarity_clash(identities: Sequence[str], out_dir: Path, page: Path | None) -> str | None:
    """Why `gymgrade grade --similarity` would overwrite a student's report or the --html class page (or its
    JSON summary) with one of its own files, or None."""
    from grader.batch import identity_stem
    from grader.similarity.command import CSV_FILE, HTML_FILE, JSON_FILE

    if page is not None:
        own = {(out_dir / name).resolve() for name in (CSV_FILE, HTML_FILE, JSON_FILE)}
        if {page.resolve(), page.with_suffix(".json").resolve()} & own:
            return (
                f"--similarity writes {HTML_FILE} and {JSON_FILE} into --out, and --html {page} (or its JSON summary) is one of them; "  # noqa: E501
                "name the class page e.g. class.html"
            )
    stem = JSON_FILE.removesuffix(".json")
    clashing = [identity for identity in identities if identity_stem(identity) == stem]
    if not clashing:
        return None
    return (
        f"--similarity writes {JSON_FILE} into --out, but student {clashing[0]!r}'s report has that name; "
        "leave out --similarity and run `gymgrade similarity` with another --out after grading"
    )


def _similarity_beside_grading(args: argparse.Namespace, download: ClassDownload) -> int:
    """The similarity check of a graded batch, written into --out with the batch's reports as behaviour
    evidence. It reads only the download and the reports: grades.csv and the reports are left as they are.

    Returns:
        0, or EXIT_ERROR when the check could not run (the grades are written either way).
    """
    from grader.similarity.cache import IndexCache, default_cache_dir
    from grader.similarity.command import summarise, write_similarity
    from grader.similarity.sources import sources_of

    try:
        report = write_similarity(
            sources_of(download),
            args.out,
            args.reference,
            cache=IndexCache(default_cache_dir()),
            reports=args.out,
        )
    except (GraderError, ValueError, OSError) as error:
        print(
            f"gymgrade grade: the similarity check could not run ({error}); the grades in {args.out} are written and unaffected; "  # noqa: E501
            "run `gymgrade similarity` on the download to retry it",
            file=sys.stderr,
        )
        return EXIT_ERROR
    summarise(report, args.out, sys.stderr)
    return 0


def class_summary(download: ClassDownload) -> str:
    """What was found: the layout, which file is graded for whom and why, what was refused or unattributed."""
    from grader.class_report.text import terminal_line as shown  # every name here is the student's choice
    from grader.classroom import LAYOUTS

    title = LAYOUTS[download.layout].title if download.layout in LAYOUTS else download.layout
    lines = [f"Found {len(download.submissions)} submissions ({title}):"]
    for submission in download.submissions:
        graded = submission.graded_file.relative if submission.graded_file else "nothing graded"
        late = " [late]" if submission.late else ""
        lines.append(f"  {shown(submission.display_name)}{late}: {shown(graded)} ({shown(submission.why)})")
    for skipped in download.refused[:MAX_SKIPPED_SHOWN]:
        lines.append(f"  refused {shown(skipped.where)}: {shown(skipped.reason)}")
    if len(download.refused) > MAX_SKIPPED_SHOWN:
        lines.append(f"  ... and {len(download.refused) - MAX_SKIPPED_SHOWN:,} more refused")
    for skipped in download.unattributed[:MAX_SKIPPED_SHOWN]:
        lines.append(f"  not attributed {shown(skipped.where)}: {shown(skipped.reason)}")
    if len(download.unattributed) > MAX_SKIPPED_SHOWN:
        lines.append(f"  ... and {len(download.unattributed) - MAX_SKIPPED_SHOWN:,} more not attributed")
    return "\n".join(lines)


MAX_SKIPPED_SHOWN = 200
"""Refused (and unattributed) files the summary names; the rest are counted (a zip of 80,000 links is one
student's, and a reason in their row)."""


def _grade_class(
    args: argparse.Namespace,
    paths: list[Path],
    identities: dict[Path, str],
    gradebook: ClassGradebook,
    regrade: set[Path] | None = None,
    instructor: InstructorData | None = None,
) -> int:
    from grader.batch import BatchOutcome, grade_many
    from grader.class_report.text import IDENTITY_SHOWN_CHARS, display_identity
    from grader.classroom.kept import regrade_refusal
    from grader.plan import GradingPlan

    policy = IsolationPolicy.ALLOW_FALLBACK if args.allow_weak_isolation else IsolationPolicy.REQUIRE_FULL
    executor = find_executor(policy)
    bar = ProgressBar(total=0)

    def planned(outcome: BatchOutcome) -> None:
        bar.total = max(len(outcome.graded) * len(problems_of(args)), 1)
        if outcome.reused:
            print(
                f"Resuming in {args.out}: {len(outcome.reused)} of {len(paths)} submissions are already graded there (same file, seed and configuration); "  # noqa: E501
                f"grading {len(outcome.graded)}.",
                file=sys.stderr,
            )
        if executor is not None:
            print(f"Grading on {executor}.", file=sys.stderr)

    shown = {path: display_identity(identity, IDENTITY_SHOWN_CHARS) for path, identity in identities.items()}

    def advance(path: Path, result: ProblemResult) -> None:
        bar.advance(f"{shown[path]}: {result.id} {result.status}")

    seed = choose_seed(args.seed, args.out)
    if regrade is not None:
        plan = GradingPlan.load(args.config, args.only)
        others = [identity for path, identity in identities.items() if path not in regrade]
        refusal = regrade_refusal(
            args.out, others, seed=seed, config_sha256=plan.config_sha256, problems=plan.problems
        )
        if refusal is not None:
            print(f"gymgrade grade: {refusal}", file=sys.stderr)
            return EXIT_ERROR
        print(
            f"Regrading {len(regrade)} submissions; every other report in {args.out} is kept as it is.",
            file=sys.stderr,
        )
    if instructor is not None:
        instructor.write_kept(args.out)
    try:
        outcome = grade_many(
            paths,
            args.out,
            seed=seed,
            workers=args.workers,
            only=args.only,
            policy=policy,
            config=args.config,
            on_result=advance,
            executor=executor,
            on_plan=planned,
            names=identities,
            gradebook=gradebook,
            regrade=regrade,
        )
    except BatchInterrupted as interruption:
        print(
            "\ngymgrade grade: interrupted. "
            f"{interruption.finished} of {interruption.total} submissions are graded in {args.out} (their reports and grades.csv are kept). "  # noqa: E501
            f"Run the same command again (same --out, --seed, --only and --config) to grade the other {interruption.total - interruption.finished}; "  # noqa: E501
            "the finished ones are skipped.",
            file=sys.stderr,
        )
        return EXIT_INTERRUPTED
    if args.html is not None and gradebook.rows is not None:
        write_class_page(args.html, gradebook, args.out)
    errors = sum(1 for report in outcome.reports if report.grader_errors)
    written = ", ".join(["grades.csv", *(f"{name}.csv" for name in args.gradebook)])
    if "canvas" in args.gradebook and gradebook.rows is not None:
        from grader.classroom.gradebooks import canvas_user_id

        unmatched = [
            display_identity(row.member.identity, IDENTITY_SHOWN_CHARS)
            for row in gradebook.rows
            if not canvas_user_id(row)
        ]
        if unmatched:
            print(
                f"canvas.csv leaves out {len(unmatched)} students without a Canvas user id ({', '.join(unmatched[:5])}{', ...' if len(unmatched) > 5 else ''}): "  # noqa: E501
                "pass --roster with a Canvas gradebook export (its ID column) to match them.",
                file=sys.stderr,
            )
    print(
        f"Graded {len(outcome.graded)} submissions"
        + (f" (reused {len(outcome.reused)} earlier reports)" if outcome.reused else "")
        + f" into {args.out} ({written}) with seed {seed}"
        + (f"; {errors} with grader errors (run again to retry them)" if errors else ""),
        file=sys.stderr,
    )
    return EXIT_ERROR if errors else 0


def class_page_clash(page: Path, identities: Sequence[str], out_dir: Path) -> str | None:
    """Why `gymgrade grade --html` would overwrite one of the batch's files (a student's report), or None."""
    from grader.batch import identity_stem
    from grader.class_report.from_batch import page_clash_of_reports
    from grader.class_report.text import IDENTITY_SHOWN_CHARS, display_identity

    reports = {
        out_dir / f"{identity_stem(identity)}.json": "student "
        + display_identity(identity, IDENTITY_SHOWN_CHARS)
        for identity in identities
    }
    return page_clash_of_reports(page, reports, out_dir)


def write_class_page(page: Path, gradebook: ClassGradebook, out_dir: Path) -> None:
    """`gymgrade grade --html`: the class report of the batch, and its JSON summary beside it."""
    from grader.class_report import write_class_report
    from grader.class_report.from_batch import entries_from_rows

    summary = write_class_report(page, entries_from_rows(gradebook.rows or [], out_dir, page))
    print(f"Wrote the class report {page} and its summary {summary}.", file=sys.stderr)


def problems_of(args: argparse.Namespace) -> tuple[str, ...]:
    """The problems a `gymgrade grade` run covers."""
    from grader.plan import GradingPlan

    return GradingPlan.load(args.config, args.only).problems


def find_executor(policy: IsolationPolicy) -> BatchExecutor | None:
    """The first configured executor of the ``gymgrade.executors`` entry points, or None (local).

    Raises:
        grader.errors.GraderError: An executor is configured but cannot be used (its message says why).
    """
    for entry_point in entry_points(group=EXECUTOR_GROUP):
        try:
            factory = entry_point.load()
        except Exception as error:
            raise ExecutorUnavailable(
                f"the batch executor {entry_point.name!r} could not be loaded ({type(error).__name__}: "
                f"{error}); reinstall the package providing it (pip install -e '.[distributed]')"
            ) from error
        executor: BatchExecutor | None = factory(policy)
        if executor is not None:
            return executor
    return None


if __name__ == "__main__":
    sys.exit(main())
