"""What the child may see: the interpreter, the libraries, the harness tree, and nothing of the project."""

from __future__ import annotations

import atexit
import compileall
import contextlib
import functools
import os
import shutil
import site
import sys
import sysconfig
import tempfile
from dataclasses import dataclass
from pathlib import Path

from grader.sandbox import process_model
from grader.sandbox.host import HOST, Feature
from grader.sandbox.isolation import ownership
from grader.sandbox.isolation.scope import temp_root

SYSTEM_DIRS = ("/usr", "/bin", "/sbin", "/lib", "/lib64", "/lib32")
"""System directories the child may read (bubblewrap binds them, Landlock allows reading them)."""
SYSTEM_CONFIG_DIRS = ("/etc/fonts",)
"""Configuration the child may read where it exists: fontconfig's, which matplotlib's font search runs
(`fc-list`) the first time a child draws; without it every plot prints a "Fontconfig error"."""
PROJECT_PACKAGES = ("grader", "reference", "api")
"""Top-level packages of the project; hidden wherever an installed copy would make them importable."""

_GRADER_ROOT = Path(__file__).resolve().parents[2]
_HARNESS_SOURCES = ("sandbox/child", "compat")
_ISOLATION_DIR = Path(__file__).resolve().parent
_CHILD_SIDE_FILES = ("bootstrap.py", "landlock_syscalls.py")
"""Stdlib-only files of this package the child runs before the harness (at the top of the tree)."""
_SCRATCH_PREFIX = "gymgrade-scratch-"
_SUBMISSION_SUBDIR = ".submission"
TREE_PREFIX = "gymgrade-tree-"
"""Harness trees are temporary directories named gymgrade-tree-<grader pid>-<random>, inside the grading's
scope when there is one (`grader.sandbox.isolation.scope`), which removes them with it. Their grader holds
a lock on the tree while it lives (`grader.sandbox.isolation.ownership`); where locks exist, only that
lock, never the pid in the name, tells a sweep the tree is abandoned."""
_TREE_CLAIMS: list[ownership.Claim] = []
"""The locks on this process's harness trees, held until it ends."""


@dataclass(frozen=True)
class PythonPaths:
    """The interpreter and the directories of the modules the child imports.

    Attributes:
        executable: The interpreter binary.
        roots: Directories to expose read-only (prefixes, the executable's directory, the stdlib and
            site directories that exist), resolved, each once, even when nested (a layer that mounts
            them decides which it needs: `grader.sandbox.isolation.bubblewrap.interpreter_binds`).
        stdlib: Standard-library entries of the child's sys.path (resolved).
        site_dirs: Existing site directories of the child's sys.path, after the stdlib (resolved).
        hidden: Files and directories inside `roots` the child must not see (.pth hooks, the editable
            install's finder, installed copies of the project's packages).
    """

    executable: Path
    roots: tuple[Path, ...]
    stdlib: tuple[str, ...]
    site_dirs: tuple[str, ...]
    hidden: tuple[Path, ...]


@dataclass(frozen=True)
class ChildView:
    """Where one child finds its scratch directory, the harness tree and the submission (paths it sees).

    Attributes:
        scratch: Its writable directory (also HOME and TMPDIR).
        harness: The harness tree (`harness_tree()`).
        submission: The submission's read-only file.
        host_scratch: The scratch directory on the host, removed after the child (None when the scratch
            is private to the child).
        cwd: The working directory of the first process (None when a wrapper sets the child's own).
    """

    scratch: str
    harness: str
    submission: str
    host_scratch: Path | None = None
    cwd: str | None = None


def host_view(tree: Path, submission: bytes, submission_name: str) -> ChildView:
    """The view without a private file system: a scratch directory on the host (in the grading's scope)
    holding a read-only copy of the submission, and the harness tree where it is."""
    scratch = Path(tempfile.mkdtemp(prefix=_SCRATCH_PREFIX, dir=temp_root()))
    try:
        os.chmod(scratch, 0o1777)
        submission_dir = scratch / _SUBMISSION_SUBDIR
        submission_dir.mkdir()
        (submission_dir / submission_name).write_bytes(submission)
        os.chmod(submission_dir, 0o555)
    except BaseException:
        remove_host_scratch(scratch)
        raise
    return ChildView(
        scratch=str(scratch),
        harness=str(tree),
        submission=str(submission_dir / submission_name),
        host_scratch=scratch,
        cwd=str(scratch),
    )


def remove_host_scratch(scratch: Path) -> None:
    """Removes a host view's scratch directory with everything in it.

    Its read-only submission directory is made writable first: without root, nothing inside a read-only
    directory can be removed. Opened without following links, since a child running as the grader's
    own uid may have replaced it.
    """
    with contextlib.suppress(OSError):
        if not HOST.has(Feature.POSIX_PROCESSES):  # Windows: chmod only clears the read-only attribute
            os.chmod(scratch / _SUBMISSION_SUBDIR, 0o700)
        else:
            descriptor = os.open(scratch / _SUBMISSION_SUBDIR, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW)
            try:
                os.fchmod(descriptor, 0o700)
            finally:
                os.close(descriptor)
    shutil.rmtree(scratch, ignore_errors=True)


def _existing_directory(path: str) -> Path | None:
    resolved = Path(path).resolve()
    return resolved if resolved.is_dir() else None


@functools.cache
def python_paths() -> PythonPaths:
    """The paths of the running interpreter (the child runs the same interpreter).

    Derived from what the interpreter imports: its prefixes (shared libraries live there), the directory of
    its executable, the standard-library entries of `sys.path` and the site directories that exist, each
    resolved (symbolic links followed) so that the child's `sys.path` names the paths that are bound.
    """
    prefixes = {Path(sys.base_prefix).resolve(), Path(sys.prefix).resolve()}
    site_dirs = list(dict.fromkeys(str(d) for p in site.getsitepackages() if (d := _existing_directory(p))))
    stdlib_dirs = {Path(sysconfig.get_path(name)).resolve() for name in ("stdlib", "platstdlib")}
    stdlib_zip = f"python{sys.version_info.major}{sys.version_info.minor}.zip"
    stdlib = [
        str(Path(p).resolve())
        for p in sys.path
        if p
        and (Path(p).name == stdlib_zip or any(Path(p).resolve().is_relative_to(d) for d in stdlib_dirs))
        and str(Path(p).resolve()) not in site_dirs
    ]
    executable = Path(sys.executable).resolve()
    candidates = [*prefixes, executable.parent, *map(Path, stdlib), *map(Path, site_dirs)]
    roots = {path for path in candidates if path.is_dir()}
    hidden: list[Path] = []
    for site_dir in site_dirs:
        for entry in Path(site_dir).iterdir():
            name = entry.name
            hook = name.endswith(".pth") or (name.startswith("__editable__") and name.endswith(".py"))
            if hook or (name in PROJECT_PACKAGES and entry.is_dir()):
                hidden.append(entry)
    return PythonPaths(
        executable=executable,
        roots=tuple(sorted(roots)),
        stdlib=tuple(dict.fromkeys(stdlib)),
        site_dirs=tuple(site_dirs),
        hidden=tuple(sorted(hidden)),
    )


def remove_stale_trees() -> None:
    """Removes trees of grader processes that ended without running their exit handlers (e.g. SIGKILL).

    Where locks exist, a tree is removed only under its lock, which its grader held while it lived (a pid
    means nothing to a grader in another PID namespace); elsewhere (Windows) when the pid in its name no
    longer runs.
    """
    for path in Path(tempfile.gettempdir()).glob(f"{TREE_PREFIX}*-*"):
        if ownership.LOCKS:
            claim = ownership.claim_abandoned(path)
            if claim is not None:
                with claim:
                    shutil.rmtree(path, ignore_errors=True)
            continue
        try:
            pid = int(path.name.removeprefix(TREE_PREFIX).split("-")[0])
        except ValueError:
            continue
        if process_model.exists(pid) is False:
            shutil.rmtree(path, ignore_errors=True)


def _owned_tree_directory() -> Path:
    """A new directory for this process's harness tree, locked by it where locks exist."""
    while True:
        root = Path(tempfile.mkdtemp(prefix=f"{TREE_PREFIX}{os.getpid()}-", dir=temp_root()))
        if not ownership.LOCKS:
            return root
        try:
            _TREE_CLAIMS.append(ownership.claim_new(root))
        except (BlockingIOError, FileNotFoundError):  # another grader's sweep took the empty directory
            continue
        return root


@functools.cache
def harness_tree() -> Path:
    """A private, read-only copy of what the child imports from the project, built once per process.

    Layout: ``bootstrap.py`` and ``landlock_syscalls.py`` at the top, and under ``lib/`` an empty
    ``grader/__init__.py`` and ``grader/sandbox/__init__.py`` with ``grader/sandbox/child`` and
    ``grader/compat``. Nothing else of the project (not `reference`, not the assignment config).
    """
    remove_stale_trees()
    root = _owned_tree_directory()
    atexit.register(shutil.rmtree, root, ignore_errors=True)
    lib = root / "lib"
    (lib / "grader" / "sandbox").mkdir(parents=True)
    (lib / "grader" / "__init__.py").write_text("")
    (lib / "grader" / "sandbox" / "__init__.py").write_text("")
    for relative in _HARNESS_SOURCES:
        shutil.copytree(
            _GRADER_ROOT / relative,
            lib / "grader" / relative,
            ignore=shutil.ignore_patterns("__pycache__", "*.pyc"),
        )
        _compile_bytecode(lib / "grader" / relative)
    for name in _CHILD_SIDE_FILES:
        shutil.copy2(_ISOLATION_DIR / name, root / name)
    for directory, _, files in os.walk(root):
        os.chmod(directory, 0o755)
        for name in files:
            os.chmod(os.path.join(directory, name), 0o644)
    return root


def _compile_bytecode(directory: Path) -> None:
    """Writes the bytecode of the harness's copied sources next to them (`__pycache__`, checked against
    each source's time stamp and size, as Python's own caches are).

    The child runs with `-B` in a read-only tree, so without these every child compiled the harness and
    the compat layer from source again (about 45 ms of its 0.3 s start, bench/RESULTS.md `## Class
    throughput`). They are written here, by the grader, from the copies it just made; the child only reads
    them, and an interpreter of another version ignores them.
    """
    if not compileall.compile_dir(directory, quiet=2, force=True):
        raise OSError(f"the harness sources in {directory} did not compile to bytecode")
