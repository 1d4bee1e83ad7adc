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
