"""The template is removed exactly: untouched provided functions and stubs go, edited ones stay."""

from __future__ import annotations

from pathlib import Path

import pytest

from grader.classroom.similarity.document import build_document, index_text
from grader.classroom.similarity.errors import TemplateError
from grader.classroom.similarity.template import TEMPLATES, load_template

ROOT = Path(__file__).resolve().parents[4]
TEMPLATE = (ROOT / "submissions" / "template.py").read_text(encoding="utf-8")


def test_the_bundled_classic_template_is_the_repositorys_template() -> None:
    assert (TEMPLATES / "opengym_classic.py.txt").read_text(encoding="utf-8") == TEMPLATE


def test_every_function_of_every_edition_is_known() -> None:
    names = set(load_template().names)
    assert {"find_qvalues", "qlearn", "epsilon_decay", "sarsa0", "compare", "taxi"} <= names


def _document(source: str):  # type: ignore[no-untyped-def]
    return build_document("s", False, [(Path("s.py"), index_text(source, "s.py"))], load_template())


def test_the_template_as_handed_out_leaves_nothing_to_compare() -> None:
    assert _document(TEMPLATE).fingerprints == {}


def test_a_provided_function_with_its_comments_and_docstring_changed_is_still_the_templates() -> None:
    edited = TEMPLATE.replace("# Make Q-table", "# the table of q values").replace(
        "Use the Q-learning", "Q-learning"
    )
    assert _document(edited).fingerprints == {}


def test_an_edited_provided_function_is_compared_without_its_unchanged_lines() -> None:
    edited = TEMPLATE.replace(
        "next_max = np.max(q_table[next_state])", "next_max = max(q_table[next_state]) * 0.5"
    )
    document = _document(edited)
    assert document.fingerprints
    assert all(first >= 40 for _, first, _ in document.fingerprints.values())


def test_an_unreadable_template_says_what_to_pass(tmp_path: Path) -> None:
    bad = tmp_path / "template.py"
    bad.write_text("def f(:\n", encoding="utf-8")
    with pytest.raises(
        TemplateError, match=r"expected the template .* to be a readable Python file, found SyntaxError"
    ):
        load_template((bad,))


RL2_EDITIONS = ("v2018", "v2019", "v2023", "v2024", "v2026")


@pytest.mark.parametrize("edition", RL2_EDITIONS)
def test_each_second_lab_template_is_bundled_as_handed_out_and_leaves_nothing(edition: str) -> None:
    from grader.lab.editions import EDITIONS

    handed_out = EDITIONS[edition].template.read_text(encoding="utf-8")
    assert (TEMPLATES / f"rl2_{edition}.py.txt").read_text(encoding="utf-8") == handed_out
    assert _document(handed_out).fingerprints == {}


def test_a_second_lab_function_a_student_wrote_is_still_compared() -> None:
    template = (TEMPLATES / "rl2_v2026.py.txt").read_text(encoding="utf-8")
    written = (ROOT / "submissions" / "rl2" / "policy_function_iteration.py").read_text(encoding="utf-8")
    assert {"value_iteration", "policy_improvement", "iter_policy_eval"} <= set(load_template().names)
    assert _document(written).fingerprints, "the student's own value_iteration is theirs, not the template's"
    assert _document(template).fingerprints == {}
