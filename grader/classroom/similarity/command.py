"""`gymgrade similarity CLASS_DIR [--reference DIR ...] --out OUT`: parse, compare, write the outputs."""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from grader.classroom.similarity.cache import IndexCache
    from grader.classroom.similarity.report import SimilarityReport
    from grader.classroom.similarity.sources import ClassSources
    from grader.classroom.similarity.template import Template

CSV_FILE = "similarity.csv"
HTML_FILE = "similarity.html"
JSON_FILE = "similarity.json"


def add_similarity_command(subparsers: Any) -> None:
    """Register the subcommand on `gymgrade`'s subparsers."""
    from grader.classroom.layouts import add_layout_option

    parser = subparsers.add_parser(
        "similarity",
        help="rank pairs of submissions whose code is alike beyond the template (changes no grade)",
    )
    parser.add_argument(
        "class_dir",
        type=Path,
        metavar="CLASS_DIR",
        help="the class download as `gymgrade grade` takes it (folder or zip, any layout)",
    )
    add_layout_option(parser)
    parser.add_argument(
        "--reference",
        type=Path,
        action="append",
        default=[],
        metavar="DIR",
        help="a folder of known solutions (earlier years, public repositories); may be repeated",
    )
    parser.add_argument(
        "--out", type=Path, required=True, metavar="DIR", help="where similarity.csv/.html go"
    )
    parser.add_argument(
        "--template",
        type=Path,
        action="append",
        default=None,
        metavar="FILE",
        help="the file handed out to students (default: every edition's template); may be repeated",
    )
    parser.add_argument(
        "--reports",
        type=Path,
        default=None,
        metavar="DIR",
        help="gymgrade grading reports (<student>.json): identical wrong results count as evidence",
    )
    parser.add_argument(
        "--cache",
        type=Path,
        default=None,
        metavar="DIR",
        help="where reference indexes are kept (default: ~/.cache/gymgrade/similarity)",
    )
    parser.add_argument("--no-cache", action="store_true", help="index the references again and keep nothing")
    parser.set_defaults(handler=run_similarity_command)


def run_similarity_command(args: argparse.Namespace) -> int:
    """Run the comparison and write ``similarity.csv``, ``similarity.html`` and ``similarity.json``."""
    from grader.classroom.similarity.cache import IndexCache, default_cache_dir
    from grader.classroom.similarity.sources import submissions_from
    from grader.classroom.similarity.template import BUNDLED, load_template

    template = load_template(tuple(args.template) if args.template else BUNDLED)
    cache = None if args.no_cache else IndexCache(args.cache or default_cache_dir())
    with tempfile.TemporaryDirectory(prefix="gymgrade-similarity-") as scratch:
        sources = submissions_from(
            args.class_dir, layout=args.layout, sections=args.sections, scratch=Path(scratch)
        )
        report = write_similarity(
            sources, args.out, args.reference, template=template, cache=cache, reports=args.reports
        )
    summarise(report, args.out, sys.stdout)
    return 0


def write_similarity(
    sources: ClassSources,
    out: Path,
    references: Sequence[Path] = (),
    *,
    template: Template | None = None,
    cache: IndexCache | None = None,
    reports: Path | None = None,
) -> SimilarityReport:
    """Compare a class's documents and write ``out/similarity.csv``, ``.html`` and ``.json``.

    The files of ``sources`` must still exist (a zip's scratch folder is removed only after this returns).

    Args:
        sources: The class's documents (``grader.classroom.similarity.sources.submissions_from`` or
        ``sources_of``). out: The folder written into. references: Folders of known solutions. template: What
        to remove (every edition's template by default). cache: Where reference indexes are kept (none: index
        every time). reports: A folder of gymgrade grading reports, named as `gymgrade grade` names them:
        identical
            wrong results count as evidence.
    """
    from grader.classroom.similarity.behaviour import WrongResults, load_wrong_results
    from grader.classroom.similarity.csv_output import render_csv
    from grader.classroom.similarity.html_output import render_html
    from grader.classroom.similarity.run import run_similarity

    behaviour: dict[str, WrongResults] | None = None
    notes: list[str] = []
    if reports is not None:
        behaviour, notes = load_wrong_results(reports, sources.identities)
    outcome = run_similarity(
        sources, references, template=template, cache=cache, behaviour=behaviour, notes=notes
    )
    report = outcome.report
    out.mkdir(parents=True, exist_ok=True)
    with (out / CSV_FILE).open("w", encoding="utf-8", newline="") as stream:
        stream.write(render_csv(report))
    (out / HTML_FILE).write_text(render_html(report, outcome.lines_of), encoding="utf-8")
    # ASCII, every other character escaped (as class.json): a bidi override in a name never reorders a
    # terminal
    document = json.dumps(report.model_dump(mode="json"), indent=2)
    (out / JSON_FILE).write_text(document + "\n", encoding="utf-8")
    return report


def summarise(report: SimilarityReport, out: Path, stream: Any) -> None:
    """Print what was compared, the notes, every file left out and what was written (each name and reason
    one inert line: ``grader.render.neutral.terminal_line``)."""
    from grader.render.neutral import IDENTITY_SHOWN_CHARS, display_identity
    from grader.render.neutral import terminal_line as shown

    print(
        f"Compared {len(report.students)} students"
        + (
            f" with each other and with {report.references} reference files"
            if report.references
            else " with each other"
        )
        + f": {len(report.pairs)} pairs flagged for reading, in {len(report.clusters)} groups"
        + (f"; {len(report.unreadable)} files left out (listed in {HTML_FILE})" if report.unreadable else "")
        + ".",
        file=stream,
    )
    for note in report.notes:
        print(f"  {shown(note)}", file=stream)
    for left_out in report.unreadable:
        who = display_identity(left_out.identity, IDENTITY_SHOWN_CHARS)
        print(f"  left out {shown(left_out.file)} ({who}): {shown(left_out.reason)}", file=stream)
    print(f"Wrote {out / CSV_FILE}, {out / HTML_FILE} and {out / JSON_FILE}.", file=stream)
