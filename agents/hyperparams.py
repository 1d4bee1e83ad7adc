"""Hyperparameters of a learning algorithm checked against its constructor before training.

A config's ``hyperparams`` are keyword arguments of the algorithm class (``PPO(...)``,
``SAC(...)``, ...) and its ``hyperparams.policy_kwargs`` keyword arguments of the policy class
(``ActorCriticPolicy(...)``, ...). Both are checked here against the constructors' signatures
and type hints, so an unknown name or a value of the wrong type is a one-line
:class:`~encctl_gym.errors.ConfigError` before anything is built, not a traceback from deep
inside stable-baselines3 or a keyword silently ignored.

What a YAML file can express is checked: numbers, booleans, strings, ``null``, lists, tuples
and mappings, by the annotation's structure (``int | None``, ``list[int] | dict[str,
list[int]]``, ...). Parameters whose type is a class or a callable (schedules, buffer or
optimizer classes, action noise) cannot be given in a config, except ``activation_fn``, given by
name (:data:`ACTIVATIONS`), and the schedules of :data:`SCHEDULED` (``learning_rate``,
``clip_range``, ``delta_std``), which may be given as rl-zoo3's ``lin_<value>``: a value that
falls linearly from ``<value>`` at the start of training to 0 at its end
(:func:`make_schedules`).
"""

from __future__ import annotations

import collections.abc
import inspect
import numbers
import types
import typing
from typing import Any

from encctl_gym._validation import format_value
from encctl_gym.errors import ConfigError

__all__ = [
    "ACTIVATIONS",
    "RESERVED",
    "SCHEDULED",
    "INT64_MAX",
    "type_hints",
    "check_value",
    "check_kwargs",
    "network_bytes",
    "policy_kwargs",
    "parse_schedule",
    "make_schedules",
]

#: ``activation_fn`` names accepted in configs -> ``torch.nn`` class names.
ACTIVATIONS = {"tanh": "Tanh", "relu": "ReLU", "elu": "ELU", "leaky_relu": "LeakyReLU", "silu": "SiLU", "gelu": "GELU"}

#: Constructor arguments that ``train`` sets itself (never from ``hyperparams``).
RESERVED = frozenset({"policy", "env", "seed", "verbose", "device", "tensorboard_log", "_init_setup_model", "policy_kwargs"})
#: Policy constructor arguments set by the algorithm.
_POLICY_RESERVED = frozenset({"observation_space", "action_space", "lr_schedule", "use_sde"})

#: Hyperparameters that must be positive integers (or floats in (0, 1]) whatever the algorithm.
_POSITIVE_INT = frozenset(
    {
        "n_steps",
        "batch_size",
        "n_epochs",
        "buffer_size",
        "stats_window_size",
        "target_update_interval",
        "policy_delay",
        "lstm_hidden_size",
        "n_lstm_layers",
        "n_delta",
        "n_top",
        "n_eval_episodes",
    }
)
_UNIT_INTERVAL = frozenset({"gamma", "gae_lambda", "tau"})
#: Largest integer hyperparameter (sizes and counts are int64 in PyTorch and NumPy).
INT64_MAX = 2**63 - 1
#: Hyperparameters that accept a schedule, given in a config as ``lin_<value>``.
SCHEDULED = frozenset({"learning_rate", "clip_range", "delta_std"})


def parse_schedule(name: str, value: Any) -> float | None:
    """The start value of a ``lin_<value>`` schedule (``None`` if ``value`` is not such a string).

    Raises
    ------
    ConfigError
        For a ``lin_`` string whose value is not a positive number.
    """
    if not (isinstance(value, str) and value.startswith("lin_")):
        return None
    try:
        start = float(value[4:])
    except ValueError:
        raise ConfigError(f"{name}={value!r}: a schedule is lin_<positive number>") from None
    if not (start > 0.0 and start < float("inf")):
        raise ConfigError(f"{name}={value!r}: a schedule is lin_<positive number>")
    return start


class LinearSchedule:
    """``start * progress_remaining``: from ``start`` at the beginning of training to 0 at its end
    (picklable, so it is saved with the model)."""

    def __init__(self, start: float) -> None:
        self.start = float(start)

    def __call__(self, progress_remaining: float) -> float:
        return self.start * float(progress_remaining)

    def __repr__(self) -> str:
        return f"lin_{self.start:g}"


def make_schedules(hyperparams: dict[str, Any]) -> dict[str, Any]:
    """``hyperparams`` with every ``lin_<value>`` of :data:`SCHEDULED` replaced by its schedule."""
    out = dict(hyperparams)
    for key in SCHEDULED & set(out):
        start = parse_schedule(key, out[key])
        if start is not None:
            out[key] = LinearSchedule(start)
    return out


def type_hints(fn: Any) -> tuple[list[str], dict[str, Any]]:
    """Keyword names and resolved type hints of ``fn`` (a constructor).

    stable-baselines3 annotates some arguments with names imported only for type checkers
    (``VecEnv``); they are supplied here. A hint that still cannot be resolved is left out (the
    name is still known, its value is then not type-checked).
    """
    params = [
        p.name
        for p in inspect.signature(fn).parameters.values()
        if p.name != "self" and p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)
    ]
    try:
        from stable_baselines3.common.vec_env import VecEnv

        hints = typing.get_type_hints(fn, localns={"VecEnv": VecEnv})
    except (NameError, TypeError, AttributeError):  # a forward reference we cannot resolve: names only
        hints = {}
    return params, hints


def _describe(annotation: Any) -> str:
    return str(annotation).replace("typing.", "").replace("<class '", "").replace("'>", "")


def _matches(value: Any, ann: Any) -> bool:
    """Whether a YAML value fits the annotation ``ann`` (structurally)."""
    if ann is Any or ann is inspect.Parameter.empty:
        return True
    if ann is type(None) or ann is None:
        return value is None
    origin = typing.get_origin(ann)
    if origin in (typing.Union, types.UnionType):
        return any(_matches(value, a) for a in typing.get_args(ann))
    if ann is bool:
        return isinstance(value, bool)
    if ann is int:
        return isinstance(value, numbers.Integral) and not isinstance(value, bool)
    if ann is float:
        return isinstance(value, numbers.Real) and not isinstance(value, bool)
    if ann is str:
        return isinstance(value, str)
    if origin in (list, collections.abc.Sequence):
        (item,) = typing.get_args(ann) or (Any,)
        return isinstance(value, list) and all(_matches(v, item) for v in value)
    if origin is tuple:
        args = typing.get_args(ann)
        if not isinstance(value, (list, tuple)):
            return False
        if len(args) == 2 and args[1] is Ellipsis:
            return all(_matches(v, args[0]) for v in value)
        return len(value) == len(args) and all(_matches(v, a) for v, a in zip(value, args))
    if origin in (dict, collections.abc.Mapping):
        k_ann, v_ann = typing.get_args(ann) or (Any, Any)
        return isinstance(value, dict) and all(_matches(k, k_ann) and _matches(v, v_ann) for k, v in value.items())
    if ann in (list, tuple, dict):
        return isinstance(value, ann if ann is not tuple else (list, tuple))
    return False  # classes, callables, objects: not expressible in a config


def _outside_int64(value: Any) -> int | None:
    """The first integer in ``value`` (nested lists, tuples and mappings) beyond :data:`INT64_MAX`."""
    stack = [value]
    while stack:
        v = stack.pop()
        if isinstance(v, numbers.Integral) and not isinstance(v, bool) and abs(int(v)) > INT64_MAX:
            return int(v)
        if isinstance(v, (list, tuple)):
            stack.extend(v)
        elif isinstance(v, dict):
            stack.extend(v.values())
    return None


def check_value(name: str, value: Any, annotation: Any) -> Any:
    """Check one value against its annotation and the domain rules; return it (tuples from lists).

    Raises
    ------
    ConfigError
        Naming ``name``, the value and the expected type; also for an integer beyond
        :data:`INT64_MAX` (a 401-digit ``batch_size`` is never a batch size).
    """
    leaf = name.rsplit(".", 1)[-1]
    if leaf in SCHEDULED and parse_schedule(name, value) is not None:
        return value
    if not _matches(value, annotation):
        raise ConfigError(f"{name}={format_value(value)} does not fit its type {_describe(annotation)}")
    big = _outside_int64(value)
    if big is not None:
        raise ConfigError(
            f"{name} holds the integer {format_value(big)}, outside the 64-bit range (|v| <= {INT64_MAX}) that "
            "PyTorch and NumPy count in"
        )
    if leaf in _POSITIVE_INT and value is not None and value < 1:
        raise ConfigError(f"{name} must be >= 1, got {value!r}")
    if leaf in _UNIT_INTERVAL and not 0.0 < float(value) <= 1.0:
        raise ConfigError(f"{name} must lie in (0, 1], got {value!r}")
    if leaf in ("learning_rate", "clip_range", "delta_std") and isinstance(value, numbers.Real) and not float(value) > 0.0:
        raise ConfigError(f"{name} must be > 0, got {value!r}")
    if leaf == "net_arch" and value is not None:
        sizes = value if isinstance(value, list) else [v for layer in value.values() for v in layer]
        if any(v < 1 for v in sizes):
            raise ConfigError(f"{name} layer sizes must be >= 1, got {value!r}")
    if isinstance(value, list):
        union = typing.get_origin(annotation) in (typing.Union, types.UnionType)
        members = typing.get_args(annotation) if union else (annotation,)
        as_list = any(a is list or typing.get_origin(a) in (list, collections.abc.Sequence) for a in members)
        if not as_list and any(a is tuple or typing.get_origin(a) is tuple for a in members):
            return tuple(value)  # e.g. train_freq: [1, "episode"]
    return value


def check_kwargs(where: str, kwargs: dict[str, Any], fn: Any, reserved: frozenset[str] = frozenset()) -> dict[str, Any]:
    """Check keyword arguments for ``fn`` (unknown names, reserved names, types).

    Parameters
    ----------
    where : str
        Prefix of the names in messages (``"hyperparams"``, ``"hyperparams.policy_kwargs"``).
    kwargs : dict
        The arguments.
    fn : callable
        The constructor they are for.
    reserved : set of str
        Names that exist but are set by the caller.

    Returns
    -------
    dict
        The checked arguments (lists converted to tuples where a tuple is expected).
    """
    if not isinstance(kwargs, dict):
        raise ConfigError(f"{where} must be a mapping, got {kwargs!r}")
    names, hints = type_hints(fn)
    owner = getattr(fn, "__qualname__", str(fn)).split(".")[0]
    out = {}
    for key, value in kwargs.items():
        if key in reserved:
            raise ConfigError(f"{where}.{key} is set by encctl-gym train itself and cannot be configured")
        if key not in names:
            known = ", ".join(n for n in names if n not in reserved and not n.startswith("_"))
            raise ConfigError(f"unknown {where} key {key!r} for {owner}; known: {known}")
        out[key] = check_value(f"{where}.{key}", value, hints.get(key, Any))
    return out


def network_bytes(net_arch: Any, n_in: int, n_out: int) -> int:
    """Estimated bytes of the policy networks of ``net_arch`` while training (an upper estimate).

    Every network of ``net_arch`` (a list: one actor and one critic of those layer sizes; a
    mapping such as ``{pi: [...], vf: [...]}``: one per entry) maps ``n_in`` inputs through its
    layers to ``n_out`` outputs. Each weight is counted 32 times in float32: the parameters,
    their gradients and Adam's two moments (16 bytes), twice for the critics' copies and targets
    of the off-policy algorithms.
    """
    if net_arch is None:
        return 0
    nets = [net_arch, net_arch] if isinstance(net_arch, (list, tuple)) else list(dict(net_arch).values())
    weights = 0
    for layers in nets:
        sizes = [int(n_in), *(int(v) for v in layers), int(n_out)]
        weights += sum((a + 1) * b for a, b in zip(sizes[:-1], sizes[1:]))
    return 32 * weights


def policy_kwargs(algo_cls: type, policy: str, kwargs: dict[str, Any] | None) -> dict[str, Any]:
    """``policy_kwargs`` checked against the policy class and made ready for the constructor.

    ``activation_fn`` is given by name (:data:`ACTIVATIONS`) and replaced by the ``torch.nn``
    class here.

    Parameters
    ----------
    algo_cls : type
        The algorithm class (its ``policy_aliases`` name the policy classes).
    policy : str
        The policy name (``MlpPolicy``, ``MlpLstmPolicy``, ...).
    kwargs : dict or None
        The config's ``hyperparams.policy_kwargs``.
    """
    aliases = getattr(algo_cls, "policy_aliases", {})
    if policy not in aliases:
        raise ConfigError(f"unknown policy {policy!r} for {algo_cls.__name__}; choose one of {', '.join(aliases)}")
    where = "hyperparams.policy_kwargs"
    pk = dict(kwargs or {})
    act = pk.pop("activation_fn", None)
    out = check_kwargs(where, pk, aliases[policy].__init__, _POLICY_RESERVED)
    if act is not None:
        if not isinstance(act, str) or act.lower() not in ACTIVATIONS:
            raise ConfigError(f"unknown {where}.activation_fn {act!r}; choose one of {', '.join(ACTIVATIONS)}")
        import torch.nn as nn

        out["activation_fn"] = getattr(nn, ACTIVATIONS[act.lower()])
    return out
