"""Kinetic theory of granular gases: the closed forms the simulator is measured against.

Knows nothing of the engine or of files; may use :mod:`granulargas.contact` (the
exact eps(beta)). Everything is importable from here (``from granulargas import
theory; theory.haff_tau0(...)``):

* :mod:`~granulargas.theory.enskog` -- particle volume, packing fraction, chi, EOS,
  a2, Enskog collision frequency and cooling rate, Haff's law, shear viscosity,
  the shear-instability length, leading-order viscoelastic cooling.
"""

from granulargas.theory.enskog import *  # noqa: F401,F403
from granulargas.theory.enskog import __all__  # noqa: F401
