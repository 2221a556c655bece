"""`detect_api` reads which gym API code expects from how it unpacks reset() and step()."""

from __future__ import annotations

import textwrap

import pytest

from grader.compat.detection import Api, detect_api

CASES = [
    ("obs, info = env.reset()", Api.GYM026, "reset() unpacked into 2 values"),
    ("obs = env.reset()[0]", Api.GYM026, "reset()[...] takes the observation"),
    ("obs, r, term, trunc, info = env.step(0)", Api.GYM026, "step() unpacked into 5 values"),
    ("obs, r, done, info = env.step(0)", Api.CLASSIC, "step() unpacked into 4 values"),
    ("obs, info = env.reset(return_info=True)", Api.CLASSIC, "reset(return_info=True)"),
    ("obs = env.reset()", Api.CLASSIC, "reset() kept as one value"),
    ("done = terminated or truncated", Api.GYM026, "uses the name 'terminated'"),
    ("env = gym.make('CartPole-v1', render_mode='rgb_array')", Api.GYM026, "render_mode"),
    ("env.seed(3)", Api.CLASSIC, "env.seed()"),
]


@pytest.mark.parametrize(("line", "api", "reason"), CASES, ids=[case[0] for case in CASES])
def test_one_line_decides(line: str, api: Api, reason: str) -> None:
    decision = detect_api(line).module
    assert decision.api is api
    assert reason in decision.explain()


def test_unpacking_outweighs_hints() -> None:
    source = (
        "env = gym.make('CartPole-v1', render_mode='human')\nobs = env.reset()\nobs, r, d, i = env.step(0)\n"
    )
    decision = detect_api(source).module
    assert decision.api is Api.CLASSIC
    assert decision.explain() == "line 3: step() unpacked into 4 values (obs, reward, done, info)"


def test_random_seeding_is_not_env_seeding() -> None:
    assert detect_api("np.random.seed(1)\nrandom.seed(2)\n").module.api is None


MIXED = textwrap.dedent(
    """
    def old():
        s = env.reset()
        s, r, d, _ = env.step(1)

    def new():
        s, _ = env.reset()
        s, r, te, tr, _ = env.step(1)

    def helper():
        env.reset()

    def confused():
        s, _ = env.reset()
        s, r, d, _ = env.step(1)
    """
)


def test_each_function_of_a_mixed_module_gets_its_own_api() -> None:
    detection = detect_api(MIXED)
    assert detection.module.conflict
    assert detection.decision_at(4)[0] == "old" and detection.decision_at(4)[1].api is Api.CLASSIC
    assert detection.decision_at(8)[0] == "new" and detection.decision_at(8)[1].api is Api.GYM026
    assert detection.decision_at(11)[0] == "<module>"
    scope, decision = detection.decision_at(15)
    assert (scope, decision.api, decision.conflict) == ("confused", None, True)
    assert [item.line for item in decision.evidence] == [14, 15]


def test_source_that_does_not_parse_is_undecided() -> None:
    detection = detect_api("def broken(:\n")
    assert detection.module.api is None and detection.error.startswith("the source does not parse")


def test_a_function_with_hints_only_follows_the_module_s_unpackings() -> None:
    source = textwrap.dedent(
        """
        def play():
            s, r, term, trunc, _ = env.step(0)

        def start():
            state = env.reset()
            return state[0]
        """
    )
    scope, decision = detect_api(source).decision_at(6)
    assert (scope, decision.api) == ("<module>", Api.GYM026)
