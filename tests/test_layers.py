"""The package's layers (ARCHITECTURE.md) are contracts of import-linter, checked here.

``lint-imports`` reads the contracts from pyproject.toml; a module that imports
from a layer above its own, or a circle between layers, breaks them. The second
test shows that the check can fail: a copy of the package with one upward import
added is rejected.
"""

import shutil
import subprocess
import sys
from pathlib import Path

import importlinter  # noqa: F401  (the 'test' extra installs it: a missing linter fails, it does not skip)
import pytest

ROOT = Path(__file__).resolve().parents[1]

_LINT = ("import sys; from importlinter.cli import lint_imports; "
         "sys.exit(lint_imports(config_filename=sys.argv[1], no_cache=True, no_logo=True))")


def lint(root: Path) -> subprocess.CompletedProcess:
    """``lint-imports`` on the package under ``root`` with ``root/pyproject.toml``."""
    env = {"PATH": "/usr/bin:/bin", "PYTHONPATH": str(root), "HOME": str(root)}
    return subprocess.run([sys.executable, "-c", _LINT, str(root / "pyproject.toml")], cwd=root, env=env,
                          capture_output=True, text=True, timeout=300)


def test_import_contracts_are_kept():
    out = lint(ROOT)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "BROKEN" not in out.stdout and "KEPT" in out.stdout


@pytest.mark.parametrize("module, upward", [
    ("contact/material.py", "import granulargas.theory"),         # contact below theory
    ("engine/rules.py", "from granulargas.io import h5md"),       # engine below io
    ("run/validity.py", "import granulargas.cli._args"),          # run below cli
])
def test_an_upward_import_breaks_the_layers(tmp_path, module, upward):
    shutil.copytree(ROOT / "granulargas", tmp_path / "granulargas",
                    ignore=shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc"))
    shutil.copy(ROOT / "pyproject.toml", tmp_path / "pyproject.toml")
    assert lint(tmp_path).returncode == 0  # the copy itself is clean
    path = tmp_path / "granulargas" / module
    path.write_text(path.read_text() + f"\n{upward}  # an upward import\n")
    out = lint(tmp_path)
    assert out.returncode != 0
    assert "BROKEN" in out.stdout and upward.split()[1].split(".")[1] in out.stdout


def test_no_import_circle_between_modules():
    """No module reaches itself through imports (strongly connected components of size 1)."""
    import grimp

    graph = grimp.build_graph("granulargas", cache_dir=None)
    edges = {m: {x for x in graph.find_modules_directly_imported_by(m) if x.startswith("granulargas")}
             for m in graph.modules if m.startswith("granulargas")}
    circles = [(m, x) for m in edges for x in edges[m] if x == m or graph.chain_exists(importer=x, imported=m)]
    assert not circles
