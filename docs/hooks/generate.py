"""MkDocs hook: pages generated from the code at build time.

A page that contains one of the markers below gets it replaced by generated
Markdown, so that the text cannot drift from the code it describes:

``<!-- generated: config-reference -->``
    Every section and key of the run configuration: type, default, allowed
    values (with the reason of each bound), unit, meaning; then the rules across
    keys (:func:`config_reference_markdown`).
``<!-- generated: cli-reference -->``
    The ``--help`` text of every command (:func:`cli_reference_markdown`).

The docstrings use Sphinx roles (``:func:`name```), which mkdocstrings shows
verbatim; :func:`on_page_content` drops the role prefix and keeps the code span.

Where the configuration reference comes from
--------------------------------------------
The config schema, :func:`granulargas.io.config.config_schema` (one entry per
key: section, key, type, default or computed default, allowed range and its
reason, unit, meaning) and :func:`granulargas.io.config.config_rules` (the rules
across keys). The validator is driven by the same schema, so the reference lists
exactly the keys it accepts; a new key appears here by itself.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
from dataclasses import dataclass
from typing import Any

CONFIG_MARKER = "<!-- generated: config-reference -->"
CLI_MARKER = "<!-- generated: cli-reference -->"


@dataclass(frozen=True)
class ConfigKey:
    """One key of the run configuration, as the reference shows it."""

    section: str  # "system", "collision.material", ...
    key: str  # "packing_fraction", "diameter.min", ...
    type: str  # "integer", "number", "string", "number or table", "table"
    default: Any  # a TOML value, None (no default) or a DefaultText (a default described in words)
    allowed: str  # what the validator and the run-start checks accept, and why
    meaning: str
    unit: str = ""

    @property
    def dotted(self) -> str:
        return f"{self.section}.{self.key}"


SECTION_TEXT = {
    "system": "The system: dimension, size, density and the random seed.",
    "particles": "Particle sizes and masses (reduced units: the reference particle has "
                 "diameter 1 and mass 1).",
    "initial": "The initial state.",
    "collision": "The collision rule.",
    "collision.material": "Instead of `damping`: the viscoelastic contact from material constants "
                          "(SI; all keys required), converted once to the reduced pair prefactor "
                          "k = (3/2) A (2Y / (3(1 − ν²)))^(2/5) (σ u / m²)^(1/5).",
    "collision.tangential": "Optional: rough particles that spin ([Rough grains](rough.md)). Without the "
                            "table the particles are smooth. Sign convention: the tangential velocity "
                            "of the contact points becomes −β_t times itself, so β_t = −1 is smooth and "
                            "+1 perfectly rough.",
    "driving": "Optional: white-noise driving (a heated granular gas in a steady state).",
    "gravity": "Optional: a uniform acceleration (see [Gravity and vibrating walls](gravity-and-vibrating-walls.md)).",
    "walls": "Optional: the kind of each wall (`system.boundary` axes with `\"wall\"`); a side left out "
             "is a hard wall at rest.",
    "walls.<side>": "The keys of each side's table in `[walls]` (`x_low`, ..., `z_high`), e.g. "
                    "`walls.z_low.amplitude`.",
    "species": "Optional, in place of `[particles]`: an array of tables `[[species]]`, one per species of "
               "a mixture ([Mixtures](mixtures.md)). Each key below is checked per species and named "
               "`species.<name>.<key>` in messages and overrides.",
    "run": "When to stop (at least one key).",
    "output": "The output file and its schedule.",
}


def config_entries() -> list[ConfigKey]:
    """Every configuration key, from the config schema, in its order."""
    from granulargas.io.config import config_schema

    return [ConfigKey(k.section, k.key, k.type, k.shown_default, k.allowed, k.meaning, k.unit)
            for k in config_schema()]


def config_rules() -> list[str]:
    """The rules across keys, one sentence each, from the config schema."""
    from granulargas.io.config import config_rules as rules

    return [r.text for r in rules()]


def _show_default(value) -> str:
    from granulargas.io.config import DefaultText

    if value is None:
        return "—"
    if isinstance(value, DefaultText):
        return str(value)
    if isinstance(value, str):
        return f'`"{value}"`'
    if isinstance(value, bool):
        return f"`{str(value).lower()}`"
    return f"`{value!r}`"


def _cell(text: str) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def key_cell(key: str) -> str:
    """A key as the reference shows it: code that a narrow column breaks only after ``_`` or
    ``.`` (``<wbr>``), never inside a word (``config-key`` in docs/stylesheets/extra.css)."""
    breakable = re.sub(r"([_.])", r"\1<wbr>", key)
    return f'<code class="config-key">{breakable}</code>'


def config_reference_markdown() -> str:
    """The configuration reference: one table per section, then the rules across keys."""
    entries = config_entries()
    lines = []
    for section in dict.fromkeys(e.section for e in entries):
        anchor = section.replace(".", "-").replace("<", "").replace(">", "")
        shown = f"[[{section}]]" if section == "species" else f"[{section}]"  # an array of tables
        lines += [f"## `{shown}` {{ #{anchor} }}", ""]
        if section in SECTION_TEXT:
            lines += [SECTION_TEXT[section], ""]
        lines += ["| key | type | default | unit | allowed | meaning |", "|---|---|---|---|---|---|"]
        for e in (e for e in entries if e.section == section):
            lines.append(f"| {key_cell(e.key)} | {e.type} | {_cell(_show_default(e.default))} | {_cell(e.unit or '—')} | "
                         f"{_cell(e.allowed)} | {_cell(e.meaning)} |")
        lines.append("")
    lines += ["## Rules across keys { #rules }", ""]
    lines += [f"* {text}" for text in config_rules()]
    lines.append("")
    return "\n".join(lines)


def cli_reference_markdown() -> str:
    """The ``--help`` output of ``granulargas`` and of each command."""
    from granulargas.cli import COMMANDS, build_parser

    def help_text(argv):
        out = io.StringIO()
        old = os.environ.get("COLUMNS")
        os.environ["COLUMNS"] = "100"
        try:
            with contextlib.redirect_stdout(out), contextlib.suppress(SystemExit):
                build_parser(argv).parse_args(argv + ["--help"])
        finally:
            if old is None:
                del os.environ["COLUMNS"]
            else:
                os.environ["COLUMNS"] = old
        return out.getvalue().rstrip()

    lines = ["## `granulargas`", "", "```text", help_text([]), "```", ""]
    for name in COMMANDS:
        lines += [f"## `granulargas {name}`", "", "```text", help_text([name]), "```", ""]
    return "\n".join(lines)


def on_page_markdown(markdown, page, config, files):  # noqa: ARG001 (MkDocs hook signature)
    if CONFIG_MARKER in markdown:
        markdown = markdown.replace(CONFIG_MARKER, config_reference_markdown())
    if CLI_MARKER in markdown:
        markdown = markdown.replace(CLI_MARKER, cli_reference_markdown())
    return markdown


_ROLE = re.compile(r":(?:func|class|mod|meth|data|attr|exc|obj):(?=<code>)")


def on_page_content(html, page, config, files):  # noqa: ARG001 (MkDocs hook signature)
    return _ROLE.sub("", html)
