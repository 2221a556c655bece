"""The frequency filter: what a large share of the class, or of the references, contains counts for nothing.

The lab has natural short answers (``1 if obs[3] > 0 else 0``) that independent students write alike;
a fragment found in more than ``COMMON_SHARE`` of the students (or of the reference files), and in more
than ``COMMON_MINIMUM`` of them, is such an answer (MOSS's ``-m``, Dolos's frequency filter).
``COMMON_MINIMUM`` keeps a small class's ring of copiers from filtering itself out.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass

from grader.classroom.similarity.document import Document

COMMON_SHARE = 0.1
COMMON_MINIMUM = 5
RARE_MAXIMUM = 2
"""A comment or constant is evidence only when at most this many students (and references) have it."""


def common_limit(population: int) -> int:
    """How many documents of a population may contain a fragment before it counts as common."""
    return max(COMMON_MINIMUM, int(COMMON_SHARE * population))


@dataclass(frozen=True)
class Frequencies:
    """How many students and references hold each fingerprint, remark and constant.

    Attributes:
        common: Fingerprint hashes too frequent to count.
        rare_remarks: Remark keys held by few enough documents to be evidence.
        rare_constants: Constants held by few enough documents to be evidence.
        rare_typos: Misspellings held by few enough documents to be evidence.
    """

    common: frozenset[int]
    rare_remarks: frozenset[str]
    rare_constants: frozenset[str]
    rare_typos: frozenset[str]


def frequencies(documents: Iterable[Document]) -> Frequencies:
    """Count every fingerprint, remark and constant over students and references separately."""
    student_hashes: Counter[int] = Counter()
    reference_hashes: Counter[int] = Counter()
    remarks: Counter[str] = Counter()
    constants: Counter[str] = Counter()
    typos: Counter[str] = Counter()
    students = references = 0
    for document in documents:
        if document.is_reference:
            references += 1
            reference_hashes.update(document.fingerprints.keys())
        else:
            students += 1
            student_hashes.update(document.fingerprints.keys())
        remarks.update(document.remarks.keys())
        constants.update(document.constants.keys())
        typos.update(document.typos.keys())
    student_limit, reference_limit = common_limit(students), common_limit(references)
    common = {hash_ for hash_, count in student_hashes.items() if count > student_limit}
    common.update(hash_ for hash_, count in reference_hashes.items() if count > reference_limit)
    return Frequencies(
        common=frozenset(common),
        rare_remarks=frozenset(key for key, count in remarks.items() if count <= RARE_MAXIMUM),
        rare_constants=frozenset(value for value, count in constants.items() if count <= RARE_MAXIMUM),
        rare_typos=frozenset(word for word, count in typos.items() if count <= RARE_MAXIMUM),
    )
