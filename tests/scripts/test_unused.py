"""scripts/unused.py lists the names only tests read, and says what may keep a listed name alive."""

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "unused.py"


@pytest.fixture(scope="module")
def unused() -> ModuleType:
    spec = importlib.util.spec_from_file_location("unused_script", SCRIPT)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses resolve the module's annotations through sys.modules
    spec.loader.exec_module(module)
    return module


def _tree(root: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    return root


def test_lists_what_only_tests_read_and_what_nothing_reads(unused: ModuleType, tmp_path: Path) -> None:
    root = _tree(
        tmp_path,
        {
            "ARCHITECTURE.md": "`documented()` is public API.\n",
            "pyproject.toml": "",
            "grader/core.py": (
                "LIMIT = 3\n"
                "def used():\n    return LIMIT\n"
                "def tested():\n    return 1\n"
                "def dead():\n    return 2\n"
                "def documented():\n    return 3\n"
                "@register\ndef route():\n    return 4\n"
                "def pytest_configure(config):\n    pass\n"
            ),
            "grader/__init__.py": "from grader.core import tested, used\n__all__ = ['tested']\n",
            "api/main.py": "from grader.core import used\nused()\n",
            "tests/test_core.py": "from grader.core import tested\ntested()\n",
        },
    )
    listed = {definition.name: (where, keepers) for definition, where, keepers in unused.unused(root)}
    assert listed == {
        "tested": ("tests", []),
        "dead": ("nowhere", []),
        "documented": ("nowhere", ["named in ARCHITECTURE.md or pyproject.toml"]),
        "route": (
            "nowhere",
            ["decorated, or a method of a subclass (a framework may call it)"],
        ),
        "pytest_configure": ("nowhere", ["pytest hook, pytest test or dunder"]),
    }


@pytest.mark.slow
def test_every_name_the_project_leaves_unread_is_one_a_framework_reaches(unused: ModuleType) -> None:
    unexplained = [
        f"{definition.path.name}: {definition.name} read by {where}"
        for definition, where, keepers in unused.unused()
        if not keepers
    ]
    assert unexplained == [], (
        "nothing outside tests/ reads these names: remove them (and their tests), or record why they stay "
        "in KEPT of scripts/unused.py"
    )
