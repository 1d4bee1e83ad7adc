"""Verification of the server's output (issue 33): the bounds, the keyed linear check, the MAC on
Paillier, the environment's defender, and the measured pass rates against the bounds."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from encctl_gym.errors import ParameterError
from encctl_gym.experiments.compare.statistics import wilson_interval
from encctl_gym.loop.verification import (
    KeyedLinearCheck,
    PaillierMac,
    evaluate_tags,
    forge_across_steps,
    row_sums_of,
    uniform_below,
)
from encctl_gym.security.verification import (
    expected_passes_before_detection,
    linear_check_pass_bound,
    mac_pass_bound,
    minimum_secret_range,
    undetected_with_check,
    verification_bound,
)

ENV_ID = "encctl_gym/EncryptedLTIAttack-v0"
Z_WIDE = 3.29  # a 99.9 % interval: the seeded trials below fail by chance once in a thousand seeds


# ---------------------------------------------------------------------- the bounds
def test_linear_check_bound_is_one_over_R_and_zero_for_one_input():
    assert linear_check_pass_bound(1, 2) == 0.0
    assert linear_check_pass_bound(2, 8) == 0.125
    assert linear_check_pass_bound(5, 1 << 64) == 2.0**-64


def test_mac_bound_adds_the_smallest_prime_term():
    # k = 512: p_min >= 2^255, so 2 / p_min <= 2^-254
    assert mac_pass_bound(8, 512) == 0.125 + 2.0**-254
    assert mac_pass_bound(2, 17) == pytest.approx(0.5 + 2 / 2**8)


def test_minimum_secret_range_and_undetected_probabilities():
    assert minimum_secret_range(1e-3) == 1000
    assert minimum_secret_range(0.3) == 4  # 1/3 > 0.3
    assert undetected_with_check(0.1, 5) == 0.1
    assert undetected_with_check(0.1, 5, adaptive=False) == pytest.approx(1e-5)
    assert undetected_with_check(0.1, 0) == 1.0
    e, H = 0.3, 7
    assert expected_passes_before_detection(e, H) == pytest.approx(sum(e**t for t in range(1, H + 1)))
    assert expected_passes_before_detection(1.0, 4) == 4.0


@pytest.mark.parametrize(
    "call, word",
    [
        (lambda: linear_check_pass_bound(0, 8), "m"),
        (lambda: linear_check_pass_bound(2, 1), "secret_range"),
        (lambda: linear_check_pass_bound(2, 2.5), "secret_range"),
        (lambda: mac_pass_bound(1, 512), "alpha_range"),
        (lambda: mac_pass_bound(4, 8), "modulus_bits"),
        (lambda: minimum_secret_range(0.0), "delta"),
        (lambda: minimum_secret_range(1.5), "delta"),
        (lambda: verification_bound("tag"), "tag"),
        (lambda: verification_bound("linear-check"), "secret_range"),
        (lambda: undetected_with_check(1.5, 3), "epsilon"),
    ],
)
def test_bad_values_raise_parameter_error_naming_them(call, word):
    with pytest.raises(ParameterError, match=word):
        call()


# ---------------------------------------------------------------------- the keyed linear check
@settings(max_examples=60, deadline=None)
@given(
    E=st.lists(st.lists(st.integers(-(2**40), 2**40), min_size=3, max_size=3), min_size=1, max_size=4),
    X=st.lists(st.integers(-(2**40), 2**40), min_size=3, max_size=3),
    seed=st.integers(0, 2**32 - 1),
)
def test_an_honest_output_always_passes(E, X, seed):
    check = KeyedLinearCheck(E, 1 << 64, np.random.default_rng(seed))
    S = [sum(e * x for e, x in zip(row, X)) for row in E]
    assert check.passes(S, X)


@settings(max_examples=60, deadline=None)
@given(
    row=st.lists(st.integers(-(2**30), 2**30), min_size=2, max_size=2),
    X=st.lists(st.integers(-(2**30), 2**30), min_size=2, max_size=2),
    D=st.integers(-(2**20), 2**20).filter(bool),
    R=st.integers(2, 2**70),
    seed=st.integers(0, 2**32 - 1),
)
def test_one_input_every_falsification_fails(row, X, D, R, seed):
    check = KeyedLinearCheck([row], R, np.random.default_rng(seed))
    S = sum(e * x for e, x in zip(row, X))
    assert not check.passes([S + D], X)


@pytest.mark.parametrize("R", [2, 5, 16])
def test_the_kerckhoffs_move_passes_with_probability_one_over_R(R):
    E, X = [[3, -7], [11, 2], [5, 5]], [13, -4]
    S = [sum(e * x for e, x in zip(row, X)) for row in E]
    rng = np.random.default_rng(R)
    trials = 3000
    passed = sum(KeyedLinearCheck(E, R, rng).passes([S[0] + 9, S[1] - 9, S[2]], X) for _ in range(trials))
    lo, hi = wilson_interval(passed, trials, z=Z_WIDE)
    assert lo <= 1 / R <= hi


def test_a_random_falsification_passes_no_more_often_than_the_bound():
    E, X = [[1, 2], [3, 4]], [5, 6]
    S = [sum(e * x for e, x in zip(row, X)) for row in E]
    R, trials, rng = 4, 3000, np.random.default_rng(7)
    passed = 0
    for _ in range(trials):
        D = [int(v) for v in rng.integers(-3, 4, size=2)]
        while not any(D):
            D = [int(v) for v in rng.integers(-3, 4, size=2)]
        passed += KeyedLinearCheck(E, R, rng).passes([s + d for s, d in zip(S, D)], X)
    assert wilson_interval(passed, trials, z=Z_WIDE)[0] <= 1 / R


def test_uniform_below_is_uniform_and_in_range():
    rng = np.random.default_rng(0)
    draws = [uniform_below(rng, 6) for _ in range(6000)]
    counts = np.bincount(draws, minlength=6)
    assert counts.size == 6 and counts.min() > 850
    big = 3**200
    assert all(0 <= uniform_below(rng, big) < big for _ in range(50))


@settings(max_examples=80, deadline=None)
@given(S=st.integers(-(2**51), 2**51), delta=st.sampled_from([4096, 1000, 12345, 2**20]))
def test_row_sums_are_recovered_exactly_from_the_decoded_input(S, delta):
    from encctl_gym.crypto.encoding import decode_scaled

    u = decode_scaled(S, (delta, 1), 2)
    assert row_sums_of([u], delta) == [S]


# ---------------------------------------------------------------------- the MAC on Paillier
@pytest.fixture(scope="module")
def paillier_key():
    from encctl_gym.crypto.paillier import keygen

    return keygen(256, rng=5)


def _mac_step(sk, E, X, rng, A=None):
    from encctl_gym.crypto.paillier import encrypt_with_secret

    mac = PaillierMac(sk, E, rng, alpha_range=A)
    n = sk.public.n
    cts = [encrypt_with_secret(sk, x % n, rng) for x in X]
    tagged, masks = mac.tag_state(X)
    rows = [sum((c * e for c, e in zip(cts, row) if e), start=encrypt_with_secret(sk, 0, rng)) for row in E]
    return mac, rows, evaluate_tags(E, tagged, masks)


def test_the_mac_passes_honest_outputs_and_fails_replays_and_scalings(paillier_key):
    from encctl_gym.crypto.arith import seeded_random

    _, sk = paillier_key
    rng = seeded_random(1)
    E, X = [[3, -2, 5], [-1, 4, 2]], [7, -3, 11]
    mac, rows, tags = _mac_step(sk, E, X, rng)
    assert mac.passes(rows, tags)
    assert not mac.passes([r * 2 for r in rows], [t * 2 for t in tags])  # the homomorphism's scaling
    assert not mac.passes([rows[0] + 1, rows[1]], tags)  # an addition without the tag
    old_rows, old_tags = rows, tags
    rows, tags = _mac_step_same(mac, sk, E, [1, 2, 3], rng)
    assert mac.passes(rows, tags)
    assert not mac.passes(old_rows, old_tags)  # the last step's output and tags: beta_t is fresh


def _mac_step_same(mac, sk, E, X, rng):
    from encctl_gym.crypto.paillier import encrypt_with_secret

    n = sk.public.n
    cts = [encrypt_with_secret(sk, x % n, rng) for x in X]
    tagged, masks = mac.tag_state(X)
    rows = [sum((c * e for c, e in zip(cts, row) if e), start=encrypt_with_secret(sk, 0, rng)) for row in E]
    return rows, evaluate_tags(E, tagged, masks)


class _OneGammaMac(PaillierMac):
    """The MAC as this package first built it: one ``gamma`` for every step (``rho_t = 1``)."""

    def tag_state(self, X):
        from encctl_gym.crypto.paillier import encrypt_with_secret

        n = self.pk.n
        self._rho = 1
        self._beta = [uniform_below(self._rng, n) for _ in range(self.m)]
        tagged = [encrypt_with_secret(self.sk, (self._alpha * int(x) + g) % n, self._rng) for x, g in zip(X, self._gamma)]
        return tagged, [encrypt_with_secret(self.sk, b, self._rng) for b in self._beta]


def _cross_step_passes(sk, mac_class, trials, rng, A=None):
    """Pass count of the cross-step forgery u' = Phi x_t + K (x_t - x_s) over ``trials`` MACs,
    each used for two steps; every forgery checked to change the decrypted output."""
    from encctl_gym.crypto.paillier import decrypt, encrypt_with_secret

    n = sk.public.n
    E, K = [[3, -2, 5], [-1, 4, 2]], [[1, 0, -1], [0, 2, 1]]
    passed = 0
    for _ in range(trials):
        mac = mac_class(sk, E, rng, alpha_range=A)
        steps = []
        for X in ([7, -3, 11], [2, 5, -4]):  # x_s, then x_t: different, so K (X_t - X_s) != 0
            cts = [encrypt_with_secret(sk, x % n, rng) for x in X]
            tagged, masks = mac.tag_state(X)
            steps.append((cts, tagged, masks))
        (cts_s, tag_s, _), (cts_t, tag_t, masks_t) = steps
        rows = [sum((c * e for c, e in zip(cts_t, row) if e), start=encrypt_with_secret(sk, 0, rng)) for row in E]
        tags = evaluate_tags(E, tag_t, masks_t)
        f_rows, f_tags = forge_across_steps(rows, tags, (cts_t, tag_t), (cts_s, tag_s), K)
        assert [decrypt(sk, c) for c in f_rows] != [decrypt(sk, c) for c in rows]
        assert mac.passes(rows, tags)  # the honest output of the same step passes
        passed += mac.passes(f_rows, f_tags)
    return passed


def test_the_cross_step_forgery_breaks_a_mac_with_one_gamma_and_not_the_mac(paillier_key):
    """With one gamma for every step the difference of two tagged states is Enc(alpha dX): the
    forgery passes always, far above the bound 1/A + 2/p_min; the per-step rho_t stops it."""
    from encctl_gym.crypto.arith import seeded_random

    _, sk = paillier_key
    assert _cross_step_passes(sk, _OneGammaMac, 20, seeded_random(4)) == 20
    assert _cross_step_passes(sk, PaillierMac, 100, seeded_random(5)) == 0
    A, trials = 2, 200  # a small alpha range: still within the bound's interval
    passed = _cross_step_passes(sk, PaillierMac, trials, seeded_random(6), A)
    assert wilson_interval(passed, trials, z=Z_WIDE)[0] <= mac_pass_bound(A, 256)


def test_the_cross_step_forgery_refuses_a_k_of_the_wrong_shape():
    with pytest.raises(ParameterError, match="K must have shape"):
        forge_across_steps([1, 2], [3, 4], ([1], [1]), ([1], [1]), [[1, 2]])


def test_a_guessed_alpha_passes_with_probability_one_over_A(paillier_key):
    from encctl_gym.crypto.arith import seeded_random

    _, sk = paillier_key
    rng, guess = seeded_random(2), np.random.default_rng(3)
    E, X, A, trials = [[2, 1], [1, 3]], [5, -4], 4, 400
    passed = 0
    for _ in range(trials):
        mac, rows, tags = _mac_step(sk, E, X, rng, A)
        a_hat = 1 + int(guess.integers(A))
        passed += mac.passes([rows[0] + 1, rows[1]], [tags[0] + a_hat, tags[1]])
    lo, hi = wilson_interval(passed, trials, z=Z_WIDE)
    assert lo <= mac_pass_bound(A, 256) and 1 / A <= hi


def test_mac_refuses_bad_alpha_ranges(paillier_key):
    _, sk = paillier_key
    with pytest.raises(ParameterError, match="alpha_range"):
        PaillierMac(sk, [[1]], np.random.default_rng(0), alpha_range=1)
    with pytest.raises(ParameterError, match="alpha_range"):
        PaillierMac(sk, [[1]], np.random.default_rng(0), alpha_range=sk.public.n)


# ---------------------------------------------------------------------- the environment's defender
def _episode(crypto: str, injection: str, steps: int = 25, check: str = "linear-check", **defender):
    scheme = {"scheme": "paillier", "key_length": 256} if check == "mac" else {"key_length": 128}
    env = gym.make(
        ENV_ID,
        preset="small",
        crypto=crypto,
        max_samples=steps,
        crypto_seed=3,
        injection=injection,
        defender={"name": check, **defender},
        **scheme,
    )
    env.reset(seed=1)
    rng = np.random.default_rng(0)
    taken, done, observations = 0, False, []
    while not done:
        obs, _, te, tr, info = env.step(rng.uniform(-1, 1, size=2))
        observations.append(obs)
        taken, done = taken + 1, te or tr
    policy = env.unwrapped.episode.defender
    env.close()
    return taken, info, policy, np.array(observations)


@pytest.mark.parametrize("crypto", ["ideal", "elgamal"])
@pytest.mark.parametrize("check", ["linear-check", "mac"])
def test_an_honest_server_never_fails_the_check_through_either_backend(crypto, check):
    steps, info, policy, _ = _episode(crypto, "pass", check=check)
    assert not info["detected"] and policy.failures == 0 and policy.checks == steps - 1


@pytest.mark.parametrize("crypto", ["ideal", "elgamal"])
@pytest.mark.parametrize("injection", ["replace", "add"])
@pytest.mark.parametrize("check", ["linear-check", "mac"])
def test_a_falsifying_server_is_caught_at_its_first_checked_step(crypto, injection, check):
    steps, info, policy, _ = _episode(crypto, injection, check=check)
    assert info["detected"] and steps == 2 and policy.failures == 1


@pytest.mark.parametrize("injection", ["pass", "add"])
def test_the_mac_gives_both_backends_one_episode(injection):
    """The MAC's tags are real Paillier ciphertexts on both backends, its secrets from the
    defender's streams: one seed, one episode, bit for bit, and one verdict."""
    ideal, cipher = _episode("ideal", injection, check="mac"), _episode("elgamal", injection, check="mac")
    assert ideal[0] == cipher[0] and np.array_equal(ideal[3], cipher[3])
    assert ideal[1]["detected"] == cipher[1]["detected"] == (injection != "pass")
    assert (ideal[2].checks, ideal[2].failures) == (cipher[2].checks, cipher[2].failures)


def test_the_mac_defender_refuses_other_loops_and_bad_ranges():
    with pytest.raises(ParameterError, match="paillier scheme's loop, not 'modified'"):
        gym.make(ENV_ID, preset="small", defender="mac")
    with pytest.raises(ParameterError, match="observe"):
        gym.make(
            ENV_ID, preset="small-output", observe="output", scheme="paillier", key_length=256, max_samples=12, defender="mac"
        )
    with pytest.raises(ParameterError, match="alpha_range"):
        gym.make(
            ENV_ID, preset="small", scheme="paillier", key_length=256, max_samples=12, defender={"name": "mac", "alpha_range": 1}
        )
    with pytest.raises(ParameterError, match="linear check verifies the ElGamal"):
        gym.make(ENV_ID, preset="small", scheme="paillier", key_length=256, max_samples=12, defender="linear-check")


def test_a_small_alpha_range_lets_a_guessing_attacker_through_at_its_bound():
    """The defender's own MAC against the Kerckhoffs move on its tags (A = 2): a pass rate within
    the bound's interval, and the honest rows pass."""
    from encctl_gym.loop.verification import MacDefender

    env = gym.make(
        ENV_ID, preset="small", scheme="paillier", key_length=256, max_samples=12, defender={"name": "mac", "alpha_range": 2}
    )
    env.reset(seed=0)
    policy = env.unwrapped.episode.defender
    assert isinstance(policy, MacDefender) and policy.epsilon == mac_pass_bound(2, 256)
    mac, E, X = policy._macs[0], policy.E, [3, -2]
    guess, passed, trials = np.random.default_rng(1), 0, 300
    S = [sum(e * x for e, x in zip(row, X)) for row in E]
    for _ in range(trials):
        tagged, masks = mac.tag_state(X)
        tags = evaluate_tags(E, tagged, masks)
        assert mac.passes_sums(S, tags)
        passed += mac.passes_sums([S[0] + 1, *S[1:]], [tags[0] + (1 + int(guess.integers(2))), *tags[1:]])
    lo, hi = wilson_interval(passed, trials, z=Z_WIDE)
    assert lo <= mac_pass_bound(2, 256) and 0.5 <= hi
    env.close()


def test_the_defender_refuses_bad_options():
    with pytest.raises(ParameterError, match="secret_range"):
        gym.make(ENV_ID, preset="small", defender={"name": "linear-check", "secret_range": 1})
    with pytest.raises(ParameterError, match="observe"):
        gym.make(ENV_ID, preset="small-output", observe="output", defender="linear-check")


# ---------------------------------------------------------------------- the experiment's cells
def test_the_experiment_cells_measure_the_checks_on_real_ciphertexts():
    from encctl_gym.experiments.integrity import step_rows

    rows = step_rows(trials=4, attackers=("sparse", "kerckhoffs"), elgamal_bits=128, paillier_bits=256, audit_rate=1.0)
    cell = {(r.scheme, r.defence, r.attacker): r for r in rows}
    for scheme in ("elgamal", "paillier"):
        # the encoding's smallest step and the largest move below the tolerance pass even an audit at every step
        assert cell[scheme, "audit", "sparse"].detected == 0 and cell[scheme, "audit", "sparse"].falsified == 4
        assert cell[scheme, "audit", "kerckhoffs"].detected == 0
        for attacker in ("sparse", "kerckhoffs"):
            r = cell[scheme, "linear-check", attacker]
            assert r.falsified == 4 and r.detected == 4  # R = 2^64: a pass has probability 2^-64
    assert cell["paillier", "mac", "kerckhoffs"].detected == 4
    assert all(math.isfinite(r.cost_seconds) and r.cost_seconds > 0 for r in rows)


# ---------------------------------------------------------------------- the game's lever
def _play_the_verify_lever(game, verify_cost=None):
    """An episode passing ``Phi x`` through with the verify lever at every step (never detected;
    a check at every step but the first), then one injecting from its second step (caught at
    the first check); returns the last infos and terminations."""
    from encctl_gym.agents.game import defender_action

    m, verify = game.params.m, defender_action(verify=1.0)
    game.reset(seed=0)
    passing = np.r_[np.full(m, 0.3), -1.0].astype(np.float32)
    steps = 0
    while game.agents:
        _, _, _, _, info = game.step({"attacker": passing, "defender": verify})
        steps += 1
        assert not info["defender"]["detected"]
        if verify_cost is not None:
            assert info["defender"]["cost"] == (verify_cost if steps > 1 else 0.0)  # nothing to check at the first step
    assert info["defender"]["checks"] == steps - 1
    game.reset(seed=0)
    inject = np.r_[np.full(m, 0.3), 1.0].astype(np.float32)
    game.step({"attacker": inject, "defender": defender_action()})
    _, _, term, _, info = game.step({"attacker": inject, "defender": verify})
    return term, info


def test_the_verify_lever_catches_an_injection_and_never_a_passed_through_input():
    pytest.importorskip("pettingzoo")
    from encctl_gym.agents.evaluate import budget_config, env_config
    from encctl_gym.multiagent import EncryptedControlGame

    game = EncryptedControlGame(budget_config(env_config({"preset": "small"}), 20), {"verify_cost": 0.125, "audit_cost": 0.0})
    term, info = _play_the_verify_lever(game, verify_cost=0.125)
    assert term["defender"] and info["defender"]["detected"] and info["defender"]["verified"]


def test_the_verify_lever_runs_the_mac_on_a_paillier_loop():
    pytest.importorskip("pettingzoo")
    from encctl_gym.agents.evaluate import budget_config, env_config
    from encctl_gym.loop.verification import MacDefender
    from encctl_gym.multiagent import EncryptedControlGame

    cfg = budget_config(env_config({"preset": "small", "scheme": "paillier", "key_length": 256, "max_samples": 12}), 12)
    game = EncryptedControlGame(cfg)
    assert isinstance(game.levers._verifier, MacDefender)
    term, info = _play_the_verify_lever(game)
    assert term["defender"] and info["defender"]["detected"]
