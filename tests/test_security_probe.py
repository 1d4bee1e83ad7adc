"""Probe: inputs that used to hang or exhaust memory, each run in a forked child with a memory cap
and a timeout (the shared harness, :func:`probe.harness.run_bounded`). Every case must end quickly
with an error of the package's hierarchy (or a correct result), never a hang, an out-of-memory
kill or another exception. The whole probe is ``tests/test_probe.py``.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from probe.harness import fork_available, run_bounded

pytestmark = pytest.mark.skipif(not fork_available(), reason="needs fork and /proc (Linux)")


def _cases(tmp: Path) -> dict[str, Callable[[], Any]]:
    from encctl_gym.cli import main
    from encctl_gym.plant_file import load_plant_file
    from encctl_gym.security.attack_design import optimal_attack_design
    from encctl_gym.security.cost_models import bit_security_of_key_length, minimum_key_length
    from encctl_gym.security.deciphering import max_affordable_samples, sample_deciphering_time_exact
    from encctl_gym.security.exact import pow2
    from encctl_gym.security.key_length import design_key_length
    from encctl_gym.security.threat import ThreatModel
    from encctl_gym.units import parse_duration

    bomb = tmp / "bomb.yaml"
    lines = ["a0: &a0 [1, 1, 1, 1, 1, 1, 1, 1, 1, 1]"]
    lines += [f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 10) + "]" for i in range(1, 9)]
    bomb.write_text("\n".join(lines) + "\nA: *a8\nB: [[1]]\n")

    def cli_exit_2(argv: list[str]) -> Callable[[], None]:
        def call() -> None:
            from encctl_gym.errors import ParameterError

            rc = main(argv)
            if rc != 2:
                raise AssertionError(f"exit code {rc}")
            raise ParameterError("exit code 2")  # reported as a package error

        return call

    n = 200
    big = tmp / "big.npz"
    np.savez(big, A=0.5 * np.eye(n), B=np.eye(n))
    return {
        "max_affordable_samples(1.0, 10**12, 1.0)": lambda: max_affordable_samples(1.0, 10**12, 1.0),
        "lambda = 2.0**53": lambda: max_affordable_samples(1.0, 2.0**53, 1.0),
        "exact time at lambda 1e12": lambda: sample_deciphering_time_exact(1, 10**12, 1.0),
        "key_length = 1e308": lambda: bit_security_of_key_length(int(1e308)),
        "minimum_key_length(1e12)": lambda: minimum_key_length(1e12),
        "pow2(1e9)": lambda: pow2(1e9),
        "generic design for Upsilon tau_c = 1e600": lambda: design_key_length(
            2, ThreatModel(tau_c=1e300, upsilon=1e300, cost_model="generic")
        ),
        "SDP for n + m = 400": lambda: optimal_attack_design(0.5 * np.eye(200), np.eye(200), sigma_u2=1, sigma_w2=1),
        "YAML alias bomb of 10^9 nodes": lambda: load_plant_file(bomb),
        "duration of a million digits": lambda: parse_duration("9" * 10**6),
        "design CLI on the alias bomb": cli_exit_2(["design", str(bomb)]),
        "design CLI at tau_c = 1e-300": cli_exit_2(["design", "--preset", "paper-example", "--tau-c", "1e-300"]),
    }


CASES = [
    "max_affordable_samples(1.0, 10**12, 1.0)",
    "lambda = 2.0**53",
    "exact time at lambda 1e12",
    "key_length = 1e308",
    "minimum_key_length(1e12)",
    "pow2(1e9)",
    "generic design for Upsilon tau_c = 1e600",
    "SDP for n + m = 400",
    "YAML alias bomb of 10^9 nodes",
    "duration of a million digits",
    "design CLI on the alias bomb",
    "design CLI at tau_c = 1e-300",
]


@pytest.mark.parametrize("name", CASES)
def test_bounded(name: str, tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    kind, message = run_bounded(_cases(tmp_path)[name])
    assert kind == "package", f"{name}: {kind} {message}"


def test_a_design_of_a_200_state_plant_completes(tmp_path: Path) -> None:
    # the plant the issue saw killed for memory after 95 s: the SDP rows are skipped with an
    # estimate, everything else is computed within the memory cap
    from encctl_gym.plant import Plant
    from encctl_gym.security.report import design_report
    from encctl_gym.security.threat import ThreatModel

    def call() -> None:
        n = 200
        threat = ThreatModel(gamma_c=1e-6, tau_c=31536e4, upsilon=442e15, sigma_u2=10, sigma_w2=0.1)
        res = design_report(Plant(0.5 * np.eye(n) + 0.1 * np.eye(n, k=1), np.eye(n)), threat)
        assert set(res["skipped"]) == {"closed_loop", "open_loop"}

    assert run_bounded(call) == ("ok", "")
