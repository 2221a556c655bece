"""Which interpreter directories bubblewrap binds, for every interpreter layout, and a real bwrap start."""

from __future__ import annotations

import dataclasses
import shutil
import subprocess
from pathlib import Path

import pytest

from grader.sandbox import Call, IsolationPolicy, Limits, OutcomeStatus, Sandbox
from grader.sandbox.errors import SandboxLayoutError
from grader.sandbox.isolation import launch
from grader.sandbox.isolation.bubblewrap import file_system_argv, interpreter_binds, without_new_root
from grader.sandbox.isolation.filesystem import PythonPaths, python_paths

SYSTEM = (Path("/usr"),)
MASKED = (Path("/usr/local"), Path("/tmp"))
DEBIAN_VENV = "/tmp/x/.venv"
LAYOUTS = [
    pytest.param(
        [
            "/usr",
            "/usr/bin",
            "/usr/lib/python3.11",
            "/usr/lib/python3.11/lib-dynload",
            "/usr/lib/python3/dist-packages",
            "/usr/local/lib/python3.11/dist-packages",
            DEBIAN_VENV,
            f"{DEBIAN_VENV}/lib/python3.11/site-packages",
        ],
        ["/tmp/x/.venv", "/usr/local/lib/python3.11/dist-packages"],
        id="debian-python3-through-the-project-venv",
    ),
    pytest.param(
        ["/usr", "/usr/bin", "/usr/lib/python3.11", "/usr/local/lib/python3.11/dist-packages"],
        ["/usr/local/lib/python3.11/dist-packages"],
        id="debian-python3-itself",
    ),
    pytest.param(
        [
            "/root/.pyenv/versions/3.11.7",
            "/root/.pyenv/versions/3.11.7/bin",
            "/root/.pyenv/versions/3.11.7/lib/python3.11",
            "/root/.pyenv/versions/3.11.7/lib/python3.11/site-packages",
        ],
        ["/root/.pyenv/versions/3.11.7"],
        id="pyenv",
    ),
    pytest.param(
        [
            "/root/.pyenv/versions/3.11.7",
            "/root/.pyenv/versions/3.11.7/lib/python3.11",
            "/tmp/ci/venv",
            "/tmp/ci/venv/lib/python3.11/site-packages",
        ],
        ["/tmp/ci/venv", "/root/.pyenv/versions/3.11.7"],  # ancestors first: by depth
        id="virtualenv-under-tmp",
    ),
    pytest.param(
        [
            "/usr",
            "/usr/lib/python3.11",
            "/home/ada/.local/pipx/venvs/gymgrade",
            "/home/ada/.local/pipx/venvs/gymgrade/lib/python3.11/site-packages",
        ],
        ["/home/ada/.local/pipx/venvs/gymgrade"],
        id="pipx-on-debian",
    ),
    pytest.param(
        [
            "/usr/local",
            "/usr/local/bin",
            "/usr/local/lib/python3.11",
            "/usr/local/lib/python3.11/site-packages",
        ],
        ["/usr/local"],
        id="python-built-from-source-in-usr-local",
    ),
    pytest.param(
        ["/opt/conda", "/opt/conda/lib/python3.11", "/opt/conda/envs/lab", "/opt/conda/envs/lab/lib"],
        ["/opt/conda"],
        id="conda-environment-inside-its-base",
    ),
]


@pytest.mark.parametrize(("roots", "expected"), LAYOUTS)
def test_each_directory_is_bound_once_unless_a_read_only_bind_already_shows_it(
    roots: list[str], expected: list[str]
) -> None:
    binds = interpreter_binds(tuple(map(Path, roots)), SYSTEM, MASKED)
    assert binds == tuple(map(Path, expected))


def test_nothing_the_usr_bind_shows_is_bound_again_so_the_usr_local_mask_stays_a_mount() -> None:
    # The bug of issue 26: Debian's prefix /usr bound again covered the tmpfs on /usr/local, and bubblewrap
    # could not remount /usr/local read-only ("Invalid argument").
    binds = interpreter_binds((Path("/usr"), Path("/usr/local/lib/python3.11/dist-packages")), SYSTEM, MASKED)
    assert not any(bind != Path("/usr/local") and Path("/usr/local").is_relative_to(bind) for bind in binds)


@pytest.mark.parametrize(
    ("root", "contained"),
    [("/", "/usr"), ("/tmp", "/tmp"), ("/usr/local", None)],
    ids=["root", "tmp", "usr-local"],
)
def test_an_interpreter_directory_over_the_sandboxs_own_mounts_is_refused_by_name(
    root: str, contained: str | None
) -> None:
    roots = (Path(root), Path(root) / "lib" / "python3.11")
    if contained is None:  # a Python built into /usr/local is bound over the /usr/local mask, as it should
        assert interpreter_binds(roots, SYSTEM, MASKED) == (Path(root),)
        return
    with pytest.raises(SandboxLayoutError) as raised:
        interpreter_binds(roots, SYSTEM, MASKED)
    assert str(raised.value).startswith(
        f"the interpreter directory {root} contains {contained}, which the sandbox"
    )


def test_bwrap_messages_name_the_hosts_path() -> None:
    message = 'bwrap: Can\'t remount readonly on /newroot/usr/local: Unable to remount "/newroot/usr/local"'
    assert without_new_root(message) == (
        'bwrap: Can\'t remount readonly on /usr/local: Unable to remount "/usr/local"'
    )


def _debian_like(tmp_path: Path) -> PythonPaths:
    """Debian's directories (those present here) around a venv under /tmp, as the project's .venv has them."""
    venv_site = tmp_path / "venv" / "lib" / "python3.11" / "site-packages"
    venv_site.mkdir(parents=True)
    (venv_site / "only_in_the_venv.py").write_text("")
    debian = [Path("/usr/lib/python3/dist-packages"), Path("/usr/local/lib/python3.11/dist-packages")]
    site_dirs = [venv_site, *(directory for directory in debian if directory.is_dir())]
    real = python_paths()
    return dataclasses.replace(
        real,
        roots=tuple(sorted({*real.roots, Path("/usr"), Path("/usr/bin"), tmp_path / "venv", *site_dirs})),
        site_dirs=(*real.site_dirs, *map(str, site_dirs)),
    )


@pytest.mark.sandbox
@pytest.mark.skipif(shutil.which("bwrap") is None, reason="needs bubblewrap")
def test_bwrap_starts_with_debians_directories_and_shows_every_one(tmp_path: Path) -> None:
    paths = _debian_like(tmp_path)
    wanted = [directory for directory in (*paths.site_dirs, *paths.stdlib) if Path(directory).is_dir()]
    script = "import os, sys; print(*[p for p in sys.argv[1:] if not os.path.isdir(p)])"
    argv = [
        "bwrap",
        "--unshare-all",
        "--die-with-parent",
        *file_system_argv(paths, 1 << 20),
        "--proc",
        "/proc",
    ]
    result = subprocess.run(
        [*argv, "--proc", "/proc", "--dev", "/dev", "--", str(paths.executable), "-S", "-c", script, *wanted],
        capture_output=True, text=True, timeout=30,
    )  # fmt: skip
    assert (result.returncode, result.stdout.strip(), result.stderr) == (0, "", "")


@pytest.mark.sandbox
def test_a_sandbox_that_cannot_start_names_the_path_and_the_reason(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # A hook to hide that does not exist inside a read-only bind: bwrap cannot create its mount point.
    missing = Path("/usr/lib/gymgrade-no-such-hook.pth")
    broken = dataclasses.replace(python_paths(), hidden=(*python_paths().hidden, missing))
    monkeypatch.setattr(launch, "python_paths", lambda: broken)
    submission = tmp_path / "opengym.py"
    submission.write_text("def random_blackjack(n):\n    return 0.28\n")
    with Sandbox(submission, seed=0, policy=IsolationPolicy.REQUIRE_FULL, limits=Limits()) as sandbox:
        outcome = sandbox.call(Call("random_blackjack", (3,), record_episodes=False))
    assert outcome.status is OutcomeStatus.SANDBOX_ERROR
    assert str(missing) in outcome.message and "/newroot" not in outcome.message
    assert outcome.message.startswith("the sandbox failed to start (bwrap: ")
    assert "gymgrade doctor" in outcome.message
