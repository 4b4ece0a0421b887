"""tools/prune_ff.py: a denoiser's attention feed-forward cut to its strongest hidden units,
written as a checkpoint that `train --init` and the loaders take like any other."""

from __future__ import annotations

import sys

import pytest
import torch

from tests.conftest import REPO

sys.path.insert(0, str(REPO / "tools"))


def _small_motion_mamba():
    from motion_core.models.denoisers import MotionMambaConfig
    from motion_core.models.latent_denoisers import build_denoiser
    from motion_core.nn.ssm import SSMConfig

    cfg = MotionMambaConfig(
        latent_tokens=6,
        z_width=16,
        frames_per_token=4,
        levels=1,
        htm_ssm=SSMConfig(expand=0.5, d_state=2),
        bsm_ssm=SSMConfig(expand=1.0, d_state=2),
        ff=64,
    )
    torch.manual_seed(0)
    return cfg, build_denoiser("motion_mamba", cfg).eval()


def test_units_that_carry_nothing_are_the_ones_dropped_and_the_call_is_unchanged():
    import prune_ff

    from motion_core.models.latent_denoisers import build_denoiser, config_from_dict

    cfg, den = _small_motion_mamba()
    dead = torch.arange(0, 64, 2)  # half the units: their output weights are zero
    with torch.no_grad():
        den.body.mid.linear2.weight[:, dead] = 0.0
    state = {k: v.clone() for k, v in den.state_dict().items()}
    pruned, kept = prune_ff.prune_state(state, 32)
    assert kept == {"body.mid": pytest.approx(1.0)}
    assert pruned["body.mid.linear1.weight"].shape == (32, 256)
    # the live units, in their order
    assert torch.equal(pruned["body.mid.linear1.weight"], state["body.mid.linear1.weight"][1::2])
    small = build_denoiser("motion_mamba", config_from_dict("motion_mamba", {**cfg.to_dict(), "ff": 32})).eval()
    small.load_state_dict(pruned)
    g = torch.Generator().manual_seed(1)
    args = (torch.randn(2, 6, 16, generator=g), torch.tensor([10, 700]), torch.randn(2, 384, generator=g))
    with torch.no_grad():
        assert torch.allclose(small(*args, torch.tensor([24, 12])), den(*args, torch.tensor([24, 12])), atol=1e-5)


def test_the_cli_writes_a_loadable_checkpoint_that_records_its_origin(tmp_path):
    import prune_ff

    from motion_core.inference.checkpoints import load_denoiser, read_float32, ship, weights_fingerprint

    cfg, den = _small_motion_mamba()
    src = tmp_path / "motion_mamba.pt"
    ship(src, den, {"kind": "motion_mamba", "config": cfg.to_dict(), "steps": 123})
    out = tmp_path / "pruned.pt"
    prune_ff.main(["--checkpoint", str(src), "--ff", "16", "--out", str(out)])
    ck = read_float32(out)
    assert ck["meta"]["config"]["ff"] == 16 and ck["meta"]["steps"] == 123
    record = ck["meta"]["pruned"]
    assert record["from"] == "motion_mamba.pt" and record["ff_from"] == 64 and record["ff"] == 16
    assert record["fingerprint"] == weights_fingerprint(read_float32(src)["state_dict"])
    assert 0.25 < record["score_kept"]["body.mid"] < 1.0
    net = load_denoiser(ck, "motion_mamba")
    assert net.body.mid.linear1.out_features == 16
    assert ck["meta"]["params"] == sum(p.numel() for p in net.parameters())
    # a second cut keeps the first in its record
    again = tmp_path / "again.pt"
    prune_ff.main(["--checkpoint", str(out), "--ff", "8", "--out", str(again)])
    second = read_float32(again)["meta"]["pruned"]
    assert (second["ff_from"], second["ff"], second["earlier"]["ff"]) == (16, 8, 16)
    with pytest.raises(SystemExit, match="cannot keep 128"):
        prune_ff.main(["--checkpoint", str(src), "--ff", "128", "--out", str(tmp_path / "x.pt")])
    with pytest.raises(SystemExit, match="at least 1"):
        prune_ff.main(["--checkpoint", str(src), "--ff", "0", "--out", str(tmp_path / "x.pt")])
