"""Compact Pade approximant of eps(beta) (Mueller & Poeschel, PRE 84, 021302 (2011)).

In u = sqrt(beta):

    eps ~ (1 + a u) / (1 + a u + C1 u^2 + a C1 u^3 + (2/5) C1^2 u^4),   a = 2 / (3 C1^2),

with C1 = Gamma(3/5) sqrt(pi) / (2^{1/5} 5^{2/5} Gamma(21/10)). It reproduces
1 - C1 beta + C2 beta^2 (C2 = (3/5) C1^2) exactly, goes to 0 as beta -> infinity,
is meant for the ``force`` end (delayed recovery): its expansion
1 - C1 u^2 + C2 u^4 + (4/15) u^5 + ... matches the force series through u^5
(our high-order series gives c_5 = 4/15, an independent check), and it goes to
0 as beta -> infinity. Beyond that it is accurate to the per-cent level
(max |error| ~ 0.009 near beta ~ 3; 1.2 % relative at beta = 1; see the tests and
``scripts/contact/epsilon_speed_accuracy.py``).
"""

from __future__ import annotations

import math
import warnings

import numpy as np

#: ``Gamma(3/5) sqrt(pi) / (2^(1/5) 5^(2/5) Gamma(21/10))``, the leading coefficient of
#: ``1 - eps = C1 beta + ...``, as scipy.special.gamma evaluates it (written out so that loading
#: the contact module loads no scipy; tests/contact/test_contact_pade_api.py recomputes it)
C1 = np.float64(1.1534488580952884)
C2 = 0.6 * C1 ** 2
A_PADE = 2.0 / (3.0 * C1 ** 2)


def restitution_pade(beta, end: str = "force"):
    """Mueller-Poeschel approximant of eps(beta) (vectorised).

    The approximant was built for the ``force`` end; asking for ``overlap`` returns
    the same formula with a warning (both ends agree only to O(beta^2)).
    """
    if end == "overlap":
        warnings.warn("the Mueller-Poeschel Pade approximant describes the 'force' end of contact; "
                      "for 'overlap' it is correct only to O(beta^2)", UserWarning, stacklevel=3)
    elif end != "force":
        raise ValueError(f"end must be 'overlap' or 'force', got {end!r}")
    u = np.sqrt(np.asarray(beta, dtype=float))
    a = A_PADE
    return (1 + a * u) / (1 + a * u + C1 * u ** 2 + a * C1 * u ** 3 + 0.4 * C1 ** 2 * u ** 4)
