"""The documentation site, the generated references and the repository files users expect."""

import importlib.util
import os
import re
import subprocess
import sys
import tomllib
from html.parser import HTMLParser
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


@pytest.fixture(scope="module")
def built_site(tmp_path_factory):
    """``mkdocs build --strict`` into a temporary directory, once for the tests below:
    (the finished process, the site directory, the docs/ tree before and after, whether
    site/ existed in the source tree before)."""
    missing = _missing_docs_extra()
    if missing:
        pytest.skip(f"docs extra not installed (pip install '.[docs]'): missing {', '.join(missing)}")
    site = tmp_path_factory.mktemp("docs") / "site"
    before = sorted(p.relative_to(ROOT) for p in (ROOT / "docs").rglob("*") if "__pycache__" not in p.parts)
    site_existed = (ROOT / "site").exists()
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1")
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT), env.get("PYTHONPATH")]))
    out = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)],
                         cwd=ROOT, env=env, capture_output=True, text=True)
    after = sorted(p.relative_to(ROOT) for p in (ROOT / "docs").rglob("*") if "__pycache__" not in p.parts)
    return out, site, before, after, site_existed


def test_docs_build_strict(built_site):
    """mkdocs build --strict: no warning (broken link or anchor, missing image, page
    outside the navigation, unparsable docstring, failing generator)."""
    out, site, before, after, site_existed = built_site
    assert out.returncode == 0, out.stdout + out.stderr
    assert (site / "index.html").is_file()
    assert (site / "configuration" / "index.html").is_file()
    assert after == before, "the build wrote into docs/"
    assert (ROOT / "site").exists() == site_existed, "the build wrote site/ into the source tree"


class _Loads(HTMLParser):
    """Every resource a page makes the browser fetch: script/img/iframe/audio/video/source/
    track/embed src and srcset, object data, link href (stylesheets, fonts, icons, preconnect,
    preload), inline style url() and @import."""

    ATTRIBUTES = {"script": ("src",), "img": ("src", "srcset"), "iframe": ("src",), "audio": ("src",),
                  "video": ("src", "poster"), "source": ("src", "srcset"), "track": ("src",), "embed": ("src",),
                  "object": ("data",), "link": ("href",), "input": ("src",)}
    #: <link rel> values that name another page rather than load a resource
    NAVIGATION = {"canonical", "alternate", "next", "prev", "author", "license", "help", "search"}

    def __init__(self):
        super().__init__()
        self.urls = []
        self._style = False

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "link" and set((attrs.get("rel") or "").split()) <= self.NAVIGATION:
            return  # a relation to another page (canonical, next, ...), not a resource
        for name in self.ATTRIBUTES.get(tag, ()):
            value = attrs.get(name) or ""
            self.urls += [part.strip().split()[0] for part in value.split(",") if part.strip()] if "srcset" in name \
                else [value]
        if attrs.get("style"):
            self.urls += _css_urls(attrs["style"])
        self._style = tag == "style"

    def handle_data(self, data):
        if self._style:
            self.urls += _css_urls(data)

    def handle_endtag(self, tag):
        self._style = False


def _css_urls(css: str) -> list:
    return [m.strip("'\" ") for m in re.findall(r"url\(([^)]*)\)", css)] + re.findall(r"@import\s+[\"']([^\"']+)", css)


def _remote(url: str) -> bool:
    return bool(re.match(r"(?i)^(https?:)?//", url.strip()))


def test_built_pages_load_nothing_from_the_network(built_site):
    """Offline (a cluster without internet) the site must look as online: no page and no
    stylesheet of the site fetches anything from another host (fonts, maths, scripts, images).
    Links to other sites (<a href>) are not loads. The theme's own script reaches out only for
    features the site does not use (repository facts for repo_url, mermaid diagrams)."""
    out, site, *_ = built_site
    assert out.returncode == 0, out.stdout + out.stderr
    remote = {}
    pages = sorted(site.rglob("*.html"))
    assert len(pages) > 20
    for page in pages:
        parser = _Loads()
        parser.feed(page.read_text(encoding="utf-8"))
        remote.update({(str(page.relative_to(site)), u): None for u in parser.urls if _remote(u)})
    for sheet in site.rglob("*.css"):
        urls = [u for u in _css_urls(sheet.read_text(encoding="utf-8")) if not u.startswith("data:")]
        remote.update({(str(sheet.relative_to(site)), u): None for u in urls if _remote(u)})
    assert list(remote) == []
    config = (ROOT / "mkdocs.yml").read_text()
    assert "repo_url" not in config and "mermaid" not in config


def test_maths_is_rendered_when_the_site_is_built(built_site):
    """Every formula is MathML in the built page (no script renders it in the browser)."""
    out, site, *_ = built_site
    assert out.returncode == 0, out.stdout + out.stderr
    theory = (site / "theory" / "index.html").read_text(encoding="utf-8")
    assert theory.count("<math") > 50 and '<math display="block">' in theory
    for page in site.rglob("*.html"):
        text = page.read_text(encoding="utf-8")
        assert 'class="arithmatex"' not in text, page
        assert not re.search(r"\\\(\\(?:varepsilon|beta|tau|sigma)", text), page  # no raw \(\varepsilon ...
    # a heading with maths: its table-of-contents entry is rendered too
    toc = re.search(r'<nav class="md-nav md-nav--secondary".*?</nav>', theory, re.S).group(0)
    assert "<math" in toc and "\\varepsilon" not in toc


def test_configuration_keys_break_only_between_words(built_site):
    """A narrow column of the configuration reference breaks packing_fraction after the
    underscore, never inside a word (the theme's code spans break anywhere)."""
    out, site, *_ = built_site
    assert out.returncode == 0, out.stdout + out.stderr
    page = (site / "configuration" / "index.html").read_text(encoding="utf-8")
    assert '<code class="config-key">packing_<wbr>fraction</code>' in page
    assert '<code class="config-key">observables_<wbr>interval</code>' in page
    css = (site / "stylesheets" / "extra.css").read_text()
    rule = re.search(r"code\.config-key\s*{([^}]*)}", css).group(1)
    assert "word-break: normal" in rule and "overflow-wrap: normal" in rule
    assert "stylesheets/extra.css" in page


def test_a_formula_the_converter_cannot_read_fails_the_build():
    spec = importlib.util.find_spec("math_core")
    if spec is None:
        pytest.skip("docs extra not installed (math-core)")
    maths = importlib.util.spec_from_file_location("granulargas_docs_maths", ROOT / "docs/hooks/maths.py")
    module = importlib.util.module_from_spec(maths)
    maths.loader.exec_module(module)
    good = module.render('<p>x <span class="arithmatex">\\(\\beta = \\tfrac32 A\\)</span></p>', "p.md")
    assert "<math>" in good and "<mi>β</mi>" in good and "arithmatex" not in good
    block = module.render('<div class="arithmatex">\\[\\mathbf v_i\\]</div>', "p.md")
    assert block.startswith('<math display="block">') and "𝐯" in block  # bold as MathML Core renders it
    with pytest.raises(ValueError, match=r"p\.md: cannot render the formula"):
        module.render('<span class="arithmatex">\\(\\frac{1}{\\)</span>', "p.md")


def _documented_keys():
    return {e.dotted for e in _generator().config_entries()}


def _keys_of(toml_text: str):
    data = tomllib.loads(toml_text)
    keys = set()

    # tables of a mixture keyed by its species' names: the key itself is what the reference lists
    named = ("collision.restitution", "collision.damping", "collision.wall_restitution")

    def walk(prefix, node):
        for k, v in node.items():
            dotted = f"{prefix}.{k}" if prefix else k
            if dotted == "species" and isinstance(v, list):  # [[species]]: each table's keys
                keys.update(f"species.{kk}" for table in v for kk in table)
            elif prefix == "walls" and isinstance(v, dict):  # walls.z_low = { kind = ... }: one entry per side
                keys.add(dotted)
                keys.update(f"walls.<side>.{kk}" for kk in v)
            elif isinstance(v, dict) and dotted in named:
                keys.add(dotted)
            elif isinstance(v, dict) and dotted not in ("particles.diameter",):
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
    from granulargas.errors import ConfigError
    from granulargas.io.config import parse_config

    for e in _generator().config_entries():
        table, _, last = f"{e.section}.{e.key}".rpartition(".")
        text = f"[{table}]\n{last} = \"__not_a_value__\"\n[run]\nend_time = 1.0\n"
        try:
            parse_config(text, "probe.toml")
            message = ""
        except ConfigError as exc:
            message = str(exc)
        assert "unknown" not in message, (e.dotted, message)


def test_every_key_the_validator_accepts_is_in_the_reference():
    """Every key the validator produces a value for (each field of the config dataclasses,
    by its TOML name) is accepted by it and has a row in the generated reference; a key
    the validator accepted without a schema entry would fail here."""
    import dataclasses

    from granulargas.errors import ConfigError
    from granulargas.io import config as c

    markdown = _generator().config_reference_markdown()
    rows = {}
    section = None
    for line in markdown.splitlines():
        m = re.match(r"## `\[+([^\]]+)\]+`", line)  # [section] or [[species]]
        if m:
            section = m.group(1)
        m = re.match(r'\| <code class="config-key">([^<]+(?:<wbr>[^<]*)*)</code> \|', line)
        if m:
            rows.setdefault(section, set()).add(m.group(1).replace("<wbr>", ""))
    toml_name = {"from_file": "from", "diameter_min": "diameter.min", "diameter_max": "diameter.max"}
    for name, cls in c.SECTION_CLASSES.items():
        for f in dataclasses.fields(cls):
            key = toml_name.get(f.name, f.name)
            assert key in rows.get(name, set()), f"{name}.{key} is missing from the configuration reference"
            table, _, last = f"{name}.{key}".rpartition(".")
            try:
                c.parse_config(f"[{table}]\n{last} = \"__x__\"\n[run]\nend_time = 1.0\n", "probe.toml")
            except ConfigError as exc:
                assert "unknown" not in str(exc), (name, key, str(exc))
    # and the reference has nothing the validator does not know
    known = {(k.section, k.key) for k in c.config_schema()}
    assert {(s, k) for s, keys in rows.items() for k in keys} == known
    # the rules across keys are rendered too
    for rule in c.config_rules():
        assert rule.text in markdown


def test_home_page_links_every_guide_and_method_page():
    """The home page describes the whole package: it links each page of the navigation's
    "User guide" and "Physics and methods" (walls and driving, DSMC, ... as they arrive)."""
    yaml = pytest.importorskip("yaml", reason="PyYAML (a dependency of the docs extra) not installed")
    config = yaml.load((ROOT / "mkdocs.yml").read_text(), Loader=yaml.BaseLoader)
    sections = {k: v for entry in config["nav"] for k, v in entry.items()}
    pages = [p for name in ("User guide", "Physics and methods") for entry in sections[name] for p in entry.values()]
    home = (ROOT / "docs" / "index.md").read_text()
    assert len(pages) >= 12
    assert [p for p in pages if f"]({p}" not in home] == []
    assert "periodic box" not in home  # walls close a box too


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
