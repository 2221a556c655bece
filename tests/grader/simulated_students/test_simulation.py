"""The in-process stand-in for the sandbox used by calibration and these tests."""

import pytest

from grader.sandbox.outcome import Call, OutcomeStatus
from grader.sandbox.replay import verify_reset_seeds
from grader.simulated_students.behaviours import REFERENCE, cartpole
from grader.simulated_students.simulation import function_infos, simulate_call, simulate_calls


def test_function_infos_hide_the_lab_parameter() -> None:
    infos = function_infos(REFERENCE["taxi"])
    first = infos["taxi"].parameters[0]
    assert (first.name, first.kind, first.has_default) == ("q_table", "POSITIONAL_OR_KEYWORD", False)


def test_missing_and_failing_functions_become_outcomes() -> None:
    def broken(lab):  # type: ignore[no-untyped-def]
        return 1 / 0

    missing, failing = simulate_calls([Call("car"), Call("cartpole")], {"cartpole": broken}, seed=1)
    assert missing.outcome.status is OutcomeStatus.MISSING_FUNCTION
    assert failing.outcome.status is OutcomeStatus.EXCEPTION
    assert failing.outcome.message == "cartpole() raised ZeroDivisionError: division by zero"


def test_episodes_use_the_sandbox_seed_streams_and_replay_identically() -> None:
    record = simulate_call(Call("cartpole"), cartpole, call_seed=99, replay=True)
    assert verify_reset_seeds(record.outcome.episodes, 99) is None
    assert [replay.mismatch for replay in record.replays] == [None]
    assert record.replays[0].length == record.outcome.value


def test_fast_blackjack_cannot_be_replayed() -> None:
    with pytest.raises(ValueError, match="fast Blackjack episodes cannot be replayed"):
        simulate_call(
            Call("random_blackjack", (10,)),
            REFERENCE["random_blackjack"]["random_blackjack"],
            1,
            replay=True,
            fast=True,
        )
