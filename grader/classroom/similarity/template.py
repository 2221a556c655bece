"""The lab's template, removed exactly before comparing: what every student was handed is nobody's work.

A function whose normalised tree equals one of the template's (its provided ``find_qvalues`` or ``qlearn``,
or a problem's untouched stub) is dropped whole; the template's fingerprints and comments are dropped
from every document too, so a provided function a student edited still shares nothing through its
unchanged lines (MOSS's base file). The bundled templates are in ``templates/``: the classic
``opengym.py`` as handed out, gymgrade's restatement of the gymnasium editions (EDITIONS.md), and the second
lab's templates of every edition (``rl2_<edition>.py.txt``, the packs' ``submissions/rl2/templates/`` as
handed out; a test holds them equal), so a class of either lab is compared beyond what it was handed.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from grader.classroom.similarity.errors import TemplateError
from grader.classroom.similarity.normalise import normalise
from grader.classroom.similarity.winnow import fingerprints

TEMPLATES = Path(__file__).with_name("templates")
BUNDLED = tuple(sorted(TEMPLATES.glob("*.py.txt")))


@dataclass(frozen=True)
class Template:
    """What the comparison removes.

    Attributes:
        shapes: Shape digests of the template's functions.
        fingerprints: The template's fingerprint hashes.
        remarks: The template's comment and docstring keys.
        names: The template's function names (for the report).
    """

    shapes: frozenset[str]
    fingerprints: frozenset[int]
    remarks: frozenset[str]
    names: tuple[str, ...]


def load_template(paths: tuple[Path, ...] = BUNDLED) -> Template:
    """Read template files (the bundled ones by default) into what the comparison removes.

    Raises:
        TemplateError: When a template file is unreadable or not Python.
    """
    shapes: set[str] = set()
    hashes: set[int] = set()
    remarks: set[str] = set()
    names: list[str] = []
    for path in paths:
        try:
            normalised = normalise(path.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, SyntaxError) as error:
            raise TemplateError(
                f"expected the template {path} to be a readable Python file, found {type(error).__name__}: {error}; "  # noqa: E501
                "pass the .py file handed out to students"
            ) from None
        shapes.update(unit.shape for unit in normalised.units)
        hashes.update(fingerprint.hash for fingerprint in fingerprints(normalised.units))
        remarks.update(remark.key for remark in normalised.remarks)
        names.extend(unit.name for unit in normalised.units if unit.name not in names)
    return Template(frozenset(shapes), frozenset(hashes), frozenset(remarks), tuple(names))
