"""Hostile: forges result frames with the right id and nonce, found in the harness's own frames: one whose
value is millions of empty objects, so that the grader builds them all when it parses the frame, and
one whose strings (compat events, value) hold escaped lone surrogates and NULs."""

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


def _forge(value, events="[]"):
    request = _request()
    frame = (
        '{"type":"result","id":%d,"nonce":"%s","status":"ok","value":%s,"message":"","traceback":"",'
        '"episodes":[],"compat_events":%s,"wall_time":0.1}' % (request.call_id, request.nonce, value, events)
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


def bomb(megabytes):
    return _forge("[" + ",".join(["{}"] * (megabytes * (1 << 20) // 3)) + "]")


def forge_strings():
    bad = "\\ud800 \\u0000 " + "x" * 5000
    event = '{"kind":"%s","env_id":"%s","detail":"%s"}' % (bad, bad, bad)
    return _forge('"%s"' % bad, "[" + event + "]")


def ok():
    return 42
