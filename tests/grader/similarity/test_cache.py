"""References are indexed once: the cache is keyed by their bytes and never trusted when damaged."""

from __future__ import annotations

from pathlib import Path

from grader.similarity.cache import IndexCache, cache_key
from grader.similarity.run import run_similarity

CORPUS = Path(__file__).resolve().parents[3] / "submissions" / "similarity"
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
