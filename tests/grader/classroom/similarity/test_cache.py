"""References are indexed once: the cache is keyed by their bytes and never trusted when damaged, planted
or writable by anyone but its owner."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from grader.classroom.similarity import cache as cache_module
from grader.classroom.similarity.cache import CacheEntry, IndexCache, cache_key, text_digest
from grader.classroom.similarity.document import IndexedFile, index_text
from grader.classroom.similarity.report import SimilarityReport
from grader.classroom.similarity.run import run_similarity

CORPUS = Path(__file__).resolve().parents[4] / "submissions" / "similarity"
REFERENCE = CORPUS / "references" / "public_2021"


def test_a_second_run_reads_every_reference_from_the_cache_with_the_same_report(tmp_path: Path) -> None:
    cache = IndexCache(tmp_path / "cache")
    first = run_similarity(CORPUS / "class", [REFERENCE], cache=cache).report
    assert (cache.hits, cache.misses) == (0, 1)
    again = IndexCache(tmp_path / "cache")
    second = run_similarity(CORPUS / "class", [REFERENCE], cache=again).report
    assert (again.hits, again.misses) == (1, 0)
    assert second == first


def test_the_key_is_the_bytes_so_an_edited_reference_is_indexed_again(tmp_path: Path) -> None:
    text = (REFERENCE / "opengym_solution.py").read_text(encoding="utf-8")
    assert cache_key(text) != cache_key(text + "\n# edited\n")
    assert cache_key(text) == cache_key(str(text))


def test_a_damaged_entry_is_indexed_again_and_rewritten(tmp_path: Path) -> None:
    cache = IndexCache(tmp_path)
    run_similarity(CORPUS / "class", [REFERENCE], cache=cache)
    (entry,) = tmp_path.glob("*.json")
    entry.write_text('{"fingerprints": "not a list"', encoding="utf-8")
    again = IndexCache(tmp_path)
    report = run_similarity(CORPUS / "class", [REFERENCE], cache=again).report
    assert (again.hits, again.misses) == (0, 1)
    assert any(pair.b_is_reference for pair in report.pairs)
    assert (
        IndexCache(tmp_path).get((REFERENCE / "opengym_solution.py").read_text(encoding="utf-8")) is not None
    )


# Hostile caches: the entries are files anyone with access to the folder could have written.


SOLUTION = (REFERENCE / "opengym_solution.py").read_text(encoding="utf-8")


@pytest.fixture(scope="module")
def without_cache() -> SimilarityReport:
    return run_similarity(CORPUS / "class", [REFERENCE]).report


def _entry_path(folder: Path) -> Path:
    return folder / f"{cache_key(SOLUTION)}.json"


def _plant(folder: Path, entry: CacheEntry | str) -> Path:
    folder.mkdir(mode=0o700, exist_ok=True)
    path = _entry_path(folder)
    path.write_text(entry if isinstance(entry, str) else entry.model_dump_json(), encoding="utf-8")
    return path


def _copies_of_the_reference(report: SimilarityReport) -> list[tuple[str, str]]:
    return sorted((pair.a, pair.b) for pair in report.pairs if pair.b_is_reference)


EMPTY = IndexedFile(lines=SOLUTION.count("\n"))
TRUE = index_text(SOLUTION, "opengym_solution.py")


@pytest.mark.parametrize(
    ("planted", "why"),
    [
        (
            CacheEntry(sha256=text_digest(SOLUTION), index=TRUE.model_copy(update={"unit_names": ["f"]})),
            "unit shapes but 1 unit names",
        ),
        (
            CacheEntry(
                sha256=text_digest(SOLUTION), index=TRUE.model_copy(update={"fingerprints": [(1, 999, 1, 2)]})
            ),
            "a fingerprint of unit 999",
        ),
        (CacheEntry(sha256=text_digest("x = 1\n"), index=EMPTY), "it is the index of another text"),
        (json.dumps(EMPTY.model_dump()), "not a cache entry"),
    ],
    ids=["mismatched-lists", "unit-out-of-range", "another-texts-entry", "an-index-without-its-digest"],
)
def test_a_planted_or_inconsistent_entry_is_indexed_again_with_a_note(
    tmp_path: Path, without_cache: SimilarityReport, planted: CacheEntry | str, why: str
) -> None:
    _plant(tmp_path / "cache", planted)
    cache = IndexCache(tmp_path / "cache")
    report = run_similarity(CORPUS / "class", [REFERENCE], cache=cache).report
    assert (cache.hits, cache.misses) == (0, 1)
    assert _copies_of_the_reference(report) == _copies_of_the_reference(without_cache) != []
    (note,) = [note for note in report.notes if "cache entry" in note]
    assert note.startswith("the cache entry of public_2021/opengym_solution.py was not used (")
    assert why in note and note.endswith("; it was indexed again")
    assert IndexCache(tmp_path / "cache").get(SOLUTION) == TRUE, "the entry was rewritten"


@pytest.mark.expected_skip("ownership is a POSIX notion")
@pytest.mark.skipif(not hasattr(os, "geteuid"), reason="ownership is a POSIX notion")
@pytest.mark.parametrize("shared", ["folder", "entry"], ids=["folder-open-to-all", "entry-open-to-all"])
def test_a_cache_others_can_write_is_not_trusted(
    tmp_path: Path, without_cache: SimilarityReport, shared: str
) -> None:
    """Hostile: an entry forged with the right digest hides the copy; only the owner may have written it."""
    entry = _plant(tmp_path / "cache", CacheEntry(sha256=text_digest(SOLUTION), index=EMPTY))
    (tmp_path / "cache" if shared == "folder" else entry).chmod(0o777 if shared == "folder" else 0o666)
    cache = IndexCache(tmp_path / "cache")
    report = run_similarity(CORPUS / "class", [REFERENCE], cache=cache).report
    assert _copies_of_the_reference(report) == _copies_of_the_reference(without_cache) != []
    expected = (
        f"the similarity cache {tmp_path / 'cache'} was not used "
        "(the folder is writable by other users (mode 777))"
        if shared == "folder"
        else "the cache entry of public_2021/opengym_solution.py was not used (the file is writable by other users (mode 666))"  # noqa: E501
    )
    assert any(note.startswith(expected) for note in report.notes), report.notes


def test_links_planted_in_the_cache_are_never_read_or_written_through(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Hostile: a link at the entry's name and one at its (predicted) temporary name, pointing outside."""
    folder = tmp_path / "cache"
    folder.mkdir(mode=0o700)
    outside = tmp_path / "precious.txt"
    outside.write_text("keep me\n")
    forged = tmp_path / "forged.json"
    forged.write_text(CacheEntry(sha256=text_digest(SOLUTION), index=EMPTY).model_dump_json())
    _entry_path(folder).symlink_to(forged)
    monkeypatch.setattr(cache_module.secrets, "token_hex", lambda _: "predicted")
    (folder / f".{_entry_path(folder).name}.predicted.tmp").symlink_to(outside)
    cache = IndexCache(folder)
    assert cache.get(SOLUTION, "public") is None
    assert cache.notes == ["the cache entry of public was not used (a symbolic link); it was indexed again"]
    cache.put(SOLUTION, TRUE)
    assert outside.read_text() == "keep me\n", "O_EXCL | O_NOFOLLOW: the planted temporary name is refused"
    monkeypatch.undo()
    cache.put(SOLUTION, TRUE)
    assert not _entry_path(folder).is_symlink() and outside.read_text() == "keep me\n"
    assert forged.read_text().startswith('{"sha256"'), "the rename replaced the link, not what it points to"
    assert IndexCache(folder).get(SOLUTION) == TRUE
