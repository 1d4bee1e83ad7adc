"""The measured defences through real ElGamal with a real breaker (experiments.defenses_elgamal):
the backends agree episode by episode, one precomputation per group and episode, one key broken
per sample; a learned attacker against every defender; refused options."""

from __future__ import annotations

import pytest

from encctl_gym.experiments.defenses import main
from encctl_gym.experiments.defenses_elgamal import ars_rows, elgamal_rows, format_elgamal
from encctl_gym.experiments.defenses_measured import MEASURED_DEFENDERS, format_measured


@pytest.mark.slow
def test_the_elgamal_table_on_a_small_plant_counts_one_key_per_sample_and_matches_the_ideal_backend():
    episodes, samples = 2, 20
    rows = elgamal_rows("small", samples=samples, episodes=episodes, attackers=("gaussian",))
    assert [r["elgamal"]["defender"] for r in rows] == [label for label, _ in MEASURED_DEFENDERS]
    for r in rows:
        e = r["elgamal"]
        assert r["same_as_ideal"] == episodes  # same seeds: the same detections and samples on both backends
        assert r["precomputations"] == episodes  # one group per episode, its precomputation charged once
        # the modified scheme changes the key every step: one key broken per sample collected
        assert r["keys"] == r["samples_total"]
        assert e["samples_median"] <= samples
    by = {r["elgamal"]["defender"]: r["elgamal"] for r in rows}
    assert by["none"]["detection_rate"] == 0.0 and by["none"]["time_ratio"] == 1.0
    assert by["chi2, W = 10, 1e-4 per step"]["detection_rate"] == 1.0  # every step injects
    assert format_elgamal(rows).count("\n") == len(rows) + 1


@pytest.mark.slow
def test_a_learned_attacker_plays_against_every_defender(tmp_path):
    pytest.importorskip("sb3_contrib")
    from encctl_gym.agents.config import load_config
    from encctl_gym.agents.train import train

    run = train(load_config("ars", "small", quick=True), out=tmp_path, progress=False, tensorboard=False)
    rows = ars_rows(run, "small", episodes=1, max_samples=30)
    assert [r["defender"] for r in rows] == [label for label, _ in MEASURED_DEFENDERS]
    assert all(r["attacker"] == "ars" and r["samples_median"] <= 30 for r in rows)
    assert rows[0]["detection_rate"] == 0.0
    assert format_measured(rows).count("\n") == len(rows) + 1


@pytest.mark.parametrize(
    "argv, text", [(["--elgamal", "--elgamal-samples", "3"], "--elgamal-samples"), (["--ars", "no/such/run"], "no/such/run")]
)
def test_bad_options_exit_2_with_one_line(argv, text, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert text in err and "\n" not in err
