"""The README's two commands are the project's contract with a new user."""

import re
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def readme_commands():
    text = (ROOT / "README.md").read_text()
    block = re.search(r"```bash\n(.*?)```", text, re.S).group(1)
    return [line for line in block.splitlines() if line.strip()]


def test_readme_opens_with_exactly_two_commands():
    cmds = readme_commands()
    assert len(cmds) == 2
    assert cmds[0].startswith("pip install ") and "granulargas run configs/" in cmds[0]
    assert cmds[1].startswith("pip install ") and "pytest" in cmds[1]
    # the test command installs the docs extra, so CI builds the documentation (tests/test_docs.py)
    assert "docs" in cmds[1].split("&&")[0]


def test_ci_runs_the_readme_test_command():
    out = subprocess.run(
        ["bash", "-c", "grep -m1 -E '^pip install .*pytest' README.md"],
        cwd=ROOT, capture_output=True, text=True, check=True,
    )
    assert out.stdout.strip() == readme_commands()[1]
    assert "grep -m1 -E '^pip install .*pytest' README.md" in (ROOT / ".ci" / "run").read_text()


def test_main_job_config_exists():
    config = readme_commands()[0].split("granulargas run ")[1].split()[0]
    assert (ROOT / config).is_file()


def test_readme_python_block_runs(tmp_path, monkeypatch, capsys):
    """The README's "From Python" block, run in a fresh directory with the quickstart config."""
    import shutil

    import matplotlib
    import pytest

    pytest.importorskip("pandas", reason="the [pandas] extra")
    matplotlib.use("Agg")
    block = re.search(r"## From Python\n\n```python\n(.*?)```", (ROOT / "README.md").read_text(), re.S).group(1)
    (tmp_path / "configs").mkdir()
    (tmp_path / "runs").mkdir()
    shutil.copy(ROOT / "configs" / "quickstart.toml", tmp_path / "configs")
    monkeypatch.chdir(tmp_path)
    exec(compile(block, "README.md", "exec"), {})
    collisions, temperature, eps = capsys.readouterr().out.split()
    assert int(collisions) > 0 and 0 < float(temperature) < 1
    assert float(eps) == pytest.approx(0.8921, abs=1e-4) and (tmp_path / "runs" / "nb.h5").is_file()
