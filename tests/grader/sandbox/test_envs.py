"""The child's cheaper Taxi and Blackjack against gymnasium's own classes, step by step.

Two envs are made by `gymnasium.make` with the same arguments; one is swapped to the cheaper class by
`grader.sandbox.child.envs.cheaper`. Both are reset with the same seeds and given the same actions
(random ones, plus actions gymnasium refuses); after every call the returned values (with their types),
the env's own state and its generator's state must be equal. A difference anywhere would make an
honest student's logged game differ from the parent's replay in gymnasium's env.
"""

from __future__ import annotations

import copy
import pickle
from typing import Any

import gymnasium
import numpy as np
import pytest
from gymnasium.envs.toy_text import blackjack, taxi

from grader.sandbox.child import envs

TAXI_STATE = ("s", "lastaction", "fickle_step", "taxi_orientation")
BLACKJACK_STATE = ("player", "dealer", "dealer_top_card_suit", "dealer_top_card_value_str")


def _pair(env_id: str, **kwargs: Any) -> tuple[gymnasium.Env[Any, Any], gymnasium.Env[Any, Any]]:
    stock = gymnasium.make(env_id, **kwargs)
    cheap = gymnasium.make(env_id, **kwargs)
    envs.cheaper(cheap.unwrapped)
    return stock, cheap


def _same(left: Any, right: Any, where: str) -> None:
    assert type(left) is type(right), f"{where}: {type(left).__name__} against {type(right).__name__}"
    if isinstance(left, np.ndarray):
        assert left.dtype == right.dtype and np.array_equal(left, right), where
    elif isinstance(left, dict):
        assert left.keys() == right.keys(), where
        for key in left:
            _same(left[key], right[key], f"{where}[{key!r}]")
    elif isinstance(left, list | tuple):
        assert len(left) == len(right), where
        for index, (one, other) in enumerate(zip(left, right, strict=True)):
            _same(one, other, f"{where}[{index}]")
    else:
        assert left == right, f"{where}: {left!r} against {right!r}"


Env = gymnasium.Env[Any, Any]


def _same_state(stock: Env, cheap: Env, names: tuple[str, ...]) -> None:
    for name in names:
        _same(getattr(stock.unwrapped, name), getattr(cheap.unwrapped, name), name)
    assert stock.unwrapped.np_random.bit_generator.state == cheap.unwrapped.np_random.bit_generator.state


def _call(env: gymnasium.Env[Any, Any], method: str, *args: Any, **kwargs: Any) -> tuple[str, Any]:
    try:
        return "returned", getattr(env, method)(*args, **kwargs)
    except Exception as error:  # the same refusal, whatever it is
        return "raised", type(error).__name__


def _play(
    stock: gymnasium.Env[Any, Any],
    cheap: gymnasium.Env[Any, Any],
    actions: list[Any],
    names: tuple[str, ...],
    seed: int,
) -> int:
    _same(_call(stock, "reset", seed=seed), _call(cheap, "reset", seed=seed), "reset")
    _same_state(stock, cheap, names)
    episodes = 1
    for step, action in enumerate(actions):
        stock_result = _call(stock, "step", action)
        _same(stock_result, _call(cheap, "step", action), f"step {step}, action {action!r}")
        _same_state(stock, cheap, names)
        if stock_result[0] == "raised" or stock_result[1][2] or stock_result[1][3]:
            reset_seed = None if step % 3 else seed + step + 1  # seeded and unseeded resets alike
            _same(_call(stock, "reset", seed=reset_seed), _call(cheap, "reset", seed=reset_seed), "reset")
            _same_state(stock, cheap, names)
            episodes += 1
    return episodes


@pytest.mark.slow  # plays every taxi variant against gymnasium, seconds each
@pytest.mark.parametrize(
    "kwargs",
    [{}, {"is_rainy": True}, {"fickle_passenger": True}, {"is_rainy": True, "fickle_passenger": True}],
    ids=["lab", "rainy", "fickle", "rainy-fickle"],
)
def test_taxi_plays_gymnasiums_game(kwargs: dict[str, Any]) -> None:
    stock, cheap = _pair("Taxi-v4", **kwargs)
    assert type(cheap.unwrapped) is envs.TaxiEnv
    rng = np.random.default_rng(7)
    actions: list[Any] = rng.integers(0, 6, 20_000).tolist()
    actions[100:110] = [np.int64(2), np.int32(4), 1.0, True, 6, -1, "2", 3, np.int8(5), 0]
    episodes = _play(stock, cheap, actions, TAXI_STATE, seed=11)
    assert episodes > 20  # the 200-step limit and the refused actions end games: resets are covered


def test_taxi_state_set_by_hand_and_masks_are_fresh() -> None:
    stock, cheap = _pair("Taxi-v4")
    stock.reset(seed=3)
    cheap.reset(seed=3)
    for env in (stock, cheap):
        env.unwrapped.s = np.int64(328)  # a student's own test position
    _same(stock.step(1), cheap.step(1), "step from a state set by hand")
    for env in (stock, cheap):
        env.step(0)[4]["action_mask"][:] = 0  # the student's copy
    _same(stock.step(0), cheap.step(0), "step after writing into a mask")
    for state in (0, 499, np.int64(42), -1, 500):
        stock_mask = _call(stock.unwrapped, "action_mask", state)
        _same(stock_mask, _call(cheap.unwrapped, "action_mask", state), f"mask of {state!r}")


@pytest.mark.slow
@pytest.mark.parametrize("natural", [False, True])
@pytest.mark.parametrize("sab", [False, True])
def test_blackjack_plays_gymnasiums_game(natural: bool, sab: bool) -> None:
    stock, cheap = _pair("Blackjack-v1", natural=natural, sab=sab)
    assert type(cheap.unwrapped) is envs.BlackjackEnv
    rng = np.random.default_rng(8)
    actions: list[Any] = rng.integers(0, 2, 6_000).tolist()
    actions[50:62] = [
        np.int64(1),
        True,
        False,
        2,
        -1,
        1.0,
        np.array(1),
        None,
        np.uint8(1),
        np.int8(-1),
        np.bool_(1),
        np.int32(0),
    ]
    actions[100:3000:2] = [
        np.int64(action) for action in actions[100:3000:2]
    ]  # as `action_space.sample()` gives
    episodes = _play(stock, cheap, actions, BLACKJACK_STATE, seed=5)
    assert episodes > 2_000


def test_blackjack_with_a_students_own_generator() -> None:
    stock, cheap = _pair("Blackjack-v1")
    for env in (stock, cheap):
        env.reset(seed=1)
        env.unwrapped.np_random = np.random.RandomState(4)  # type: ignore[assignment]  # a student's choice
    for _ in range(300):
        _same(_call(stock, "reset"), _call(cheap, "reset"), "reset with a RandomState")
        _same(_call(stock, "step", 1), _call(cheap, "step", 1), "hit with a RandomState")
        _same(_call(stock, "step", 0), _call(cheap, "step", 0), "stick with a RandomState")
    assert (
        stock.unwrapped.np_random.get_state()[1].tolist() == cheap.unwrapped.np_random.get_state()[1].tolist()
    )


def test_blackjack_renders_the_same_cards() -> None:
    stock, cheap = _pair("Blackjack-v1", render_mode="rgb_array")
    for seed in range(40):  # aces, faces and numbers on top
        stock.reset(seed=seed)
        cheap.reset(seed=seed)
        _same_state(stock, cheap, BLACKJACK_STATE)
    assert np.array_equal(stock.render(), cheap.render())


def test_the_student_sees_gymnasiums_names() -> None:
    for env_id in ("Taxi-v4", "Blackjack-v1"):
        stock, cheap = _pair(env_id)
        assert str(cheap) == str(stock)
        assert type(cheap.unwrapped).__name__ == type(stock.unwrapped).__name__
        assert isinstance(cheap.unwrapped, type(stock.unwrapped))
        assert cheap.spec == stock.spec
        assert type(pickle.loads(pickle.dumps(cheap.unwrapped))) is type(cheap.unwrapped)
        assert type(copy.deepcopy(cheap).unwrapped) is type(cheap.unwrapped)


def test_only_gymnasiums_own_classes_are_swapped() -> None:
    class StudentTaxi(taxi.TaxiEnv):
        pass

    student = StudentTaxi()
    envs.cheaper(student)
    assert type(student) is StudentTaxi
    cartpole = gymnasium.make("CartPole-v1").unwrapped
    kind = type(cartpole)
    envs.cheaper(cartpole)
    assert type(cartpole) is kind
    assert type(blackjack.BlackjackEnv()) is blackjack.BlackjackEnv  # gymnasium's class itself is untouched
