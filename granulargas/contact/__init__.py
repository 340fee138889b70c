"""Viscoelastic contact of two spheres: eps(beta) and tau_c(beta) (Schwager & Poeschel 1997).

Knows nothing of particles. Public API:

* :func:`restitution`, :func:`duration` -- by ODE, series, Pade or table;
* :func:`series_coefficients` -- high-order series of eps in beta (overlap) or sqrt(beta) (force);
* :func:`restitution_table` / :class:`RestitutionTable` -- the cached table the engine uses,
  looked up by :func:`granulargas.contact.lookup.table_lookup`;
* :mod:`granulargas.contact.material` -- Young modulus, Poisson ratio, A -> beta; validity range;
* :func:`solve_oblique`, :func:`oblique_table` / :class:`ObliqueTable` -- the oblique contact that
  takes time (:mod:`granulargas.contact.oblique`), looked up by
  :func:`granulargas.contact.oblique_lookup.resolve_collision`.
"""

from granulargas.contact.api import duration, restitution, series_coefficients
from granulargas.contact.material import (
    ContactValidityWarning,
    check_validity,
    prefactor_from_damping,
    prefactor_from_material,
    validity_problems,
)
from granulargas.contact.oblique import solve_oblique
from granulargas.contact.oblique_grid import ObliqueTable, oblique_table
from granulargas.contact.table import RestitutionTable, ensure_covers, restitution_table

__all__ = [
    "ContactValidityWarning",
    "ObliqueTable",
    "RestitutionTable",
    "check_validity",
    "duration",
    "ensure_covers",
    "oblique_table",
    "prefactor_from_damping",
    "prefactor_from_material",
    "restitution",
    "restitution_table",
    "series_coefficients",
    "solve_oblique",
    "validity_problems",
]
