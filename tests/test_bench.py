"""The benchmark command's report, at a tiny size (its figures come from the full command)."""

from __future__ import annotations

from motion_core.bench import bench_generate


def test_bench_reports_latency_timeline_params_flops_and_memory():
    both = bench_generate(["baseline", "kmm"], frames=40, steps=5, repeats=1, timeline_repeats=1)
    out = both["baseline"]
    keys = ("median_ms", "p90_ms", "timeline_10s_median_ms", "timeline_30s_median_ms", "timeline_30s_p90_ms")
    for key in (*keys, "peak_rss_mib_after"):
        assert out[key] > 0, key
        assert both["kmm"][key] > 0, key
    # KMM counts its generator and its own tokeniser, not the diffusion VAE
    assert both["kmm"]["vae_params"] != out["vae_params"] and both["kmm"]["speedup_vs_baseline"] > 0
    assert out["timeline_30s_median_ms"] > out["median_ms"]  # 600 frames take longer than 40
    assert 1e6 < out["denoiser_params"] < 2e7 and out["vae_params"] > 1e5
    assert out["gflops_per_motion_second"] > 0
