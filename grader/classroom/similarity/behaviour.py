"""Shared wrong behaviour: two submissions that fail a problem with the same numbers, from the same starts.

gymgrade replays every episode from the grading seed, so two programs that make the same wrong decisions
return the same wrong measurements on the same seed. Only failed results count (identical correct
behaviour is what every right answer looks like), and only wrong results at most two students share (a
mistake half the class makes, such as a percentage instead of a fraction, is a common misreading).
"""

from __future__ import annotations

import hashlib
import json
from collections import Counter
from collections.abc import Mapping
from pathlib import Path

from pydantic import ValidationError

from grader.classroom.similarity.frequency import RARE_MAXIMUM
from grader.grading.batch import identity_stem
from grader.report import Report

WrongResults = dict[str, str]
"""Key of one wrong result (problem, seed, measurements) -> how the reader sees it."""


def wrong_results(report: Report) -> WrongResults:
    """The failed problems of one grading report, keyed so that identical wrong results compare equal."""
    found: WrongResults = {}
    for result in report.problems:
        if result.status != "failed" or not result.measurements:
            continue
        measured = json.dumps(result.measurements, sort_keys=True, default=str)
        actions = result.replay.actions if result.replay is not None else []
        digest = hashlib.blake2b(f"{measured}|{actions}".encode(), digest_size=12).hexdigest()
        found[f"{result.id}|{report.seed}|{digest}"] = (
            f"the same wrong result on {result.title} from the same seed ({report.seed}): {measured[:120]}"
        )
    return found


def load_wrong_results(reports_dir: Path, identities: list[str]) -> tuple[dict[str, WrongResults], list[str]]:
    """Read each student's grading report from ``reports_dir``, named as `gymgrade grade` names it
    (``grader.grading.batch.identity_stem``: the identity, with unsafe characters percent-encoded).

    Returns:
        The wrong results by identity, and a note per report that could not be read.
    """
    found: dict[str, WrongResults] = {}
    notes: list[str] = []
    for identity in identities:
        path = reports_dir / f"{identity_stem(identity)}.json"
        if not path.is_file():
            continue
        try:
            found[identity] = wrong_results(Report.model_validate_json(path.read_bytes()))
        except (OSError, ValidationError, ValueError) as error:
            notes.append(
                f"{path.name}: not a gymgrade report ({type(error).__name__}); its behaviour is not compared."
            )
    return found, notes


def shared_wrong_results(a: WrongResults, b: WrongResults, rare: frozenset[str]) -> list[str]:
    """What two students got wrong identically, among wrong results few students share."""
    return [a[key] for key in sorted(a.keys() & b.keys() & rare)]


def rare_wrong_results(all_results: Mapping[str, WrongResults]) -> frozenset[str]:
    """The wrong-result keys held by at most ``RARE_MAXIMUM`` students."""
    counts = Counter(key for results in all_results.values() for key in results)
    return frozenset(key for key, count in counts.items() if count <= RARE_MAXIMUM)
