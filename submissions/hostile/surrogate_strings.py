"""Hostile: strings no UTF-8 encoder accepts (lone surrogates), NULs and huge messages, in every place a
child's string reaches the grader: an exception's message, printed output, a returned value."""

import sys

BAD = "bad " + chr(0xD800) + " nul \x00 end"


def fails():
    sys.stdout.buffer.write(b"invalid utf-8 \xed\xa0\x80 and nul \x00\n")
    sys.stdout.flush()
    raise ValueError(BAD + "," * 100_000)


def returns_surrogate():
    return {"text": BAD, BAD: [BAD]}


def ok():
    return 42
