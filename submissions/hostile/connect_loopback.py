"""Hostile: connects to a TCP server on the host's loopback (port given by the grader's test)."""

import socket


def connect(port):
    with socket.create_connection(("127.0.0.1", port), timeout=1) as connection:
        connection.sendall(b"stolen answers")
    return "connected"


def ok():
    return 42
