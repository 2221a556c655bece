"""Hostile: returns objects whose comparisons always succeed."""


class AlwaysEqual(float):
    def __eq__(self, other):
        return True

    def __ge__(self, other):
        return True

    def __le__(self, other):
        return True

    __hash__ = float.__hash__


class Convertible:
    def __float__(self):
        return 1.0


def rigged_float():
    return AlwaysEqual(0.0)


def rigged_object():
    return Convertible()


def ok():
    return 42
