"""The benchmark command's report, at a tiny size (its figures come from the full command)."""

from __future__ import annotations

import pytest

from motion_core.eval.bench import bench_generate


@pytest.mark.long
def test_bench_reports_latency_timeline_params_flops_and_memory():
    rates = {"sgemm_gflops": 50.0, "exp_per_ns": 2.0}  # as machine() records them: the floors follow from them
    both = bench_generate(
        ["baseline", "kmm", "baseline:fast"], frames=40, steps=2, repeats=3, timeline_repeats=1, rates=rates
    )
    out = both["baseline"]
    keys = ("median_ms", "p90_ms", "timeline_10s_median_ms", "timeline_30s_median_ms", "timeline_30s_p90_ms")
    for key in (*keys, "peak_rss_mib_after"):
        assert out[key] > 0, key
        assert both["kmm"][key] > 0, key
    # KMM counts its generator and its own tokeniser, not the diffusion VAE
    assert both["kmm"]["vae_params"] != out["vae_params"] and both["kmm"]["speedup_vs_baseline"] > 0
    assert 1e6 < out["denoiser_params"] < 2e7 and out["vae_params"] > 1e5
    # a fast row counts the network its sampler runs: the student, its w-embedding with it
    from motion_core.inference.registry import load_method

    student = load_method("baseline").student
    assert both["baseline:fast"]["denoiser_params"] == sum(p.numel() for p in student.parameters())
    assert both["baseline:fast"]["denoiser_params"] > out["denoiser_params"]
    assert out["gflops_per_motion_second"] > 0
    # the FLOP floor: the arithmetic at this machine's measured sgemm rate, and the run's time
    # over it (not asserted above 1: with other jobs on the machine the sgemm probe can run
    # slower than the bench, which happened once while two training jobs ran beside)
    assert out["flop_floor_ms"] > 0
    assert abs(out["times_flop_floor"] - out["median_ms"] / out["flop_floor_ms"]) < 1e-9 * out["times_flop_floor"]
    # the scans' state updates, apart from the FLOPs: none in the transformer, some in KMM's
    # generator; the floor adds them at the machine's exp rate
    assert out["scan_updates_per_motion_second"] == 0 == out["scan_floor_ms"]
    assert abs(out["times_floor"] - out["times_flop_floor"]) < 1e-9 * out["times_floor"]
    k = both["kmm"]
    assert k["scan_updates_per_motion_second"] > 0
    assert k["flop_floor_ms"] == pytest.approx(1e3 * k["gflops_per_motion_second"] * 2.0 / 50.0)
    assert k["scan_floor_ms"] == pytest.approx(1e3 * k["scan_updates_per_motion_second"] * 2.0 / 2e9)
    floor = k["flop_floor_ms"] + k["scan_floor_ms"]
    assert abs(k["times_floor"] - k["median_ms"] / floor) < 1e-9 * k["times_floor"]


def _updates_per_pass(den, rows: int) -> int:
    """A Motion Mamba denoiser's scan state updates in one pass of ``rows`` samples: every
    SSM's k scans x B x L x E x N, L being the latent and prefix tokens in HTM and the d
    channels in BSM (told apart by where the SSM sits)."""
    from motion_core.nn.ssm import SelectiveSSM

    d, tokens = den.head.in_features, den.n_z + 2
    return sum(
        s.k * rows * (d if ".bsm." in name else tokens) * s.d_inner * s.cfg.d_state
        for name, s in den.named_modules()
        if isinstance(s, SelectiveSSM)
    )


def test_scan_updates_of_a_generation_follow_its_network_and_steps():
    """Motion Mamba's state updates per generation: every SSM of its denoiser, B x L x E x N
    per scan (E its expanded width, L its tokens or, in BSM, its channels), for each of its
    guided DDIM steps (a batch of two); the student's sampler makes one pass of one per
    step. The baseline has no scan."""
    from motion_core.eval.bench import work_per_second_of_motion
    from motion_core.inference.registry import load_method

    per_pass = _updates_per_pass(load_method("motion_mamba").denoiser, 1)
    assert per_pass > 0
    seconds, steps = 2.0, 1
    _, quality = work_per_second_of_motion("motion_mamba", seconds, steps, "quality")
    _, fast = work_per_second_of_motion("motion_mamba", seconds, steps, "fast")
    assert quality * seconds == steps * 2 * per_pass
    assert fast * seconds == steps * per_pass
    assert work_per_second_of_motion("baseline", seconds, steps, "quality")[1] == 0


def test_batch_bench_times_each_batch_size_per_motion():
    from motion_core.eval.bench import bench_batch

    out = bench_batch(["baseline", "kmm"], batches=(1, 3), frames=40, steps=3, device="cpu", repeats=1)
    assert out["device"] == "cpu" and out["frames"] == 40
    for m in ("baseline", "kmm"):
        rows = out["by_method"][m]
        assert set(rows) == {"1", "3"}
        for b, row in rows.items():
            assert row["median_ms"] > 0 and row["peak_memory_mib"] > 0
            assert abs(row["ms_per_motion"] * int(b) - row["median_ms"]) < 1e-6
            assert abs(row["motions_per_s"] - 1e3 / row["ms_per_motion"]) < 1e-6


def test_kmm_flops_do_not_follow_the_scans_chunk_size(monkeypatch):
    # the chunked scan's cumulative sums are matmuls sized by the chunk length the weights
    # allow; a model's FLOP figure must not move with them (it read 0.068, then 0.063)
    from motion_core.eval.bench import flops_per_second_of_motion
    from motion_core.nn import ssm

    counts = []
    for k in (4, 16):
        monkeypatch.setattr(ssm, "chunk_size_for", lambda delta, A, limit=None, k=k: k)
        counts.append(flops_per_second_of_motion("kmm", seconds=4.0))
    assert counts[0] == counts[1] > 0


@pytest.mark.long
def test_op_counts_and_per_step_costs():
    import torch

    from motion_core.eval.bench import bench_ops, count_ops, machine

    x = torch.randn(8, 8)
    ops = count_ops(lambda: torch.relu(x @ x + 1))
    assert ops["top_level_ops"] == 3 and ops["aten_ops"] >= 3
    assert machine()["sgemm_gflops"] > 0.1
    # rows are keyed by what ran: "motion_mamba" is its guided DDIM, as the baseline's
    out = bench_ops(["baseline", "motion_mamba:quality"], frames=40, steps=(2, 4), repeats=1)
    for m in ("baseline", "motion_mamba"):
        assert out[m]["steps_compared"] == [2, 4]
        assert out[m]["top_level_ops_per_step"] > 10 and out[m]["ops_per_step"] >= out[m]["top_level_ops_per_step"]
        assert out[m]["ms_per_step"] != 0
    # the Mamba U-Net dispatches more ops per step than the fused transformer layers
    assert out["motion_mamba"]["top_level_ops_per_step"] > out["baseline"]["top_level_ops_per_step"]


@pytest.mark.long
def test_op_counts_of_a_student_compare_steps_it_takes():
    """Motion Mamba's shipped student takes 1-5 steps: the default pair (4, 8) is halved to
    (2, 4) for it instead of failing on 8. A guided step runs its pair as one batch of two,
    so a student step (one pass of one, plus its scale embedding) dispatches about as many ops."""
    from motion_core.eval.bench import bench_ops

    out = bench_ops(["motion_mamba:fast", "motion_mamba:quality"], frames=40, repeats=1)
    assert out["motion_mamba:fast"]["steps_compared"] == [2, 4]
    assert out["motion_mamba"]["steps_compared"] == [4, 8]  # "quality" is written as the bare name
    fast, quality = (out[k]["top_level_ops_per_step"] for k in ("motion_mamba:fast", "motion_mamba"))
    assert 0 < fast and abs(fast - quality) < 0.1 * quality


def test_flops_count_the_transformer_layers_that_run_fused_at_inference():
    """Under no_grad a TransformerEncoderLayer runs as one fused op the FLOP counter missed:
    the baseline's call counted 15 of its 260 MFLOP. Lower bound: every guided DDIM step
    is a batch of two, and each of its latent tokens passes every layer's four weight
    matrices (2 FLOP a weight)."""
    import torch

    from motion_core.eval.bench import flops_per_second_of_motion
    from motion_core.inference.registry import load_method

    m = load_method("baseline")
    per_token = sum(
        2 * p.numel()
        for layer in m.denoiser.modules()
        if isinstance(layer, torch.nn.TransformerEncoderLayer)
        for p in layer.parameters()
        if p.dim() == 2
    )
    assert per_token > 0
    steps, seconds = 2, 4.0
    at_least = steps * 2 * m.vae.latent_shape[0] * per_token
    assert flops_per_second_of_motion("baseline", seconds=seconds, steps=steps) * seconds >= at_least
    assert torch.backends.mha.get_fastpath_enabled()  # put back for everything after the count


@pytest.mark.long  # a timing
def test_a_denoiser_call_is_timed_part_by_part():
    """bench --blocks: Motion Mamba's call split into its shell, its HTM and BSM blocks (each
    with the fused SSM kernel it ran), its attention mixer and skip fusions; FTMoMamba's
    kernels run inside its FreqSSM and TextSSM and are found there too; KMM has no call."""
    from motion_core.eval.bench import bench_blocks

    out = bench_blocks(["motion_mamba", "kmm", "ftmomamba"], frames=40, repeats=1)
    assert list(out) == ["motion_mamba", "ftmomamba"]
    mm = out["motion_mamba"]
    assert mm["latent_tokens"] == 10 and mm["call_ms"] > 0
    types = [r["type"] for r in mm["parts"]]
    assert types.count("HTM") == types.count("BSM") == 6 and types.count("TransformerEncoderLayer") == 1
    assert {"cond", "head", "body.enc.0.htm", "body.enc.0.bsm", "body.mid", "body.fuse.0"} <= {
        r["part"] for r in mm["parts"]
    }
    for r in mm["parts"]:
        assert r["ms"] > 0
        # every Mamba block's one kernel call is timed, and nothing else has one
        assert r.get("fused_ssm_calls", 0) == (1 if r["type"] in ("HTM", "BSM") else 0)
    assert mm["fused_ssm_calls"] == 12
    assert mm["fused_ssm_ms"] == pytest.approx(sum(r.get("fused_ssm_ms", 0) for r in mm["parts"]))
    assert mm["other_ms"] == pytest.approx(mm["call_ms"] - mm["parts_ms"])
    # the call's scan work: its twelve blocks' scans at the guided pair's batch of two, all
    # of them in its kernels; the call with the kernels' outputs given, timed on its own
    from motion_core.inference.registry import load_method
    from motion_core.nn import ssm, ssm_fused

    updates = _updates_per_pass(load_method("motion_mamba").denoiser, 2)
    assert mm["state_updates"] == updates
    assert mm["fused_ssm_ns_per_update"] == pytest.approx(1e6 * mm["fused_ssm_ms"] / updates)
    assert mm["call_without_kernels_ms"] > 0
    assert ssm.fused_ssm is ssm_fused.fused_ssm  # put back after timing without it
    ftm = out["ftmomamba"]
    blocks = [r for r in ftm["parts"] if r["type"] == "FTMambaBlock"]
    assert blocks and all(r["fused_ssm_calls"] >= 2 and r["fused_ssm_ms"] > 0 for r in blocks)
