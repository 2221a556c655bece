"""Interpreters shaped like another operating system's CPython, for the portable check's tests.

`shaped_python(directory, shape)` makes a virtual environment whose `bin/python` is a shell script running
this interpreter through `launch.py`, which applies `shapes.SHAPES[shape]` first: every process of a run
(the `gymgrade check` process, its pytest-xdist workers, the sandbox's children and the notebook reader)
starts shaped, since each is started with `sys.executable`. Its site-packages is this environment's, so
the shaped run grades with the same packages and the same copy of the project.
"""

from __future__ import annotations

import os
import shlex
import site
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent


def shaped_python(directory: Path, shape: str) -> Path:
    """Makes the shaped environment in `directory` (created) and returns its interpreter."""
    version = f"python{sys.version_info.major}.{sys.version_info.minor}"
    real = Path(sys._base_executable if hasattr(sys, "_base_executable") else sys.executable).resolve()
    (directory / "bin").mkdir(parents=True)
    (directory / "lib" / version).mkdir(parents=True)
    own, *system = site.getsitepackages()  # this environment's, then the base interpreter's if it uses them
    (directory / "lib" / version / "site-packages").symlink_to(Path(own).resolve())
    with_system = "true" if system else "false"
    (directory / "pyvenv.cfg").write_text(
        f"home = {real.parent}\ninclude-system-site-packages = {with_system}\n"
        f"version = {sys.version.split()[0]}\n",
        encoding="utf-8",
    )
    python = directory / "bin" / "python"
    command = shlex.join([str(real), "-S", str(HERE / "launch.py"), shape])
    python.write_text(f'#!/bin/bash\nexec -a "$0" {command} "$@"\n', encoding="utf-8")
    python.chmod(0o755)
    os.symlink("python", directory / "bin" / version)
    return python
