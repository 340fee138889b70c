"""Which analysis a run gets: a dispatcher on the run's kind.

:func:`granulargas.analysis.run.run_kind` names the kind of a run from its
``parameters/collision`` group; :data:`ANALYSES` maps each kind to the function
that analyses such a file. Every analysis object has ``kind``, ``info``
(:class:`~granulargas.analysis.run.RunInfo`), ``theory_name`` and
``summary() -> dict`` (the JSON of ``granulargas analyze --json``); the text
report and the figure of each kind are registered in
:mod:`granulargas.cli.analyze` and :mod:`granulargas.analysis.plots`. A new kind
of run (a driven steady state, say) plugs in by adding its entry here, a branch
in ``run_kind`` and its report and figure there. A file whose collision model is
not recorded (kind ``"unknown"``) is refused with one line: no theory applies.
"""

from __future__ import annotations

from granulargas.analysis.driven import analyze_driven
from granulargas.analysis.elastic import analyze_elastic
from granulargas.analysis.rough import analyze_rough
from granulargas.analysis.run import RunInfo, analyze_cooling
from granulargas.analysis.shear import analyze_shear
from granulargas.analysis.vibrated import analyze_vibrated
from granulargas.errors import InputFileError
from granulargas.io.scene import MODELS

__all__ = ["ANALYSES", "analyze_file", "unknown_model"]

#: kind -> analysis function ``f(path, **options)``
ANALYSES = {
    "cooling": analyze_cooling,
    "elastic": analyze_elastic,
    "driven": analyze_driven,
    "shear": analyze_shear,
    "vibrated": analyze_vibrated,
    "rough": analyze_rough,
}


def analyze_file(path, **options):
    """Analyse one run's H5MD file with the analysis of its kind.

    ``options`` go to the kind's function (``t_range``, ``with_sonine`` for cooling
    runs; ``with_sonine`` for elastic ones).
    """
    info = RunInfo.from_file(path)
    if info.kind == "unknown":
        raise InputFileError(unknown_model(info))
    return ANALYSES[info.kind](path, **options)


def unknown_model(info) -> str:
    """The line that refuses a file whose collision model the analysis does not know."""
    coll = info.parameters.get("collision")
    given = coll.get("model") if isinstance(coll, dict) else None
    what = ("records no collision model (parameters/collision/model)" if given is None else
            f"records collision model {given!r} without its parameters" if given in MODELS else
            f"records collision model {given!r}, which the analysis does not know")
    return (f"{info.path}: {what}, so there is no kinetic theory to compare it with; a run built in Python "
            "records its model when written with granulargas.run.record.RunWriter (docs/engine.md)")
