"""The documentation site, the generated references and the repository files users expect."""

import importlib.util
import os
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

import granulargas

ROOT = Path(__file__).resolve().parents[1]
DOCS_EXTRA = ("mkdocs", "material", "mkdocstrings", "mkdocstrings_handlers.python")


def _missing_docs_extra():
    return [m for m in DOCS_EXTRA if importlib.util.find_spec(m.split(".")[0]) is None
            or importlib.util.find_spec(m) is None]


def _generator():
    """docs/hooks/generate.py, the build-time generator of the reference pages."""
    spec = importlib.util.spec_from_file_location("granulargas_docs_generate", ROOT / "docs/hooks/generate.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def _pyproject():
    return tomllib.loads((ROOT / "pyproject.toml").read_text())


def test_docs_build_strict(tmp_path):
    """mkdocs build --strict: no warning (broken link or anchor, missing image, page
    outside the navigation, unparsable docstring, failing generator)."""
    missing = _missing_docs_extra()
    if missing:
        pytest.skip(f"docs extra not installed (pip install '.[docs]'): missing {', '.join(missing)}")
    before = sorted(p.relative_to(ROOT) for p in (ROOT / "docs").rglob("*") if "__pycache__" not in p.parts)
    site_existed = (ROOT / "site").exists()
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1")
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT), env.get("PYTHONPATH")]))
    out = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")],
                         cwd=ROOT, env=env, capture_output=True, text=True)
    assert out.returncode == 0, out.stdout + out.stderr
    assert (tmp_path / "site" / "index.html").is_file()
    assert (tmp_path / "site" / "configuration" / "index.html").is_file()
    after = sorted(p.relative_to(ROOT) for p in (ROOT / "docs").rglob("*") if "__pycache__" not in p.parts)
    assert after == before, "the build wrote into docs/"
    assert (ROOT / "site").exists() == site_existed, "the build wrote site/ into the source tree"


def _documented_keys():
    return {e.dotted for e in _generator().config_entries()}


def _keys_of(toml_text: str):
    data = tomllib.loads(toml_text)
    keys = set()

    def walk(prefix, node):
        for k, v in node.items():
            dotted = f"{prefix}.{k}" if prefix else k
            if isinstance(v, dict) and dotted not in ("particles.diameter",):
                walk(dotted, v)
            else:
                keys.add(dotted)
                if isinstance(v, dict):
                    keys.update(f"{dotted}.{kk}" for kk in v)

    walk("", data)
    return keys


def test_config_reference_lists_every_key_the_config_writer_and_the_examples_use():
    """Keys written by the resolved-config writer (every optional key set) and keys used
    by the example configs are all in the generated reference."""
    from granulargas.io.config import parse_config

    documented = _documented_keys()
    full = [
        """[system]\ndimension = 2\nparticles = 100\npacking_fraction = 0.1\nseed = 3
[particles]\ndiameter = { min = 0.8, max = 1.2 }\ndensity = 2.0
[initial]\ntemperature = 2.0\nfrom = "x.h5"
[collision]\nmodel = "constant"\nrestitution = 0.9\ntc_time = 1e-4
[run]\nend_time = 10.0\ncollisions_per_particle = 5
[output]\nfile = "a.h5"\nsnapshots = 5\nfirst_snapshot = 0.5\nobservables_interval = 0.1\n""",
        """[collision]\nmodel = "viscoelastic"\ncontact_end = "force"
[collision.material]\nyoung_modulus = 1e7\npoisson_ratio = 0.3\ndissipation_time = 1e-5
diameter = 0.01\ndensity = 1000.0\nspeed_unit = 1.0
[run]\nend_time = 10.0\n[output]\nsnapshot_interval = 1.0\n""",
    ]
    written = set()
    for text in full:
        written |= _keys_of(parse_config(text).to_toml())
    examples = set()
    for path in (ROOT / "configs").glob("*.toml"):
        examples |= _keys_of(path.read_text())
    assert written - documented == set()
    assert examples - documented == set()
    assert len(written) >= 25


def test_config_reference_keys_are_accepted_by_the_validator():
    """No key in the reference is one the validator calls unknown."""
    g = _generator()
    for e in g.config_entries():
        section, key = e.section, e.key
        context = g.MEANINGS.get((section, key), {}).get("context", {})
        message = g._probe(section, key, "__not_a_value__", context) or ""
        assert "unknown" not in message, (e.dotted, message)


def test_citation_cff_matches_the_package():
    yaml = pytest.importorskip("yaml", reason="PyYAML (a dependency of the docs extra) not installed")
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))
    project = _pyproject()["project"]
    assert cff["cff-version"] == "1.2.0"
    assert cff["version"] == project["version"] == granulargas.__version__
    assert cff["license"] == project["license"]["text"] == "MIT"
    assert [a["name"] for a in cff["authors"]] == [a["name"] for a in project["authors"]]
    assert cff["title"] and cff["message"]
    paper = cff["references"][0]
    assert paper["title"] == "Contact of viscoelastic spheres" and paper["year"] == 1997
    assert [a["family-names"] for a in paper["authors"]] == ["Schwager", "Pöschel"]


def test_license_file_is_the_license_pyproject_names():
    assert _pyproject()["project"]["license"]["text"] == "MIT"
    assert (ROOT / "LICENSE").read_text().startswith("MIT License")


def test_changelog_has_unreleased_and_the_current_version():
    text = (ROOT / "CHANGELOG.md").read_text()
    assert "## [Unreleased]" in text
    assert re.search(rf"^## \[{re.escape(granulargas.__version__)}\] - \d{{4}}-\d{{2}}-\d{{2}}$", text, re.M)


def test_version_command():
    out = subprocess.run([sys.executable, "-m", "granulargas", "--version"], capture_output=True, text=True,
                         cwd=ROOT, env=dict(os.environ, PYTHONPATH=str(ROOT)))
    assert out.returncode == 0
    assert out.stdout.strip() == f"granulargas {_pyproject()['project']['version']}"


def test_readme_links_point_to_files():
    text = (ROOT / "README.md").read_text()
    targets = re.findall(r"\]\(((?!https?:)[^)#\s]+)(?:#[^)]*)?\)", text)
    assert targets
    missing = [t for t in targets if not (ROOT / t).exists()]
    assert missing == []


def test_readme_is_a_guide():
    text = (ROOT / "README.md").read_text()
    assert len(text.splitlines()) <= 300
    assert len(text.encode()) <= 20_000
