"""The environment is registered once, in either import order, and the math layers do not
import gymnasium."""

from __future__ import annotations

import subprocess
import sys

import pytest


def _run(code: str) -> str:
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    return out.stdout.strip()


@pytest.mark.parametrize(
    "module", ["encctl_gym", "encctl_gym.security", "encctl_gym.crypto", "encctl_gym.ident", "encctl_gym.sim"]
)
def test_the_lower_layers_do_not_import_gymnasium(module):
    assert _run(f"import sys, {module}; print('gymnasium' in sys.modules)") == "False"


@pytest.mark.parametrize(
    "imports",
    [
        "import encctl_gym; import gymnasium as gym",
        "import gymnasium as gym; import encctl_gym",
        "import encctl_gym; import gymnasium.spaces; import gymnasium as gym",
        "import encctl_gym.envs; import gymnasium as gym",
    ],
)
def test_make_finds_the_environment_in_every_import_order(imports):
    code = (
        f"{imports}\n"
        "env = gym.make('encctl_gym/EncryptedLTIAttack-v0', config={'preset': 'small', 'gamma_opt': False})\n"
        "print(env.reset(seed=0)[0].shape, sum(1 for k in gym.registry if k.startswith('encctl_gym/')))"
    )
    assert _run(code) == "(11,) 1"


def test_moved_names_keep_their_old_import_paths():
    """The README's table of moved names: each old path still imports, and the names are the
    new homes' own objects (the forge names with a DeprecationWarning)."""
    import importlib
    import warnings

    from encctl_gym import parallel
    from encctl_gym.attacks import forgery
    from encctl_gym.crypto import quantized, servers

    old = importlib.import_module("encctl_gym.sim.identification")
    for name in old.__all__:
        assert getattr(old, name) is getattr(importlib.import_module("encctl_gym.ident.least_squares"), name)
    assert "least_squares" in old.__all__ and "identification_errors" in old.__all__
    assert importlib.import_module("encctl_gym.sim.parallel").run_tasks is parallel.run_tasks
    controller = importlib.import_module("encctl_gym.crypto.controller")
    assert controller.ControllerServer is servers.ControllerServer
    assert controller.QuantizedLinearController is quantized.QuantizedLinearController
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert controller.forge_injection is forgery.forge_injection
    assert any(issubclass(w.category, DeprecationWarning) for w in caught)
