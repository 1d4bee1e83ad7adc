"""Identification of the plant ``(A, B)`` from (deciphered) data, and its error.

* :mod:`.error` -- the estimation error of Definition def:error.
* :mod:`.least_squares` -- the data matrices of eq:data and the least-squares estimate of
  eq:estimate: batch, recursive, and on a whole grid of sample sizes in one pass.
* :mod:`.estimator` -- the :class:`Estimator` protocol (batch fit, grid of N, online update of
  K copies in lockstep, the estimate, the error) and the shared moment machinery.
* :mod:`.ordinary`, :mod:`.bayes`, :mod:`.forgetting`, :mod:`.instrumental` -- the estimators:
  least squares, Bayesian least squares (Gaussian prior, ridge posterior mean), exponential
  forgetting, instrumental variables.
* :mod:`.registry` -- estimators by name (``make_estimator("bayes")``).
* :mod:`.grid` -- the error on a grid of ``N`` for least squares or any estimator by name.
* :mod:`.subspace` -- identification from outputs ``y = C x + D u + v``: N4SID, PO-MOESP and
  ARX on batches of runs, and the basis-free Markov-parameter error.
* :mod:`.output_estimators` -- N4SID and PO-MOESP behind the estimator protocol (states, and
  online on outputs), and the online ARX least squares of the environment on outputs.
* :mod:`.tails` -- when the error's mean and variance exist (the tail rule), the Hill
  estimator, and summaries that report medians and flag a mean that does not exist.

Pure numerical code (numpy): it imports only the package's base modules. The sample
identifying complexities of :mod:`encctl_gym.security` bound the expected error of these
estimates; the Monte Carlo engine (:mod:`encctl_gym.sim`) and the environment use them.
"""

from __future__ import annotations

import sys

from .bayes import *  # noqa: F403
from .error import *  # noqa: F403
from .estimator import *  # noqa: F403
from .forgetting import *  # noqa: F403
from .grid import *  # noqa: F403
from .instrumental import *  # noqa: F403
from .least_squares import *  # noqa: F403
from .ordinary import *  # noqa: F403
from .output_estimators import *  # noqa: F403
from .registry import *  # noqa: F403
from .subspace import *  # noqa: F403
from .tails import *  # noqa: F403

#: The public names of the modules above, in their order (each module's ``__all__``).
__all__ = list(
    dict.fromkeys(
        name
        for module in (
            "error",
            "least_squares",
            "estimator",
            "ordinary",
            "bayes",
            "forgetting",
            "instrumental",
            "registry",
            "grid",
            "subspace",
            "output_estimators",
            "tails",
        )
        for name in sys.modules[f"{__name__}.{module}"].__all__
    )
)
