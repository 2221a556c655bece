"""Gradescope: the autograder zip, and what its ``run_autograder`` runs to write ``results.json``.

The results themselves (Gradescope's specification as pydantic models, and a report as those results)
are an output format: `grader.render.gradescope`.
"""

from __future__ import annotations

import io
import json
import os
import shutil
import stat
import tempfile
import tomllib
import zipfile
from importlib.metadata import requires, version
from pathlib import Path

import grader
from grader.errors import GradescopeError
from grader.grading.batch import SUBMISSION_SUFFIXES
from grader.lab.assignment import DEFAULT_CONFIG_PATH
from grader.render.gradescope import GradescopeResults, failed_run, results, seed_record
from grader.seeds import new_secret, upload_seed
from grader.submission.gradescope_upload import METADATA_FILE, UploadSeed, read_metadata
from grader.submission.untrusted_file import UnsafeFile, read_untrusted

DEFAULT_ROOT = Path("/autograder")
PREFERRED_STEM = "opengym"
"""The lab's file name: chosen when a submission holds several gradable files."""
PROJECT_PACKAGES = ("grader", "reference")
"""What the bundle installs on Gradescope: the grader and its oracles (the service is not needed)."""
BUNDLE_PYTHON = "python3.11"
BUNDLE_VENV = "/opt/gymgrade"
MAX_UPLOAD_DEPTH = 32
"""Folders an upload is walked into (a lab's file sits at its top, or a folder or two down)."""
SECRET_FILE = "seed_secret"
"""The bundle's seed secret (hex), drawn when the bundle is built; only the grader (root) reads it."""


def pick_submission(directory: Path) -> Path | str:
    """The file to grade in Gradescope's submission directory, or why there is none.

    One ``.py`` or ``.ipynb`` file is graded as it is; among several, the one named like the lab's
    ``opengym.py`` (or ``opengym.ipynb``) is chosen; otherwise the student is told what was found. The
    directory is walked without following links: a symbolic link (to a file or a folder), a hard link or
    anything but a regular file counts by its name, and when it is the one chosen the student is told
    why it is not graded (it is never read).
    """
    candidates: list[Path] = []
    refused: dict[Path, str] = {}
    _walk_upload(directory, directory, candidates, refused)
    candidates.sort()
    if len(candidates) == 1:
        return refused.get(candidates[0], candidates[0])
    preferred = [path for path in candidates if path.stem == PREFERRED_STEM]
    if len(preferred) == 1:
        return refused.get(preferred[0], preferred[0])
    found = ", ".join(str(path.relative_to(directory)) for path in candidates) or "no .py or .ipynb file"
    links = "".join(f" {reason}" for path, reason in sorted(refused.items()) if path not in candidates)
    return (
        f"Expected one Python file (.py) or Jupyter notebook (.ipynb) with your functions, ideally named {PREFERRED_STEM}.py; "  # noqa: E501
        f"found {found}. Submit exactly one such file.{links}"
    )


def _walk_upload(
    directory: Path, top: Path, candidates: list[Path], refused: dict[Path, str], depth: int = 0
) -> None:
    """Gradable names under ``directory`` (hidden ones skipped), never following a link."""
    if depth > MAX_UPLOAD_DEPTH:
        refused[directory] = (
            f"{directory.relative_to(top)} is deeper than {MAX_UPLOAD_DEPTH} folders: not read."
        )
        return
    try:
        with os.scandir(directory) as listing:
            entries = sorted(listing, key=lambda entry: entry.name)
    except OSError:
        return
    for entry in entries:
        if entry.name.startswith("."):
            continue
        path = Path(entry.path)
        try:
            info = entry.stat(follow_symlinks=False)
        except OSError:
            continue
        gradable = path.suffix.lower() in SUBMISSION_SUFFIXES
        if stat.S_ISDIR(info.st_mode):
            _walk_upload(path, top, candidates, refused, depth + 1)
            continue
        if gradable:
            candidates.append(path)
        if stat.S_ISLNK(info.st_mode) or (gradable and (not stat.S_ISREG(info.st_mode) or info.st_nlink > 1)):
            refused[path] = _refusal(path, top)


def _refusal(path: Path, top: Path) -> str:
    """Why an upload's entry is not read (`grader.submission.untrusted_file` says it as it would on reading
    it)."""
    try:
        read_untrusted(path, limit=0, root=top)
    except UnsafeFile as error:
        return str(error)
    return f"{path.relative_to(top)} is not a regular file: it was not read."


def bundle(out: Path, *, config: Path | None, secret: str | None = None) -> Path:
    """Write the Gradescope autograder zip.

    It holds ``setup.sh`` (Debian/Ubuntu packages, Python 3.11 and a virtualenv with this gymgrade),
    ``run_autograder``, the assignment configuration, the seed secret, and the source of this gymgrade's
    ``grader`` and ``reference`` packages with a minimal ``pyproject.toml`` (so the autograder grades
    exactly as this installation does, without reaching any package index for gymgrade itself).

    Each upload is graded on its own seed, derived from the secret and the upload's identity
    (`grader.seeds.upload_seed`); keep the zip: with it and an upload's ``submission_metadata.json``,
    ``gymgrade gradescope-seed`` gives that upload's seed and regrades it identically.

    Args:
        out: The zip to write.
        config: Assignment configuration; the bundled one when None.
        secret: The seed secret (hex); a fresh one when None (the usual case: tests pass one).

    Returns:
        ``out``.
    """
    config_text = (config or DEFAULT_CONFIG_PATH).read_text(encoding="utf-8")
    source_root = Path(grader.__file__).resolve().parents[1]
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        _add(archive, "setup.sh", SETUP_SH, executable=True)
        _add(archive, "run_autograder", RUN_AUTOGRADER, executable=True)
        _add(archive, "assignment.toml", config_text)
        _add(archive, SECRET_FILE, (secret or new_secret()) + "\n", private=True)
        _add(archive, "gymgrade/pyproject.toml", _pyproject(_dependencies(source_root)))
        for package in PROJECT_PACKAGES:
            for path in sorted((source_root / package).rglob("*")):
                if path.is_file() and "__pycache__" not in path.parts and path.suffix != ".pyc":
                    relative = path.relative_to(source_root).as_posix()
                    _add(archive, f"gymgrade/{relative}", path.read_bytes())
    out.write_bytes(buffer.getvalue())
    return out


def bundle_secret(archive_path: Path) -> str:
    """The seed secret kept in an autograder zip (what ``gymgrade gradescope-seed`` reads).

    Raises:
        GradescopeError: The file is not a zip, or a zip without a seed secret (an older bundle graded
            every upload on one seed: its ``run_autograder`` names it).
    """
    try:
        with zipfile.ZipFile(archive_path) as archive:
            return archive.read(SECRET_FILE).decode("ascii").strip()
    except (OSError, zipfile.BadZipFile, KeyError, UnicodeDecodeError) as error:
        raise GradescopeError(
            f"expected an autograder zip built by gymgrade gradescope-bundle with a {SECRET_FILE} file; "
            f"{archive_path} gave {type(error).__name__}: {error}. Pass the zip you uploaded to Gradescope."
        ) from error


def bundle_config(archive_path: Path) -> str:
    """The assignment configuration (TOML text) kept in an autograder zip."""
    with zipfile.ZipFile(archive_path) as archive:
        return archive.read("assignment.toml").decode("utf-8")


def _add(
    archive: zipfile.ZipFile,
    name: str,
    content: str | bytes,
    *,
    executable: bool = False,
    private: bool = False,
) -> None:
    info = zipfile.ZipInfo(name, date_time=(2026, 1, 1, 0, 0, 0))
    mode = 0o755 if executable else 0o600 if private else 0o644
    info.external_attr = (stat.S_IFREG | mode) << 16
    info.compress_type = zipfile.ZIP_DEFLATED
    archive.writestr(info, content)


def _dependencies(source_root: Path) -> list[str]:
    """The project's runtime requirements: from its pyproject.toml in a source tree, else as installed."""
    pyproject = source_root / "pyproject.toml"
    if pyproject.is_file():
        declared: list[str] = tomllib.loads(pyproject.read_text(encoding="utf-8"))["project"]["dependencies"]
        return declared
    return [requirement for requirement in requires("gymgrade") or [] if "extra ==" not in requirement]


def _pyproject(dependencies: list[str]) -> str:
    listed = ",\n".join(f"    {json.dumps(requirement)}" for requirement in dependencies)
    return (
        '[build-system]\nrequires = ["setuptools>=69", "wheel"]\nbuild-backend = "setuptools.build_meta"\n\n'
        f'[project]\nname = "gymgrade"\nversion = "{version("gymgrade")}"\nrequires-python = ">=3.11"\n'
        f"dependencies = [\n{listed},\n]\n\n"
        '[project.scripts]\ngymgrade = "grader.cli:main"\n\n'
        '[tool.setuptools.packages.find]\ninclude = ["reference*", "grader*"]\n\n'
        '[tool.setuptools.package-data]\n"*" = ["*.toml", "*.ini", "*.md", "py.typed"]\n'
    )


def default_root() -> Path:
    """Gradescope's root, ``/autograder``, or ``GYMGRADE_AUTOGRADER_ROOT`` (tests use a temporary one)."""
    return Path(os.environ.get("GYMGRADE_AUTOGRADER_ROOT", str(DEFAULT_ROOT)))


def run_autograder(
    root: Path, *, upload: UploadSeed, config: Path | None, workers: int | None
) -> GradescopeResults:
    """Grade ``<root>/submission`` into ``<root>/results/results.json`` (what ``run_autograder`` runs).

    Never raises for a student's file: no file, a bad file, a crash are all results. The policy is
    ``ALLOW_FALLBACK``: Gradescope's containers do not allow every isolation layer (see
    docs/operations.md, "Isolation on Gradescope"), and the results' output names the missing ones.

    Args:
        root: The autograder's root (``/autograder``).
        upload: The upload's grading seed (`seed_for_upload`), recorded for the instructor.
        config: Assignment configuration; the bundled one when None.
        workers: Parallel workers; the machine's cores when None.
    """
    from grader.grading.grade import grade_submission
    from grader.sandbox import IsolationPolicy

    picked = pick_submission(root / "submission")
    with tempfile.TemporaryDirectory(prefix="gymgrade-upload-") as private:
        copy = _private_copy(picked, root / "submission", Path(private))
        if isinstance(copy, str):
            graded = failed_run(copy)
        else:
            try:
                report = grade_submission(
                    copy,
                    seed=upload.seed,
                    workers=workers,
                    policy=IsolationPolicy.ALLOW_FALLBACK,
                    config=config,
                )
            except (
                Exception
            ) as error:  # results.json must exist whatever happens, or Gradescope shows nothing
                graded = failed_run(
                    f"The autograder failed (not your fault; please tell your instructor): "
                    f"{type(error).__name__}: {error}"
                )
            else:
                graded = results(report, upload=upload)
    if graded.extra_data is None:
        graded = graded.model_copy(update={"extra_data": seed_record(upload)})
    target = root / "results" / "results.json"
    target.parent.mkdir(parents=True, exist_ok=True)
    target.write_text(graded.to_json(), encoding="utf-8")
    return graded


def _private_copy(picked: Path | str, submission: Path, private: Path) -> Path | str:
    """The chosen upload file, read once without following a link anywhere below ``submission``, as a
    copy in the grader's private folder (what is graded); or why it cannot be graded."""
    if isinstance(picked, str):
        return picked
    from grader.grading.grade import READ_LIMIT

    try:
        data = read_untrusted(picked, limit=READ_LIMIT, root=submission)
    except UnsafeFile as error:
        return str(error)
    copy = private / picked.name
    copy.write_bytes(data)
    return copy


def upload_seed_of(archive_path: Path, metadata_path: Path) -> UploadSeed:
    """The seed the bundle gave the upload that ``metadata_path`` describes (the instructor's side).

    Raises:
        GradescopeError: The zip has no secret, or the metadata cannot be read.
    """
    identity = read_metadata(metadata_path).identity()
    return UploadSeed(upload_seed(bundle_secret(archive_path), identity), "derived", identity)


def regrade_upload(
    archive_path: Path, metadata_path: Path, submission: Path, out: Path, *, workers: int | None = None
) -> GradescopeResults:
    """Grade a recorded upload again exactly as the bundle did: same secret, metadata and configuration.

    Args:
        archive_path: The autograder zip the upload was graded with.
        metadata_path: The upload's ``submission_metadata.json``.
        submission: The upload's file, or the directory of its files.
        out: Where to write its ``results.json``.
        workers: Parallel workers; the machine's cores when None.

    Raises:
        GradescopeError: The zip has no secret, or the metadata cannot be read.
    """
    upload = upload_seed_of(archive_path, metadata_path)
    with tempfile.TemporaryDirectory(prefix="gymgrade-regrade-") as temporary:
        root = Path(temporary)
        (root / "source").mkdir()
        config = root / "source" / "assignment.toml"
        config.write_text(bundle_config(archive_path), encoding="utf-8")
        # Links are copied as links (never followed), so the regrade refuses them as the bundle did.
        if submission.is_dir() and not submission.is_symlink():
            shutil.copytree(submission, root / "submission", symlinks=True)
        else:
            (root / "submission").mkdir()
            shutil.copy2(submission, root / "submission" / submission.name, follow_symlinks=False)
        graded = run_autograder(root, upload=upload, config=config, workers=workers)
        shutil.copy2(root / "results" / "results.json", out)
    return graded


SETUP_SH = f"""#!/usr/bin/env bash
# Gradescope setup: runs once, as root, on Gradescope's Ubuntu image, from /autograder/source.
set -euo pipefail
cd "$(dirname "$0")"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
# bubblewrap + libseccomp: the sandbox's namespaces and system-call filter (used where the container
# allows them); Python 3.11 from the distribution (Ubuntu 22.04's default python3 is 3.10).
apt-get install -y -qq --no-install-recommends bubblewrap libseccomp2 {BUNDLE_PYTHON} \\
  {BUNDLE_PYTHON}-venv ca-certificates >/dev/null
{BUNDLE_PYTHON} -m venv {BUNDLE_VENV}
{BUNDLE_VENV}/bin/python -m pip install --quiet --disable-pip-version-check --upgrade pip
{BUNDLE_VENV}/bin/python -m pip install --quiet --disable-pip-version-check ./gymgrade
{BUNDLE_VENV}/bin/gymgrade --help >/dev/null
# The seed secret is the grader's alone: student code runs as an unprivileged uid.
chmod 600 {SECRET_FILE}
"""

RUN_AUTOGRADER = f"""#!/usr/bin/env bash
# Gradescope runs this for every submission: grade /autograder/submission/* into
# /autograder/results/results.json, on a seed derived from the bundle's secret and this upload's
# submission_metadata.json (never passed on a command line, where other processes could read it).
# GYMGRADE_AUTOGRADER_ROOT and GYMGRADE_COMMAND move it (tests).
set -uo pipefail
root="${{GYMGRADE_AUTOGRADER_ROOT:-/autograder}}"
command="${{GYMGRADE_COMMAND:-{BUNDLE_VENV}/bin/gymgrade}}"
# Only the grader (root) reads the secret and the metadata (which embeds earlier uploads' results).
chmod 600 "$root/source/{SECRET_FILE}" "$root/{METADATA_FILE}" 2>/dev/null
# $command is split on spaces on purpose: tests pass "python3 -m grader.cli".
$command gradescope-run --root "$root" --secret-file "$root/source/{SECRET_FILE}" \\
  --config "$root/source/assignment.toml"
"""
