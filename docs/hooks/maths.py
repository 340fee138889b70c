"""MkDocs hook: the maths rendered to MathML when the site is built.

``pymdownx.arithmatex`` (generic mode) leaves each formula as ``\\( ... \\)`` in a
``<span class="arithmatex">`` (inline) or ``\\[ ... \\]`` in a ``<div
class="arithmatex">`` (display). :func:`on_page_content` turns each into MathML Core
with ``math-core`` (a LaTeX to MathML converter from PyPI), which browsers render
natively: the built site shows its formulas without a script and without the
network. Headings with maths reach the table of contents as plain text, so their
formulas are converted there too. A formula the converter cannot read fails the
build with the page and the formula.
"""

from __future__ import annotations

import html
import re

import math_core

_BLOCK = re.compile(r'<(span|div) class="arithmatex">(.*?)</\1>', re.S)
_INLINE_TEXT = re.compile(r"\\\((.+?)\\\)", re.S)

_converter = math_core.LatexToMathML()


def to_mathml(latex: str, display: bool, where: str = "") -> str:
    """MathML of one formula (``display``: a block of its own)."""
    try:
        out = _converter.convert_with_local_state(latex, displaystyle=display)
    except math_core.LatexError as exc:
        raise ValueError(f"{where}: cannot render the formula {latex!r}: {exc}") from None
    return out.replace("<math>", '<math display="block">', 1) if display else out


def render(page_html: str, where: str = "") -> str:
    """The page's arithmatex formulas replaced by MathML."""

    def one(m):
        text = html.unescape(m.group(2)).strip()
        display = m.group(1) == "div"
        opening, closing = (r"\[", r"\]") if display else (r"\(", r"\)")
        if not (text.startswith(opening) and text.endswith(closing)):
            raise ValueError(f"{where}: unexpected maths markup {text[:60]!r}")
        return to_mathml(text[2:-2], display, where)

    return _BLOCK.sub(one, page_html)


def _toc_titles(items, where):
    for item in items:
        item.title = _INLINE_TEXT.sub(lambda m: to_mathml(html.unescape(m.group(1)), False, where), item.title)
        _toc_titles(item.children, where)


def on_page_content(html_text, page, config, files):  # noqa: ARG001 (MkDocs hook signature)
    where = page.file.src_uri
    _toc_titles(page.toc, where)
    return render(html_text, where)
