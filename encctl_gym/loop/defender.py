"""The defender: the plant side's decisions as one policy object, called by the episode each step.

The attacker is the environment's agent; the defender is the other party of the loop, the plant
side. Its decisions are the group the loop runs on (the key length), what it checks of what it
sees and what noise it adds to its own actuator input. A :class:`DefenderPolicy` makes them:

* :meth:`DefenderPolicy.group`, once, when the environment is built: the group of the loop
  (the default is the loop's group for the configured key length, :meth:`~encctl_gym.loop.spec.LoopSpec.group`);
* :meth:`DefenderPolicy.reset`, at every reset, with a random generator per copy of its own
  (spawned from each copy's generator: drawing from it changes none of the plant's draws);
* :meth:`DefenderPolicy.act`, at every attack step before the period runs, with a
  :class:`PlantView` of what the plant side knows (its state, the inputs it decoded). It returns
  ``None`` (nothing to do) or a :class:`DefenderAction`: noise added to the input the plant
  applies this period, whether the plant side stops the attack (the episode then ends,
  ``terminated``, with every paid sample delivered), and a fresh group to move the loop to
  (group rotation, :mod:`encctl_gym.loop.rotation`);
* :meth:`DefenderPolicy.on_new_group`, when the loop moved to a fresh group (group rotation);
* :meth:`DefenderPolicy.close`, by the environment's ``close``, to release what the policy holds
  (the rotating defender's group pool stops its worker).

:class:`DefenderBase` implements every member with the paper's defaults; a new defence
subclasses it and overrides what it decides.

Policies are picked by the environment's ``defender`` key: a name of :data:`DEFENDERS` or an
object that implements the protocol. The default, :class:`FixedDefender` (``"fixed"``), is the
paper's defender: a fixed key length, no checks, no noise; it returns ``None`` every step, so
the trajectories are those of an environment without the seam, bit for bit.

The input noise ``v`` enters the plant as ``x_{k+1} = A x_k + B (u_k + v_k) + w_k``: the
attacker's record of the input stays the ``u_k`` it forged (it cannot see ``v_k``), so to the
attacker the defence is extra process noise ``B v_k``, and the episode applies it as such on
every step path.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Protocol, overload, runtime_checkable

import numpy as np

from .._validation import as_finite_array, format_value
from ..errors import ParameterError
from .spec import LoopSpec

__all__ = [
    "DefenderAction",
    "DefenderPolicy",
    "PlantView",
    "DefenderStreams",
    "DefenderBase",
    "FixedDefender",
    "DEFENDERS",
    "make_defender",
    "check_defender_action",
]


@dataclass(frozen=True)
class DefenderAction:
    """What the defender does in one attack step.

    Attributes
    ----------
    input_noise : array_like of shape (K, m) (or (m,) for K = 1), optional
        Added to the input every copy's plant applies this period (finite values).
    end : bool
        The plant side stops the attack now: the episode ends this step (``terminated``) for
        every copy (the copies of a batch run in lockstep).
    new_group : GroupParams, optional
        Move the loop to this safe-prime group (of the loop's size) before the period: KeyGen in
        it and the server re-provisioned (group rotation, :mod:`encctl_gym.loop.rotation`; the
        backend's ``rotate_group``).
    """

    input_noise: Any = None
    end: bool = False
    new_group: Any = None


class PlantView:
    """What the plant side knows, read-only, as the episode updates it (no copies).

    Parameters
    ----------
    x, U : numpy.ndarray
        The episode's state (K, n) and applied inputs (N, K, m), which the view reads.
    step : callable
        Returns the attack step about to run.
    """

    def __init__(self, x: np.ndarray, U: np.ndarray, step: Callable[[], int]) -> None:
        self._x, self._U, self._step = x, U, step  # the episode's own arrays (a copy of the episode keeps them shared)

    @property
    def step(self) -> int:
        """The attack step about to run (0 at the first)."""
        return self._step()

    @property
    def state(self) -> np.ndarray:
        """The plant's current state ``x_k``, shape (K, n) (a read-only view)."""
        return _read_only(self._x)

    @property
    def last_input(self) -> np.ndarray:
        """The input ``u_{k-1}`` the plant decoded and applied last step, shape (K, m) (zeros at the first)."""
        k = self.step
        return np.zeros(self._U.shape[1:]) if k < 1 else _read_only(self._U[k - 1])


class DefenderStreams(Sequence[np.random.Generator]):
    """The defender's generators, one per copy, each spawned from that copy's generator
    (``Generator.spawn``: an independent stream; the copy's own draws are unchanged) when first
    used, so a defender that draws nothing costs nothing."""

    def __init__(self, parents: Sequence[np.random.Generator]) -> None:
        self._parents = list(parents)
        self._children: list[np.random.Generator | None] = [None] * len(self._parents)

    def __len__(self) -> int:
        return len(self._parents)

    @overload
    def __getitem__(self, i: int) -> np.random.Generator: ...

    @overload
    def __getitem__(self, i: slice) -> list[np.random.Generator]: ...

    def __getitem__(self, i: int | slice) -> np.random.Generator | list[np.random.Generator]:
        if isinstance(i, slice):
            return [self[j] for j in range(*i.indices(len(self)))]
        child = self._children[i]
        if child is None:
            try:
                child = self._parents[i].spawn(1)[0]
            except (TypeError, ValueError) as exc:
                raise ParameterError(f"the episode's generator {i} cannot spawn a stream for the defender ({exc})") from None
            self._children[i] = child
        return child


def _read_only(a: np.ndarray) -> np.ndarray:
    v = a.view()
    v.flags.writeable = False
    return v


@runtime_checkable
class DefenderPolicy(Protocol):
    """The plant side's decisions (see the module docstring): every member the loop and the
    episode use. :class:`DefenderBase` implements the optional ones (no rotation, no hooks).

    Attributes
    ----------
    name : str
        The registry name (:data:`DEFENDERS`), or any label for a policy given as an object.
    rotates : bool
        The policy moves the loop to fresh groups (the episode's info then carries the rotation
        fields, :func:`~encctl_gym.loop.rotation.rotation_info`).
    tally : object or None
        What the policy's group generation cost this episode
        (:class:`~encctl_gym.loop.rotation.GenerationTally`), ``None`` when it generates nothing.
    """

    name: str

    @property
    def rotates(self) -> bool: ...

    @property
    def tally(self) -> Any: ...

    def group(self, params: LoopSpec) -> Any:
        """The group the loop runs on (its key length), for the loop's ``params``."""
        ...

    def reset(self, K: int, n: int, m: int, rngs: Sequence[np.random.Generator]) -> None:
        """A new episode of ``K`` copies starts; ``rngs`` are the defender's own generators, one
        per copy (:class:`DefenderStreams`)."""
        ...

    def act(self, view: PlantView) -> DefenderAction | None:
        """The decision of the coming attack step: ``None`` (nothing) or a :class:`DefenderAction`."""
        ...

    def on_new_group(self, group: Any) -> None:
        """The loop moved to ``group`` (group rotation): what depends on the group follows it."""
        ...

    def close(self) -> None:
        """Release what the policy holds (the environment's ``close``)."""
        ...


class DefenderBase:
    """The defaults of :class:`DefenderPolicy`: the loop's own group (:meth:`LoopSpec.group`), no
    decision, no rotation, nothing to follow or release. Subclass it and override what the
    policy does."""

    name = "base"
    rotates = False
    tally: Any = None

    def group(self, params: LoopSpec) -> Any:
        """The loop's group for its key length (:meth:`LoopSpec.group`)."""
        return params.group()

    def reset(self, K: int, n: int, m: int, rngs: Sequence[np.random.Generator]) -> None:
        pass

    def act(self, view: PlantView) -> DefenderAction | None:
        return None

    def on_new_group(self, group: Any) -> None:
        pass

    def close(self) -> None:
        pass


class FixedDefender(DefenderBase):
    """The paper's defender (registry name ``"fixed"``): the configured key length, no checks and
    no noise (:meth:`act` returns ``None``)."""

    name = "fixed"

    def __repr__(self) -> str:
        return "FixedDefender()"


#: Defender policies by the name the environment's ``defender`` key gives.
DEFENDERS: dict[str, type] = {"fixed": FixedDefender}


def make_defender(spec: Any = None) -> DefenderPolicy:
    """A defender policy from a name of :data:`DEFENDERS` (``None``: ``"fixed"``), a mapping with
    a ``name`` and that policy's options (``{"name": "audit", "rate": 5e-4}``), or a policy object.

    Raises
    ------
    ParameterError
        For an unknown name or option, a bad option value, or an object that does not implement
        :class:`DefenderPolicy`.
    """
    if spec is None:
        spec = "fixed"
    if isinstance(spec, Mapping):
        options = dict(spec)
        name = options.pop("name", None)
        if not isinstance(name, str) or name not in DEFENDERS:
            raise ParameterError(f"unknown defender {format_value(name)}; choose one of {', '.join(DEFENDERS)}")
        try:
            return DEFENDERS[name](**options)
        except TypeError as exc:
            raise ParameterError(f"the defender {name!r} takes no such options {sorted(options)} ({exc})") from None
    if isinstance(spec, str):
        try:
            return DEFENDERS[spec]()
        except KeyError:
            raise ParameterError(f"unknown defender {spec!r}; choose one of {', '.join(DEFENDERS)}") from None
    if isinstance(spec, type) or not isinstance(spec, DefenderPolicy):
        missing = [k for k in _MEMBERS if not hasattr(spec, k)]
        raise ParameterError(
            f"defender must be a name ({', '.join(DEFENDERS)}) or a DefenderPolicy (subclass DefenderBase), "
            f"got {format_value(spec)}"
            + (f", which lacks {', '.join(missing)}" if missing and not isinstance(spec, type) else "")
        )
    return spec


_MEMBERS = ("name", "rotates", "tally", "group", "reset", "act", "on_new_group", "close")


def check_defender_action(action: Any, K: int, m: int) -> tuple[np.ndarray | None, bool]:
    """``(input_noise (K, m) float64 or None, end)`` of a defender's decision, checked.

    Raises
    ------
    ParameterError
        For a decision that is not a :class:`DefenderAction`, noise of another shape, or noise
        that is not a finite real array (the message names the value).
    """
    if not isinstance(action, DefenderAction):
        raise ParameterError(f"a defender's act() must return None or a DefenderAction, got {format_value(action)}")
    end = action.end
    if not isinstance(end, (bool, np.bool_)):
        raise ParameterError(f"DefenderAction.end must be a bool, got {format_value(end)}")
    v = action.input_noise
    if v is None:
        return None, bool(end)
    arr = as_finite_array("DefenderAction.input_noise", v)
    if K == 1 and arr.shape == (m,):
        arr = arr[None]
    if arr.shape != (K, m):
        raise ParameterError(f"DefenderAction.input_noise must have shape {(K, m) if K > 1 else (m,)}, got {arr.shape}")
    return arr, bool(end)
