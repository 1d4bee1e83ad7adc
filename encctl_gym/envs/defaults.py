"""Every key of the attack environment's configuration and its default (:func:`default_config`).

Following HighwayEnv, every knob lives in one dictionary, documented once here; the user's
``config`` and keyword arguments are merged with it and resolved into
:class:`~encctl_gym.envs.config.AttackParams` by :func:`~encctl_gym.envs.config.resolve_params`.

============================  ==============================================================
key                           meaning
============================  ==============================================================
``preset``                    system preset (:mod:`encctl_gym.presets`); ``None`` needs A, B
``A``, ``B``                  plant matrices of eq:system (override the preset's)
``sigma_w2``                  process noise variance (preset's if ``None``)
``sigma_x2``                  variance of x_0 (preset's if ``None``; the paper uses 1)
``sigma_u2``                  attacker's average input power per channel (energy budget)
``scheme``                    ``"modified"`` (the paper's), ``"token"``, ``"static"``, any
                              row of :data:`encctl_gym.loop.scheme.SCHEMES`, or
                              ``{"name": ..., **options}``
``adversary``                 ``"eavesdropper"`` or ``"server"``
``security_parameter``        lambda in bits; ``None``: from ``key_length``, else lambda* of
                              Theorem thm:opt_sec for the preset's design parameters
``key_length``                key length k in bits (lambda = log2 Omega(k), eq:opt_key);
                              for ``scheme="lwe"`` the dimension n of the secret
``deciphering_model``         what breaking the keys costs: a model of the scheme's ``cost_models``
                              (``None``: its ``baseline_model``); ElGamal's
                              (:mod:`encctl_gym.security.cost_models`):
                              ``"paper"`` (def:sdt: ``2^lambda`` per key), ``"precomputation"``
                              (one GNFS precomputation per group, then a cheap step per key),
                              ``"generic"`` (Pollard rho per key); LWE's: ``"core-svp"``,
                              ``"core-svp-quantum"``, ``"core-svp-plausible"`` (primal uSVP)
``breaker``                   ``None`` (the break is simulated: the plant's key of the period
                              is read) or a key breaker of :mod:`encctl_gym.cryptanalysis`
                              (``"index-calculus"``, ``"pari"``, ``"rho-multi"``, ...): every
                              key paid for is broken for real and the states are decrypted
                              with the recovered exponents only; needs ``crypto="elgamal"``
                              and a group the breaker can break (the loop's group has
                              64 bits for ``key_length <= 64``: index calculus and PARI
                              break it in about 0.5 s, then about 1 ms resp. 0.1 s per key);
                              with ``scheme="paillier"`` a factorer (``"ecm"``,
                              ``"rho-factor"``, ``"p-1"``, ``"pari-factor"``) factors each
                              modulus met and decrypts with the recovered key (``lwe``: no
                              breaker in the environment yet, refused by name)
``breaker_precomputation``    ``None`` or a file saved by ``encctl-gym crack
                              --save-precomputation`` (the index calculus's factor base
                              of the loop's group, checked against it): the breaker loads
                              it instead of precomputing (needs
                              ``breaker="index-calculus"``); the time charged for the
                              precomputation is still the file's
``breaker_time_limit``        seconds (or a duration) the breaker may take for its
                              precomputation and for each key; a breaker expected to take
                              longer is refused when the environment is made
``deciphering_clock``         ``"model"``: the time charged is the cost model's tau(N)
                              (deterministic, also with a breaker: the same numbers as
                              without); ``"measured"``: the wall seconds the breaker took on
                              this machine (not reproducible across machines; needs a
                              breaker and ``max_samples``; the episode terminates when the
                              time passes ``tau_c``)
``gnfs_correction``           o(1) correction of the GNFS cost in bits (0: the paper's; the
                              documented alternative ``"guillevic"``, 11.91)
``upsilon``, ``tau_c``        attacker FLOPS and defense period in s or a duration such as
                              ``"10y"`` (preset's if ``None``)
``gamma_c``                   acceptable error, used for the default lambda*
``max_samples``               cap on the attack length N (truncation); required when one
                              break reveals every sample (static; token vs server);
                              ``None``: N is what the budget buys within ``tau_c``, at most
                              ``MAX_DEFAULT_HORIZON`` = 2^20 (then truncated, with a warning)
``decipher_delay``            0 (adaptive), an integer number of steps, or ``"end"``
``warmup_steps``              steps of normal encrypted LQR control before the attack
``estimator``                 the attacker's identification method behind ``info["epsilon"]``
                              and the ``log_error`` reward: ``"ls"`` (least squares,
                              eq:estimate; compiled), ``"bayes"``, ``"forgetting"``,
                              ``"iv"``, or ``{"name": ..., **parameters}``
                              (:mod:`encctl_gym.ident`)
``reward``                    ``"log_error"``, ``"logdet"`` or ``"a_optimality"``
                              (:mod:`encctl_gym.envs.rewards`)
``logdet_regularization``     delta of ``G + delta I`` in the Gram-matrix rewards
                              (``logdet``, ``a_optimality``)
``crypto``                    ``"ideal"`` (exact arithmetic, no big integers) or ``"elgamal"``
``delta``                     encoder scaling factor Delta (Definition def:ec), an integer
                              in 2 .. 2^53
``x_bound``                   declared state range of the encoder (overflow raises); the
                              ideal backend tabulates |round(Delta v)| up to 2^24
                              (``MAX_TABLE_LIMIT``): Delta * max(x_bound, u_max) must stay below
``action_scale``              actuator bound in units of sigma_u: a = action * scale * sigma_u
``input_history``             number of own past inputs in the observation (at most 64)
``gamma_opt``                 compute gamma_opt(N) of the optimal attack design for info
``crypto_seed``               seed of the crypto randomness (``None``: secure source)
``defender``                  the plant side's policy (:mod:`encctl_gym.loop.defender`): a
                              name of ``DEFENDERS`` (``"fixed"``: the paper's fixed defender)
                              or an object implementing ``DefenderPolicy``
``audit_probability``         ``None`` or ``p`` in [0, 1]: the plant side audits the decoded
                              input against its own ``Phi x`` with probability ``p`` per
                              step (:class:`~encctl_gym.loop.defenses.AuditDefender`, added
                              to ``defender``)
``defense_noise_sigma2``      ``None`` or ``sigma_d2 >= 0``: the plant side adds
                              ``N(0, sigma_d2 I)`` to its input every step
                              (:class:`~encctl_gym.loop.defenses.NoiseDefender`, added to
                              ``defender``)
``rotate_group_every``        ``None`` (one group) or ``K >= 1``: every K attack steps the
                              plant side moves to a fresh safe-prime group of the same size
                              and re-provisions the server (:mod:`encctl_gym.loop.rotation`);
                              the attacker pays each group's precomputation
                              (:mod:`encctl_gym.security.rotation`)
``observe``                   ``"state"`` (the paper's: the plant sends ``x``) or
                              ``"output"``: the plant sends ``y = C x + v``, the loop runs
                              on outputs and the attacker deciphers outputs only
                              (:mod:`encctl_gym.envs.output_episode`)
``C``, ``sigma_v2``           sensors and measurement noise of ``observe="output"``
                              (preset's, else ``C = I`` and ``sigma_v2 = 0``); ``(A, C)``
                              observable
``controller``                the loop's controller on outputs
                              (:mod:`encctl_gym.loop.output_feedback`): ``"static"``
                              (``u = Phi y``) or ``"lqg"`` (observer-based, dynamic)
``injection``                 how the action enters the loop (:mod:`encctl_gym.loop.injection`):
                              ``"replace"`` (the forgery of def:adversary replaces ``Phi x``),
                              ``"add"`` (the server's honest ``Phi x`` plus the action: what the
                              scheme makes the adversary break for it, e.g. ``sk_0`` and the
                              period's key on ElGamal, needs ``decipher_delay = 0``) or
                              ``"pass"`` (the honest loop; the action is unused)
============================  ==============================================================
"""

from __future__ import annotations

from typing import Any

__all__ = ["default_config"]


def default_config() -> dict[str, Any]:
    """Every parameter of ``EncryptedLTIAttack-v0`` with its default (the keys are documented in
    the module docstring's table)."""
    return {
        "preset": "paper-example",
        "A": None,
        "B": None,
        "sigma_w2": None,
        "sigma_x2": None,
        "sigma_u2": None,
        "scheme": "modified",
        "adversary": "eavesdropper",
        "security_parameter": None,
        "key_length": None,
        "deciphering_model": None,
        "gnfs_correction": 0.0,
        "breaker": None,
        "breaker_time_limit": 60.0,
        "breaker_precomputation": None,
        "deciphering_clock": "model",
        "upsilon": None,
        "tau_c": None,
        "gamma_c": None,
        "max_samples": None,
        "decipher_delay": 0,
        "warmup_steps": 0,
        "estimator": "ls",
        "reward": "log_error",
        "logdet_regularization": 1.0,
        "crypto": "ideal",
        "delta": 4096,
        "x_bound": 256.0,
        "action_scale": 4.0,
        "input_history": 2,
        "gamma_opt": True,
        "crypto_seed": None,
        "defender": "fixed",
        "audit_probability": None,
        "defense_noise_sigma2": None,
        "rotate_group_every": None,
        "observe": "state",
        "C": None,
        "sigma_v2": None,
        "controller": "static",
        "injection": "replace",
    }
