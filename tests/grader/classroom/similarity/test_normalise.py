"""The normalised token streams ignore what a disguise changes and keep what a program computes."""

from __future__ import annotations

import pytest

from grader.classroom.similarity.normalise import MODULE_UNIT, normalise

ORIGINAL = '''
import numpy as np

def win_rate(env, n):
    """Fraction of games won."""
    wins = 0
    for game in range(n):
        state = env.reset()
        done = False
        while not done:
            state, reward, done, info = env.step(int(state[0] <= 11))  # hit on 11 or less
        wins += reward > 0
    return wins / n
'''

DISGUISES = {
    "renamed": ORIGINAL.replace("wins", "victories")
    .replace("game", "g")
    .replace("state", "obs")
    .replace("win_rate", "rate"),
    "comments and docstring changed": ORIGINAL.replace(
        '"""Fraction of games won."""', '"""Returns the share of wins, mine."""'
    ).replace("# hit on 11 or less", "# my own comment"),
    "docstring removed": ORIGINAL.replace('    """Fraction of games won."""\n', ""),
    "dead code padded": ORIGINAL.replace(
        "    wins = 0\n",
        "    wins = 0\n    unused = 42\n    if False:\n        print('never')\n"
        "    pass\n    print('debug', n)\n",
    ).replace("    return wins / n\n", "    return wins / n\n    print('after return')\n"),
    "import alias": ORIGINAL.replace("import numpy as np", "import numpy as npy"),
    "other literal of the same kind": ORIGINAL.replace("<= 11", "<= 12"),
}


def _tokens(source: str) -> list[tuple[str, tuple[str, ...]]]:
    return [(unit.name, unit.tokens) for unit in normalise(source).units]


@pytest.mark.parametrize("disguise", list(DISGUISES), ids=list(DISGUISES))
def test_a_disguise_leaves_the_tokens_unchanged(disguise: str) -> None:
    original = [tokens for _, tokens in _tokens(ORIGINAL)]
    assert [tokens for _, tokens in _tokens(DISGUISES[disguise])] == original


def test_a_real_change_of_the_program_changes_the_tokens() -> None:
    changed = ORIGINAL.replace("wins += reward > 0", "wins += reward >= 0")
    assert _tokens(changed) != _tokens(ORIGINAL)


def test_every_function_is_a_unit_so_their_order_does_not_matter() -> None:
    first = "def a(x):\n    return x + 1\n\ndef b(y):\n    return y * 2\n"
    second = "def b(y):\n    return y * 2\n\ndef a(x):\n    return x + 1\n"
    assert sorted(_tokens(first)) == sorted(_tokens(second))
    assert [unit.shape for unit in normalise(first).units] == [
        unit.shape for unit in normalise(second).units
    ][::-1]


def test_module_code_and_methods_are_units_of_their_own() -> None:
    source = "class Agent:\n    def act(self, s):\n        return s\n\n"
    source += "TABLE = {}\nfor key in 'ab':\n    TABLE[key] = 1\n"
    assert [unit.name for unit in normalise(source).units] == ["Agent.act", MODULE_UNIT]


def test_library_names_are_kept_while_the_files_own_names_become_ids() -> None:
    tokens = normalise("def f(env):\n    return np.argmax(env.step(range(3)))\n").units[0].tokens
    assert {".argmax", "np", ".step", "range"} <= set(tokens)
    assert "env" not in tokens and "ID" in tokens


def test_comments_strings_and_constants_are_kept_as_evidence() -> None:
    source = "x = 0.0173  # we recieve the reward here\ns = 'a message printed by the student'\n"
    normalised = normalise(source)
    assert [remark.key for remark in normalised.remarks] == [
        "we recieve the reward here",
        "a message printed by the student",
    ]
    assert ("0.0173", 1) in normalised.constants


@pytest.mark.parametrize(
    "source",
    ["def broken(:\n    pass\n", "x = (" * 300 + ")" * 300],
    ids=["syntax error", "nesting too deep for the parser"],
)
def test_what_the_parser_rejects_is_a_syntax_error(source: str) -> None:
    with pytest.raises(SyntaxError):
        normalise(source)
