"""What the attacker of ``EncryptedLTIAttack-v0`` observes, and what ``info`` reports, defined once.

:class:`ObservationLayout` is the one definition of the flat observation vector: its slices
(used by the attackers in :mod:`agents`), its bounds (the observation space), the offsets the
compiled kernels write at (:mod:`encctl_gym.envs._kernels`), and the column subsets (*modes*)
that learned attackers are trained on. :func:`info_dict` is the one definition of the info
entries, for one copy (Python scalars) and for a batch (arrays).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ParameterError

__all__ = ["ObservationLayout", "OBSERVATION_MODES", "INFO_KEYS", "SHARED_INFO", "PRIVILEGED_INFO", "info_dict"]

#: Column subsets of the observation for learned attackers (:meth:`ObservationLayout.columns`).
OBSERVATION_MODES = ("full", "no_budget", "blind")

#: Largest distance of the encoder's chosen group element from ``round(Delta x)`` that the
#: observation bounds allow for (the residue table's search pad: :mod:`encctl_gym.crypto.residue_table`).
_SHIFT_PAD = 65.0


@dataclass(frozen=True)
class ObservationLayout:
    """The flat ``float32`` observation for ``n`` states, ``m`` inputs and ``H`` own past inputs.

    ====================  =====================================================================
    slice                 content
    ====================  =====================================================================
    :attr:`state`         latest delivered deciphered state ``x_j`` (zeros before any)
    :attr:`input`         delivered input ``u_{j-1}`` that led to ``x_j`` (zeros if none)
    :attr:`flag`          1.0 if a sample was delivered at this step, else 0.0
    :attr:`history`       the agent's own last ``H`` actions, newest first (action units)
    :attr:`time_fraction` fraction of the deciphering budget ``tau_c`` spent
    :attr:`energy_fraction` fraction of the input energy budget spent
    ====================  =====================================================================
    """

    n: int
    m: int
    H: int

    @classmethod
    def of(cls, params: Any) -> ObservationLayout:
        """The layout of an environment's resolved parameters (:class:`~encctl_gym.envs.config.AttackParams`);
        with ``observe="output"`` the "state" slice holds the ``p`` deciphered outputs."""
        return cls(int(params.observed_dim), int(params.m), int(params.input_history))

    @property
    def dim(self) -> int:
        """Length of the observation vector: ``n + m + 1 + H m + 2``."""
        return self.n + self.m + 1 + self.H * self.m + 2

    @property
    def state(self) -> slice:
        """Latest delivered deciphered state ``x_j``."""
        return slice(0, self.n)

    @property
    def input(self) -> slice:
        """Delivered input ``u_{j-1}``."""
        return slice(self.n, self.n + self.m)

    @property
    def flag(self) -> int:
        """1.0 when a sample was delivered at this step."""
        return self.n + self.m

    @property
    def history(self) -> slice:
        """Own last ``H`` actions, newest first (action units)."""
        start = self.n + self.m + 1
        return slice(start, start + self.H * self.m)

    @property
    def time_fraction(self) -> int:
        """Fraction of the deciphering budget spent."""
        return self.dim - 2

    @property
    def energy_fraction(self) -> int:
        """Fraction of the input energy budget spent."""
        return self.dim - 1

    @property
    def offsets(self) -> tuple[int, int, int, int, int, int]:
        """``(state, input, flag, history, time_fraction, energy_fraction)`` start indices, as the
        compiled kernels take them."""
        return (0, self.input.start, self.flag, self.history.start, self.time_fraction, self.energy_fraction)

    def bounds(self, *, x_bound: float, u_max: float, delta: float) -> tuple[np.ndarray, np.ndarray]:
        """Finite bounds ``(low, high)`` of the observation (float32).

        States lie within the encoder's declared range ``x_bound`` (encoding beyond it raises)
        plus the encoder's largest shift to the group (65 / Delta); inputs within the actuator
        bound plus the forged input's quantisation (``Ecd(a) Ecd(1) / Delta^2`` with both
        factors shifted, plus ``(n - 1) Ecd(0)^2 / Delta^2``, see
        :func:`encctl_gym.attacks.forgery.injection_value`); flag, history and fractions within
        their ranges.
        """
        n, m, H = self.n, self.m, self.H
        x_hi = x_bound + _SHIFT_PAD / delta
        u_hi = (u_max + _SHIFT_PAD / delta) * (1.0 + _SHIFT_PAD / delta) + n / delta**2
        high = np.concatenate([np.full(n, x_hi), np.full(m, u_hi), [1.0], np.ones(H * m), [1.0, 1.0]])
        low = np.concatenate([-high[: n + m], [0.0], -np.ones(H * m), [0.0, 0.0]])
        return low.astype(np.float32), high.astype(np.float32)

    def columns(self, mode: str) -> np.ndarray:
        """Columns of the observation a learned attacker sees in ``mode``.

        * ``"full"``: everything.
        * ``"no_budget"``: without the two budget fractions. Their scale depends on the episode
          length (``max_samples``, ``tau_c``), so a stationary policy trained on short episodes
          transfers to the full attack only if it does not see them.
        * ``"blind"``: the attacker's own past actions and the two budget fractions, i.e. what
          the paper's attacker knows before the attack ends (``decipher_delay="end"``); no
          delivered data. Use with a recurrent policy.

        The budget fractions let a policy pace its input energy; they mean "fraction of the
        attack elapsed" only when the horizon is set by ``tau_c``, not by ``max_samples``.

        Raises
        ------
        ParameterError
            For an unknown mode, or ``"blind"`` without an input history.
        """
        if mode == "full":
            return np.arange(self.dim)
        if mode == "no_budget":
            return np.arange(self.dim - 2)
        if mode == "blind":
            if self.H == 0:
                raise ParameterError("observation mode 'blind' needs input_history >= 1")
            return np.concatenate([np.arange(self.history.start, self.history.stop), [self.time_fraction, self.energy_fraction]])
        raise ParameterError(f"unknown observation mode {mode!r}; choose one of {', '.join(OBSERVATION_MODES)}")


# ----------------------------------------------------------------------------- info
def info_dict(
    eps: Any, energy: Any, shared: tuple, with_gamma_opt: bool, num_envs: int | None = None, detected: bool = False
) -> dict[str, Any]:
    """The info of the attack environment, defined once for the single and the vector environment.

    Parameters
    ----------
    eps, energy : float or numpy.ndarray of shape (K,)
        The error of the attacker's current estimate (Definition def:error) and the input
        energy spent, of one copy (Python floats) or of every copy (arrays, handed out as they are).
    shared : tuple
        The entries all copies share: ``(gamma, deciphering_time, power_den, gamma_opt,
        samples_collected, samples_delivered)``; ``average_power = energy / power_den``.
    with_gamma_opt : bool
        Include ``gamma_opt`` (computed only when the environment was asked to).
    num_envs : int, optional
        ``K`` for the vector environment: every shared entry becomes an array of shape (K,).
    detected : bool
        The defender stopped the attack (:mod:`encctl_gym.loop.defenses`; the copies of a batch
        stop together).

    Returns
    -------
    dict
        Keys in the order of :data:`INFO_KEYS`.
    """
    gamma, time, power_den, gamma_opt, collected, delivered = shared
    info = {
        "epsilon": eps,
        "gamma": gamma,
        "samples_collected": collected,
        "samples_delivered": delivered,
        "deciphering_time": time,
        "input_energy": energy,
        "average_power": energy / power_den,
        "detected": bool(detected),
    }
    if with_gamma_opt:
        info["gamma_opt"] = gamma_opt
    if num_envs is not None:
        for key in SHARED_INFO:
            if key in info:
                info[key] = np.full(num_envs, info[key])
    return info


#: The info entries all copies share (arrays of one value in the vector environment).
SHARED_INFO = ("gamma", "samples_collected", "samples_delivered", "deciphering_time", "gamma_opt", "detected")
#: The keys of the info dict, in order (:func:`info_dict`).
INFO_KEYS: tuple[str, ...] = tuple(info_dict(0.0, 0.0, (0.0, 0.0, 1.0, 0.0, 0, 0), True))

#: Info entries that are functions of the true plant (A, B): for training and evaluation only,
#: not something the attacker observes (see the environment's docstring, section Info).
PRIVILEGED_INFO = ("epsilon", "gamma", "gamma_opt")
