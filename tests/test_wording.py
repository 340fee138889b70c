"""The repository speaks of the software only.

Docs, docstrings, comments, test names, scripts and configs refer to nothing
outside the repository, cite papers by name (the word "seed" means a random
seed), and do not date the code by how it was built; history belongs in git
and in CHANGELOG.md.
"""

import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

# this file holds the patterns themselves and is left out of the search
OUTSIDE = "|".join(["issue [0-9]", "seed (eq|fig)", r"physics\.md", "shared/", "physics notes"])
DATING = "|".join([r"\bsession\b", "before this change", "former engine", "the engine before",
                   "old engine", "new engine", "earlier engine", "previous engine"])


def _git_grep(pattern, *exclude):
    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("not a git checkout (git grep needs one)")
    exclude = ("tests/test_wording.py", *exclude)
    out = subprocess.run(["git", "grep", "-nEi", pattern, "--", ".", *[f":!{e}" for e in exclude]],
                         cwd=ROOT, capture_output=True, text=True)
    assert out.returncode in (0, 1), out.stderr
    return out.stdout.splitlines()


def test_nothing_refers_outside_the_repository_or_to_a_paper_as_seed():
    assert _git_grep(OUTSIDE) == []


def test_no_line_dates_the_code_by_how_it_was_built():
    assert _git_grep(DATING, "CHANGELOG.md") == []
