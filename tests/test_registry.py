"""The one registry helper (encctl_gym.registry.Registry) and the registries built on it."""

from __future__ import annotations

import pytest

from encctl_gym.errors import ConfigError, EncctlError, ParameterError
from encctl_gym.registry import Registry


class Quiet:
    name = "quiet"

    def __init__(self, level: int = 0, *, scale: float = 1.0) -> None:
        self.level = level
        self.scale = scale


class Loud:
    name = "loud"

    def __init__(self, *args: object, **kwargs: object) -> None:
        self.args = args


def test_rows_by_their_name_attribute_or_by_mapping() -> None:
    reg = Registry("sound", [Quiet, Loud])
    assert reg.names() == ["quiet", "loud"] and list(reg) == ["quiet", "loud"] and len(reg) == 2
    assert reg["quiet"] is Quiet and reg.lookup("loud") is Loud and "quiet" in reg and "soft" not in reg
    by_map = Registry("sound", {"q": Quiet})
    assert by_map.names() == ["q"] and by_map.lookup("q") is Quiet


def test_unknown_names_list_the_registered_ones_in_the_registry_error() -> None:
    reg = Registry("sound", [Quiet, Loud])
    with pytest.raises(ParameterError, match=r"unknown sound 'soft'; choose one of quiet, loud"):
        reg.lookup("soft")
    with pytest.raises(ParameterError, match="unknown sound"):
        reg.lookup(["quiet"])  # unhashable: still the registry's error, not a TypeError
    strict = Registry("sound", [Quiet], error=ConfigError)
    with pytest.raises(ConfigError):
        strict.lookup("loud")
    with pytest.raises(KeyError):  # the mapping protocol keeps KeyError (so .get and `in` work)
        strict["loud"]
    assert strict.get("loud") is None


def test_build_checks_options_against_the_constructor() -> None:
    reg = Registry("sound", [Quiet, Loud])
    assert reg.options("quiet") == ("level", "scale")
    q = reg.build("quiet", level=3, scale=0.5)
    assert isinstance(q, Quiet) and (q.level, q.scale) == (3, 0.5)
    with pytest.raises(ParameterError, match=r"the sound 'quiet' has no option 'volume'; its options: level, scale"):
        reg.build("quiet", volume=2)
    assert reg.options("loud") == ()  # *args and **kwargs are not named options
    with pytest.raises(ParameterError, match="its options: none"):
        reg.build("loud", anything=1)


def test_register_refuses_duplicates_and_nameless_entries_and_decorates() -> None:
    reg: Registry[type] = Registry("sound")

    @reg.register
    class Hum:
        name = "hum"

    assert reg.lookup("hum") is Hum
    with pytest.raises(ParameterError, match="already registered"):
        reg.register(Hum)
    with pytest.raises(ParameterError, match="no registry name"):
        reg.register(object)
    with pytest.raises(ParameterError, match="non-empty str"):
        reg.register(Hum, name="")
    assert issubclass(ParameterError, EncctlError)


def test_every_registry_of_the_package_is_one_registry() -> None:
    from encctl_gym.agents.features import FEATURES
    from encctl_gym.cryptanalysis import BREAKERS
    from encctl_gym.envs.rewards import REWARDS
    from encctl_gym.experiments.compare.attackers import ATTACKERS
    from encctl_gym.ident import ESTIMATORS
    from encctl_gym.presets import PRESETS
    from encctl_gym.security.cost_models import DECIPHERING_MODELS

    for reg in (BREAKERS, ESTIMATORS, DECIPHERING_MODELS, REWARDS, PRESETS, FEATURES, ATTACKERS):
        assert isinstance(reg, Registry) and len(reg) > 0
        with pytest.raises(EncctlError, match=f"unknown {reg.kind} 'no-such-name'; choose one of {', '.join(reg)}"):
            reg.lookup("no-such-name")
    # the options of a cost model are its constructor's (no table of option names beside it)
    assert DECIPHERING_MODELS.options("precomputation") == ("gnfs_correction", "calibration")
    assert DECIPHERING_MODELS.options("generic") == ()
