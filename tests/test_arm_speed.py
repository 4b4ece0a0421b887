"""tools/arm_speed.py: one guided call of Motion Mamba's architecture arms, timed against the
baseline's in the same rounds, each arm built from the shipped config as `train --set` would."""

from __future__ import annotations

import json
import sys

from tests.conftest import REPO

sys.path.insert(0, str(REPO / "tools"))


def test_arms_are_the_shipped_config_changed_and_read_as_ratios_to_the_baseline(tmp_path):
    import arm_speed

    out = tmp_path / "arms.json"
    arm_speed.main(["--arm", "one=levels=1,bsm_ssm.expand=1", "--rounds", "2", "--repeats", "1", "--out", str(out)])
    rows = json.loads(out.read_text())["rows"]
    assert list(rows) == ["baseline", "motion_mamba", "motion_mamba[one]"]
    assert rows["baseline"]["x_baseline_per_round"] == [1.0, 1.0]
    arm, shipped = rows["motion_mamba[one]"], rows["motion_mamba"]
    assert arm["set"] == ["levels=1", "bsm_ssm.expand=1"] and arm["weights"] == "fresh"
    assert len(arm["ms_per_round"]) == 2 and all(r > 0 for r in arm["x_baseline_per_round"])
    # one level of HTM + BSM instead of three: fewer parameters and matmul FLOPs than shipped
    assert arm["params"] < shipped["params"] and 0 < arm["mflop"] < shipped["mflop"]
