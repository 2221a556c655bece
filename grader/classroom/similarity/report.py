"""The similarity report: ranked pairs for a person to read, their clusters, and every file left out."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field


class Fragment(BaseModel):
    """One stretch of code two documents share (lines of each document's compared text, inclusive)."""

    model_config = ConfigDict(frozen=True)

    a_first: int
    a_last: int
    b_first: int
    b_last: int

    @property
    def lines(self) -> int:
        """Length of the fragment in the first document's lines."""
        return self.a_last - self.a_first + 1


class Pair(BaseModel):
    """Two documents worth a person's reading (score or evidence passed its bar) and what they share.

    ``b`` may be a reference file; ``a`` is always a student.
    """

    a: str = Field(description="A student, as the class folder names them.")
    b: str = Field(description="Another student, or a reference file's folder/path.")
    b_is_reference: bool = False
    score: float = Field(description="Shared rare fingerprints over the smaller document's, in [0, 1].")
    shared_fingerprints: int
    shared_fragments: int
    longest_fragment_lines: int
    evidence: list[str] = Field(
        default_factory=list, description="Identical comments, constants, wrong results."
    )
    fragments: list[Fragment] = Field(default_factory=list)


class UnreadableFile(BaseModel):
    """A file left out of the comparison, and why."""

    identity: str
    file: str
    reason: str


class SimilarityReport(BaseModel):
    """Everything `gymgrade similarity` found. It ranks; it never decides and never changes a grade."""

    students: list[str] = Field(description="Every student compared (with at least one readable file).")
    references: int = Field(description="Reference files compared against.")
    pairs: list[Pair] = Field(description="Flagged pairs, highest score first.")
    clusters: list[list[str]] = Field(description="Connected groups of flagged pairs, largest first.")
    unreadable: list[UnreadableFile] = Field(default_factory=list)
    notes: list[str] = Field(default_factory=list, description="What else the reader should know.")
    template_functions: list[str] = Field(
        default_factory=list, description="Functions removed as the template's."
    )
