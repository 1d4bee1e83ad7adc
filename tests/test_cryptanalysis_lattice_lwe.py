"""The lattice attacks on LWE (encctl_gym.cryptanalysis.lattice_lwe): every secret of a seeded test
set recovered and checked, the shared-matrix precomputation, refusals, and ``crack --scheme lwe``."""

from __future__ import annotations

import json

import numpy as np
import pytest

from encctl_gym.cli import main
from encctl_gym.cryptanalysis import lattice_lwe as LL
from encctl_gym.crypto import lwe
from encctl_gym.errors import BreakerError, BreakerLimitError, OptionalDependencyError, ParameterError

#: the lattice attacks run on fpylll, the ``lattice`` extra: without it those tests are skipped
needs_fpylll = pytest.mark.skipif(not LL.fpylll_available(), reason="needs fpylll (pip install 'encctl-gym[lattice]')")


def independent_error(inst: LL.LWEInstance, s: list[int]) -> list[int]:
    out = []
    for row, b in zip(inst.A.tolist(), inst.b.tolist()):
        r = (b - sum(a * v for a, v in zip(row, s))) % inst.q
        out.append(r - inst.q if r > inst.q // 2 else r)
    return out


@needs_fpylll
@pytest.mark.parametrize("attack", ["primal", "bdd"])
@pytest.mark.parametrize("n", [20, 30, 40])
def test_every_secret_of_a_seeded_set_is_recovered(attack: str, n: int) -> None:
    items = LL.lwe_instances(n, 3, rng=100 + n)
    pre, found = LL.get_lwe_breaker(attack, rng=1).break_instances([inst for inst, _ in items])
    for (inst, s), rec in zip(items, found):
        assert np.array_equal(rec.s, s)
        err = independent_error(inst, rec.s.tolist())
        assert max(abs(v) for v in err) <= inst.eta and rec.e.tolist() == err
    assert pre.seconds >= 0


@needs_fpylll
def test_the_scheme_public_key_is_broken() -> None:
    params = lwe.LWEParams(n=24, q=2**30, t=2**8, eta=2)
    pk, sk = lwe.keygen(params, 9)
    rec = LL.get_lwe_breaker("primal").precompute(pk.A, params.q, params.eta).break_key(LL.LWEInstance.from_public_key(pk))
    assert np.array_equal(rec.s, sk.s)


def test_verify_secret_refuses_a_wrong_secret() -> None:
    ((inst, s),) = LL.lwe_instances(16, 1, rng=3)
    wrong = s.copy()
    wrong[0] = (wrong[0] + 1) if wrong[0] < inst.eta else wrong[0] - 1
    with pytest.raises(BreakerError, match="b - A s"):
        LL.verify_secret(inst, wrong)
    with pytest.raises(BreakerError, match="entries in"):
        LL.verify_secret(inst, s * 5 + 3)


@needs_fpylll
def test_bdd_reuses_the_reduced_basis_and_rejects_another_matrix() -> None:
    items = LL.lwe_instances(40, 4, rng=7)
    breaker = LL.get_lwe_breaker("bdd", rng=2)
    pre = breaker.precompute(items[0][0].A, 3329, 2)
    assert pre.cost.seconds > 0
    for inst, s in items:
        assert np.array_equal(pre.break_key(inst).s, s)
    other, _ = LL.lwe_instances(40, 1, rng=8)[0]
    with pytest.raises(ParameterError, match="public matrix"):
        pre.break_key(other)


def test_refused_before_any_work() -> None:
    ((inst, _),) = LL.lwe_instances(256, 1, rng=1)
    with pytest.raises(BreakerLimitError, match="block size"):
        LL.get_lwe_breaker("primal").check_time(inst, 600.0)
    with pytest.raises(ParameterError, match="LWE breaker"):
        LL.get_lwe_breaker("dual")


@needs_fpylll
def test_time_attack_and_fit() -> None:
    r = LL.time_attack("primal", 20, keys=2, seed=4)
    assert r.model_beta >= 2 and r.measured_beta >= 2 and r.first_key_seconds > 0
    a, b = LL.fit_exponential([10, 20, 30], [1.0, 2.0, 4.0])
    assert a == pytest.approx(-1.0) and b == pytest.approx(0.1)


@needs_fpylll
def test_crack_scheme_lwe_json(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["crack", "--scheme", "lwe", "--dimension", "30", "--keys", "2", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["secrets_match"] and len(doc["instances"]) == 2
    for item in doc["instances"]:
        inst = LL.LWEInstance(np.array(item["A"]), np.array(item["b"]), item["q"], item["eta"])
        assert max(abs(v) for v in independent_error(inst, item["secret"])) <= item["eta"]
    assert main(["crack", "--scheme", "lwe", "--dimension", "400", "--keys", "2"]) == 2
    assert "refuses" in capsys.readouterr().err


def test_missing_fpylll_is_one_line_naming_the_extra(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    import sys

    monkeypatch.setitem(sys.modules, "fpylll", None)  # import fpylll raises ImportError
    assert not LL.fpylll_available()
    ((inst, _),) = LL.lwe_instances(20, 1, rng=3)
    with pytest.raises(OptionalDependencyError, match=r"encctl-gym\[lattice\]"):
        LL.get_lwe_breaker("primal", rng=1).break_instances([inst])
    assert main(["crack", "--scheme", "lwe", "--dimension", "20", "--keys", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "lattice" in err[0]
