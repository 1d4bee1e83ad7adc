"""Training configurations: the schema, the default per algorithm, the per-system files, overrides.

A configuration is one mapping (in the spirit of rl-zoo3's YAML files) that holds everything a
training run needs. It is built in layers, each merged over the previous one:

1. :data:`COMMON`: the algorithm-independent entries and their defaults (the schema below);
2. ``agents/configs/defaults/{algo}.yaml``: the algorithm's policy, hyperparameters and budget;
3. ``agents/configs/{algo}_{preset}.yaml`` when that file exists (tuned for one system), or the
   file given with ``--config``;
4. ``--preset NAME`` (the system) and ``--system FILE`` (a plant file's ``A`` and ``B``);
5. the ``quick:`` sections of the files above, with ``--quick`` (a smoke test);
6. ``--set key.sub=value`` overrides, in order.

================  ==========================================================================
key               meaning
================  ==========================================================================
``algo``          learning algorithm (a key of :data:`agents.sb3.ALGORITHMS`)
``env``           environment configuration (keys of ``encctl_gym.envs.default_config()``)
``horizon``       attack length N of the training episodes, set through the deciphering
                  budget (:func:`agents.evaluate.budget_config`); ``null``: the preset's own
``observation``   what the policy sees: ``full``, ``no_budget``, ``blind``
``features``      columns the attacker computes itself and appends to them (names of
                  :data:`agents.features.FEATURES`, e.g. ``[dither]``: its own randomness)
``reward_scaling`` ``none`` or ``samples`` (:class:`agents.sb3.SB3VecEnv`)
``n_envs``        parallel copies of the native vector environment
``n_timesteps``   training budget in environment steps (summed over the copies)
``seed``          training seed
``normalize``     ``norm_obs``, ``norm_reward`` of ``VecNormalize``
``policy``        policy name of the algorithm (``MlpPolicy``, ``MlpLstmPolicy``, ...)
``hyperparams``   keyword arguments of the algorithm class, checked against its signature
                  (:mod:`agents.hyperparams`); ``policy_kwargs`` against the policy's
``eval``          ``freq`` (steps between evaluations), ``episodes`` (per evaluation, on the
                  same seeds every time: ``seed``), ``final_episodes``, ``final_horizon``,
                  ``elgamal`` (``episodes``, ``max_samples``, ``key_length``) of the final
                  evaluation
``stopping``      ``rule`` (``none``: train ``n_timesteps``; ``oracle``: the rule of
                  :mod:`agents.stopping` on the learning curve, with ``tolerance``,
                  ``window``, ``plateau_gain``, ``min_evaluations``), ``budget``
                  (``fixed``: ``n_timesteps``; ``plant``: :func:`agents.stopping.plant_budget`
                  with ``iterations_per_gain``, at most ``n_timesteps``)
================  ==========================================================================

Every entry is checked (:func:`validate_config`): an unknown key, a value of the wrong type or
outside its range is a one-line :class:`~encctl_gym.errors.ConfigError`, whether it comes from
a file or from ``--set``. Files and ``--set`` values are read by the package's safe YAML reader
(:mod:`encctl_gym.safe_yaml`): at most 1 MiB, without aliases (nested aliases can expand a small
file into gigabytes), nested at most :data:`MAX_CONFIG_DEPTH` levels, no key given twice, and
``1e-3`` is a number as in YAML 1.2. Step counts are at most :data:`MAX_STEPS` and seeds at most
:data:`MAX_SEED`.
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from encctl_gym._validation import check_int, check_nonnegative, check_positive, format_value
from encctl_gym.envs.config import completion_preset, resolve_params
from encctl_gym.envs.config import default_config as env_default_config
from encctl_gym.errors import ConfigError, EncctlError, ParameterError
from encctl_gym.safe_yaml import load_yaml, read_yaml_file

from .base import OBSERVATION_MODES

__all__ = [
    "CONFIG_DIR",
    "DEFAULTS_DIR",
    "COMMON",
    "REWARD_SCALINGS",
    "BUDGETS",
    "MAX_CONFIG_BYTES",
    "MAX_CONFIG_DEPTH",
    "MAX_CONFIG_NODES",
    "MAX_STEPS",
    "MAX_SEED",
    "read_yaml",
    "default_config",
    "load_config",
    "apply_override",
    "validate_config",
    "env_config",
    "plant_config",
    "run_name",
]

CONFIG_DIR = Path(__file__).resolve().parent / "configs"
DEFAULTS_DIR = CONFIG_DIR / "defaults"
#: Largest config file read (bytes).
MAX_CONFIG_BYTES = 1 << 20
#: Deepest nesting of mappings and lists in a config file or an override value.
MAX_CONFIG_DEPTH = 32
#: Most YAML nodes in a config file or an override value (no aliases: the nodes written).
MAX_CONFIG_NODES = 1 << 20
#: How config files and override values are read: no aliases, every bound a ConfigError.
_YAML_POLICY: dict[str, Any] = {
    "max_nodes": MAX_CONFIG_NODES,
    "max_depth": MAX_CONFIG_DEPTH,
    "aliases": False,
    "limit_error": ConfigError,
}
#: Largest step count (``n_timesteps``, ``eval.freq``): stable-baselines3 divides step counts in
#: float64, exact for integers up to 2**53.
MAX_STEPS = 2**53
#: Largest seed: stable-baselines3 seeds NumPy's global generator, which takes seeds below 2**32.
MAX_SEED = 2**32 - 1
#: Choices of ``reward_scaling`` (:class:`agents.sb3.SB3VecEnv`).
REWARD_SCALINGS = ("none", "samples")
#: Choices of ``stopping.budget``: ``n_timesteps`` as given, or scaled to the plant
#: (:func:`agents.stopping.plant_budget`) with ``n_timesteps`` as its ceiling.
BUDGETS = ("fixed", "plant")

#: The algorithm-independent entries and their defaults.
COMMON: dict[str, Any] = {
    "env": {"preset": "paper-example", "reward": "log_error", "decipher_delay": 0},
    "horizon": None,
    "observation": "full",
    "features": [],
    "reward_scaling": "none",
    "n_envs": 16,
    "n_timesteps": 100_000,
    "seed": 0,
    "normalize": {"norm_obs": True, "norm_reward": False},
    "policy": "MlpPolicy",
    "hyperparams": {},
    "eval": {
        "freq": 50_000,
        "episodes": 16,
        "seed": 1_000_000,
        "final_episodes": 50,
        "final_horizon": None,
        "elgamal": {"episodes": 2, "max_samples": 40, "key_length": 64},
    },
    "stopping": {
        "rule": "none",
        "tolerance": 0.02,
        "window": 20,
        "plateau_gain": 0.02,
        "min_evaluations": 4,
        "budget": "fixed",
        "iterations_per_gain": 200.0,
    },
}


# --------------------------------------------------------------------------- reading
def read_yaml(path: str | Path) -> dict[str, Any]:
    """Read one config file: a YAML mapping, safe tags only, no aliases, at most 1 MiB, nested at
    most :data:`MAX_CONFIG_DEPTH` levels, no key twice (:func:`encctl_gym.safe_yaml.read_yaml_file`).

    Raises
    ------
    ConfigError
        Missing or unreadable file, a YAML error (including ``!!python/...`` tags and integers
        of over 4300 digits), an alias, deeper nesting, a key given twice, or a top level that
        is not a mapping.
    """
    p = Path(path)
    if not p.is_file():
        raise ConfigError(f"config file {str(p)!r} does not exist")
    data = read_yaml_file(p, what="config file", max_bytes=MAX_CONFIG_BYTES, limit_name="MAX_CONFIG_BYTES", **_YAML_POLICY)
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise ConfigError(f"config file {str(p)!r} must hold a mapping at the top level, got a {type(data).__name__}")
    return data


def _merge(base: dict[str, Any], over: dict[str, Any]) -> dict[str, Any]:
    """``over`` merged into a copy of ``base`` (mappings recursively, everything else replaced)."""
    out = copy.deepcopy(base)
    for k, v in over.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = _merge(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


def _algorithms() -> Mapping[str, type[Any]]:
    from .sb3 import ALGORITHMS

    return ALGORITHMS


def _split_quick(raw: dict[str, Any], where: str) -> tuple[dict[str, Any], dict[str, Any]]:
    raw = dict(raw)
    quick = raw.pop("quick", None) or {}
    if not isinstance(quick, dict):
        raise ConfigError(f"{where}: 'quick' must be a mapping, got {quick!r}")
    return raw, quick


def _defaults_file(algo: str) -> tuple[dict[str, Any], dict[str, Any]]:
    return _split_quick(read_yaml(DEFAULTS_DIR / f"{algo}.yaml"), f"defaults/{algo}.yaml")


def default_config(algo: str) -> dict[str, Any]:
    """:data:`COMMON` merged with ``agents/configs/defaults/{algo}.yaml`` (without its quick part)."""
    _check_algo(algo)
    raw, _ = _defaults_file(algo)
    return _merge(_merge(COMMON, raw), {"algo": algo})


def _check_algo(algo: Any) -> None:
    algos = _algorithms()
    if algo not in algos:
        raise ConfigError(f"unknown algorithm {algo!r}; choose one of {', '.join(algos)}")


def plant_config(path: str | Path, preset: str | None) -> dict[str, Any]:
    """The environment entries of a plant file: ``A``, ``B`` and every design value.

    The one place ``train --system FILE`` reads a plant, through the package's one plant-file
    schema (:func:`encctl_gym.plant_file.load_plant_file`, the reader of ``encctl-gym design``):
    the values the file gives (variances, gamma_c, tau_c, Upsilon) are used, the others come
    from ``preset`` (the environment's rule, :func:`encctl_gym.envs.config.completion_preset`:
    the system the configuration names, else ``paper-example``); with ``preset=None`` the file
    must give them all. Every value is written out, so the environment takes nothing from the
    preset silently.
    """
    from encctl_gym.plant_file import load_plant_file
    from encctl_gym.presets import get_preset

    spec = load_plant_file(path, defaults=get_preset(preset) if preset is not None else {})
    return {"preset": preset, "A": spec.A.tolist(), "B": spec.B.tolist(), **spec.values()}


def load_config(
    algo: str, preset: str | None = None, *, path: str | Path | None = None, system: str | Path | None = None, quick: bool = False
) -> dict[str, Any]:
    """The configuration of one training run, merged in the layers of the module docstring.

    Parameters
    ----------
    algo : str
        A key of :data:`agents.sb3.ALGORITHMS`.
    preset : str, optional
        The system preset (``env.preset``); its tuned file ``{algo}_{preset}.yaml`` is merged
        when it exists and no ``path`` is given.
    path : path, optional
        An explicit config file (instead of the preset's tuned file).
    system : path, optional
        A plant file whose ``A`` and ``B`` (and the design values it gives) replace the preset's
        (:func:`plant_config`); the design values it does not give (noise variances,
        ``gamma_c``, ``tau_c``, Upsilon) are the preset's.
    quick : bool
        Apply the ``quick:`` sections (a smoke test of a few thousand steps).

    Returns
    -------
    dict
        The validated configuration, with ``algo``, ``system`` (the label of the plant),
        ``config_files`` (the files merged) and ``quick``.

    Raises
    ------
    ConfigError
        For anything :func:`read_yaml` or :func:`validate_config` rejects.
    """
    _check_algo(algo)
    base, quick_parts = _defaults_file(algo)
    quick_layers = [quick_parts]
    cfg = _merge(COMMON, base)
    files = [str(DEFAULTS_DIR / f"{algo}.yaml")]
    if path is None and preset is not None and (CONFIG_DIR / f"{algo}_{preset}.yaml").is_file():
        path = CONFIG_DIR / f"{algo}_{preset}.yaml"
    if path is not None:
        raw, q = _split_quick(read_yaml(path), str(path))
        if raw.get("algo", algo) != algo:
            raise ConfigError(f"{Path(path).name} is a config for {raw['algo']!r}, not {algo!r}")
        cfg = _merge(cfg, raw)
        quick_layers.append(q)
        files.append(str(path))
    if not isinstance(cfg.get("env"), dict):
        raise ConfigError(f"env must be a mapping, got {cfg.get('env')!r}")
    if preset is not None:
        cfg["env"]["preset"] = preset
    if quick:
        for q in quick_layers:
            cfg = _merge(cfg, q)
        if not isinstance(cfg.get("env"), dict):
            raise ConfigError(f"env must be a mapping, got {cfg.get('env')!r}")
    if system is not None:
        cfg["env"].update(plant_config(system, completion_preset(cfg["env"])))
        cfg["system"] = Path(system).stem
    else:
        cfg["system"] = str(cfg["env"].get("preset"))
    cfg.update(algo=algo, config_files=files, quick=bool(quick))
    validate_config(cfg)
    return cfg


# --------------------------------------------------------------------------- schema
Check = Callable[[str, Any], Any]


def _int(minimum: int, optional: bool = False, maximum: int | None = None) -> Check:
    def check(name: str, v: Any) -> Any:
        if v is None and optional:
            return v
        return check_int(name, v, minimum, maximum, error=ConfigError)  # the package's one integer rule

    return check


def _choice(options: tuple[str, ...]) -> Check:
    def check(name: str, v: Any) -> Any:
        if not isinstance(v, str) or v not in options:
            raise ConfigError(f"{name} must be one of {', '.join(options)}, got {v!r}")
        return v

    return check


def _typed(typ: type | tuple[type, ...], label: str) -> Check:
    def check(name: str, v: Any) -> Any:
        if not isinstance(v, typ):
            raise ConfigError(f"{name} must be {label}, got {v!r}")
        return v

    return check


_bool = _typed(bool, "true or false")


def _features(name: str, v: Any) -> Any:
    from .features import check_features

    return check_features(v, name)


_str = _typed(str, "a string")


def _checked(check: Callable[[str, Any], float]) -> Check:
    """A number check of :mod:`encctl_gym._validation` raising :class:`ConfigError` instead."""

    def run(name: str, v: Any) -> Any:
        try:
            return check(name, v)
        except ParameterError as exc:
            raise ConfigError(str(exc)) from None

    return run


def _stopping_rules() -> tuple[str, ...]:
    from .stopping import RULES

    return RULES


#: Checks of every entry but ``env`` and ``hyperparams`` (checked against the environment and
#: the algorithm). A nested mapping is a nested schema.
SCHEMA: dict[str, Any] = {
    "algo": _str,
    "system": _str,
    "config_files": _typed(list, "a list of paths"),
    "quick": _bool,
    "horizon": _int(2, optional=True, maximum=MAX_STEPS),
    "observation": _choice(OBSERVATION_MODES),
    "features": lambda name, v: _features(name, v),
    "reward_scaling": _choice(REWARD_SCALINGS),
    "n_envs": _int(1, maximum=MAX_STEPS),
    "n_timesteps": _int(1, maximum=MAX_STEPS),
    "seed": _int(0, maximum=MAX_SEED),
    "normalize": {"norm_obs": _bool, "norm_reward": _bool},
    "policy": _str,
    "eval": {
        "freq": _int(1, maximum=MAX_STEPS),
        "episodes": _int(1, maximum=MAX_STEPS),
        "seed": _int(0, maximum=MAX_SEED),
        "final_episodes": _int(1, maximum=MAX_STEPS),
        "final_horizon": _int(2, optional=True, maximum=MAX_STEPS),
        "elgamal": {"episodes": _int(0, maximum=MAX_STEPS), "max_samples": _int(2, maximum=MAX_STEPS), "key_length": _int(16)},
    },
    "stopping": {
        "rule": lambda name, v: _choice(_stopping_rules())(name, v),
        "tolerance": _checked(check_nonnegative),
        "window": _int(3, maximum=MAX_STEPS),
        "plateau_gain": _checked(check_nonnegative),
        "min_evaluations": _int(2, maximum=MAX_STEPS),
        "budget": _choice(BUDGETS),
        "iterations_per_gain": _checked(check_positive),
    },
}


def _check_tree(prefix: str, node: Any, schema: dict[str, Any]) -> None:
    if not isinstance(node, dict):
        raise ConfigError(f"{prefix or 'config'} must be a mapping, got {node!r}")
    for key, value in node.items():
        name = f"{prefix}.{key}" if prefix else str(key)
        if key not in schema:
            raise ConfigError(f"unknown config key {name!r}; known here: {', '.join(schema)}")
        rule = schema[key]
        if isinstance(rule, dict):
            _check_tree(name, value, rule)
        else:
            rule(name, value)


def validate_config(cfg: dict[str, Any]) -> None:
    """Check a whole configuration; raise :class:`ConfigError` naming the first bad entry.

    ``env`` is resolved by the environment's own checks (every key of
    ``encctl_gym.envs.default_config()``, at the training attack length, and the final
    evaluation's ElGamal episodes of ``eval.elgamal``); ``hyperparams`` and
    ``hyperparams.policy_kwargs`` are checked against the algorithm's and the policy's
    constructors (:mod:`agents.hyperparams`).
    """
    if not isinstance(cfg, dict):
        raise ConfigError(f"a config must be a mapping, got {cfg!r}")
    rest = {k: v for k, v in cfg.items() if k not in ("env", "hyperparams")}
    _check_tree("", rest, SCHEMA)
    _check_algo(cfg.get("algo"))
    env = cfg.get("env")
    if not isinstance(env, dict):
        raise ConfigError(f"env must be a mapping, got {env!r}")
    unknown = sorted(set(env) - set(env_default_config()))
    if unknown:
        raise ConfigError(f"unknown config key(s) env.{unknown[0]}; known: {', '.join(sorted(env_default_config()))}")
    try:
        resolve_params(env_config(cfg))
    except ParameterError as exc:
        raise ConfigError(f"env: {exc}") from exc
    _check_elgamal_evaluation(cfg)
    from .hyperparams import RESERVED, check_kwargs, policy_kwargs

    algo_cls = _algorithms()[cfg["algo"]]
    hp = cfg.get("hyperparams", {})
    if not isinstance(hp, dict):
        raise ConfigError(f"hyperparams must be a mapping, got {hp!r}")
    check_kwargs(
        "hyperparams", {k: v for k, v in hp.items() if k != "policy_kwargs"}, algo_cls.__init__, RESERVED - {"policy_kwargs"}
    )
    policy_kwargs(algo_cls, cfg.get("policy", "MlpPolicy"), hp.get("policy_kwargs"))


def _check_elgamal_evaluation(cfg: dict[str, Any]) -> None:
    """The final evaluation's ElGamal episodes (``eval.elgamal``) resolved now, not after training."""
    from .evaluate import elgamal_config

    el = (cfg.get("eval") or {}).get("elgamal") or {}
    if not el.get("episodes"):
        return
    try:
        resolve_params(elgamal_config(env_config(cfg), int(el["max_samples"]), key_length=int(el["key_length"]), crypto_seed=0))
    except EncctlError as exc:
        raise ConfigError(
            f"eval.elgamal (max_samples = {format_value(el['max_samples'])}, key_length = "
            f"{format_value(el['key_length'])}): {exc}"
        ) from None


# --------------------------------------------------------------------------- overrides
def _yaml_value(text: str) -> Any:
    """A YAML value (:func:`encctl_gym.safe_yaml.load_yaml`, the bounds of a config file); a plain
    string that Python reads as a number (``inf``, ``1_000.5``) is that float."""
    v = load_yaml(text, what=f"override value {format_value(text)}", **_YAML_POLICY)
    if isinstance(v, str):
        try:
            return float(v)
        except ValueError:
            return v
    return v


def apply_override(cfg: dict[str, Any], item: str) -> None:
    """Apply one ``key.sub=value`` override (value read as YAML) to ``cfg`` in place, then check
    the whole configuration (:func:`validate_config`).

    Raises
    ------
    ConfigError
        ``item`` is not ``KEY=VALUE``, the key is unknown (in the schema, the environment, the
        algorithm's or the policy's signature), a level above it is not a mapping, or the value
        is rejected.
    """
    if "=" not in item:
        raise ConfigError(f"override {item!r} is not KEY=VALUE")
    key, value = item.split("=", 1)
    parts = key.strip().split(".")
    if not all(parts):
        raise ConfigError(f"override key {key!r} has an empty part")
    trial = copy.deepcopy(cfg)
    nested = {"policy_kwargs", *(k for k, v in SCHEMA.items() if isinstance(v, dict))}
    node = trial
    for i, p in enumerate(parts[:-1]):
        if node.get(p) is None and p in nested:
            node[p] = {}
        if not isinstance(node.get(p), dict):
            raise ConfigError(f"override {key!r}: {'.'.join(parts[: i + 1])!r} is not a mapping of the config")
        node = node[p]
    node[parts[-1]] = _yaml_value(value)
    validate_config(trial)
    cfg.clear()
    cfg.update(trial)


# --------------------------------------------------------------------------- derived
def env_config(cfg: dict[str, Any], **over: Any) -> dict[str, Any]:
    """The training environment's configuration (``horizon`` applied through the budget)."""
    from .evaluate import budget_config

    env = {"gamma_opt": False, **cfg["env"]}
    env.update(over)
    if cfg.get("horizon"):
        env = budget_config(env, int(cfg["horizon"]))
    return env


def run_name(cfg: dict[str, Any], seed: int) -> str:
    """``{algo}_{system}_d{delay}_{observation}_s{seed}`` (``-quick`` for smoke tests)."""
    delay = cfg["env"].get("decipher_delay", 0)
    name = f"{cfg['algo']}_{cfg.get('system', cfg['env'].get('preset', 'custom'))}_d{delay}_{cfg['observation']}_s{seed}"
    return name + ("-quick" if cfg.get("quick") else "")
