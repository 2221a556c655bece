"""Hostile: imports the grader's reference solutions."""


def steal():
    import reference.solutions

    return reference.solutions.cartpole()


def ok():
    return 42
