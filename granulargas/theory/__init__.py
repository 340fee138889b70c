"""Kinetic theory of granular gases: the yardstick the simulator is measured against.

Knows nothing of the engine or of files; uses :mod:`granulargas.contact` for the
exact eps(beta). The closed forms are importable from here (``from granulargas
import theory; theory.haff_tau0(...)``):

* :mod:`~granulargas.theory.enskog` -- particle volume, packing fraction, chi, EOS,
  a2, Enskog collision frequency and cooling rate, Haff's law, shear viscosity,
  the shear-instability length (constant restitution);
* :mod:`~granulargas.theory.viscoelastic` -- viscoelastic cooling at leading order
  in the damping (``T ~ t^(-5/3)``), C1, C2;
* :mod:`~granulargas.theory.gas` -- a homogeneous gas with the exact eps(beta):
  impact speeds, the spread of eps, the cooling curve, the instability length of
  a config's gas (:class:`~granulargas.theory.gas.Gas`; import it from there);
* :mod:`~granulargas.theory.driven` -- the white-noise driven steady state
  (temperature, a2, kick interval; viscoelastic: effective restitution);
* :mod:`~granulargas.theory.shear` -- uniform shear flow: the Grad solution (dilute
  and Enskog, with or without a thermostat) and the Navier-Stokes shear viscosity of
  a granular gas (import it from there).
* :mod:`~granulargas.theory.vibrated` -- gases under gravity and on vibrating walls:
  hydrostatic and barometric profiles, the bouncing ball, the dilute vibrofluidized bed;
* :mod:`~granulargas.theory.rough` -- rough grains: the two-temperature (translation,
  rotation) Maxwellian theory, free cooling, driven steady states, the Mpemba crossing
  (import it from there: ``from granulargas.theory import rough``);
* :mod:`~granulargas.theory.mixture` -- mixtures of species: cooling rates and the
  temperature of each species in the homogeneous cooling and the driven states
  (Garzó & Dufty 1999), contact values of a mixture (import it from there).
"""

from granulargas.theory import driven, enskog, gas, mixture, rough, shear, vibrated, viscoelastic  # noqa: F401
from granulargas.theory.driven import *  # noqa: F401,F403
from granulargas.theory.enskog import *  # noqa: F401,F403
from granulargas.theory.vibrated import *  # noqa: F401,F403
from granulargas.theory.viscoelastic import *  # noqa: F401,F403

__all__ = enskog.__all__ + viscoelastic.__all__ + driven.__all__ + vibrated.__all__
