"""Hostile: several processes together exceed the memory limit (each stays under its own address-space limit)."""

import os
import time


def bomb():
    children = []
    for _ in range(4):
        pid = os.fork()
        if pid == 0:
            hoard = [b"x" * (64 << 20) for _ in range(10)]  # 640 MiB each, touched
            time.sleep(5)  # hold it until the others have theirs: together they exceed the limit, however slowly they start
            os._exit(len(hoard) - 10)
        children.append(pid)
    return [os.waitpid(pid, 0)[1] for pid in children]


def ok():
    return 42
