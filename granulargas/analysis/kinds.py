"""Which analysis a run gets: a dispatcher on the run's kind.

:func:`granulargas.analysis.run.run_kind` names the kind of a run from its
``parameters/collision`` group; :data:`ANALYSES` maps each kind to the function
that analyses such a file. Every analysis object has ``kind``, ``info``
(:class:`~granulargas.analysis.run.RunInfo`), ``theory_name`` and
``summary() -> dict`` (the JSON of ``granulargas analyze --json``); the text
report and the figure of each kind are registered in
:mod:`granulargas.cli.analyze` and :mod:`granulargas.analysis.plots`. A new kind
of run (a driven steady state, say) plugs in by adding its entry here, a branch
in ``run_kind`` and its report and figure there.
"""

from __future__ import annotations

from granulargas.analysis.driven import analyze_driven
from granulargas.analysis.elastic import analyze_elastic
from granulargas.analysis.run import RunInfo, analyze_cooling
from granulargas.analysis.vibrated import analyze_vibrated

__all__ = ["ANALYSES", "analyze_file"]

#: kind -> analysis function ``f(path, **options)``
ANALYSES = {
    "cooling": analyze_cooling,
    "elastic": analyze_elastic,
    "driven": analyze_driven,
    "vibrated": analyze_vibrated,
}


def analyze_file(path, **options):
    """Analyse one run's H5MD file with the analysis of its kind.

    ``options`` go to the kind's function (``t_range``, ``with_sonine`` for cooling
    runs; ``with_sonine`` for elastic ones).
    """
    kind = RunInfo.from_file(path).kind
    return ANALYSES[kind](path, **options)
