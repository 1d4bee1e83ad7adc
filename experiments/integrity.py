"""Integrity by verification (issue 33): every check against every attacker class, on real ciphertexts.

    python -m encctl_gym.experiments.integrity [--trials 400] [--episodes 200] [--horizon 20] [--quick] [--record]

Three parts, each a function the tests call too:

* :func:`step_rows`: one falsified step per trial through the real encrypted controller
  (dynamic-key ElGamal with the modified evaluation of Definition def:modification at
  ``--elgamal-bits``; Paillier at ``--paillier-bits``), judged by every defence that applies:
  audits at ``--audit-rate`` (the plant side's ``Phi x``, :class:`~encctl_gym.loop.detection.Audit`
  with :func:`~encctl_gym.loop.defenses.audit_tolerance`), the keyed linear check
  (:class:`~encctl_gym.loop.verification.KeyedLinearCheck`) and, on Paillier, the MAC
  (:class:`~encctl_gym.loop.verification.PaillierMac`). Each trial draws the defences' secrets
  afresh. The attackers (:data:`ATTACKERS`): ``replace`` (the forgery of def:adversary from public
  keys), ``add`` (the server's output plus a random action: on ElGamal through the broken
  ``sk_0, sk_t``; on Paillier keyless), ``sparse`` (one input moved by the encoding's smallest step),
  ``malleability`` (no key: one product ciphertext of ElGamal times ``Enc``-free ``4``, every
  Paillier row and tag raised to the power 2), ``replay`` (the previous step's output, its labels
  stripped), ``mix`` (across steps, no key: on Paillier ``u' = Phi x_t + K (x_t - x_s)`` with the
  tags moved alike, :func:`~encctl_gym.loop.verification.forge_across_steps`, from an earlier step
  under the same MAC; on ElGamal one product of the previous step put into this step's output) and
  ``kerckhoffs`` (knows the check and its parameters, not its secret: against the
  linear check ``(+d, -d)`` on two rows, passing iff ``r_1 = r_2``; against the MAC a guessed
  ``alpha``; against audits the largest falsification below the tolerance). Detection per
  falsified step with its Wilson 95 % interval, against the bound ``1 - epsilon``.
* :func:`sweep_rows`: the Kerckhoffs attacker against small secrets (``R``, ``A`` in
  :data:`SWEEP_RANGES`): its measured pass rate against the bound ``1 / R`` (``1 / A + 2 / p_min``).
* :func:`episode_rows`: falsified steps one after another against one key per episode, the
  attacker adaptive (a Kerckhoffs move that passed is repeated): the falsified steps that pass
  before the first detection (capped at ``--horizon``).

Costs: the plant side's encrypted step and each defence's added work per step, measured
(median seconds) on the same machine.

Writes ``results/integrity/integrity.md`` and ``integrity.png`` by default; ``--record`` writes
``docs/results/integrity/integrity.md`` and ``docs/figures/integrity.png``.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from collections.abc import Callable
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np

from encctl_gym.errors import EncctlError, ParameterError
from encctl_gym.experiments.common import ensure_out_dir, write_recorded_table
from encctl_gym.experiments.compare.statistics import wilson_interval

__all__ = [
    "ATTACKERS",
    "SWEEP_RANGES",
    "StepRow",
    "ElGamalBench",
    "PaillierBench",
    "step_rows",
    "sweep_rows",
    "episode_rows",
    "environment_rows",
    "trained_defender_rows",
    "format_tables",
    "plot_integrity",
    "main",
]

#: The attacker classes, in the table's order.
ATTACKERS: tuple[str, ...] = ("replace", "add", "sparse", "malleability", "replay", "mix", "kerckhoffs")
#: The small secret ranges of the Kerckhoffs sweep.
SWEEP_RANGES: tuple[int, ...] = (2, 4, 8, 16, 32)


@dataclasses.dataclass(frozen=True)
class StepRow:
    """One (scheme, defence, attacker) cell: falsified steps, detections, the bound, the cost."""

    scheme: str
    defence: str
    attacker: str
    trials: int
    falsified: int
    detected: int
    epsilon: float
    cost_seconds: float
    step_seconds: float
    server_seconds: float = 0.0
    secret_range: int | None = None

    @property
    def detection(self) -> float:
        return self.detected / self.falsified if self.falsified else float("nan")

    @property
    def interval(self) -> tuple[float, float]:
        return wilson_interval(self.detected, self.falsified)


# ---------------------------------------------------------------------- the two encrypted loops
class ElGamalBench:
    """The modified scheme's parties for the loop of ``preset`` at ``bits`` (the environment's own
    loop specification, :class:`~encctl_gym.loop.elgamal.ElGamalLoop`)."""

    scheme = "elgamal"

    def __init__(self, preset: str, bits: int, seed: int) -> None:
        from encctl_gym.envs.config import resolve_params
        from encctl_gym.loop.defenses import audit_tolerance
        from encctl_gym.loop.elgamal import ElGamalLoop

        spec = resolve_params(preset=preset, crypto="elgamal", key_length=bits, crypto_seed=seed).loop
        self.loop = ElGamalLoop(spec, spec.group())
        self.loop.start_episode()
        self.plant, self.server, self.enc = self.loop.plant, self.loop.server, self.loop.encryption
        self.encoder, self.group = self.loop.encoder, self.loop.group
        self.quant = self.plant.quantization
        self.E = [[int(v) for v in row] for row in self.quant.phi_int]
        self.Phi, self.delta, self.x_bound = self.loop.Phi, float(spec.delta), float(spec.x_bound)
        self._tol = lambda x: audit_tolerance(self.Phi, x[None], self.delta, int(self.encoder.max_shift))[0]
        self.m, self.n = len(self.E), len(self.E[0])
        self.u_max = float(spec.u_max)

    def tolerance(self, x: np.ndarray) -> np.ndarray:
        return self._tol(x)

    def honest(self, x: np.ndarray) -> Any:
        """One period's server output (the plant encrypts ``x``); the keys move on first (KeyUpd)."""
        self.enc.update_keys(self.plant, self.server)
        return self.enc.evaluate(self.server, self.enc.encrypt_state(self.plant, x))

    def sums(self, out: Any) -> list[int]:
        """``Sum`` of eq:ec over the decrypted, lifted products."""
        return [sum(r) for r in self.plant.decrypt_products(out)]

    def X(self, x: np.ndarray) -> list[int]:
        return self.quant.encode_state(x)

    def _mask(self, c: Any) -> int:
        from encctl_gym.crypto import arith

        p = self.group.p
        s0, st = int(self.plant.initial_secret_key.s), int(self.plant.secret_key.s)
        return int(arith.mulmod(arith.powmod(c.c1, s0, p), arith.powmod(c.c2, st, p), p))

    def product(self, c: Any) -> int:
        """The product an entry carries, read with ``sk_0`` and ``sk_t`` (a key-breaking attacker)."""
        from encctl_gym.crypto import arith
        from encctl_gym.crypto.encoding import lift

        p = self.group.p
        return lift(self.group, int(arith.mulmod(c.c3, arith.invert(self._mask(c), p), p)))

    def rewrite(self, c: Any, value: int) -> Any:
        """The entry re-masked to carry ``value`` (a member of G, as a signed integer)."""
        return dataclasses.replace(c, c3=int((value % self.group.p) * self._mask(c) % self.group.p))

    def member_step(self, v: int, d: int) -> int:
        """The smallest ``D >= d`` with ``v + D`` a plaintext (in G)."""
        D = d
        while not self.group.contains((v + D) % self.group.p):
            D += 1
        return D


class PaillierBench:
    """Paillier's plant and server (:class:`~encctl_gym.loop.paillier_scheme.PaillierScheme`) for
    the controller of ``preset`` at ``bits``."""

    scheme = "paillier"

    def __init__(self, preset: str, bits: int, seed: int) -> None:
        from encctl_gym.crypto.arith import seeded_random
        from encctl_gym.crypto.paillier_controller import controller_error_bound
        from encctl_gym.envs.config import resolve_params
        from encctl_gym.loop.backend import lqr_gain
        from encctl_gym.loop.paillier_scheme import PaillierParameters, PaillierScheme

        spec = resolve_params(preset=preset).loop
        sch = PaillierScheme()
        self.Phi, self.delta, self.x_bound = -lqr_gain(spec.A, spec.B), float(spec.delta), float(spec.x_bound)
        quant = SimpleNamespace(Phi=self.Phi, x_bound=self.x_bound, encoder=sch.encoder(PaillierParameters(bits), self.delta))
        self.rng = seeded_random(seed)
        self.plant, self.server = sch.parties(quant, self.rng, seeded_random(seed + 1))
        self.E = self.server.Phi_bar
        self.m, self.n = len(self.E), len(self.E[0])
        self.u_max = float(spec.u_max)
        self._bound = controller_error_bound

    def tolerance(self, x: np.ndarray) -> np.ndarray:
        return np.asarray(self._bound(self.Phi, x, self.delta), dtype=float) * (1 + 1e-12)

    def X(self, x: np.ndarray) -> list[int]:
        return self.plant.encoder.quantize_array(x)

    def sums(self, rows: Any) -> list[int]:
        from encctl_gym.crypto.paillier import decrypt
        from encctl_gym.crypto.paillier_controller import to_signed

        return [to_signed(decrypt(self.plant.sk, c), self.plant.pk.n) for c in rows]


# ---------------------------------------------------------------------- the attackers
def _random_action(bench: Any, rng: np.random.Generator) -> np.ndarray:
    return rng.uniform(-bench.u_max, bench.u_max, size=bench.m)


def _elgamal_attack(
    bench: ElGamalBench, name: str, out: Any, prev: Any, x: np.ndarray, rng: np.random.Generator, defence: str
) -> Any:
    """The falsified output of the attacker ``name`` (:data:`ATTACKERS`) on ElGamal."""
    plant, enc, src = bench.plant, bench.enc, bench.loop.random_sources["adversary"]
    secret = lambda pk: enc.oracle_secret(plant, pk)  # noqa: E731  the key-breaking attacker's keys
    if name == "replace":
        return enc.forge(plant, _random_action(bench, rng), bench.encoder, bench.n, src)
    if name == "add":
        return enc.add(plant, out, _random_action(bench, rng), bench.encoder, secret, src)
    rows = [list(r) for r in out]
    if name == "malleability":  # no key: Enc(m) -> Enc(4 m) (4 = 2^2 lies in G)
        i, j = int(rng.integers(bench.m)), int(rng.integers(bench.n))
        rows[i][j] = dataclasses.replace(rows[i][j], c3=int(rows[i][j].c3 * 4 % bench.group.p))
        return rows
    if name == "replay":
        return None if prev is None else [[dataclasses.replace(c, t1=None, t2=None) for c in r] for r in prev]
    if name == "mix":  # across steps, no key: one product of the last step in this step's output
        if prev is None:
            return None
        i, j = int(rng.integers(bench.m)), int(rng.integers(bench.n))
        rows[i][j] = dataclasses.replace(prev[i][j], t1=None, t2=None)
        return rows
    i = int(rng.integers(bench.m))
    if name == "sparse" or (name == "kerckhoffs" and defence == "audit"):
        d = int(bench.delta) if name == "sparse" else max(1, int(bench.tolerance(x)[i] * bench.delta**2 * 0.5))
        P = bench.product(rows[i][0])
        rows[i][0] = bench.rewrite(rows[i][0], P + bench.member_step(P, d))
        return rows
    if name == "kerckhoffs":  # (+D, -D) on rows 0 and 1: passes the linear check iff r_1 = r_2
        if bench.m < 2:
            return None
        P0, P1 = bench.product(rows[0][0]), bench.product(rows[1][0])
        D = int(bench.delta)
        while not (bench.group.contains((P0 + D) % bench.group.p) and bench.group.contains((P1 - D) % bench.group.p)):
            D += 1
        rows[0][0], rows[1][0] = bench.rewrite(rows[0][0], P0 + D), bench.rewrite(rows[1][0], P1 - D)
        return rows
    raise ParameterError(f"unknown attacker {name!r}; choose one of {', '.join(ATTACKERS)}")


def _paillier_attack(
    bench: PaillierBench,
    name: str,
    rows: list,
    tags: list,
    prev: Any,
    x: np.ndarray,
    rng: np.random.Generator,
    defence: str,
    mac: Any,
) -> Any:
    """The falsified ``(rows, tags)`` of the attacker ``name`` on Paillier (tags forwarded
    unchanged by an attacker that does not know the check)."""
    from encctl_gym.crypto.paillier import encrypt

    pk, d2 = bench.plant.pk, bench.delta**2
    if name == "replace":
        return [encrypt(pk, int(round(v * d2)) % pk.n, bench.rng) for v in _random_action(bench, rng)], tags
    if name == "add":
        return [c + int(round(v * d2)) for c, v in zip(rows, _random_action(bench, rng))], tags
    if name == "malleability":  # Enc(m)^2 = Enc(2 m), rows and tags alike: no key
        return [c * 2 for c in rows], [t * 2 for t in tags]
    if name == "replay":
        return (None, None) if prev is None else prev
    if name == "mix":  # across steps, no key: u' = Phi x_t + K (x_t - x_s), tags moved alike
        if prev is None:
            return None, None
        from encctl_gym.loop.verification import forge_across_steps

        K = rng.integers(-2, 3, size=(bench.m, bench.n))
        K[0, int(rng.integers(bench.n))] = 1  # K != 0
        return forge_across_steps(rows, tags, prev[0], prev[1], K)
    i = int(rng.integers(bench.m))
    if name == "sparse" or (name == "kerckhoffs" and defence == "audit"):
        d = 1 if name == "sparse" else max(1, int(bench.tolerance(x)[i] * d2 * 0.5))
        return [c + (d if k == i else 0) for k, c in enumerate(rows)], tags
    if name == "kerckhoffs" and defence == "mac":  # a guessed alpha
        a_hat = 1 + int(rng.integers(mac.A)) if mac.A < 2**62 else 1 + int(rng.integers(2**62))
        return [c + (1 if k == i else 0) for k, c in enumerate(rows)], [t + (a_hat if k == i else 0) for k, t in enumerate(tags)]
    if name == "kerckhoffs":
        if bench.m < 2:
            return None, None
        return [rows[0] + 1, rows[1] + (-1), *rows[2:]], tags
    raise ParameterError(f"unknown attacker {name!r}; choose one of {', '.join(ATTACKERS)}")


# ---------------------------------------------------------------------- judging one step
def _audit_caught(bench: Any, x: np.ndarray, sums: list[int], rate: float, rng: np.random.Generator) -> bool:
    from encctl_gym.loop.detection import Audit

    u = np.array([s / bench.delta**2 for s in sums], dtype=float)
    return bool(Audit(bench.Phi, rate, [rng]).check(x[None], u[None], bench.tolerance(x)[None])[0])


def _timed(acc: list[float], f: Callable[..., Any], *args: Any) -> Any:
    """``f(*args)``, its wall time appended to ``acc``."""
    t0 = time.perf_counter()
    v = f(*args)
    acc.append(time.perf_counter() - t0)
    return v


def _elgamal_cells(
    bench: ElGamalBench, attacker: str, defences: tuple[str, ...], trials: int, rng: np.random.Generator, params: dict
) -> list[StepRow]:
    from encctl_gym.loop.verification import KeyedLinearCheck

    counts = {d: [0, 0] for d in defences}
    cost: dict[str, list[float]] = {d: [] for d in defences}
    step: list[float] = []
    prev = None
    for _ in range(trials):
        x = rng.uniform(-1.0, 1.0, size=bench.n)
        t0 = time.perf_counter()
        out = bench.honest(x)
        bench.plant.decrypt_output(out)
        step.append(time.perf_counter() - t0)
        honest = bench.sums(out)
        for d in defences:
            forged = _elgamal_attack(bench, attacker, out, prev, x, rng, d)
            if forged is None:
                continue
            S = bench.sums(forged)
            if S == honest:
                continue
            counts[d][0] += 1
            if d == "audit":
                caught = _timed(cost[d], _audit_caught, bench, x, S, params["audit_rate"], rng)
            else:
                check = KeyedLinearCheck(bench.E, params["secret_range"], rng)
                caught = not _timed(cost[d], check.passes, S, bench.X(x))
            counts[d][1] += caught
        prev = out
    t_step = float(np.median(step))  # the period: KeyUpd, Enc(x), Eval_bar, Dec_bar, Sum, Dcd
    return [
        StepRow(
            "elgamal",
            d,
            attacker,
            trials,
            c[0],
            c[1],
            _epsilon(bench, d, params),
            _cost(cost[d], d, params),
            t_step,
            0.0,
            _secret(d, params),
        )
        for d, c in counts.items()
    ]


def _epsilon(bench: Any, defence: str, params: dict) -> float:
    from encctl_gym.security.verification import linear_check_pass_bound, mac_pass_bound

    if defence == "audit":
        return 1.0 - params["audit_rate"]
    if defence == "linear-check":
        return linear_check_pass_bound(bench.m, params["secret_range"])
    return mac_pass_bound(params.get("alpha_range") or bench.plant.pk.n - 1, bench.plant.pk.bits)


def _secret(defence: str, params: dict) -> int | None:
    return {"linear-check": params["secret_range"], "mac": params.get("alpha_range")}.get(defence)


def _cost(times: list[float], defence: str, params: dict) -> float:
    if not times:
        return float("nan")
    t = float(np.median(times))
    return t * params["audit_rate"] if defence == "audit" else t  # audits run at rate p


def _paillier_cells(
    bench: PaillierBench, attacker: str, defences: tuple[str, ...], trials: int, rng: np.random.Generator, params: dict
) -> list[StepRow]:
    from encctl_gym.loop.verification import KeyedLinearCheck, PaillierMac, evaluate_tags

    counts = {d: [0, 0] for d in defences}
    cost: dict[str, list[float]] = {d: [] for d in defences}
    step: list[float] = []
    server: list[float] = []
    tagging: list[float] = []
    prev = None
    for _ in range(trials):
        x = rng.uniform(-1.0, 1.0, size=bench.n)
        X = bench.X(x)
        mac = PaillierMac(bench.plant.sk, bench.E, bench.rng, alpha_range=params.get("alpha_range"))
        earlier = None
        if attacker == "mix":  # one key serves a whole episode: an earlier step under this MAC
            x_s = rng.uniform(-1.0, 1.0, size=bench.n)
            cts_s = bench.plant.encrypt_state(x_s)
            earlier = (cts_s, mac.tag_state(bench.X(x_s))[0])
        t0 = time.perf_counter()
        cts = bench.plant.encrypt_state(x)
        rows = bench.server.evaluate(cts)
        bench.plant.decrypt_output(rows)
        step.append(time.perf_counter() - t0)
        tagged, masks = _timed(tagging, mac.tag_state, X)
        tags = _timed(server, evaluate_tags, bench.E, tagged, masks)
        honest = bench.sums(rows)
        for d in defences:
            before = prev if attacker != "mix" else ((cts, tagged), earlier)
            f_rows, f_tags = _paillier_attack(bench, attacker, rows, tags, before, x, rng, d, mac)
            if f_rows is None:
                continue
            S = bench.sums(f_rows)
            if S == honest:
                continue
            counts[d][0] += 1
            if d == "audit":
                caught = _timed(cost[d], _audit_caught, bench, x, S, params["audit_rate"], rng)
            elif d == "linear-check":
                check = KeyedLinearCheck(bench.E, params["secret_range"], rng)
                caught = not _timed(cost[d], check.passes, S, X)
            else:
                caught = not _timed(cost[d], mac.passes, f_rows, f_tags)
            counts[d][1] += caught
        prev = (rows, tags)
    t_step = float(np.median(step))  # the period: Enc(x), Eval, Dec, Dcd
    t_server = float(np.median(server))
    if cost.get("mac"):
        cost["mac"] = [float(np.median(cost["mac"])) + float(np.median(tagging))]  # tags sent + the check
    return [
        StepRow(
            "paillier",
            d,
            attacker,
            trials,
            c[0],
            c[1],
            _epsilon(bench, d, params),
            _cost(cost[d], d, params),
            t_step,
            t_server if d == "mac" else 0.0,
            _secret(d, params),
        )
        for d, c in counts.items()
    ]


# ---------------------------------------------------------------------- the tables
#: The defences that apply to each scheme.
DEFENCES: dict[str, tuple[str, ...]] = {"elgamal": ("audit", "linear-check"), "paillier": ("audit", "linear-check", "mac")}


def _params(audit_rate: float, secret_range: int, alpha_range: int | None) -> dict[str, Any]:
    from encctl_gym.loop.detection import check_audit_rate
    from encctl_gym.security.verification import check_secret_range

    return {
        "audit_rate": check_audit_rate(audit_rate),
        "secret_range": check_secret_range("secret_range", secret_range),
        "alpha_range": None if alpha_range is None else check_secret_range("alpha_range", alpha_range),
    }


def step_rows(
    *,
    preset: str = "small",
    trials: int = 400,
    elgamal_bits: int = 256,
    paillier_bits: int = 512,
    audit_rate: float = 0.05,
    secret_range: int = 1 << 64,
    alpha_range: int | None = None,
    attackers: tuple[str, ...] = ATTACKERS,
    seed: int = 0,
) -> list[StepRow]:
    """Every (scheme, defence, attacker) cell of one falsified step per trial (module docstring)."""
    from encctl_gym._validation import check_int

    trials = check_int("trials", trials, minimum=1)
    params = _params(audit_rate, secret_range, alpha_range)
    rows: list[StepRow] = []
    for k, attacker in enumerate(attackers):
        if attacker not in ATTACKERS:
            raise ParameterError(f"unknown attacker {attacker!r}; choose one of {', '.join(ATTACKERS)}")
        rng = np.random.default_rng([seed, k])
        rows += _elgamal_cells(ElGamalBench(preset, elgamal_bits, seed + k), attacker, DEFENCES["elgamal"], trials, rng, params)
        rows += _paillier_cells(
            PaillierBench(preset, paillier_bits, seed + k), attacker, DEFENCES["paillier"], trials, rng, params
        )
    return rows


def sweep_rows(
    *,
    preset: str = "small",
    trials: int = 400,
    ranges: tuple[int, ...] = SWEEP_RANGES,
    elgamal_bits: int = 256,
    paillier_bits: int = 512,
    seed: int = 0,
) -> list[StepRow]:
    """The Kerckhoffs attacker against the linear check (ElGamal, ``R`` of ``ranges``) and the MAC
    (Paillier, ``A`` of ``ranges``): measured detection against ``1 - epsilon``."""
    rows: list[StepRow] = []
    for k, R in enumerate(ranges):
        params = _params(0.0, R, R)
        rng = np.random.default_rng([seed, 100 + k])
        rows += _elgamal_cells(ElGamalBench(preset, elgamal_bits, seed + k), "kerckhoffs", ("linear-check",), trials, rng, params)
        rows += _paillier_cells(PaillierBench(preset, paillier_bits, seed + k), "kerckhoffs", ("mac",), trials, rng, params)
    return rows


@dataclasses.dataclass(frozen=True)
class EpisodeRow:
    """Falsified steps in a row against one key: the passes before the first detection."""

    scheme: str
    defence: str
    attacker: str
    secret_range: int
    episodes: int
    horizon: int
    mean_passes: float
    undetected: int
    epsilon: float


def _episode_passes(bench: ElGamalBench, attacker: str, R: int, horizon: int, rng: np.random.Generator) -> int:
    """One episode on ElGamal: falsified steps against one ``r`` until the first failure. The
    Kerckhoffs attacker repeats its ``(+D, -D)`` move, which keeps passing once ``r_1 = r_2``."""
    from encctl_gym.loop.verification import KeyedLinearCheck

    check = KeyedLinearCheck(bench.E, R, rng)
    passes, prev = 0, None
    for _ in range(horizon):
        x = rng.uniform(-1.0, 1.0, size=bench.n)
        out = bench.honest(x)
        forged = _elgamal_attack(bench, attacker, out, prev, x, rng, "linear-check")
        prev = out
        if forged is None or bench.sums(forged) == bench.sums(out):
            continue
        if not check.passes(bench.sums(forged), bench.X(x)):
            break
        passes += 1
    return passes


def episode_rows(
    *,
    preset: str = "small",
    episodes: int = 200,
    horizon: int = 20,
    ranges: tuple[int, ...] = (8, 1 << 64),
    attackers: tuple[str, ...] = ("add", "kerckhoffs"),
    elgamal_bits: int = 256,
    seed: int = 0,
) -> list[EpisodeRow]:
    """Samples before detection on the ElGamal loop with the linear check, one key per episode."""
    from encctl_gym._validation import check_int
    from encctl_gym.security.verification import check_secret_range, linear_check_pass_bound

    episodes = check_int("episodes", episodes, minimum=1)
    horizon = check_int("horizon", horizon, minimum=1)
    out: list[EpisodeRow] = []
    bench = ElGamalBench(preset, elgamal_bits, seed)
    for k, R in enumerate(ranges):
        R = check_secret_range("secret_range", R)
        for j, attacker in enumerate(attackers):
            rng = np.random.default_rng([seed, 200 + k, j])
            passes = [_episode_passes(bench, attacker, R, horizon, rng) for _ in range(episodes)]
            out.append(
                EpisodeRow(
                    "elgamal",
                    "linear-check",
                    attacker,
                    R,
                    episodes,
                    horizon,
                    float(np.mean(passes)),
                    sum(p == horizon for p in passes),
                    linear_check_pass_bound(bench.m, R),
                )
            )
    return out


@dataclasses.dataclass(frozen=True)
class EnvironmentRow:
    """A defender policy of the environment against an injection mode: episodes of random
    actions, the samples collected before the attack was stopped and the wall time per step."""

    defender: str
    injection: str
    crypto: str
    episodes: int
    horizon: int
    detected: int
    mean_samples: float
    step_seconds: float


#: The environment's defenders of the table (the ``defender`` key), by label.
ENV_DEFENDERS: dict[str, Any] = {
    "fixed": "fixed",
    "audit p=0.05": {"name": "audit", "rate": 0.05},
    "chi2": {"name": "chi2", "window": 10, "false_alarm_rate": 1e-3},
    "cusum": {"name": "cusum", "false_alarm_rate": 1e-3},
    "linear-check": "linear-check",
}
#: On the Paillier loop: the MAC in place of the linear check (which needs the ElGamal schemes' Phi).
PAILLIER_ENV_DEFENDERS: dict[str, Any] = {**{k: v for k, v in ENV_DEFENDERS.items() if k != "linear-check"}, "mac": "mac"}


def environment_rows(
    *,
    preset: str = "small",
    episodes: int = 50,
    horizon: int = 40,
    crypto: str = "ideal",
    injections: tuple[str, ...] = ("pass", "replace", "add"),
    seed: int = 0,
    scheme: str | None = None,
    key_length: int | None = None,
) -> list[EnvironmentRow]:
    """Every defender of :data:`ENV_DEFENDERS` (:data:`PAILLIER_ENV_DEFENDERS` with ``scheme=
    "paillier"``) in the environment against each injection mode (random actions uniform in the
    action space; ``pass``: the honest loop, whose detections are false alarms)."""
    import gymnasium as gym

    import encctl_gym  # noqa: F401  registers the environment

    rows: list[EnvironmentRow] = []
    loop: dict[str, Any] = {k: v for k, v in (("scheme", scheme), ("key_length", key_length)) if v is not None}
    defenders = PAILLIER_ENV_DEFENDERS if scheme == "paillier" else ENV_DEFENDERS
    for label, spec in defenders.items():
        for injection in injections:
            env = gym.make(
                "encctl_gym/EncryptedLTIAttack-v0",
                preset=preset,
                crypto=crypto,
                max_samples=horizon,
                injection=injection,
                defender=spec,
                crypto_seed=seed,
                **loop,
            )
            rng = np.random.default_rng([seed, len(rows)])
            detected, samples, steps, t0 = 0, [], 0, time.perf_counter()
            for e in range(episodes):
                env.reset(seed=seed + e)
                done = False
                while not done:
                    _, _, te, tr, info = env.step(rng.uniform(-1.0, 1.0, size=env.action_space.shape))
                    done, steps = te or tr, steps + 1
                detected += bool(info["detected"])
                samples.append(info["samples_collected"])
            rows.append(
                EnvironmentRow(
                    label,
                    injection,
                    crypto if scheme is None else f"{crypto} ({scheme})",
                    episodes,
                    horizon,
                    detected,
                    float(np.mean(samples)),
                    (time.perf_counter() - t0) / steps,
                )
            )
            env.close()
    return rows


class _Recording:
    """A defender player whose actions are kept (the levers it pulled, per step)."""

    def __init__(self, player: Any) -> None:
        self.player = player
        self.actions: list[Any] = []
        self.name = getattr(player, "name", "defender")

    def reset(self, seed: int | None = None) -> None:
        self.player.reset(seed)

    def act(self, obs: np.ndarray) -> np.ndarray:
        a = np.asarray(self.player.act(obs), dtype=np.float32)
        self.actions.append(a)
        return a


def trained_defender_rows(
    *,
    steps: int = 20_000,
    episodes: int = 50,
    horizon: int = 40,
    seed: int = 0,
    scheme: str | None = None,
    key_length: int | None = None,
) -> list[dict[str, Any]]:
    """A PPO defender trained (``steps`` game steps, :func:`encctl_gym.agents.game_training.train_side`)
    against the sparse Gaussian attacker (injects at a quarter of the steps) on the ``small``
    plant with the game's default costs (rotation off), and static defenders beside it: per
    defender the share of steps each lever of :data:`~encctl_gym.multiagent.levers.LEVERS` is
    pulled, the detection rate, the samples the attacker collected and the defender's cost.
    ``scheme="paillier"`` (with ``key_length``) plays the Paillier loop, whose verify lever is
    the MAC."""
    from encctl_gym.agents.baselines import GaussianAttacker
    from encctl_gym.agents.evaluate import budget_config, env_config
    from encctl_gym.agents.game import NoDefence, RandomAudit, ScheduledAttacker, defender_action, play
    from encctl_gym.agents.game_training import train_side
    from encctl_gym.envs.config import resolve_params
    from encctl_gym.multiagent.levers import LEVERS

    loop = {k: v for k, v in (("scheme", scheme), ("key_length", key_length)) if v is not None}
    cfg = budget_config(env_config({"preset": "small", **loop, **({"max_samples": horizon} if loop else {})}), horizon)
    attacker = ScheduledAttacker(GaussianAttacker(resolve_params(cfg)), q=0.25)
    rules = {"rotation": False}
    learned, _ = train_side("defender", attacker, cfg, rules, algo="ppo", steps=steps, seed=seed)

    class VerifyAlways(NoDefence):
        name = "verify every step"

        def act(self, obs: np.ndarray) -> np.ndarray:
            return defender_action(verify=1.0)

    rows = []
    for player in (NoDefence(), RandomAudit(0.05), VerifyAlways(), learned):
        rec = _Recording(player)
        out = play(attacker, rec, cfg, rules, episodes=episodes, seed=seed + 1000)
        acts = np.array(rec.actions)
        rows.append(
            {
                "defender": rec.name,
                **{f"pulls {name}": float(np.mean(acts[:, i] > 0.0)) for i, name in enumerate(LEVERS)},
                "detected": float(out.detected.mean()),
                "samples": float(out.samples.mean()),
                "cost": float(out.cost.mean()),
                "attacker_return": float(out.attacker_return.mean()),
            }
        )
    return rows


def format_trained(rows: list[dict[str, Any]], steps: int) -> str:
    """The Markdown table of :func:`trained_defender_rows`."""
    keys = list(rows[0])
    lines = [f"## A trained defender's use of the levers (PPO, {steps} steps, against the sparse Gaussian attacker)", ""]
    lines += ["| " + " | ".join(keys) + " |", "|" + "---|" * len(keys)]
    for r in rows:
        lines.append("| " + " | ".join(v if isinstance(v, str) else f"{v:.4g}" for v in r.values()) + " |")
    return "\n".join(lines)


# ---------------------------------------------------------------------- output
def _range_text(v: int | None) -> str:
    if v is None:
        return "n-1"
    return f"2^{v.bit_length() - 1}" if v > 1024 and v & (v - 1) == 0 else str(v)


def format_tables(
    steps: list[StepRow], sweep: list[StepRow], episodes: list[EpisodeRow], env: list[EnvironmentRow] | None = None
) -> str:
    """The Markdown tables of the page."""
    head = "| scheme | defence | attacker | falsified / trials | detected | 95 % interval | bound 1 - eps | plant s/step | x step | server s/step |"
    lines = ["## One falsified step, every defence against every attacker", "", head, "|" + "---|" * 10]
    for r in steps:
        lo, hi = r.interval
        lines.append(
            f"| {r.scheme} | {r.defence} | {r.attacker} | {r.falsified} / {r.trials} | {r.detection:.4f} | [{lo:.4f}, {hi:.4f}] "
            f"| {1 - r.epsilon:.4g} | {r.cost_seconds:.3g} | {r.cost_seconds / r.step_seconds:.3g} | {r.server_seconds:.3g} |"
        )
    lines += ["", "## The Kerckhoffs attacker against small secrets: pass rate against the bound", ""]
    lines += ["| scheme | check | R or A | falsified | passed | pass rate | 95 % interval | bound epsilon |", "|" + "---|" * 8]
    for r in sweep:
        lo, hi = wilson_interval(r.falsified - r.detected, r.falsified)
        R = (
            round(1 / (r.epsilon - (0 if r.defence == "linear-check" else r.epsilon - 1 / round(1 / r.epsilon))))
            if r.epsilon
            else 0
        )
        lines.append(
            f"| {r.scheme} | {r.defence} | {R} | {r.falsified} | {r.falsified - r.detected} | {1 - r.detection:.4f} "
            f"| [{lo:.4f}, {hi:.4f}] | {r.epsilon:.4g} |"
        )
    lines += ["", "## Falsified steps that pass before the first detection (one key per episode, ElGamal)", ""]
    lines += ["| attacker | R | episodes | horizon | mean passes | undetected through the horizon | epsilon |", "|" + "---|" * 7]
    for e in episodes:
        lines.append(
            f"| {e.attacker} | {_range_text(e.secret_range)} | {e.episodes} | {e.horizon} | {e.mean_passes:.3f} | {e.undetected} | {e.epsilon:.3g} |"
        )
    if env:
        lines += ["", "## The environment's defenders against its injection modes (random actions; pass: false alarms)", ""]
        lines += [
            "| defender | injection | backend | episodes | samples per attack | detected | 95 % interval | mean samples collected | s/step |",
            "|" + "---|" * 9,
        ]
        for row in env:
            lo, hi = wilson_interval(row.detected, row.episodes)
            lines.append(
                f"| {row.defender} | {row.injection} | {row.crypto} | {row.episodes} | {row.horizon} | {row.detected} | [{lo:.3f}, {hi:.3f}] | {row.mean_samples:.2f} | {row.step_seconds:.3g} |"
            )
    return "\n".join(lines)


def plot_integrity(steps: list[StepRow], sweep: list[StepRow], path: Path) -> Path:
    """Left: detection per falsified step for each cell (intervals, bound ticks); right: the
    Kerckhoffs pass rate against ``epsilon`` for small secrets."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from encctl_gym.plotting import save_figure

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12, 4.8), gridspec_kw={"width_ratios": [2.2, 1]})
    colours = {"audit": "tab:gray", "linear-check": "tab:blue", "mac": "tab:green"}
    cells = [r for r in steps if r.falsified]
    for i, r in enumerate(cells):
        lo, hi = r.interval
        ax.errorbar(
            i,
            r.detection,
            yerr=[[max(0.0, r.detection - lo)], [max(0.0, hi - r.detection)]],
            fmt="o",
            color=colours[r.defence],
            ms=4,
        )
        ax.plot([i - 0.35, i + 0.35], [1 - r.epsilon] * 2, "-", color="k", lw=0.8)
    ax.set_xticks(range(len(cells)))
    ax.set_xticklabels([f"{r.scheme[:2]} {r.attacker}" for r in cells], rotation=70, fontsize=7)
    ax.set_ylabel("detection per falsified step")
    ax.set_ylim(-0.05, 1.05)
    for d, c in colours.items():
        ax.plot([], [], "o", color=c, label=d)
    ax.plot([], [], "-", color="k", lw=0.8, label="bound 1 - epsilon")
    ax.legend(fontsize=7, loc="center right")
    ax.set_title("one falsified step (audits at the table's rate)", fontsize=9)
    for d, marker in (("linear-check", "o"), ("mac", "s")):
        rs = [r for r in sweep if r.defence == d and r.falsified]
        eps = np.array([r.epsilon for r in rs])
        rate = np.array([1 - r.detection for r in rs])
        ci = np.array([wilson_interval(r.falsified - r.detected, r.falsified) for r in rs])
        bx.errorbar(
            eps,
            rate,
            yerr=[np.clip(rate - ci[:, 0], 0, None), np.clip(ci[:, 1] - rate, 0, None)],
            fmt=marker,
            color=colours[d],
            label=f"{d} (Kerckhoffs)",
            ms=4,
        )
    grid = np.array([0.02, 0.6])
    bx.plot(grid, grid, ":", color="k", label="pass rate = epsilon")
    bx.set_xscale("log")
    bx.set_yscale("log")
    bx.set_xlabel("bound epsilon (1/R, 1/A + 2/p_min)")
    bx.set_ylabel("measured pass rate")
    bx.legend(fontsize=7)
    bx.set_title("small secrets", fontsize=9)
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)
    return path


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="python -m encctl_gym.experiments.integrity", description=__doc__.splitlines()[0])
    parser.add_argument(
        "--out", type=Path, default=Path("results/integrity"), help="directory of the page and figure (default results/integrity)"
    )
    parser.add_argument(
        "--record", action="store_true", help="write docs/results/integrity/integrity.md and docs/figures/integrity.png"
    )
    parser.add_argument("--quick", action="store_true", help="40 trials, 40 episodes: a smoke test")
    parser.add_argument("--trials", type=int, default=400, help="trials per cell (default 400)")
    parser.add_argument(
        "--episodes", type=int, default=200, help="episodes per row of the samples-before-detection table (default 200)"
    )
    parser.add_argument("--horizon", type=int, default=20, help="falsified steps per episode at most (default 20)")
    parser.add_argument("--audit-rate", type=float, default=0.05, help="audit probability per step (default 0.05)")
    parser.add_argument("--elgamal-bits", type=int, default=256, help="ElGamal group size (default 256)")
    parser.add_argument("--paillier-bits", type=int, default=512, help="Paillier modulus size (default 512)")
    parser.add_argument("--seed", type=int, default=0, help="seed (default 0)")
    parser.add_argument(
        "--trained-defender",
        type=int,
        default=0,
        metavar="STEPS",
        help="only train a PPO defender for STEPS game steps and report its levers",
    )
    parser.add_argument(
        "--scheme",
        choices=("modified", "paillier"),
        default="modified",
        help="the loop of --trained-defender: ElGamal's modified scheme (verify lever: the linear check) or Paillier "
        "at --paillier-bits (verify lever: the MAC); default modified",
    )
    return parser


def main(argv: list[str] | None = None) -> int:
    """``python -m encctl_gym.experiments.integrity``: the three tables and the figure."""
    args = _parser().parse_args(argv)
    trials, episodes = (40, 40) if args.quick else (args.trials, args.episodes)
    if args.trained_defender:
        return _trained_main(args, argv)
    kw = {"elgamal_bits": args.elgamal_bits, "seed": args.seed}
    try:
        steps = step_rows(trials=trials, paillier_bits=args.paillier_bits, audit_rate=args.audit_rate, **kw)
        sweep = sweep_rows(trials=trials, paillier_bits=args.paillier_bits, **kw)
        eps = episode_rows(episodes=episodes, horizon=args.horizon, **kw)
        env = environment_rows(episodes=episodes, seed=args.seed) + environment_rows(
            episodes=max(4, episodes // 10), crypto="elgamal", seed=args.seed
        )
        for crypto, n_episodes in (("ideal", episodes), ("elgamal", max(4, episodes // 10))):  # the MAC's real tags on both
            env += environment_rows(
                episodes=n_episodes, crypto=crypto, seed=args.seed, scheme="paillier", key_length=args.paillier_bits
            )
    except EncctlError as exc:
        print(f"integrity: {exc}", file=sys.stderr)
        return 2
    out = ensure_out_dir(Path("docs/results/integrity") if args.record else args.out)
    figures = ensure_out_dir(Path("docs/figures")) if args.record else out
    cmd = "python -m encctl_gym.experiments.integrity" + "".join(f" {a}" for a in (argv if argv is not None else sys.argv[1:]))
    notes = (
        f"\n\nPreset `small` (n = m = 2), ElGamal (modified scheme) at {args.elgamal_bits} bits, Paillier at "
        f"{args.paillier_bits} bits, audits at rate {args.audit_rate}, linear check R = 2^64, MAC alpha in Z_n; "
        "seconds are medians on this machine; x step: over the encrypted period of the same scheme."
    )
    write_recorded_table(
        out / "integrity.md", "Integrity by verification (issue 33)", cmd, format_tables(steps, sweep, eps, env), notes
    )
    print(f"  wrote {plot_integrity(steps, sweep, figures / 'integrity.png')}")
    return 0


def _trained_main(args: argparse.Namespace, argv: list[str] | None) -> int:
    try:
        loop = {"scheme": "paillier", "key_length": args.paillier_bits} if args.scheme == "paillier" else {}
        rows = trained_defender_rows(steps=args.trained_defender, episodes=50 if not args.quick else 5, seed=args.seed, **loop)
    except EncctlError as exc:
        print(f"integrity: {exc}", file=sys.stderr)
        return 2
    out = ensure_out_dir(Path("docs/results/integrity") if args.record else args.out)
    cmd = "python -m encctl_gym.experiments.integrity" + "".join(f" {a}" for a in (argv if argv is not None else sys.argv[1:]))
    where = f"the Paillier loop at {args.paillier_bits} bits (verify lever: the MAC)" if args.scheme == "paillier" else "ElGamal"
    notes = f"\n\nPreset `small`, {where}, 40 samples per attack, game rules: defaults with rotation off; 50 evaluation episodes."
    write_recorded_table(
        out / ("trained_defender_paillier.md" if args.scheme == "paillier" else "trained_defender.md"),
        "A trained defender with the verify lever (issue 33)",
        cmd,
        format_trained(rows, args.trained_defender),
        notes,
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
