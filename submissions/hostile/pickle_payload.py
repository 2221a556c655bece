"""Hostile: returns a pickle that would run a command if the grader unpickled it."""

import os
import pickle


class Payload:
    def __init__(self, marker):
        self.marker = marker

    def __reduce__(self):
        return (os.system, (f"touch /tmp/{self.marker}",))


def payload(marker):
    return pickle.dumps(Payload(marker))


def ok():
    return 42
