"""The one safe YAML reader (encctl_gym.safe_yaml) and its two policies: plant files (aliases
counted expanded) and training configurations (no aliases); both refuse billion laughs before
building anything, deep nesting and keys given twice, and read the repository's own files as the
previous loaders did (PyYAML's safe loader; for plant files with ``1e-6`` as a float)."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import pytest
import yaml

import encctl_gym.safe_yaml as safe_yaml
from encctl_gym.agents.config import MAX_CONFIG_DEPTH, apply_override, load_config, read_yaml
from encctl_gym.errors import ConfigError, ResourceLimitError
from encctl_gym.plant_file import MAX_YAML_DEPTH, MAX_YAML_NODES, load_plant_file
from encctl_gym.safe_yaml import load_yaml

REPO = Path(__file__).resolve().parents[1]


def _bomb(levels: int, width: int, leaf: str = "1") -> str:
    """A billion-laughs document: level i is ``width`` aliases of level i - 1, so the last one
    expands to width**levels leaves (written in a few hundred bytes)."""
    lines = [f"a0: &a0 [{', '.join([leaf] * width)}]"]
    lines += [f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * width) + "]" for i in range(1, levels)]
    return "\n".join(lines) + f"\nA: *a{levels - 1}\nB: [[1]]\n"


@pytest.fixture(params=["C", "pure Python"])
def parser(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> str:
    """Every test runs with libyaml's parser and with PyYAML's own (the fallback without libyaml)."""
    if request.param == "C":
        if not hasattr(yaml, "CSafeLoader"):
            pytest.skip("PyYAML without libyaml")
        return request.param
    cls: Any = type("PurePythonLoader", (yaml.SafeLoader,), {})
    cls.add_implicit_resolver("tag:yaml.org,2002:float", re.compile(safe_yaml._EXPONENT_FLOAT), list("-+0123456789"))
    monkeypatch.setattr(safe_yaml, "_loader_class", lambda: cls)
    return request.param


def _refuse_construction(monkeypatch: pytest.MonkeyPatch) -> None:
    """From now on, fail the test if PyYAML's constructor builds any Python object."""

    def refuse(self: Any, node: Any) -> Any:
        raise AssertionError("a Python object was built from a refused document")

    monkeypatch.setattr(safe_yaml._loader_class(), "construct_document", refuse)


@pytest.fixture
def nothing_built(monkeypatch: pytest.MonkeyPatch, parser: str) -> None:
    """Fail the test if PyYAML's constructor builds any Python object."""
    _refuse_construction(monkeypatch)


# --------------------------------------------------------------------------- billion laughs
def test_plant_file_billion_laughs_is_refused_before_expansion(tmp_path: Path, nothing_built: None) -> None:
    # 40 levels of 10 aliases: 10**40 leaves, which no machine could expand, in under 3 kB
    path = tmp_path / "bomb.yaml"
    path.write_text(_bomb(40, 10))
    assert path.stat().st_size < 3000
    with pytest.raises(ResourceLimitError) as exc:
        load_plant_file(path)
    message = str(exc.value)
    assert str(path) in message and f"expand to more than {MAX_YAML_NODES} nodes" in message and "\n" not in message


def test_config_billion_laughs_is_refused_at_the_first_alias(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, parser: str
) -> None:
    pytest.importorskip("sb3_contrib", reason="the training configurations name the rl extra's algorithms")
    cfg = load_config("ppo", "small", quick=True)
    _refuse_construction(monkeypatch)
    path = tmp_path / "bomb.yaml"
    path.write_text(_bomb(40, 10, leaf="lol"))
    with pytest.raises(ConfigError, match=r"config file '.*bomb\.yaml' uses a YAML alias \(\*a0\)"):
        read_yaml(path)
    with pytest.raises(ConfigError, match=r"override value .* uses a YAML alias \(\*x\)"):
        apply_override(cfg, "hyperparams.policy_kwargs={a: &x [1], b: *x}")


def test_aliases_within_the_node_bound_expand_as_pyyaml_expands_them(parser: str) -> None:
    text = _bomb(3, 4)  # 4**3 = 64 leaves under A
    # by hand: a0 = [1 x 4] is 5 nodes, a1 = [*a0 x 4] 1 + 4 * 5 = 21, a2 = A = 1 + 4 * 21 = 85,
    # B = [[1]] 3; the top mapping 1 + 5 keys + 5 + 21 + 85 + 85 + 3 = 205
    assert load_yaml(text, what="t", max_nodes=205, max_depth=8, aliases=True) == yaml.safe_load(text)
    with pytest.raises(ResourceLimitError, match="t: its YAML aliases expand to more than 204 nodes"):
        load_yaml(text, what="t", max_nodes=204, max_depth=8, aliases=True)


def test_node_count_is_exact_at_the_bound(parser: str) -> None:
    text = "[" + ", ".join(["1"] * 9) + "]"  # one list and nine scalars: ten nodes
    assert load_yaml(text, what="t", max_nodes=10, max_depth=2, aliases=False) == [1] * 9
    with pytest.raises(ConfigError, match="t holds more than 9 YAML nodes"):
        load_yaml(text, what="t", max_nodes=9, max_depth=2, aliases=False, limit_error=ConfigError)
    # a shared node counts once per use: [*x, *x] with x = [1, 1] is 1 + 2 * 3 = 7 nodes
    shared = "[&x [1, 1], *x]"
    assert load_yaml(shared, what="t", max_nodes=7, max_depth=2, aliases=True) == [[1, 1], [1, 1]]
    with pytest.raises(ResourceLimitError):
        load_yaml(shared, what="t", max_nodes=6, max_depth=2, aliases=True)


def test_recursive_and_undefined_aliases(parser: str) -> None:
    with pytest.raises(ConfigError, match="recursive alias"):
        load_yaml("A: &x [*x]\n", what="t", max_nodes=100, max_depth=8, aliases=True)
    with pytest.raises(ConfigError, match="undefined alias 'y'"):
        load_yaml("A: [*y]\n", what="t", max_nodes=100, max_depth=8, aliases=True)


# --------------------------------------------------------------------------- nesting
@pytest.mark.parametrize("depth", [33, 999, 100_000])
def test_deep_nesting_is_refused_in_both_uses(tmp_path: Path, parser: str, depth: int) -> None:
    plant = tmp_path / "deep.yaml"
    plant.write_text("A: " + "[" * depth + "]" * depth + "\nB: [[1]]\n")
    with pytest.raises(ConfigError, match=f"more than {MAX_YAML_DEPTH} levels deep") as exc:
        load_plant_file(plant)
    assert str(plant) in str(exc.value)
    config = tmp_path / "config.yaml"
    config.write_text("x:\n" + "".join(" " * i + "-\n" for i in range(1, min(depth, 1200))))  # block lists
    with pytest.raises(ConfigError, match=f"more than {MAX_CONFIG_DEPTH} levels deep"):
        read_yaml(config)


def test_nesting_at_the_bound_is_read(parser: str) -> None:
    text = "x: " + "[" * 3 + "]" * 3  # the mapping and three lists: four levels
    assert load_yaml(text, what="t", max_nodes=100, max_depth=4, aliases=False) == {"x": [[[]]]}
    with pytest.raises(ConfigError, match="t nests mappings or lists more than 3 levels deep"):
        load_yaml(text, what="t", max_nodes=100, max_depth=3, aliases=False)
    # a list without indentation under a key is a level too
    assert load_yaml("x:\n- 1\n", what="t", max_nodes=100, max_depth=2, aliases=False) == {"x": [1]}
    with pytest.raises(ConfigError, match="more than 1 levels"):
        load_yaml("x:\n- 1\n", what="t", max_nodes=100, max_depth=1, aliases=False)


# --------------------------------------------------------------------------- duplicate keys
@pytest.mark.parametrize(
    "text, where",
    [
        ("a: 1\nb: 2\na: 3\n", "a"),
        ("env:\n  preset: x\n  reward: r\n  preset: y\n", "env.preset"),
        ("a: [1, {b: 1, c: 2, b: 3}]\n", "a[1].b"),
        ("- {k: 1}\n- {k: 1, k: 2}\n", "[1].k"),
    ],
)
def test_a_key_given_twice_is_refused(parser: str, text: str, where: str) -> None:
    assert len(yaml.safe_load(text)) >= 1  # PyYAML alone keeps the last value silently
    with pytest.raises(ConfigError, match=re.escape(f"t: field '{where}' is given more than once")):
        load_yaml(text, what="t", max_nodes=100, max_depth=8, aliases=False)


def test_duplicate_keys_in_both_uses(tmp_path: Path, parser: str) -> None:
    plant = tmp_path / "p.yaml"
    plant.write_text("A: [[0.5]]\nB: [[1]]\nA: [[0.9]]\n")
    with pytest.raises(ConfigError, match=r"system file '.*p\.yaml': field 'A' is given more than once"):
        load_plant_file(plant)
    config = tmp_path / "c.yaml"
    config.write_text("n_envs: 2\nhyperparams:\n  gamma: 0.9\n  gamma: 0.99\n")
    with pytest.raises(ConfigError, match=r"config file '.*c\.yaml': field 'hyperparams.gamma' is given more than once"):
        read_yaml(config)
    # the same text under different tags is two keys ('1' the string, 1 the integer)
    assert load_yaml("'1': a\n1: b\n", what="t", max_nodes=10, max_depth=2, aliases=False) == {"1": "a", 1: "b"}


# --------------------------------------------------------------------------- what is read
def test_unsafe_tags_syntax_and_documents(parser: str) -> None:
    with pytest.raises(ConfigError, match="cannot read t: .could not determine a constructor"):
        load_yaml("!!python/object/apply:os.system ['true']", what="t", max_nodes=10, max_depth=2, aliases=False)
    with pytest.raises(ConfigError, match=r"cannot read t: not valid YAML: .*\(line \d+, column \d+\)"):
        load_yaml("a: [1, 2\n", what="t", max_nodes=10, max_depth=2, aliases=False)
    with pytest.raises(ConfigError, match="more than one YAML document"):
        load_yaml("a: 1\n---\nb: 2\n", what="t", max_nodes=10, max_depth=2, aliases=False)
    with pytest.raises(ConfigError, match="cannot read t: .*4300"):
        load_yaml("n: " + "9" * 5000, what="t", max_nodes=10, max_depth=2, aliases=False)
    assert load_yaml("", what="t", max_nodes=10, max_depth=2, aliases=False) is None
    assert load_yaml("# only a comment\n", what="t", max_nodes=10, max_depth=2, aliases=False) is None
    values = load_yaml("[1e-6, 442e15, '1e-6', 3.0e-4, lin_1.0e-3]", what="t", max_nodes=10, max_depth=2, aliases=False)
    assert values == [1e-6, 442e15, "1e-6", 3.0e-4, "lin_1.0e-3"]
    assert [type(v) for v in values] == [float, float, str, float, str]


def _typed(value: Any) -> Any:
    """``value`` with the type of every leaf (1 == 1.0 == True in Python; the loads must agree on types)."""
    if isinstance(value, dict):
        return {(type(k).__name__, k): _typed(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_typed(v) for v in value]
    return (type(value).__name__, value)


def _previous_plant_loader() -> Any:
    """The plant file's reader before the one safe reader: PyYAML's safe loader with ``1e-6`` a float."""
    cls: Any = type("PreviousPlantLoader", (yaml.SafeLoader,), {})
    cls.add_implicit_resolver(
        "tag:yaml.org,2002:float", re.compile(r"^[-+]?[0-9][0-9_]*(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"), list("-+0123456789")
    )
    return cls


CONFIG_FILES = sorted((REPO / "agents" / "configs").rglob("*.yaml")) + sorted(
    (REPO / "docs" / "results" / "learned" / "ppo_trials").glob("*.yaml")
)
PLANT_FILES = [REPO / "docs" / "results" / "learned" / "plant3x2_r10.yaml"]


def test_the_repository_files_are_found() -> None:
    assert len(CONFIG_FILES) >= 5 and all(p.is_file() for p in CONFIG_FILES + PLANT_FILES)


@pytest.mark.parametrize("path", CONFIG_FILES, ids=lambda p: str(p.relative_to(REPO)))
def test_config_files_load_as_before(path: Path) -> None:
    assert _typed(read_yaml(path)) == _typed(yaml.safe_load(path.read_text()) or {})


@pytest.mark.parametrize("path", PLANT_FILES, ids=lambda p: str(p.relative_to(REPO)))
def test_plant_files_load_as_before(path: Path) -> None:
    text = path.read_text()
    previous = yaml.load(text, Loader=_previous_plant_loader())  # noqa: S506 - a safe loader
    now = load_yaml(text, what="t", max_nodes=MAX_YAML_NODES, max_depth=MAX_YAML_DEPTH, aliases=True)
    assert _typed(now) == _typed(previous)
    spec = load_plant_file(path)
    assert spec.A.tolist() == previous["A"] and spec.B.tolist() == previous["B"]
