"""Each reset()/step() call gets the API its call site was written for, through the `gym` module."""

from __future__ import annotations

from .conftest import RunScript

GYM026 = """
import gym

def cartpole():
    env = gym.make("CartPole-v1", render_mode="rgb_array")
    obs, info = env.reset(seed=3)
    steps = 0
    while True:
        obs, reward, terminated, truncated, info = env.step(int(obs[3] > 0))
        steps += 1
        if terminated or truncated:
            return steps

def car():
    env = gym.make("MountainCar-v0")
    obs = env.reset()
    done = False
    steps = 0
    while not done:
        obs, reward, done, info = env.step(2 if obs[1] > 0 else 0)
        steps += 1
    return steps

def play(env):
    env.reset()
    return env.step(0)

def newer():
    env = gym.make("MountainCar-v0")
    result = play(env)
    obs, info = env.reset()
    return len(result)

print(cartpole() > 100, car() < 200, newer())
"""


def test_a_module_mixing_apis_serves_each_function_its_own(run_through_layer: RunScript) -> None:
    result = run_through_layer(GYM026)
    assert result.returncode == 0, result.stderr
    assert result.stdout == "True True 5\n"
    detections = [line.strip() for line in result.stderr.splitlines() if "api_detected" in line]
    assert detections == [
        "api_detected [CartPole-v1 in cartpole()]: cartpole() in snippet.py was served the gym 0.26 API "
        "(5-value step): line 6: reset() unpacked into 2 values (obs, info); line 9: step() unpacked into "
        "5 values (obs, reward, terminated, truncated, info)",
        "api_detected [MountainCar-v0 in car()]: car() in snippet.py was served the classic gym API (4-value "
        "step): line 20: step() unpacked into 4 values (obs, reward, done, info)",
        "api_detected [MountainCar-v0 in newer()]: newer() in snippet.py was served the gym 0.26 API "
        "(5-value step): line 31: reset() unpacked into 2 values (obs, info)",
    ]


def test_a_function_expecting_both_apis_gets_a_message_naming_its_lines(run_through_layer: RunScript) -> None:
    result = run_through_layer(
        """
        import gym
        env = gym.make("CartPole-v1")
        obs, info = env.reset()
        obs, reward, done, info = env.step(0)
        """
    )
    assert result.returncode == 1
    assert (
        "AmbiguousApiError: gymgrade cannot tell which gym API this file in snippet.py expects: line 4: "
        "reset() unpacked into 2 values (obs, info) (gym 0.26); line 5: step() unpacked into 4 values "
        "(obs, reward, done, info) (classic gym)."
    ) in result.stderr


def test_gym_toytext_registers_the_package_s_games(run_through_layer: RunScript) -> None:
    result = run_through_layer(
        """
        import gym
        import gym_toytext
        from gym.envs.toy_text import BlackjackEnv, TaxiEnv
        from gym.envs.toy_text.nchain import NChainEnv
        for env_id in ["GuessingGame-v0", "HotterColder-v0", "KellyCoinflip-v0",
                       "KellyCoinflipGeneralized-v0", "NChain-v0", "Roulette-v0"]:
            env = gym.make(env_id)
            obs, info = env.reset(seed=1)
            while True:
                obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
                if terminated or truncated:
                    break
            print(env_id, env.spec.id == env_id)
        print(gym_toytext.NChainEnv is NChainEnv, BlackjackEnv.__module__)
        """
    )
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert all(line.endswith(" True") for line in lines[:6]), lines
    assert lines[6] == "True gymnasium.envs.toy_text.blackjack"
