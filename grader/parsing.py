"""Python source parsed into an `ast` tree by the trusted parent, one thread at a time.

CPython before 3.11.9 and 3.12.3 keeps the depth counter of its AST constructor in interpreter-wide state
(gh-106905). When two threads parse at once and a collection runs Python code in between (a `__del__`, a
weakref callback), one thread's count lands in the other's and `ast.parse` raises
``SystemError: AST constructor recursion depth mismatch`` on a file that parses. The grader parses in
threads (a class's files, a service's in-process workers, the similarity readers), so every parse in
`grader/` goes through `parse` here and its lock. A bytes `compile()` to code never builds Python AST
objects and needs no lock.
"""

from __future__ import annotations

import ast
import threading

_ONE_AT_A_TIME = threading.Lock()


def parse(source: str | bytes, filename: str = "<unknown>") -> ast.Module:
    """`ast.parse(source, filename)`, holding the one lock every parse in the parent shares."""
    with _ONE_AT_A_TIME:
        return ast.parse(source, filename)
