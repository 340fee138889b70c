"""The scripts the repository names exist, and every figure and measured table of the docs names one.

``scripts/`` is sorted by purpose (ARCHITECTURE.md, "Scripts"): a reader who meets a figure or a
table of numbers in the documentation finds, in the same section, the command that makes it,
and that command's file exists.
"""

import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = re.compile(r"scripts/[\w/.-]+?\.py\b")
COMMAND = re.compile(r"scripts/[\w/.-]+?\.py\b|granulargas (run|analyze|advise|sweep|compile)\b")
DOCS = sorted((ROOT / "docs").glob("*.md"))

#: tables that hold no measurement (references, maps, summaries that link to the measured ones),
#: by page and the first cell of their header row
NOT_MEASURED = {
    ("dsmc.md", "comparison"), ("validation.md", "comparison"), ("engine.md", "what happens"),
    ("running.md", "config"), ("running.md", "code"), ("theory.md", "quantity"), ("writing-docs.md", "path"),
}


def _named_files():
    """Every file whose text may name a script: docs, README, ARCHITECTURE, code, tests, scripts, configs."""
    files = [ROOT / "README.md", ROOT / "ARCHITECTURE.md", ROOT / "pyproject.toml", *DOCS,
             *(ROOT / "docs" / "api").glob("*.md")]
    for sub, pattern in (("granulargas", "*.py"), ("tests", "*.py"), ("scripts", "*.py"), ("configs", "*.toml"),
                         ("granulargas", "*.csv")):
        files += sorted((ROOT / sub).rglob(pattern))
    return files


def _sections(lines):
    """(start, end) line ranges of the page's sections (a heading up to the next heading)."""
    heads = [i for i, line in enumerate(lines) if line.startswith("#")] + [len(lines)]
    return [(0, heads[0])] + list(zip(heads[:-1], heads[1:]))


def _section_text(lines, i):
    for a, b in _sections(lines):
        if a <= i < b:
            return "\n".join(lines[a:b])
    return ""


def _tables(lines):
    """(line index, first header cell) of every Markdown table."""
    out = []
    for i in range(len(lines) - 1):
        if (lines[i].startswith("|") and (i == 0 or not lines[i - 1].startswith("|"))
                and re.fullmatch(r"\|[\s:|-]+\|", lines[i + 1].strip())):
            out.append((i, lines[i].strip("| ").split("|")[0].strip()))
    return out


def test_every_named_script_exists():
    missing = []
    for f in _named_files():
        for m in SCRIPT.finditer(f.read_text(errors="replace")):
            if not (ROOT / m.group(0)).is_file():
                missing.append(f"{f.relative_to(ROOT)}: {m.group(0)}")
    for r in json.loads((ROOT / "docs" / "performance" / "results.json").read_text())["records"]:
        for m in SCRIPT.finditer(r["command"]):
            if not (ROOT / m.group(0)).is_file():
                missing.append(f"docs/performance/results.json: {r['table']} {r['id']}: {m.group(0)}")
    assert not missing, "named scripts that do not exist:\n" + "\n".join(missing)


def test_every_docs_figure_names_the_command_that_makes_it():
    bare = []
    for page in DOCS:
        lines = page.read_text().splitlines()
        for i, line in enumerate(lines):
            shown = line.strip().startswith("![") and re.search(r"\]\(figures/[^)]+\)", line)
            if shown and not COMMAND.search(_section_text(lines, i)):
                bare.append(f"{page.name}:{i + 1}: {line.strip()}")
    assert not bare, "figures whose section names no command:\n" + "\n".join(bare)


def test_every_measured_table_names_the_command_that_makes_it():
    bare = []
    for page in DOCS:
        lines = page.read_text().splitlines()
        for i, head in _tables(lines):
            if (page.name, head) not in NOT_MEASURED and not COMMAND.search(_section_text(lines, i)):
                bare.append(f"{page.name}:{i + 1}: {lines[i][:80]}")
    assert not bare, "tables whose section names no command:\n" + "\n".join(bare)


def test_the_not_measured_tables_are_still_there():
    # the exemptions above name real tables (a renamed table must not stay exempt by accident)
    found = {(page.name, head) for page in DOCS for _, head in _tables(page.read_text().splitlines())}
    assert NOT_MEASURED <= found, NOT_MEASURED - found


def test_scripts_are_sorted_into_folders_by_purpose():
    top = sorted(p.name for p in (ROOT / "scripts").glob("*.py"))
    assert top == [], f"scripts at the top level of scripts/ (sort them into a folder by purpose): {top}"
    folders = sorted(p.name for p in (ROOT / "scripts").iterdir() if p.is_dir() and p.name != "__pycache__")
    architecture = (ROOT / "ARCHITECTURE.md").read_text()
    unmapped = [f for f in folders if f"scripts/{f}/" not in architecture]
    assert not unmapped, f"folders of scripts/ that ARCHITECTURE.md's map does not describe: {unmapped}"


@pytest.mark.parametrize("text, found", [("python scripts/validation/haff_comparison.py --seeds 3", True),
                                         ("`granulargas analyze run.h5`", True), ("made by hand", False)])
def test_the_command_pattern(text, found):
    assert bool(COMMAND.search(text)) is found
