"""Analysis of granulargas runs: plain functions on arrays, file-level helpers on top.

* :mod:`~granulargas.analysis.cooling` -- temperature, Sonine coefficients a2/a3,
  velocity distribution, cooling-law fits, local exponent;
* :mod:`~granulargas.analysis.structure` -- S(k) (2D/3D, direct, small k), g(r),
  coarse-grained density;
* :mod:`~granulargas.analysis.clusters` -- periodic distance/contact clusters and
  their size distribution;
* :mod:`~granulargas.analysis.flow` -- coarse-grained velocity, vorticity, energy spectrum;
* :mod:`~granulargas.analysis.run` -- an H5MD file against kinetic theory
  (:func:`~granulargas.analysis.run.analyze_cooling`), frame by frame;
* ``granulargas analyze FILE`` is :mod:`granulargas.cli.analyze`.
"""
