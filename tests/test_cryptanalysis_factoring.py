"""Factoring breakers of Paillier keys (cryptanalysis.factoring, pollard_factor, ecm, pari_factor,
paillier_keys) and ``crack --scheme paillier``: every modulus of a seeded set factored and
checked, refusals before work, bad input."""

from __future__ import annotations

import json

import pytest

from encctl_gym.cli import main
from encctl_gym.cryptanalysis.ecm import ladder, suyama_curve
from encctl_gym.cryptanalysis.factoring import check_modulus, verify_factors
from encctl_gym.cryptanalysis.factoring_registry import FACTORERS, get_factorer
from encctl_gym.cryptanalysis.paillier_keys import break_paillier_key, break_paillier_sequence, paillier_key_sequence
from encctl_gym.cryptanalysis.pari import pari_available
from encctl_gym.cryptanalysis.pollard_factor import prime_array
from encctl_gym.crypto import arith
from encctl_gym.crypto import paillier as P
from encctl_gym.errors import BreakerError, BreakerLimitError, ParameterError

#: (factorer, modulus bits) of the seeded test sets: every modulus must factor.
SETS = [("rho-factor", 48), ("rho-factor", 64), ("p-1", 40), ("ecm", 64), ("ecm", 80)]


@pytest.mark.parametrize(("name", "bits"), SETS)
def test_every_modulus_of_a_seeded_set_is_factored_and_every_key_decrypts(name: str, bits: int) -> None:
    keys = paillier_key_sequence(bits, 4, rng=bits)
    report = break_paillier_sequence(get_factorer(name, rng=1), [pk for pk, _ in keys], rng=arith.seeded_random(2))
    for (pk, sk), got in zip(keys, report.keys):
        f = got.factorization
        assert f.p * f.q == pk.n and 1 < f.p <= f.q and {f.p, f.q} == {sk.p, sk.q}
        assert got.secret.lam == sk.lam and got.secret.mu == sk.mu
        m = 12345 % pk.n
        assert P.decrypt(got.secret, P.encrypt(pk, m, arith.seeded_random(3))) == m
    assert report.tau().shape == (4,) and (report.key_seconds() >= 0).all()


def test_pari_factors_what_ecm_factors() -> None:
    if not pari_available():
        pytest.skip("cypari not installed")
    pk, sk = P.keygen(128, rng=7)
    got = break_paillier_key(get_factorer("pari-factor"), pk, rng=1)
    assert (got.factorization.p, got.factorization.q) == tuple(sorted((sk.p, sk.q)))


@pytest.mark.slow
def test_ecm_factors_128_bit_moduli() -> None:
    for seed in range(3):
        pk, sk = P.keygen(128, rng=100 + seed)
        f = get_factorer("ecm", rng=seed).factor(pk.n)
        assert {f.p, f.q} == {sk.p, sk.q}


def test_montgomery_ladder_agrees_with_repeated_addition_modulo_a_prime() -> None:
    # [6]P by the ladder equals [3]([2]P): x-coordinates compared projectively modulo a prime
    p = 1_000_003
    X0, Z0, a24 = suyama_curve(11, p)  # type: ignore[misc]
    x6, z6 = ladder(X0, Z0, 6, a24, p)
    x2, z2 = ladder(X0, Z0, 2, a24, p)
    x32, z32 = ladder(x2, z2, 3, a24, p)
    assert (x6 * z32 - x32 * z6) % p == 0


def test_prime_array_counts_pi_of_x() -> None:
    assert prime_array(100).tolist()[:5] == [2, 3, 5, 7, 11]
    assert prime_array(10**6).size == 78498  # pi(10^6)


def test_p_minus_one_gives_up_with_a_breaker_error_when_p_minus_one_is_not_smooth() -> None:
    # p = 2 p' + 1 and q = 2 q' + 1 safe primes of 32 bits: p - 1 has a 31-bit prime factor
    def safe(start: int) -> int:
        x = start | 1
        while not (arith.is_prime(x) and arith.is_prime((x - 1) // 2)):
            x += 2
        return x

    n = safe(3 << 30) * safe(7 << 29)
    with pytest.raises(BreakerError, match="smooth"):
        get_factorer("p-1", rng=1).factor(n)


def test_refusals_come_before_any_work() -> None:
    with pytest.raises(BreakerLimitError, match="limit is 80 bits"):
        get_factorer("rho-factor").factor(P.keygen(96, rng=1)[0].n)
    with pytest.raises(BreakerLimitError, match="more than"):
        get_factorer("ecm").check_time(128, 1e-3, keys=4)
    with pytest.raises(BreakerLimitError, match="one year"):
        get_factorer("rho-factor", max_bits=4096).check_feasible(1024)


@pytest.mark.parametrize("n", [14, 13, 2**61 - 1, 1.5, "91", True])
def test_a_non_modulus_is_refused(n: object) -> None:
    with pytest.raises(ParameterError):
        check_modulus(n)


def test_a_wrong_divisor_never_passes_the_check() -> None:
    with pytest.raises(BreakerError):
        verify_factors(91, 5, "test")
    assert verify_factors(91, 13, "test") == (7, 13)


def test_the_registry_lists_the_factorers() -> None:
    assert list(FACTORERS) == ["rho-factor", "p-1", "ecm", "pari-factor"]
    with pytest.raises(ParameterError, match="rho-factor"):
        get_factorer("nfs")


# ----------------------------------------------------------------------------- crack --scheme paillier
def test_crack_scheme_paillier_prints_json_with_every_key_checked(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["crack", "--scheme", "paillier", "--bits", "64", "--keys", "3", "--breaker", "ecm", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["scheme"] == "paillier" and out["keys_match"] and len(out["keys"]) == 3 and out["bits"] == 64


def test_crack_scheme_paillier_refuses_in_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["crack", "--scheme", "paillier", "--bits", "128", "--keys", "4", "--max-seconds", "0.01"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--max-seconds" in err[0]
    assert main(["crack", "--scheme", "paillier", "--breaker", "index-calculus", "--bits", "64"]) == 2
    assert main(["crack", "--breaker", "ecm", "--bits", "32"]) == 2
