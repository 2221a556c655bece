"""Clusters are the connected components of the flagged pairs."""

from __future__ import annotations

from grader.classroom.similarity.clusters import clusters


def test_a_ring_is_one_cluster_and_separate_pairs_stay_apart() -> None:
    pairs = [("c", "a"), ("b", "c"), ("x", "y"), ("a", "b"), ("ref/p.py", "z")]
    assert clusters(pairs) == [["a", "b", "c"], ["ref/p.py", "z"], ["x", "y"]]


def test_a_chain_through_a_reference_joins_its_students() -> None:
    assert clusters([("s1", "ref/a.py"), ("s2", "ref/a.py")]) == [["ref/a.py", "s1", "s2"]]
    assert clusters([]) == []
