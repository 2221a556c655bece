"""Shared by the grading tests: sample paths and a fast assignment configuration."""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
SUBMISSIONS = ROOT / "submissions"
CLASSIC_COMPLETE = SUBMISSIONS / "classic_complete.py"
DEFAULT_CONFIG = ROOT / "grader" / "lab" / "assignment.toml"

FAST_OVERRIDES: dict[str, dict[str, Any]] = {
    # Verdicts that do not depend on size: the lab solution's car() reaches the flag every time, and
    # 2000 random games keep the exact binomial test's false-fail probability at the configured 1e-6.
    "random_blackjack": {"games": 2000},
    "car": {"calls": 20},
    "cartpole": {"calls": 20},
}


def write_config(path: Path, overrides: dict[str, dict[str, Any]], base: Path = DEFAULT_CONFIG) -> Path:
    """Write an assignment configuration (the bundled one unless `base` names an edition's) with some problem
    fields replaced; return the path."""
    config = tomllib.loads(base.read_text(encoding="utf-8"))
    for problem, fields in overrides.items():
        config["problems"][problem].update(fields)
    path.write_text(_toml(config), encoding="utf-8")
    return path


def _toml(config: dict[str, Any]) -> str:
    lines: list[str] = [f"edition = {_value(config['edition'])}"] if "edition" in config else []
    for problem, fields in config["problems"].items():
        lines.append(f"[problems.{problem}]")
        lines += [f"{name} = {_value(value)}" for name, value in fields.items()]
    lines.append("[sandbox]")
    lines += [f"{name} = {_value(value)}" for name, value in config["sandbox"].items()]
    return "\n".join(lines) + "\n"


def _value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, list):
        return "[" + ", ".join(_value(item) for item in value) + "]"
    return repr(value)
