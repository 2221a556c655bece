"""Hostile: finds the result channel through /proc/self/fd and writes its own result frame."""

import json
import os
import struct


def forge():
    frame = json.dumps({
        "type": "result", "id": 0, "nonce": "0" * 32, "status": "ok", "value": 1.0, "message": "",
        "traceback": "", "episodes": [], "compat_events": [], "wall_time": 0.1,
    }).encode()
    data = struct.pack(">I", len(frame)) + frame
    for name in os.listdir("/proc/self/fd"):
        descriptor = int(name)
        if descriptor in (1, 2):
            continue
        try:
            with open(f"/proc/self/fdinfo/{name}") as info:
                flags = int(info.read().split("flags:")[1].split()[0], 8)
            if os.readlink(f"/proc/self/fd/{name}").startswith("pipe:") and flags & os.O_ACCMODE == os.O_WRONLY:
                os.write(descriptor, data)
        except OSError:
            continue
    return 0.0


def ok():
    return 42
