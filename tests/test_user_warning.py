"""Warnings point at the user's line (issue 34, item 7): :func:`encctl_gym._user_warning.warn_user`.

The package's frames are simulated by code compiled under a file name inside ``encctl_gym/``; the
Gymnasium path by a toy environment whose entry point is such code, made with ``gymnasium.make``.
"""

from __future__ import annotations

import inspect
import warnings
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import encctl_gym
from encctl_gym._user_warning import user_frame, warn_user
from encctl_gym.registration import ENV_ID

PACKAGE_DIR = Path(encctl_gym.__file__).resolve().parent

INTERNAL_SOURCE = """
import gymnasium as gym
import numpy as np

def inner(message):
    warn_user(message)

def outer(message):
    inner(message)

class ToyEnv(gym.Env):
    observation_space = gym.spaces.Box(-1.0, 1.0, (1,), dtype=np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (1,), dtype=np.float32)

    def __init__(self, **kwargs):
        outer("made a toy")
"""


@pytest.fixture(scope="module")
def internal() -> dict[str, object]:
    """Functions whose frames lie in the package (a file name under encctl_gym/)."""
    namespace: dict[str, object] = {"warn_user": warn_user, "__name__": "encctl_gym._fake_internal"}
    exec(compile(INTERNAL_SOURCE, str(PACKAGE_DIR / "_fake_internal.py"), "exec"), namespace)  # noqa: S102
    return namespace


def _line() -> int:
    frame = inspect.currentframe()
    assert frame is not None and frame.f_back is not None
    return frame.f_back.f_lineno


def test_a_warning_from_nested_package_frames_points_at_the_callers_line(internal: dict[str, object]) -> None:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        line = _line() + 1
        internal["outer"]("deep")  # type: ignore[operator]
    assert [(w.filename, w.lineno, str(w.message)) for w in caught] == [(__file__, line, "deep")]


def test_through_gymnasium_make_it_points_at_the_make_line(internal: dict[str, object]) -> None:
    env_id = "encctl_gym_test/ToyWarning-v0"
    if env_id not in gym.registry:
        gym.register(id=env_id, entry_point=internal["ToyEnv"], disable_env_checker=True)  # type: ignore[arg-type]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        line = _line() + 1
        gym.make(env_id)
    ours = [w for w in caught if str(w.message) == "made a toy"]
    assert [(w.filename, w.lineno) for w in ours] == [(__file__, line)]
    assert "registration.py" not in ours[0].filename


def test_filters_see_the_users_module(internal: dict[str, object]) -> None:
    with warnings.catch_warnings():
        warnings.filterwarnings("error", module=__name__)
        with pytest.raises(UserWarning, match="filtered"):
            internal["outer"]("filtered")  # type: ignore[operator]


def test_with_no_frame_outside_the_package_the_callers_line_is_used() -> None:
    assert user_frame(None) is None
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        line = _line() + 1
        warn_user("direct")  # this file is outside the package: its own line
    assert [(w.filename, w.lineno) for w in caught] == [(__file__, line)]


def _capped_or_inherited(make: str) -> list[warnings.WarningMessage]:
    config = {"A": 0.5 * np.eye(2), "B": np.eye(2)}  # values from the preset: the A/B warning
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        if make == "gym.make":
            gym.make(ENV_ID, config=config)
        elif make == "class":
            from encctl_gym.envs import EncryptedLTIAttackEnv

            EncryptedLTIAttackEnv(config=config)
        else:
            gym.make_vec(ENV_ID, num_envs=2, config=config)
    return [w for w in caught if "come from preset" in str(w.message)]


def test_built_directly_the_environments_warning_points_at_the_users_line() -> None:
    caught = _capped_or_inherited("class")
    assert caught and all(w.filename == __file__ for w in caught), [(w.filename, w.lineno) for w in caught]


@pytest.mark.parametrize("make", ["gym.make", "gym.make_vec"])
def test_through_gymnasium_the_environments_warnings_point_at_the_users_line(make: str) -> None:
    caught = _capped_or_inherited(make)
    assert caught and all(w.filename == __file__ for w in caught), [(w.filename, w.lineno) for w in caught]
