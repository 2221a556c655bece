"""The child's light IPython: the lab's two display calls without importing IPython, the real IPython for
anything else. Each case runs in a fresh interpreter (what is imported is the point)."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
INSTALL = f"""
import sys
sys.path.insert(1, {str(ROOT)!r})
from grader.sandbox.child.light_ipython import LightIPython
sys.meta_path.insert(0, LightIPython())
"""


def _run(code: str, *, light: bool = True, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    source = (INSTALL if light else "") + textwrap.dedent(code)
    command = [sys.executable, "-c", source]
    return subprocess.run(command, capture_output=True, text=True, check=False, timeout=120, cwd=cwd)


def _facts(code: str) -> dict[str, object]:
    done = _run(textwrap.dedent(code) + "\nimport json, sys\nprint(json.dumps(facts))\n")
    assert done.returncode == 0, done.stderr
    result: dict[str, object] = json.loads(done.stdout.strip().splitlines()[-1])
    return result


@pytest.mark.parametrize(
    "code",
    [
        "from IPython.display import clear_output\nclear_output(wait=True)\nclear_output()",
        "from IPython import display\ndisplay.clear_output(wait=True)\ndisplay.display(1, 'two', [3])",
        "import IPython.display\nIPython.display.clear_output()\nIPython.display.display({'a': 1})",
        "from IPython.display import display, clear_output\n"
        "for i in range(3):\n    clear_output(wait=True)\n    display(i)",
    ],
    ids=["clear_output", "from-IPython-import-display", "import-IPython.display", "both"],
)
def test_the_lab_calls_print_what_ipython_prints_without_loading_it(code: str) -> None:
    light, real = (
        _run(code + "\nimport sys\nprint('loaded:', 'IPython.core' in sys.modules)"),
        _run(code, light=False),
    )
    assert light.returncode == real.returncode == 0, light.stderr + real.stderr
    assert light.stdout == real.stdout + "loaded: False\n"
    assert light.stderr == real.stderr


@pytest.mark.slow
def test_anything_else_of_ipython_is_the_real_one() -> None:
    facts = _facts("""
        from IPython.display import clear_output
        from IPython.display import HTML, Image
        import IPython
        from IPython import get_ipython
        facts = {
            "html": HTML.__module__, "image": Image.__module__, "version": IPython.__version__,
            "shell": get_ipython() is None, "real": hasattr(sys.modules["IPython"], "__file__"),
            "html_rendered": HTML("<b>x</b>")._repr_html_(),
        }
    """)
    assert facts == {
        "html": "IPython.core.display",
        "image": "IPython.core.display",
        "version": _real_version(),
        "shell": True,
        "real": True,
        "html_rendered": "<b>x</b>",
    }


def test_a_submodule_imported_after_the_light_modules_is_loaded_once() -> None:
    facts = _facts("""
        from IPython import display
        display.clear_output()
        from IPython.core.interactiveshell import InteractiveShell
        import IPython.core.interactiveshell as shell_module
        import IPython.lib.pretty
        import IPython
        facts = {
            "same": shell_module.InteractiveShell is InteractiveShell,
            "in_modules": sys.modules["IPython.core.interactiveshell"] is shell_module,
            "spec": shell_module.__spec__.name == "IPython.core.interactiveshell"
            and shell_module.__spec__.origin == shell_module.__file__,
            "package": IPython is sys.modules["IPython"] and hasattr(IPython, "__file__"),
            "attribute": IPython.core.interactiveshell is shell_module,
            "pretty": IPython.lib.pretty.pretty([1]),
            "initialized": InteractiveShell.initialized(),
        }
    """)
    assert facts == {
        "same": True,
        "in_modules": True,
        "spec": True,
        "package": True,
        "attribute": True,
        "pretty": "[1]",
        "initialized": False,
    }


def test_star_import_gives_all_of_ipython_display() -> None:
    facts = _facts("""
        from IPython.display import *
        wanted = ("HTML", "Markdown", "clear_output", "display", "Image")
        facts = {"names": sorted(name for name in wanted if name in globals())}
    """)
    assert facts == {"names": ["HTML", "Image", "Markdown", "clear_output", "display"]}


def test_a_missing_name_is_still_an_import_error() -> None:
    done = _run("from IPython.display import no_such_function")
    assert done.returncode == 1
    assert "cannot import name 'no_such_function'" in done.stderr


def _real_version() -> str:
    done = _run("import IPython; print(IPython.__version__)", light=False)
    return done.stdout.strip()


def test_a_students_own_ipython_module_is_theirs(tmp_path: Path) -> None:
    (tmp_path / "IPython.py").write_text(
        "def clear_output(wait=False):\n    print('mine')\n", encoding="utf-8"
    )
    done = _run("import IPython\nIPython.clear_output()\nprint(IPython.__file__)", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == ["mine", str(tmp_path / "IPython.py")]
