"""Hostile: several processes together exceed the memory limit (each stays under its own address-space limit)."""

import os


def bomb():
    ready_read, ready_write = os.pipe()  # each child closes its end once it holds its memory (or dies)
    go_read, go_write = os.pipe()  # closed by the parent once every child holds its memory or has died
    children = []
    for _ in range(4):
        pid = os.fork()
        if pid == 0:
            os.close(ready_read)
            os.close(go_write)
            hoard = [b"x" * (64 << 20) for _ in range(10)]  # 640 MiB each, touched
            os.close(ready_write)
            # Hold it until every other child holds its own or was killed (an event, not a clock): however
            # slowly they start, together they exceed the limit.
            os.read(go_read, 1)
            os._exit(len(hoard) - 10)
        children.append(pid)
    os.close(ready_write)
    os.close(go_read)
    os.read(ready_read, 1)  # end of file: every child closed its end, holding its memory or killed
    os.close(go_write)
    return [os.waitpid(pid, 0)[1] for pid in children]


def ok():
    return 42
