"""Probe cases of :mod:`encctl_gym.crypto`: arithmetic, groups, encoding, ElGamal, dynamic keys, the
modified scheme and the encrypted controller; and its security properties (seeded keys, fresh
randomness, ciphertexts bound to their group, degenerate keys)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from .build import FILES, GROUP64, bad_args, case, write_file
from .harness import Case, Lazy, NotApplicable, SecurityFinding, api, resolve
from .values import BAD, HUGE, HUGER, NAN, explicit

A = "crypto"
PROPERTY = settings(max_examples=25, derandomize=True, database=None, deadline=None, suppress_health_check=list(HealthCheck))


def _keys(bits_or_group: Any = 64, seed: int | None = 1) -> Any:
    grp = resolve(bits_or_group)
    keygen = api("encctl_gym.crypto.elgamal:keygen")
    return keygen(grp, rng=seed)


def _stream(seed: int = 7) -> Any:
    return api("encctl_gym.crypto.arith:seeded_random")(seed)


PK = Lazy(lambda: _keys()[0], "<pk>")
SK = Lazy(lambda: _keys()[1], "<sk>")
ENCODER = Lazy(
    lambda: api("encctl_gym.crypto.encoding:Encoder")(api("encctl_gym.crypto.group:get_group")(64), 1024.0), "<encoder>"
)


def _ct(m: int = 4) -> Any:
    pk, _ = _keys()
    return api("encctl_gym.crypto.elgamal:encrypt")(pk, m, rng=_stream())


CT = Lazy(_ct, "<ct>")

# a member of the 64-bit group and a non-member (quadratic non-residue) are found in the child
_NOT_MEMBER = Lazy(
    lambda: next(v for v in range(2, 200) if not api("encctl_gym.crypto.group:get_group")(64).contains(v)), "<non-member>"
)


def _arith() -> list[Case]:
    out: list[Case] = []
    out += bad_args(A, "encctl_gym.crypto.arith:seeded_random", {"seed": 3}, {"seed": "seed"}, drawn=1)
    out += bad_args(
        A,
        "encctl_gym.crypto.arith:seeded_random",
        {"seed": 3, "purpose": "keygen"},
        {"purpose": explicit([3, None, b"keygen", ["a"]], "traceback")},
        name="seeded_random.purpose",
        drawn=0,
    )
    out += bad_args(
        A,
        lambda kw: api("encctl_gym.crypto.arith:seeded_random")(1).below(**kw),
        {"n": 5},
        {"n": explicit([0, -1, 2.5, True, "5", None, NAN, -HUGE])},
        name="RandomSource.below",
        drawn=0,
    )
    out += bad_args(
        A,
        lambda kw: api("encctl_gym.crypto.arith:seeded_random")(1).between(**kw),
        {"low": 1, "high": 5},
        {"high": explicit([1, 0, 2.5, "9", None])},
        name="RandomSource.between",
        drawn=0,
    )
    out += bad_args(
        A,
        "encctl_gym.crypto.arith:powmod",
        {"base": 3, "exp": 5, "mod": 7},
        {
            "mod": explicit([0, -7, 2.5, "7", None]),
            "exp": explicit([2.5, "5", None], "traceback"),
            "base": explicit([2.5, "3", None], "traceback"),
        },
        drawn=0,
    )
    out += bad_args(
        A,
        "encctl_gym.crypto.arith:powmod",
        {"base": 4, "exp": -1, "mod": 8},
        {"base": explicit([2, 6])},
        name="powmod(exp=-1)",
        drawn=0,
    )
    out += bad_args(
        A,
        "encctl_gym.crypto.arith:invert",
        {"a": 3, "mod": 7},
        {"a": explicit([0, 14, 2.5, "3", None]), "mod": explicit([0, 1, -7, 2.5, None])},
        drawn=0,
    )
    out += bad_args(
        A,
        "encctl_gym.crypto.arith:jacobi",
        {"a": 3, "n": 7},
        {"n": explicit([4, 0, -7, 2.5, "7"]), "a": explicit([2.5, "3", None], "traceback")},
        drawn=0,
    )
    out += bad_args(A, "encctl_gym.crypto.arith:legendre", {"a": 3, "p": 7}, {"p": explicit([4, 0, -7, 1, 2.5])}, drawn=0)
    out += bad_args(
        A,
        "encctl_gym.crypto.arith:is_prime",
        {"n": 7},
        {"n": explicit([2.5, "7", None, [7]], "traceback"), "reps": explicit([-1, 2.5, "a"])},
        drawn=0,
    )
    return out


def _group() -> list[Case]:
    out: list[Case] = []
    gp = "encctl_gym.crypto.group:GroupParams"

    def group_verify(kw: dict[str, Any]) -> Any:
        return api(gp)(**kw).verify()

    valid = {"p": 23, "q": 11, "g": 4}
    bad_p = explicit([21, 25, 4, 1, -23, 0, 23.5, True, "abc", None, [23], HUGE + 1, 2**16400 + 1], "silent")
    bad_q = explicit([2, 9, 5, 22, 0, -11, 11.5, "x", None])
    bad_g = explicit([1, 0, 22, 23, 5, -4, 4.5, "x", None, 2**64])
    out += bad_args(A, group_verify, valid, {"p": bad_p, "q": bad_q, "g": bad_g}, name="GroupParams.verify", drawn=0)
    # q = 2 is the only subgroup of p = 5; the q = 2 group that passed verify()
    out.append(case(A, "GroupParams(p=5,q=2,g=4).verify", "security", lambda _: api(gp)(5, 2, 4).verify()))
    out.append(case(A, "GroupParams(p=7,q=3,g=6).verify", "security", lambda _: api(gp)(7, 3, 6).verify()))
    fd = lambda kw: api(gp + ".from_dict")(kw["data"])  # noqa: E731
    out += bad_args(
        A,
        fd,
        {"data": {"p": 23, "q": 11, "g": 4}},
        {
            "data": explicit(
                [
                    {"p": 23, "q": 11},
                    {"p": "0x17", "q": "0xb", "g": "zz"},
                    {"p": 23, "q": 11, "g": 4, "bits": 6},
                    {"p": 23, "q": 11, "g": 4, "cofactor": 3},
                    {"p": "9" * 5000, "q": 11, "g": 4},
                    [23, 11, 4],
                    "abc",
                    None,
                    42,
                    {"p": 23.5, "q": 11, "g": 4},
                    {"p": [23], "q": 11, "g": 4},
                    {"p": True, "q": 11, "g": 4},
                ],
                "traceback",
            )
        },
        name="GroupParams.from_dict",
        drawn=0,
    )
    fj = lambda kw: api(gp + ".from_json")(kw["text"])  # noqa: E731
    out += bad_args(
        A,
        fj,
        {"text": '{"p": 23, "q": 11, "g": 4}'},
        {
            "text": explicit(
                [
                    "not json",
                    "[]",
                    "{}",
                    "null",
                    '{"p": ' + "9" * 5000 + ', "q": 11, "g": 4}',
                    "[" * 100000 + "]" * 100000,
                    '{"p": 23, "q": 11, "g": 4, "p": "x"}',
                    b'{"p": 23}',
                    None,
                    42,
                ],
                "traceback",
            )
        },
        name="GroupParams.from_json",
        drawn=0,
    )

    def load(which: str) -> Any:
        def run(tmp: Path) -> Any:
            return api(gp + ".load")(write_file(tmp, which))

        return run

    for which in (
        "missing",
        "directory",
        "empty",
        "binary_junk",
        "utf16",
        "deep_nesting_json",
        "digits_5000",
        "top_level_list",
        "oversized",
    ):
        out.append(case(A, f"GroupParams.load({which})", "traceback", load(which)))

    def save_to(target: str) -> Any:
        def run(tmp: Path) -> Any:
            grp = api("encctl_gym.crypto.group:get_group")(64)
            dest = {"directory": tmp, "no_parent": tmp / "no" / "such" / "dir.json", "dev_full": Path("/proc/self/status")}[
                target
            ]
            return grp.save(dest)

        return run

    for target in ("directory", "no_parent", "dev_full"):
        out.append(case(A, f"GroupParams.save(to {target})", "traceback", save_to(target)))

    gen = "encctl_gym.crypto.group:generate_safe_prime_group"
    out += bad_args(
        A,
        gen,
        {"bits": 32, "rng": 1},
        {
            "bits": explicit([0, 1, 2, 8, 15, -64, 32.5, True, "32", None, NAN, [32]]),
            "rng": explicit(["seed", 2.5, -1, [1], NAN], "traceback"),
        },
        drawn=0,
    )
    out += bad_args(
        A,
        gen,
        {"bits": 32, "rng": 1},
        {"bits": explicit([10**6, 2**20, HUGE, 4096, 20000], "hang")},
        name="generate_safe_prime_group.huge",
        drawn=0,
        timeout=30,
    )
    out += bad_args(
        A,
        gen,
        {"bits": 32, "rng": 1, "max_seconds": 5.0},
        {"max_seconds": explicit([-1.0, 0.0, NAN, "a", None, True]), "window": explicit([-1, 0, 2.5, "a", True])},
        name="generate_safe_prime_group.limits",
        drawn=0,
    )
    out += bad_args(
        A,
        gen,
        {"bits": 1500, "rng": 1, "max_seconds": 0.01},
        {"bits": explicit([1500, 3000], "hang")},
        name="generate_safe_prime_group(max_seconds=0.01)",
        drawn=0,
        timeout=30,
    )
    out += bad_args(
        A,
        "encctl_gym.crypto.group:shipped_group",
        {"bits": 64},
        {"bits": explicit([100, 0, -64, 64.5, "64", None, True, HUGE, NAN])},
        drawn=0,
    )
    out += bad_args(
        A,
        "encctl_gym.crypto.group:get_group",
        {"bits": 64},
        {"bits": explicit([0, 3, -64, 64.5, "64", None, True, NAN, HUGER]), "rng": explicit(["seed", 2.5, [1]], "traceback")},
        drawn=0,
    )
    out += bad_args(
        A,
        "encctl_gym.crypto.group:get_group",
        {"bits": 64},
        {"bits": explicit([10**6, 5000, 2**40, HUGE], "hang")},
        name="get_group.huge",
        drawn=0,
        timeout=30,
    )
    out += bad_args(
        A,
        "encctl_gym.crypto.group:as_group",
        {"group_or_bits": 64},
        {"group_or_bits": explicit(["abc", None, 64.5, [64], {"p": 23}], "traceback")},
        drawn=0,
    )
    out += bad_args(
        A,
        "encctl_gym.crypto.group:estimate_generation_seconds",
        {"bits": 512},
        {"bits": explicit([0, -1, 2.5, "a", None, True]), "window": explicit([0, -1, 2.5, "a"])},
        drawn=0,
    )
    out += bad_args(
        A,
        "encctl_gym.crypto.group:sieve_window",
        {"q0": 10**6 + 1, "n_cand": 100, "limit": 1000},
        {
            "n_cand": explicit([-1, 2.5, 10**12, "a"], "hang"),
            "limit": explicit([-1, 2.5, 10**12, "a"], "hang"),
            "q0": explicit([-5, 2.5, "a"]),
        },
        drawn=0,
    )
    return out


def _encoding() -> list[Case]:
    out: list[Case] = []
    enc = "encctl_gym.crypto.encoding:Encoder"
    out += bad_args(
        A,
        enc,
        {"group": GROUP64, "delta": 1024.0, "x_bound": 10.0},
        {"delta": "pos", "x_bound": "nonneg?", "group": explicit(["abc", None, 64.5, [1]], "traceback")},
    )
    out += bad_args(
        A,
        enc,
        {"group": GROUP64, "delta": 1024.0, "x_bound": 10.0},
        {
            "delta": explicit([1e308, 2.0**600], "hang"),
            "x_bound": explicit([1e308], "hang"),
            "max_shift": explicit([-1, 2.5, "a", True, HUGE]),
        },
        name="Encoder.range",
        drawn=0,
    )

    def method(name: str, **fixed: Any) -> Any:
        def call(kw: dict[str, Any]) -> Any:
            e = api(enc)(api("encctl_gym.crypto.group:get_group")(64), 1024.0, x_bound=100.0)
            return getattr(e, name)(**{**fixed, **kw})

        return call

    scalar_bad = BAD["real"] + explicit([1e300, 1e20, -1e20, 100.5])
    out += bad_args(A, method("encode"), {"x": 1.5}, {"x": scalar_bad}, name="Encoder.encode", drawn=1)
    out += bad_args(
        A,
        method("quantize"),
        {"x": 1.5},
        {"x": explicit([NAN, 2 + 1j, "a", None, 1e300, True])},
        name="Encoder.quantize",
        drawn=0,
    )
    out += bad_args(
        A,
        method("decode"),
        {"m": 4, "power": 1},
        {"m": explicit([-1, 2**64, HUGE, 2.5, "4", None, True]), "power": explicit([-1, 0, 3, 2.5, True, "2", None, 1.0])},
        name="Encoder.decode",
        drawn=0,
    )
    out += bad_args(
        A,
        method("decode_signed"),
        {"w": 4, "power": 1},
        {"w": explicit([2.5, "4", None, True, HUGER]), "power": explicit([-1, 0, 3, 2.5, "1"])},
        name="Encoder.decode_signed",
        drawn=0,
    )
    out += bad_args(
        A,
        method("error_bound"),
        {"shift": 0},
        {"shift": explicit([-5, -1, 2.5, "a", True, HUGE])},
        name="Encoder.error_bound",
        drawn=0,
    )
    out += bad_args(
        A,
        method("max_abs_signed"),
        {"x_bound": 10.0},
        {"x_bound": explicit([-1.0, NAN, "a", 1e308, 2 + 1j])},
        name="Encoder.max_abs_signed",
        drawn=0,
    )
    elementwise_bad = [
        (v, c)
        for v, c in BAD["vector"]
        if not (isinstance(v, np.ndarray) and v.dtype.kind == "f" and (v.size == 0 or v.ndim == 3))
    ]
    out += bad_args(
        A,
        method("quantize_array"),
        {"x": np.array([1.0, 2.0])},
        {"x": elementwise_bad + explicit([np.array([1e300])], "hang")},
        name="Encoder.quantize_array",
        drawn=0,
    )
    out += bad_args(
        A,
        method("encode_signed_array"),
        {"x": np.array([1.0, 2.0])},
        {"x": explicit([np.array([1e300]), np.array([150.0]), [[1.0], [2.0, 3.0]], np.array([1 + 1j])])},
        name="Encoder.encode_signed_array",
        drawn=0,
    )
    out += bad_args(
        A,
        method("decode_signed_array"),
        {"w": np.array([4, 5]), "power": 1},
        {"w": explicit([np.array([1.5]), np.array(["a"]), np.array([1 + 1j]), [HUGER]]), "power": explicit([-1, 3, 2.5])},
        name="Encoder.decode_signed_array",
        drawn=0,
    )
    out += bad_args(
        A,
        "encctl_gym.crypto.encoding:encode_int",
        {"group": GROUP64, "v": 5},
        {
            "v": explicit([HUGE, 2**70, 2.5, "5", None, True]),
            "max_shift": explicit([-1, 2.5, "a"]),
            "group": explicit(["abc", 64], "traceback"),
        },
        drawn=0,
    )
    out += bad_args(
        A,
        "encctl_gym.crypto.encoding:decode_int",
        {"group": GROUP64, "m": 4},
        {"m": explicit([-4, 2**64, 2.5, "4", None]), "group": explicit(["abc", 64, None], "traceback")},
        drawn=0,
    )
    out += bad_args(
        A,
        "encctl_gym.crypto.encoding:decode_scaled",
        {"w": 5, "delta_ratio": (1024, 1), "power": 1},
        {
            "delta_ratio": explicit([(0, 1), (1024, 0), (-1, 1), "ab", (1.5, 1), (1, 2, 3), None]),
            "power": explicit([-1, 0, 3, 2.5, "1"]),
            "w": explicit([2.5, "5", None, HUGER]),
        },
        drawn=0,
    )
    out += bad_args(
        A,
        "encctl_gym.crypto.residue_table:residue_table",
        {"p": GROUP64, "limit": 100},
        {
            "limit": explicit([-1, 2.5, "a", None, True, 10**12, 2**62, HUGE], "hang"),
            "p": explicit([21, -23, "abc", None, 2.5], "traceback"),
            "max_bytes": explicit([-1, 0, 2.5, "a", NAN]),
        },
        drawn=0,
    )
    return out


def _elgamal() -> list[Case]:
    out: list[Case] = []
    eg = "encctl_gym.crypto.elgamal"
    out += bad_args(
        A,
        f"{eg}:keygen",
        {"group_or_bits": 64, "rng": 1},
        {
            "group_or_bits": explicit([0, 1, 2, 3, -64, 64.5, True, "64", None, NAN, [64], {"p": 23}]),
            "rng": explicit(["seed", 2.5, -1, [1], NAN, 1 + 0j], "traceback"),
        },
        drawn=0,
    )
    out += bad_args(
        A,
        f"{eg}:keygen",
        {"group_or_bits": 64},
        {"group_or_bits": explicit([10**6, 5000, HUGE], "hang")},
        name="keygen.huge",
        drawn=0,
        timeout=30,
    )
    out += bad_args(
        A,
        f"{eg}:encrypt",
        {"pk": PK, "m": 4, "rng": Lazy(_stream, "<stream>")},
        {
            "m": explicit([0, -1, 2**64, HUGE, 2.5, "4", None, True, _NOT_MEMBER, 4.0]),
            "rng": explicit([5, "seed", 2.5, [1]], "security"),
            "pk": explicit(["abc", None, 42, SK], "traceback"),
        },
        drawn=0,
    )
    out += bad_args(
        A,
        f"{eg}:decrypt",
        {"sk": SK, "ct": CT},
        {"ct": explicit(["abc", None, (1, 2), 42, PK], "traceback"), "sk": explicit(["abc", None, 42, PK], "traceback")},
        drawn=0,
    )
    out += bad_args(
        A,
        f"{eg}:mult",
        {"pk": PK, "ct1": CT, "ct2": CT},
        {"ct2": explicit(["abc", None, (1, 2), 7], "traceback"), "pk": explicit([SK, None], "traceback")},
        drawn=0,
    )

    def with_group(cls: str, **fields: Any) -> Any:
        def call(kw: dict[str, Any]) -> Any:
            return api(f"{eg}:{cls}", "group")(group=api("encctl_gym.crypto.group:get_group")(64), **{**fields, **kw})

        return call

    out += bad_args(
        A,
        with_group("PublicKey"),
        {"h": 4},
        {"h": explicit([1, 0, -4, 2**64, 2.5, "4", None, True, _NOT_MEMBER])},
        name="PublicKey",
        drawn=0,
    )
    out += bad_args(
        A, with_group("PublicKey", h=4), {"t": 0}, {"t": explicit([-1, 2.5, "0", True, NAN])}, name="PublicKey.t", drawn=0
    )
    q64 = Lazy(lambda: api("encctl_gym.crypto.group:get_group")(64).q, "q")
    out += bad_args(
        A,
        with_group("SecretKey"),
        {"s": 5},
        {"s": explicit([0, -5, q64, 2**64, 2.5, "5", None, True])},
        name="SecretKey",
        drawn=0,
    )
    out += bad_args(
        A,
        with_group("Ciphertext"),
        {"c1": 4, "c2": 9},
        {"c1": explicit([2.5, "4", None]), "c2": explicit([2.5, None]), "t": explicit([-1, 2.5, "a"])},
        name="Ciphertext",
        drawn=0,
    )

    def decrypt_built(kw: dict[str, Any]) -> Any:  # components are checked where a ciphertext is used
        _, sk = _keys()
        ct = api(f"{eg}:Ciphertext", "group")(group=sk.group, **{"c1": 4, "c2": 9, **kw})
        return api(f"{eg}:decrypt")(sk, ct)

    out += bad_args(
        A,
        decrypt_built,
        {},
        {"c1": explicit([0, -4, 2**64, _NOT_MEMBER]), "c2": explicit([0, -9, 2**64, _NOT_MEMBER])},
        name="decrypt(Ciphertext)",
        drawn=0,
    )
    return out


def _dynamic() -> list[Case]:
    out: list[Case] = []
    dy = "encctl_gym.crypto.dyn_elgamal"
    stream = Lazy(_stream, "<stream>")
    out += bad_args(
        A,
        f"{dy}:key_update",
        {"pk": PK, "sk": SK, "rng": stream},
        {
            "rng": explicit([5, "seed", 2.5], "security"),
            "sk": explicit([PK, None, "abc"], "traceback"),
            "pk": explicit([SK, None], "traceback"),
        },
        drawn=0,
    )

    def token() -> Any:
        pk, sk = _keys()
        return api(f"{dy}:key_update")(pk, sk, rng=_stream())

    def upd(kw: dict[str, Any]) -> Any:
        pk1, _, tok = token()
        ct = kw.pop("ct", None) or api("encctl_gym.crypto.elgamal:encrypt")(_keys()[0], 4, rng=_stream(9))
        return api(f"{dy}:ciphertext_update")(kw.pop("pk", pk1), ct, kw.pop("token", tok), **kw)

    out += bad_args(
        A,
        upd,
        {},
        {
            "token": explicit(["abc", None, 42], "traceback"),
            "rng": explicit([5, "x"], "security"),
            "ct": explicit(["abc", (1, 2)], "traceback"),
        },
        name="ciphertext_update",
        drawn=0,
    )

    def recover(kw: dict[str, Any]) -> Any:
        _, sk = _keys()
        return api(f"{dy}:recover_next_secret_key")(kw.get("sk_t", sk), kw.get("token", token()[2]))

    out += bad_args(
        A,
        recover,
        {},
        {"token": explicit(["abc", None, 7], "traceback"), "sk_t": explicit([None, "abc", PK], "traceback")},
        name="recover_next_secret_key",
        drawn=0,
    )

    def with_group(cls: str, module: str, **fields: Any) -> Any:
        def call(kw: dict[str, Any]) -> Any:
            return api(f"{module}:{cls}", "group")(group=api("encctl_gym.crypto.group:get_group")(64), **{**fields, **kw})

        return call

    out += bad_args(
        A,
        with_group("UpdateToken", dy, d=3),
        {"h": 4},
        {"h": explicit([1, 0, 2**64, 2.5, None, _NOT_MEMBER])},
        name="UpdateToken.h",
        drawn=0,
    )
    out += bad_args(
        A,
        with_group("UpdateToken", dy, h=4),
        {"d": 3},
        {"d": explicit([-1, 2**64, 2.5, "3", None])},
        name="UpdateToken.d",
        drawn=0,
    )
    md = "encctl_gym.crypto.modified"
    out += bad_args(
        A,
        with_group("ModifiedCiphertext", md, c2=4, c3=9),
        {"c1": 4},
        {"c1": explicit([2.5, None, "4"])},
        name="ModifiedCiphertext",
        drawn=0,
    )

    def mdec_built(kw: dict[str, Any]) -> Any:
        _, sk = _keys()
        ct = api(f"{md}:ModifiedCiphertext", "group")(group=sk.group, **{"c1": 4, "c2": 4, "c3": 9, **kw})
        return api(f"{md}:modified_decrypt")(sk, sk, ct)

    out += bad_args(
        A,
        mdec_built,
        {},
        {"c1": explicit([0, 2**64, _NOT_MEMBER]), "c3": explicit([0, -9, 2**64, _NOT_MEMBER])},
        name="modified_decrypt(ModifiedCiphertext)",
        drawn=0,
    )
    out += bad_args(
        A,
        f"{md}:modified_eval",
        {"pk": PK, "ct1": CT, "ct2": CT},
        {"ct1": explicit(["abc", None, (1, 2)], "traceback"), "pk": explicit([None, SK], "traceback")},
        drawn=0,
    )

    def mdec(kw: dict[str, Any]) -> Any:
        pk, sk = _keys()
        ct = api(f"{md}:modified_eval")(pk, _ct(), _ct(9))
        return api(f"{md}:modified_decrypt")(kw.get("sk1", sk), kw.get("sk2", sk), kw.get("ct", ct))

    out += bad_args(
        A,
        mdec,
        {},
        {"ct": explicit(["abc", None, CT], "traceback"), "sk2": explicit([PK, None], "traceback")},
        name="modified_decrypt",
        drawn=0,
    )
    return out


def _controller() -> list[Case]:
    out: list[Case] = []
    ctl = "encctl_gym.crypto.controller:EncryptedLinearController"
    phi = np.array([[-0.3, -0.1], [0.05, -0.2]])
    valid = {"Phi": phi, "group": 64, "delta": 256.0, "x_bound": 10.0, "rng": 1}
    phi_bad = [
        (v, c)
        for v, c in BAD["matrix"]
        if not (isinstance(v, np.ndarray) and v.dtype.kind == "f" and v.ndim in (1, 2) and v.size)
    ]
    out += bad_args(
        A,
        ctl,
        valid,
        {
            "Phi": phi_bad,
            "delta": "pos",
            "x_bound": "nonneg",
            "scheme": explicit(["bogus", "", 3, None, ["modified"], "MODIFIED"]),
            "group": explicit(["abc", None, 3, 64.5, HUGE], "traceback"),
            "rng": explicit(["seed", 2.5, [1]], "traceback"),
        },
        name="EncryptedLinearController",
    )
    out += bad_args(
        A,
        ctl,
        valid,
        {
            "Phi": explicit([np.full((2, 2), 1e30), np.full((2, 2), 1e300)], "silent"),
            "x_bound": explicit([1e300, 1e30], "hang"),
            "delta": explicit([1e300, 2.0**200], "hang"),
        },
        name="EncryptedLinearController.range",
        drawn=0,
    )

    def step(kw: dict[str, Any]) -> Any:
        c = api(ctl)(phi, 64, 256.0, 10.0, rng=1)
        return c.step(**kw)

    out += bad_args(
        A,
        step,
        {"x": np.array([1.0, 2.0])},
        {"x": BAD["vector"] + explicit([np.array([1.0, 2.0, 3.0]), np.array([11.0, 0.0]), [1.0, "a"]])},
        name="EncryptedLinearController.step",
        drawn=0,
    )

    def step_inject(kw: dict[str, Any]) -> Any:
        c = api(ctl)(phi, 64, 256.0, 10.0, rng=1)
        return c.step(np.array([1.0, 2.0]), **kw)

    out += bad_args(
        A,
        step_inject,
        {},
        {"inject": explicit(["abc", [[1, 2]], [[None, None], [None, None]], 42], "traceback")},
        name="EncryptedLinearController.step(inject)",
        drawn=0,
    )

    def reference(kw: dict[str, Any]) -> Any:
        return api(ctl)(phi, 64, 256.0, 10.0, rng=1).reference(**kw)

    out += bad_args(
        A,
        reference,
        {"x": np.array([1.0, 2.0])},
        {"x": explicit([np.array([1 + 1j, 0]), np.array([NAN, 0]), "ab"])},
        name="EncryptedLinearController.reference",
        drawn=0,
    )
    q = "encctl_gym.crypto.quantized:QuantizedLinearController"
    out += bad_args(
        A,
        q,
        {"Phi": phi, "encoder": ENCODER, "x_bound": 10.0},
        {
            "Phi": explicit([np.array([[1 + 1j, 0], [0, 1]]), np.array([[NAN, 0], [0, 1]]), "ab"]),
            "encoder": explicit(["abc", None, GROUP64], "traceback"),
            "x_bound": explicit([-1.0, NAN, "a", 1e300]),
        },
        drawn=0,
    )

    def server(kw: dict[str, Any]) -> Any:
        return api("encctl_gym.crypto.servers:ControllerServer")(**{"pk0": _keys()[0], "ct_phi": [[_ct()]], **kw})

    out += bad_args(
        A,
        server,
        {},
        {
            "ct_phi": explicit(["abc", [], [[]], [[1, 2]], [[_ct_lazy()], [_ct_lazy(), _ct_lazy()]], None], "traceback"),
            "pk0": explicit([None, "abc", SK], "traceback"),
        },
        name="ControllerServer",
        drawn=0,
    )
    out += bad_args(A, "encctl_gym.crypto.schemes:get_scheme", {"name": "modified"}, {"name": "name"}, drawn=1)
    return out


def _ct_lazy() -> Lazy:
    return Lazy(_ct, "<ct>")


# --------------------------------------------------------------------------- security properties
def _other_group_keys() -> tuple[Any, Any]:
    """Key pairs of two different 64-bit groups: the shipped one and a fresh seeded one."""
    shipped = api("encctl_gym.crypto.group:get_group")(64)
    fresh = api("encctl_gym.crypto.group:generate_safe_prime_group")(64, rng=11)
    if (fresh.p, fresh.q, fresh.g) == (shipped.p, shipped.q, shipped.g):  # pragma: no cover
        raise NotApplicable("the fresh group equals the shipped one")
    return _keys(shipped, 3), _keys(fresh, 4)


def _cross_group_decrypt(_: Path) -> None:
    errors = api("encctl_gym.errors:KeyMismatchError")
    enc = api("encctl_gym.crypto.elgamal:encrypt")
    dec = api("encctl_gym.crypto.elgamal:decrypt")
    (pk_a, _), (_, sk_b) = _other_group_keys()
    src = _stream(5)

    @PROPERTY
    @given(st.integers(min_value=1, max_value=10**6))
    def prop(m: int) -> None:
        m2 = m * m % pk_a.group.p  # a quadratic residue: a member of G_a
        ct = enc(pk_a, m2, rng=src)
        try:
            out = dec(sk_b, ct)
        except errors:
            return
        raise SecurityFinding(f"decrypt under a key of another group returned {out} for a message of group A")

    prop()


def _refused(call: Any, finding: str) -> None:
    """``call()`` must raise KeyMismatchError; a result is a :class:`SecurityFinding`."""
    try:
        out = call()
    except api("encctl_gym.errors:KeyMismatchError"):
        return
    raise SecurityFinding(f"{finding} returned {out!r}")


def _cross_group_modified(_: Path) -> None:
    (pk_a, sk_a), (_, sk_b) = _other_group_keys()
    enc = api("encctl_gym.crypto.elgamal:encrypt")
    ct = api("encctl_gym.crypto.modified:modified_eval")(pk_a, enc(pk_a, 4, rng=_stream(1)), enc(pk_a, 9, rng=_stream(2)))
    _refused(
        lambda: api("encctl_gym.crypto.modified:modified_decrypt")(sk_a, sk_b, ct), "modified_decrypt with keys of two groups"
    )


def _cross_group_mult(_: Path) -> None:
    (pk_a, _), (pk_b, _) = _other_group_keys()
    enc = api("encctl_gym.crypto.elgamal:encrypt")
    _refused(
        lambda: api("encctl_gym.crypto.elgamal:mult")(pk_a, enc(pk_a, 4, rng=_stream(1)), enc(pk_b, 9, rng=_stream(2))),
        "mult of ciphertexts of two groups",
    )


def _cross_group_token(_: Path) -> None:
    (pk_a, sk_a), (pk_b, sk_b) = _other_group_keys()
    _, _, tok_b = api("encctl_gym.crypto.dyn_elgamal:key_update")(pk_b, sk_b, rng=_stream(3))
    _refused(
        lambda: api("encctl_gym.crypto.dyn_elgamal:recover_next_secret_key")(sk_a, tok_b),
        "recover_next_secret_key with a token of another group",
    )


def _seeded_secret_far_from_q(bits: int, seed: int) -> Any:
    def run(_: Path) -> None:
        keygen = api("encctl_gym.crypto.elgamal:keygen")
        pk, sk = keygen(bits, rng=seed)
        q = pk.group.q
        gap = min(sk.s, q - sk.s)
        if gap < 2 ** (bits // 2):
            raise SecurityFinding(
                f"keygen({bits}, rng={seed}): s is within {gap} of 0 or q: it follows from the public group by a short scan"
            )
        # the secret must not come from the same stream as the prime search either
        p_search = api("encctl_gym.crypto.group:generate_safe_prime_group")(bits, rng=seed)
        if abs(sk.s - p_search.q) < 2 ** (bits // 2) or abs(sk.s - p_search.p) < 2 ** (bits // 2):
            raise SecurityFinding("the secret key lies next to the seeded prime search's start")

    return run


def _related_seeds(_: Path) -> None:
    keygen = api("encctl_gym.crypto.elgamal:keygen")
    grp = api("encctl_gym.crypto.group:get_group")(64)
    ss = [keygen(grp, rng=seed)[1].s for seed in range(8)]
    for i in range(8):
        for j in range(i + 1, 8):
            d = abs(ss[i] - ss[j])
            if d < 2**32 or (ss[i] ^ ss[j]).bit_count() < 8:
                raise SecurityFinding(f"keygen with seeds {i} and {j} gives secret keys {d} apart")


def _enc_fresh_r(_: Path) -> None:
    """Two encryptions with one stream never share r; an int seed is refused, never repeated."""
    pk, _ = _keys(64, 2)
    enc = api("encctl_gym.crypto.elgamal:encrypt")
    errors = api("encctl_gym.errors:ParameterError")
    try:
        a, b = enc(pk, 4, rng=5), enc(pk, 9, rng=5)
    except errors:
        pass
    else:
        if a.c1 == b.c1 or a.c1 == pk.h:
            raise SecurityFinding("encrypt(pk, m, rng=5) twice repeats r: c1 is equal (or c1 = h)")
    src = _stream(5)
    cs = {enc(pk, 4, rng=src).c1 for _ in range(20)}
    if len(cs) != 20:
        raise SecurityFinding("one stream repeated r over 20 encryptions")


def _keygen_seed_vs_encrypt_seed(_: Path) -> None:
    """keygen(..., rng=5) then encrypt with seeded_random(5): r must not equal s (c1 = h)."""
    pk, _ = _keys(64, 5)
    ct = api("encctl_gym.crypto.elgamal:encrypt")(pk, 4, rng=_stream(5))
    if ct.c1 == pk.h:
        raise SecurityFinding("the seed of keygen reused by encrypt gives c1 = h: r = s")


def _generator_rng(_: Path) -> None:
    keygen = api("encctl_gym.crypto.elgamal:keygen")
    gen = np.random.default_rng(0)
    s1, s2 = keygen(64, rng=gen)[1].s, keygen(64, rng=gen)[1].s
    if s1 == s2:
        raise SecurityFinding("two keygen calls with one numpy Generator gave the same key")


def _secure_default(_: Path) -> None:
    keygen = api("encctl_gym.crypto.elgamal:keygen")
    if keygen(64)[1].s == keygen(64)[1].s:
        raise SecurityFinding("two keygen calls without rng gave the same key")


def _degenerate(cls: str, **fields: Any) -> Any:
    def run(_: Path) -> None:
        errors = api("encctl_gym.errors:EncctlError")
        try:
            obj = api(f"encctl_gym.crypto.elgamal:{cls}", "group")(group=api("encctl_gym.crypto.group:get_group")(64), **fields)
        except errors:
            return
        raise SecurityFinding(f"{cls}({fields}) is accepted: {obj!r}")

    return run


def _encrypt_under_h1(_: Path) -> None:
    errors = api("encctl_gym.errors:EncctlError")
    grp = api("encctl_gym.crypto.group:get_group")(64)
    try:
        pk = api("encctl_gym.crypto.elgamal:PublicKey")(grp, 1)
        ct = api("encctl_gym.crypto.elgamal:encrypt")(pk, 4, rng=_stream())
    except errors:
        return
    if ct.c2 == 4:
        raise SecurityFinding("encryption under h = 1 leaves the message in the clear (c2 = m)")


def _order2_generator(_: Path) -> None:
    errors = api("encctl_gym.errors:EncctlError")
    grp = api("encctl_gym.crypto.group:get_group")(64)
    try:
        api("encctl_gym.crypto.group:GroupParams")(grp.p, grp.q, grp.p - 1).verify()
    except errors:
        return
    raise SecurityFinding("g = p - 1 (order 2) passes verify()")


def _repr_hides_secret(_: Path) -> None:
    _, sk = _keys(64, 3)
    text = repr(sk) + str(sk)
    if str(sk.s) in text or hex(sk.s)[2:] in text:
        raise SecurityFinding("repr of a secret key shows s")


def _server_holds_no_secret(_: Path) -> None:
    """The modified scheme's server holds public keys and ciphertexts only."""
    ctl = api("encctl_gym.crypto.controller:EncryptedLinearController")(
        np.array([[-0.3, -0.1], [0.05, -0.2]]), 64, 256.0, 10.0, rng=1
    )
    server = getattr(ctl, "server", None)
    if server is None:
        raise NotApplicable("no controller.server")
    sk_cls = api("encctl_gym.crypto.elgamal:SecretKey")
    rs_cls = api("encctl_gym.crypto.arith:RandomSource")
    found = _walk(server, (sk_cls, rs_cls))
    if found:
        raise SecurityFinding(f"the modified scheme's server holds {found[:3]}")


def _walk(root: Any, classes: tuple[type, ...], limit: int = 20000) -> list[str]:
    """Paths from ``root`` to objects of ``classes`` through attributes, slots, lists, tuples, dicts."""
    seen: set[int] = set()
    found: list[str] = []
    todo = [(root, "root")]
    while todo and len(seen) < limit:
        obj, path = todo.pop()
        if (
            id(obj) in seen
            or isinstance(obj, (str, bytes, int, float, complex, np.ndarray, type))
            or callable(obj)
            and not hasattr(obj, "__dict__")
        ):
            continue
        seen.add(id(obj))
        if obj is not root and isinstance(obj, classes):
            found.append(f"{path}: {type(obj).__name__}")
            continue
        children: list[tuple[Any, str]] = []
        if isinstance(obj, dict):
            children = [(v, f"{path}[{k!r}]") for k, v in obj.items()]
        elif isinstance(obj, (list, tuple, set, frozenset)):
            children = [(v, f"{path}[{i}]") for i, v in enumerate(obj)][:200]
        else:
            if type(obj).__module__.split(".")[0] not in ("encctl_gym", "agents", "builtins", "numpy") and not isinstance(
                obj, classes
            ):
                continue
            for slot in getattr(type(obj), "__slots__", ()):
                if hasattr(obj, slot):
                    children.append((getattr(obj, slot), f"{path}.{slot}"))
            for k, v in getattr(obj, "__dict__", {}).items():
                children.append((v, f"{path}.{k}"))
        todo.extend(children)
    return found


def _forgery_masks(_: Path) -> None:
    """With per_entry=True no two forged entries share randomness (the known entries do not reveal the mask)."""
    forge = api("encctl_gym.attacks.forgery:forge_injection", "per_entry")
    pk, _ = _keys(64, 3)
    enc = api("encctl_gym.crypto.encoding:Encoder")(pk.group, 256.0)
    out = forge(pk, pk, np.array([0.5, -0.25]), enc, 3, rng=_stream(4), per_entry=True)
    pairs = [(ct.c1, ct.c2) for row in out for ct in row]
    if len(set(pairs)) != len(pairs):
        raise SecurityFinding("forge_injection(per_entry=True) reuses randomness between entries")


def _forgery_documented(_: Path) -> None:
    doc = api("encctl_gym.attacks.forgery:forge_injection").__module__
    text = (__import__(doc, fromlist=["_"]).__doc__ or "").lower()
    if "who reads" not in text and "who may see" not in text:
        raise SecurityFinding("the forgery's documentation does not say who can read a forged injection")


def _security() -> list[Case]:
    S = "security"
    out = [
        case(A, "decrypt under a key of another group (property)", S, _cross_group_decrypt, expect="result"),
        case(A, "modified_decrypt with keys of two groups", S, _cross_group_modified, expect="result"),
        case(A, "mult of ciphertexts of two groups", S, _cross_group_mult, expect="result"),
        case(A, "recover_next_secret_key with a token of another group", S, _cross_group_token, expect="result"),
        case(A, "keygen seeds 0..7 give unrelated keys", S, _related_seeds, expect="result"),
        case(A, "encrypt never repeats r", S, _enc_fresh_r, expect="result"),
        case(A, "keygen seed reused by encrypt", S, _keygen_seed_vs_encrypt_seed, expect="result"),
        case(A, "keygen with one numpy Generator twice", S, _generator_rng, expect="result"),
        case(A, "keygen without rng is secure and fresh", S, _secure_default, expect="result"),
        case(A, "degenerate SecretKey(s=0) refused", S, _degenerate("SecretKey", s=0), expect="result"),
        case(A, "degenerate PublicKey(h=1) refused", S, _degenerate("PublicKey", h=1), expect="result"),
        case(A, "encrypt under h = 1", S, _encrypt_under_h1, expect="result"),
        case(A, "GroupParams with a generator of order 2", S, _order2_generator, expect="result"),
        case(A, "repr of a secret key", S, _repr_hides_secret, expect="result"),
        case(A, "the modified scheme's server holds no secret", S, _server_holds_no_secret, expect="result"),
        case(A, "forged entries with per_entry=True share no randomness", S, _forgery_masks, expect="result", owner="lead"),
        case(A, "the forgery's docs say who can read a forged injection", S, _forgery_documented, expect="result", owner="lead"),
    ]
    for bits in (80, 96):
        for seed in (0, 1, 2):
            out.append(
                case(
                    A,
                    f"keygen({bits}, rng={seed}): s far from q and the prime search",
                    S,
                    _seeded_secret_far_from_q(bits, seed),
                    expect="result",
                )
            )
    for seed in (0, 1):
        out.append(
            case(
                A,
                f"keygen(300, rng={seed}): s far from q and the prime search",
                S,
                _seeded_secret_far_from_q(300, seed),
                expect="result",
                slow=True,
            )
        )
    return out


def _more() -> list[Case]:
    """Cases of the same classes found beyond the issue's reproducers: values shown in messages
    (an integer over 4300 digits makes ``repr`` raise), helpers without type checks, flags that
    took any truthy value, and an encoder that could never encode."""
    out: list[Case] = []
    enc = "encctl_gym.crypto.encoding"
    grp = Lazy(lambda: api("encctl_gym.crypto.group:get_group")(64), "<64-bit group>")
    out += bad_args(
        A,
        f"{enc}:nearest_member",
        {"group": grp, "v": 5, "max_shift": 64},
        {
            "group": explicit(["abc", 64, None], "traceback"),
            "v": explicit([2.5, "5", None, True]),
            "max_shift": explicit([-1, 2.5, "a"], "traceback"),
        },
        drawn=0,
    )
    out += bad_args(
        A,
        f"{enc}:lift",
        {"group": grp, "m": 5},
        {"group": explicit(["abc", None], "traceback"), "m": explicit([2.5, "5", None], "traceback")},
        drawn=0,
    )
    out += bad_args(A, f"{enc}:default_max_shift", {"group": grp}, {"group": explicit(["abc", 64, None], "traceback")}, drawn=0)
    out += bad_args(
        A,
        f"{enc}:Encoder",
        {"group": grp, "delta": 1024.0},
        {"max_shift": explicit([2**63, HUGE], "silent")},
        name="Encoder(no x_bound)",
        drawn=0,
    )

    def group_method(name: str) -> Any:
        def call(kw: dict[str, Any]) -> Any:
            return getattr(api("encctl_gym.crypto.group:get_group")(64), name)(**kw)

        return call

    out += bad_args(
        A,
        group_method("contains"),
        {"m": 4},
        {"m": explicit(["4", 2.5, None, [4]], "traceback")},
        name="GroupParams.contains",
        drawn=0,
    )
    out += bad_args(
        A,
        group_method("verify"),
        {"recheck": False},
        {"recheck": explicit(["no", 1, None, [True]])},
        name="GroupParams.verify(recheck)",
        drawn=0,
    )
    out += bad_args(
        A,
        "encctl_gym.crypto.group:generate_safe_prime_group",
        {"bits": 32, "rng": 1},
        {"progress": explicit(["no", 2, None])},
        name="generate_safe_prime_group.progress",
        drawn=0,
    )
    gp = "encctl_gym.crypto.group:GroupParams"
    out += bad_args(
        A,
        lambda kw: api(gp + ".load")(**kw),
        {"path": "g.json"},
        {"path": explicit([42, None, ["g.json"], HUGER], "traceback")},
        name="GroupParams.load(path)",
        drawn=0,
    )
    out += bad_args(
        A,
        lambda kw: api(gp + ".from_dict")(**kw),
        {"data": {"p": 23, "q": 11, "g": 4}},
        {"data": explicit([np.array([23, 11, 4]), HUGER], "traceback")},
        name="GroupParams.from_dict(array)",
        drawn=0,
    )
    # values beyond the int-to-str limit, shown in a message
    eg = "encctl_gym.crypto.elgamal"
    out += bad_args(
        A,
        f"{eg}:encrypt",
        {"pk": PK, "m": 4, "rng": Lazy(_stream, "<stream>")},
        {"pk": explicit([HUGER], "traceback")},
        name="encrypt(huge pk)",
        drawn=0,
    )
    out += bad_args(
        A,
        "encctl_gym.crypto.schemes:get_scheme",
        {"name": "modified"},
        {"name": explicit([HUGER], "traceback")},
        name="get_scheme(huge)",
        drawn=0,
    )
    out += bad_args(
        A,
        lambda kw: _stream().spawn(**kw),
        {"purpose": "x"},
        {"purpose": explicit([HUGER, None], "traceback")},
        name="RandomSource.spawn",
        drawn=0,
    )
    out += bad_args(
        A,
        "encctl_gym.crypto.quantized:QuantizedLinearController",
        {"Phi": np.eye(2), "encoder": ENCODER, "x_bound": 10.0},
        {"encoder": explicit([HUGER], "traceback")},
        name="QuantizedLinearController(huge encoder)",
        drawn=0,
    )

    def server_call(method: str, scheme: str = "modified") -> Any:
        def call(kw: dict[str, Any]) -> Any:
            c = api("encctl_gym.crypto.controller:EncryptedLinearController")(
                np.eye(2) * 0.1, 64, 256.0, 10.0, scheme=scheme, rng=1
            )
            return getattr(c.server, method)(**kw)

        return call

    out += bad_args(
        A,
        server_call("evaluate"),
        {"ct_xi": None},
        {"ct_xi": explicit([42, 2.5, HUGER], "traceback")},
        name="server.evaluate",
        drawn=0,
    )
    out += bad_args(
        A,
        server_call("receive_token", "token"),
        {"token": None},
        {"token": explicit([HUGER, "abc"], "traceback")},
        name="server.receive_token",
        drawn=0,
    )
    return out


def _valid() -> list[Case]:
    """Valid inputs with known answers (a broken happy path is a silent wrong number)."""

    def roundtrip(_: Path) -> None:
        pk, sk = _keys(64, 1)
        src = _stream(2)
        for m in (1, 4, 9, 16, 2**40 % pk.group.p):
            mm = m * m % pk.group.p
            got = api("encctl_gym.crypto.elgamal:decrypt")(sk, api("encctl_gym.crypto.elgamal:encrypt")(pk, mm, rng=src))
            assert got == mm, (m, got)

    def toy_group(_: Path) -> None:
        grp = api("encctl_gym.crypto.group:GroupParams")(23, 11, 4).verify()
        assert grp.bits == 5 and grp.contains(4) and not grp.contains(5)

    def encode_decode(_: Path) -> None:
        e = api("encctl_gym.crypto.encoding:Encoder")(api("encctl_gym.crypto.group:get_group")(64), 1024.0)
        for x in (0.0, 1.5, -2.25, 7.0):
            assert abs(e.decode(e.encode(x)) - x) <= e.error_bound() + 1e-12, x

    def shipped(_: Path) -> None:
        for bits in api("encctl_gym.crypto.group:SHIPPED_BITS"):
            grp = api("encctl_gym.crypto.group:shipped_group")(bits)
            assert grp.bits == bits and grp.p == 2 * grp.q + 1

    def controller_matches_reference(_: Path) -> None:
        c = api("encctl_gym.crypto.controller:EncryptedLinearController")(
            np.array([[-0.3, -0.1], [0.05, -0.2]]), 64, 256.0, 10.0, rng=1
        )
        x = np.array([1.0, -2.0])
        assert np.array_equal(c.step(x), c.reference(x))

    return [
        case(A, "valid: encrypt/decrypt round trip", "silent", roundtrip, expect="result"),
        case(A, "valid: toy group (23, 11, 4)", "silent", toy_group, expect="result"),
        case(A, "valid: encode/decode within the error bound", "silent", encode_decode, expect="result"),
        case(A, "valid: shipped groups are safe primes of their size", "silent", shipped, expect="result"),
        case(
            A,
            "valid: the encrypted controller equals its plaintext twin",
            "silent",
            controller_matches_reference,
            expect="result",
        ),
    ]


def cases() -> list[Case]:
    """Every crypto case."""
    return [*_arith(), *_group(), *_encoding(), *_elgamal(), *_dynamic(), *_controller(), *_more(), *_security(), *_valid()]


_ = FILES, HUGER  # re-exported names used by other case modules
