"""Independent truths for the contact tests (closed forms, not computed by the package).

C1, C2: Ramirez, Poeschel, Brilliantov & Schwager, PRE 60, 4465 (1999).
HERTZ_DURATION: elastic (Hertz) contact duration (4/5)(5/4)^{2/5} B(2/5, 1/2).
"""

import math

from scipy.special import beta as beta_fn
from scipy.special import gamma

C1 = gamma(0.6) * math.sqrt(math.pi) / (2 ** 0.2 * 5 ** 0.4 * gamma(2.1))
C2 = 0.6 * C1 ** 2
HERTZ_DURATION = 0.8 * 1.25 ** 0.4 * beta_fn(0.4, 0.5)
# elastic maximum compression from energy conservation: x'^2/2 + (2/5) x^{5/2} = 1/2
HERTZ_MAX_COMPRESSION = 1.25 ** 0.4
