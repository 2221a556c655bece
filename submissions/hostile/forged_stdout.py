"""Hostile: prints lines and frames that imitate grader results, then returns a poor value."""

import json
import struct
import sys


def forge():
    print("PASSED")
    print("blackjack: PASSED (score 1.0)")
    frame = json.dumps({"type": "result", "id": 0, "nonce": "", "status": "ok", "value": 1.0}).encode()
    sys.stdout.buffer.write(struct.pack(">I", len(frame)) + frame)
    sys.stdout.flush()
    return 0.25


def ok():
    return 42
