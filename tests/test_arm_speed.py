"""tools/arm_speed.py: one guided call of Motion Mamba's architecture arms, timed against the
baseline's in the same rounds, each arm built from the shipped config as `train --set` would."""

from __future__ import annotations

import json
import sys

import torch

from tests.conftest import REPO

sys.path.insert(0, str(REPO / "tools"))


def test_arms_are_the_shipped_config_changed_and_read_as_ratios_to_the_baseline(tmp_path):
    import arm_speed

    threads = torch.get_num_threads()
    out = tmp_path / "arms.json"
    arm_speed.main(["--arm", "one=levels=1,bsm_ssm.expand=1", "--rounds", "2", "--repeats", "1", "--out", str(out)])
    rows = json.loads(out.read_text())["rows"]
    assert list(rows) == ["baseline", "motion_mamba", "motion_mamba[fresh]", "motion_mamba[one]"]
    assert len(rows["baseline"]["ms_per_round"]) == 2 * 3  # once before each of the three others, twice
    assert rows["motion_mamba[fresh]"]["mflop"] == rows["motion_mamba"]["mflop"]
    arm, shipped = rows["motion_mamba[one]"], rows["motion_mamba"]
    assert arm["set"] == ["levels=1", "bsm_ssm.expand=1"] and arm["weights"] == "fresh"
    assert len(arm["ms_per_round"]) == 2 and all(r > 0 for r in arm["x_baseline_per_round"])
    # one level of HTM + BSM instead of three: fewer parameters and matmul FLOPs than shipped
    assert arm["params"] < shipped["params"] and 0 < arm["mflop"] < shipped["mflop"]
    torch.set_num_threads(threads)


def test_the_flop_count_sees_an_ssm_state_change():
    """The fused SSM kernel does its projections out of the counter's sight: the count runs
    the scans as the plain loop, so a smaller state counts fewer FLOPs."""
    import arm_speed

    from motion_core.eval.bench import guided_call_args
    from motion_core.inference.checkpoints import WEIGHTS, read_float32
    from motion_core.models.latent_denoisers import build_denoiser, config_from_dict
    from motion_core.models.overrides import override_config

    cfg = config_from_dict("motion_mamba", read_float32(WEIGHTS / "motion_mamba.pt")["meta"]["config"])
    counts = []
    for sets in ([], ["htm_ssm.d_state=4"]):
        den = build_denoiser("motion_mamba", override_config(cfg, sets)).eval()
        counts.append(arm_speed.call_mflop(den, guided_call_args(den, 196)))
    assert counts[1] < counts[0]
