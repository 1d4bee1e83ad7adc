"""``encctl-gym crack --scheme paillier``: factor the moduli of N rotated Paillier keys and time each.

Usage::

    encctl-gym crack --scheme paillier --bits 96 --keys 4 [--breaker ecm] [--json]
                     [--seed S] [--time-limit T] [--max-seconds S] [--max-bits B]

The keys are ``--keys`` independent seeded KeyGens of ``--bits``-bit moduli (a fresh modulus per
key, as under rotation; reproducible, unsafe for deployment). The factorer (default ``ecm``;
:data:`~.factoring_registry.FACTORERS`) factors each; every factorisation is checked
(``p q = n``), the secret key rebuilt and checked by decrypting, and compared with the key
generated. The expected time (the factorer's cost model, ``keys`` times one modulus: nothing is
shared between moduli) is printed first and a job above ``--max-seconds`` is refused in one line
before any work, as for ElGamal.
"""

from __future__ import annotations

import argparse
import json
import sys

from .._validation import check_int, check_positive
from ..crypto import arith
from ..errors import BreakerError, ParameterError
from .base import format_seconds
from .factoring_registry import FACTORERS, get_factorer
from .keys import check_keys
from .paillier_keys import break_paillier_sequence, paillier_key_sequence

__all__ = ["run_paillier", "DEFAULT_FACTORER"]

#: The factorer of ``crack --scheme paillier`` without ``--breaker``.
DEFAULT_FACTORER = "ecm"


def run_paillier(args: argparse.Namespace, max_seconds_default: float) -> int:
    """Build the key sequence, factor every modulus, print the table (or JSON)."""
    name = DEFAULT_FACTORER if args.breaker is None else args.breaker
    if name not in FACTORERS:
        raise ParameterError(f"--scheme paillier needs a factoring breaker ({', '.join(FACTORERS)}), got {name!r}")
    for option, default in (("save_precomputation", None), ("load_precomputation", None), ("scheduler", None)):
        if getattr(args, option, default) is not None:
            raise ParameterError(f"--{option.replace('_', '-')} is not available with --scheme paillier")
    if args.time_limit is not None:
        check_positive("--time-limit", args.time_limit)
    n = check_keys(args.keys, "--keys")
    seed = check_int("--seed", args.seed, minimum=0)
    bits = check_int("--bits", args.bits, minimum=16, maximum=8192)
    kwargs = {"rng": arith.seeded_random(seed + 2)}
    if args.max_bits is not None:
        kwargs["max_bits"] = args.max_bits
    factorer = get_factorer(name, **kwargs)
    max_seconds = check_positive("--max-seconds", max_seconds_default if args.max_seconds is None else args.max_seconds)
    advice = "raise --max-seconds, or use fewer --keys, a smaller --bits or another --breaker"
    per_key, total = factorer.check_time(bits, max_seconds, keys=n, limit_name="--max-seconds", advice=advice)
    print(
        f"crack: {factorer.name} on {n} fresh {bits}-bit Paillier moduli: expected about {format_seconds(total)} on this "
        f"machine ({format_seconds(per_key)} per modulus; nothing is shared between moduli)",
        file=sys.stderr if args.json else sys.stdout,
        flush=True,
    )
    keys = paillier_key_sequence(bits, n, arith.seeded_random(seed + 1))
    report = break_paillier_sequence(
        factorer, [pk for pk, _ in keys], time_limit=args.time_limit, rng=arith.seeded_random(seed + 3)
    )
    for (_, sk), got in zip(keys, report.keys):
        if (got.secret.p, got.secret.q) != tuple(sorted((sk.p, sk.q))) or got.secret.lam != sk.lam:
            raise BreakerError("a recovered Paillier key differs from the generated one")  # pragma: no cover
    t = report.key_seconds()
    if args.json:
        out = report.to_dict()
        out.update({"scheme": "paillier", "keys_match": True, "mean_key": float(t.mean()), "total": float(t.sum())})
        print(json.dumps(out, indent=1))
        return 0
    print(f"crack: {factorer.name} on {n} Paillier keys of {bits}-bit moduli (a fresh modulus per key)")
    print(f"{'t':>5}  {'seconds':>12}  {'cpu seconds':>12}  operations")
    for i, key in enumerate(report.keys):
        cost = key.factorization.cost
        ops = " ".join(f"{k}={v}" for k, v in cost.operations.items()) or "-"
        print(f"{i:>5}  {cost.seconds:12.6f}  {cost.cpu_seconds:12.6f}  {ops}")
    print(f"mean per key = {format_seconds(float(t.mean()))}, total = {format_seconds(float(t.sum()))}")
    print(f"all {n} moduli factored (p q = n), every key checked by decrypting and equal to the generated key")
    return 0
