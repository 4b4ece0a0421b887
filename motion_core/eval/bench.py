"""Speed measurements, printed as JSON.

    python -m motion_core.eval bench                 # per method: 196 frames and a 30 s timeline
    python -m motion_core.eval bench --scans         # selective-scan implementations, d_inner 512, d_state 16
    python -m motion_core.eval bench --batch 1,32    # 196 frames for 1 and 32 prompts sampled as one batch
    python -m motion_core.eval bench --ops           # torch ops and ms per sampling step, per method
    python -m motion_core.eval bench --blocks --frames 200   # one guided denoiser call, part by part

On a machine with a CUDA GPU the plain command also times every method on the GPU at
batch 1 and 32 (``--device`` picks another device, ``--device cpu`` the CPU only).

Every figure is a median over repeated runs in this one process, after warm-up, so the
methods are compared on the same machine state.
"""

from __future__ import annotations

import argparse
import functools
import json
import os
import platform
import statistics
import time
from collections.abc import Callable

import torch


def timed(fn: Callable[[], object], repeats: int, warmup: int = 2) -> list[float]:
    """Wall-clock seconds of ``repeats`` calls after ``warmup`` calls."""
    for _ in range(warmup):
        fn()
    out = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t0)
    return out


def machine() -> dict:
    return {
        "python": platform.python_version(),
        "torch": torch.__version__,
        "threads": torch.get_num_threads(),
        "cpus": os.cpu_count(),
        "cuda": torch.cuda.get_device_name(0) if torch.cuda.is_available() else None,
        "sgemm_gflops": sgemm_gflops(),
        "exp_per_ns": exp_rate() / 1e9,
    }


def sgemm_gflops(n: int = 512, repeats: int = 20) -> float:
    """This machine's float32 matrix-multiply rate on torch's current threads (GFLOP/s,
    median of ``repeats`` n x n products): the yardstick of the FLOP floor."""
    a, b = torch.randn(n, n), torch.randn(n, n)
    times = timed(lambda: a @ b, repeats, warmup=3)
    return 2 * n**3 / statistics.median(times) / 1e9


def count_ops(fn: Callable[[], object]) -> dict:
    """torch ops of one call of ``fn`` (torch profiler): every aten op, and those called
    from Python or an autograd function rather than from inside another aten op (the
    dispatches the interpreter pays for one by one)."""
    from torch.profiler import ProfilerActivity, profile

    with profile(activities=[ProfilerActivity.CPU]) as prof:
        fn()
    aten = [e for e in prof.events() if e.name.startswith("aten::")]
    top = [e for e in aten if e.cpu_parent is None or not e.cpu_parent.name.startswith("aten::")]
    return {"aten_ops": len(aten), "top_level_ops": len(top)}


def bench_ops(methods: list[str], frames: int = 196, steps: tuple[int, int] = (4, 8), repeats: int = 7) -> dict:
    """Per method, the cost of one sampling step (a guided denoiser call, or one of KMM's
    decoding passes): ops and milliseconds of ``generate`` at two step counts, differenced,
    so text encoding, decoding and the join drop out. One ``frames``-long segment, no foot
    lock; ops of one call, ms the difference of medians."""
    from ..inference.generation import generate, method_spec, row_name
    from ..inference.registry import load_method, sampler_options

    text = BENCH_TEXT
    out: dict = {}
    for spec in methods:
        m, sampler = method_spec(spec)
        method = load_method(m)
        # a student takes fewer steps than the pair compared (Motion Mamba's 1-5): halve the
        # pair until it fits, so its per-step cost is measured too
        lo, hi = steps
        top = sampler_options(method.info)[sampler]["max_steps"]
        while hi > top and lo > 1:
            lo, hi = max(1, lo // 2), max(2, hi // 2)

        def run(k: int, m: str = m, sampler: str = sampler) -> None:
            generate([(text, frames / 20.0)], method=m, seed=0, steps=k, foot_lock=False, sampler=sampler)

        run(lo)  # warms the text encoder's caches: counted once, they would not drop out
        ops = {k: count_ops(lambda k=k: run(k)) for k in (lo, hi)}
        ms = {k: 1e3 * statistics.median(timed(lambda k=k: run(k), repeats)) for k in (lo, hi)}
        out[row_name(m, sampler)] = row = {
            "sampler": sampler,
            "ops_per_step": (ops[hi]["aten_ops"] - ops[lo]["aten_ops"]) / (hi - lo),
            "top_level_ops_per_step": (ops[hi]["top_level_ops"] - ops[lo]["top_level_ops"]) / (hi - lo),
            "ms_per_step": (ms[hi] - ms[lo]) / (hi - lo),
            "ms_fixed": ms[lo] - lo * (ms[hi] - ms[lo]) / (hi - lo),
            "steps_compared": [lo, hi],
        }
        row["us_per_top_level_op"] = 1e3 * row["ms_per_step"] / max(row["top_level_ops_per_step"], 1)
    return out


def _holds_ssm(module: torch.nn.Module) -> bool:
    from ..nn.ssm import SelectiveSSM

    return any(isinstance(m, SelectiveSSM) for m in module.modules())


def _call_blocks(den: torch.nn.Module) -> list[tuple[str, torch.nn.Module]]:
    """The parts one denoiser call is timed in: the shell's own layers (conditioning, input
    and output projections), the body's list entries (encoder and decoder blocks, skip
    fusions, transformer layers) and its other children (a mid block). An entry made of
    several SSM-holding parts (Motion Mamba's level: HTM then BSM) is split into them."""
    parts: list[tuple[str, torch.nn.Module]] = []
    for name, child in den.named_children():
        if name != "body":
            parts.append((name, child))
    body = den.body
    for name, child in body.named_children():
        entries = list(child.named_children()) if isinstance(child, torch.nn.ModuleList) else [("", child)]
        for sub, module in entries:
            full = f"body.{name}" + (f".{sub}" if sub else "")
            holders = [(n, c) for n, c in module.named_children() if _holds_ssm(c)]
            if len(holders) >= 2 and len(holders) == len(list(module.children())):
                parts.extend((f"{full}.{n}", c) for n, c in holders)
            else:
                parts.append((full, module))
    return parts


def guided_call_args(den: torch.nn.Module, frames: int) -> tuple:
    """The inputs of one guided denoiser call (the guided pair, batch 2) on a ``frames``-long
    latent: (z, t, text, frames), seeded; a temporal latent is zero past the clip's tokens."""
    fpt = den.frames_per_token
    tokens = min(den.n_z, -(-frames // fpt)) if fpt else den.n_z
    g = torch.Generator().manual_seed(0)
    z = torch.randn(2, den.n_z, den.head.out_features, generator=g)
    z[:, tokens:] = 0
    return z, torch.full((2,), 500), torch.randn(2, 384, generator=g), torch.full((2,), tokens * fpt or frames)


def bench_blocks(methods: list[str], frames: int = 196, repeats: int = 50) -> dict:
    """Where one guided denoiser call goes (the guided pair: batch 2, a ``frames``-long
    latent), per latent diffusion method: the whole call's median ms, then each part of it
    (``_call_blocks``) timed alone on the input it got in that call, and within each part
    the fused SSM kernels it ran (``ssm_fused``: Conv1D, projections, softplus, decays, scan,
    mix and gate), each timed alone on its own arguments. Under ``no_grad`` as the samplers
    run, no hooks while timing; "other_ms" is the call less its parts (the glue between
    them: concatenations, residual adds, Python). A part is timed on the first input it got:
    one called twice in a call is refused rather than half measured."""
    from ..inference.registry import load_method
    from ..nn import ssm as ssm_module
    from ..nn.ssm_fused import fused_ssm

    out: dict = {}
    for name in methods:
        den = getattr(load_method(name), "denoiser", None)
        if den is None:
            continue  # KMM: no denoiser call
        args = guided_call_args(den, frames)
        tokens = int(args[3][0]) // den.frames_per_token if den.frames_per_token else den.n_z
        parts = _call_blocks(den)
        seen: dict[int, list] = {}
        kernels: dict[int, tuple] = {}  # id(ssm) -> (ssm, args, kwargs) of the kernel calls it made

        def keep(module, a, kw, seen=seen):
            seen.setdefault(id(module), []).append((a, kw))

        def record(ssm, *a, kernels=kernels, **kw):
            if id(ssm) in kernels:
                raise RuntimeError(f"{type(ssm).__name__} ran its kernel twice in one call: bench --blocks times one")
            kernels[id(ssm)] = (ssm, a, kw)
            return fused_ssm(ssm, *a, **kw)

        hooks = [m.register_forward_pre_hook(keep, with_kwargs=True) for _, m in parts]
        ssm_module.fused_ssm = record  # the kernel calls the SSMs make, wherever they make them
        try:
            with torch.no_grad():
                den(*args)
        finally:
            ssm_module.fused_ssm = fused_ssm
            for h in hooks:
                h.remove()
        for pname, part in parts:
            if len(seen.get(id(part), ())) != 1:
                raise RuntimeError(
                    f"{pname} ran {len(seen.get(id(part), ()))} times in one call: bench --blocks times once"
                )
        with torch.no_grad():
            call = 1e3 * statistics.median(timed(lambda den=den, args=args: den(*args), repeats))
            rows = []
            for pname, part in parts:
                ((a, kw),) = seen[id(part)]
                row = {
                    "part": pname,
                    "type": type(part).__name__,
                    "ms": 1e3 * statistics.median(timed(lambda p=part, a=a, kw=kw: p(*a, **kw), repeats)),
                }
                inside = {id(m) for m in part.modules()}
                ran = [k for key, k in kernels.items() if key in inside]
                if ran:
                    row["fused_ssm_ms"] = sum(
                        1e3 * statistics.median(timed(lambda k=k: fused_ssm(k[0], *k[1], **k[2]), repeats)) for k in ran
                    )
                    row["fused_ssm_calls"] = len(ran)
                rows.append(row)
            with ssm_module.counted_state_updates() as updates:
                den(*args)
            # the call with each kernel replaced by the output it gave: what the rest of the
            # network costs on its own, measured (the call less its kernels timed alone, with
            # warm caches, is off by as much as "other_ms" is)
            outs = {key: fused_ssm(k[0], *k[1], **k[2]) for key, k in kernels.items()}
            ssm_module.fused_ssm = lambda ssm, *a, outs=outs, **kw: outs[id(ssm)]
            try:
                without = 1e3 * statistics.median(timed(lambda den=den, args=args: den(*args), repeats))
            finally:
                ssm_module.fused_ssm = fused_ssm
        parts_ms = sum(r["ms"] for r in rows)
        kernels_ms = sum(r.get("fused_ssm_ms", 0.0) for r in rows)
        # the kernels' own updates (B x L x k x E x N each): the ones the call counted, unless
        # some scan of it ran unfused
        kernel_updates = sum(
            a[0].shape[0] * a[0].shape[1] * s.k * s.d_inner * s.cfg.d_state for s, a, _ in kernels.values()
        )
        out[name] = {
            "latent_tokens": tokens,
            "call_ms": call,
            "parts": rows,
            "parts_ms": parts_ms,
            "fused_ssm_ms": kernels_ms,
            "fused_ssm_calls": len(kernels),
            "other_ms": call - parts_ms,
            # the scans' work (state updates: B x L x D x N a scan, ``ssm.counted_state_updates``)
            # and what the kernels take a unit of theirs; and the call without its kernels, what
            # the rest of the network (in- and out-projections, norms, mixer, glue) costs alone
            "state_updates": updates[0],
            "fused_ssm_ns_per_update": 1e6 * kernels_ms / kernel_updates if kernel_updates else None,
            "call_without_kernels_ms": without,
        }
    return out


def bench_scans(lengths=(2, 16, 64, 196), batches=(1, 32), d_inner=512, d_state=16, repeats=3) -> list[dict]:
    """Forward and forward+backward time of each scan at the given lengths and batches."""
    from ..nn.ssm import SCANS, selective_scan

    rows = []
    g = torch.Generator().manual_seed(0)
    for bsz in batches:
        for L in lengths:
            u = torch.randn(bsz, L, d_inner, generator=g)
            delta = torch.nn.functional.softplus(torch.randn(bsz, L, d_inner, generator=g) - 3)
            A = -torch.arange(1, d_state + 1, dtype=torch.float32).repeat(d_inner, 1)
            Bm = torch.randn(bsz, L, 1, d_state, generator=g)
            Cm = torch.randn(bsz, L, 1, d_state, generator=g)
            D = torch.ones(d_inner)
            row: dict = {"batch": bsz, "L": L}
            args = (u, delta, A, Bm, Cm, D)
            for impl in SCANS:
                with torch.no_grad():
                    fwd = timed(lambda impl=impl, args=args: selective_scan(*args, impl=impl), repeats)
                leaves = [t.clone().requires_grad_() for t in (u, delta, Bm, Cm)]

                def step(impl=impl, leaves=leaves, A=A, D=D):
                    selective_scan(leaves[0], leaves[1], A, leaves[2], leaves[3], D, impl=impl).sum().backward()

                # backward at the largest sizes takes tens of seconds: one warm run, one timed
                both = timed(step, 1, warmup=1)
                row[impl] = {"fwd_ms": 1e3 * statistics.median(fwd), "fwd_bwd_ms": 1e3 * statistics.median(both)}
            row["fastest_fwd"] = min(SCANS, key=lambda s: row[s]["fwd_ms"])
            rows.append(row)
    return rows


# the single-segment request every latency row times
BENCH_TEXT = "a person walks forward and waves with the right hand"
TIMELINE_10S = [("a person walks forward", 5.0), ("a person waves with the right hand", 5.0)]
TIMELINE_30S = [("a person walks forward", 10.0), ("a person turns left", 10.0), ("a person waves", 10.0)]


def _pct(times: list[float], q: float) -> float:
    return 1e3 * sorted(times)[max(0, round(q * len(times)) - 1)]


def flops_per_second_of_motion(
    method: str, seconds: float = 9.8, steps: int | None = None, sampler: str | None = None
) -> float:
    """FLOPs of one generation divided by the seconds of motion it makes (``work_per_second_of_motion``'s first)."""
    return work_per_second_of_motion(method, seconds, steps, sampler)[0]


def work_per_second_of_motion(
    method: str, seconds: float = 9.8, steps: int | None = None, sampler: str | None = None
) -> tuple[float, float]:
    """(FLOPs, scan state updates) of one generation, each divided by the seconds of motion
    it makes. FLOPs as torch's FlopCounterMode counts them (matmuls, convolutions,
    attention). The selective scans run as the element-wise loop here (``forced_scan``),
    which the counter does not see, so the FLOPs are the same whatever the weights (the
    chunked scan's cumulative-sum matmuls would follow the weights' chunk sizes), and the
    scans are counted apart, as state updates (``ssm.counted_state_updates``: B x L x D x N
    a scan, at least one decay exp and one multiply-add each).
    The prompt is encoded first, so the text encoder (cached per prompt, and the same for every
    method) is never counted; it used to be, only when the cache was cold.

    Transformer layers are counted with their inference fast path off: under ``no_grad`` an
    ``nn.TransformerEncoderLayer`` runs as one fused op the counter does not see: until
    2026-11-26 the baseline's denoiser call counted 15 of its 260 MFLOP, and Motion Mamba's
    175 of 257 (its middle layer). The fused op does the same arithmetic, so the count stands for it."""
    from torch.utils.flop_counter import FlopCounterMode

    from ..inference.generation import generate
    from ..nn.ssm import counted_state_updates, forced_scan
    from ..nn.text import get_text_encoder

    get_text_encoder().encode([prompt := "a person walks forward", ""])
    fastpath = torch.backends.mha.get_fastpath_enabled()
    torch.backends.mha.set_fastpath_enabled(False)
    try:
        with forced_scan("sequential"), counted_state_updates() as updates, FlopCounterMode(display=False) as counter:
            generate([(prompt, seconds)], method=method, seed=0, steps=steps, sampler=sampler)
    finally:
        torch.backends.mha.set_fastpath_enabled(fastpath)
    return counter.get_total_flops() / seconds, updates[0] / seconds


def exp_rate(n: int = 1 << 16, repeats: int = 50) -> float:
    """This machine's float32 exp rate (elements per second, median of ``repeats`` passes
    over an ``n``-element buffer that stays in cache): the compiled kernels' vectorised exp
    (``kernel_math``, one thread) where numba imports, torch's on its current threads
    otherwise. Every state update of a selective scan takes at least one such exp, its
    decay exp(delta_t A_n), so this is the yardstick of the scans' floor as sgemm is of the
    matmuls'. Like the sgemm rate it is this machine's one-thread figure when the bench
    runs on one torch thread, as its tables are made; the scan floor is not a bound for
    runs on more threads."""
    import numpy as np

    from ..nn import numba_kernels

    buf = np.linspace(-8.0, 0.0, n, dtype=np.float32)
    if numba_kernels.available():
        from ..nn.kernel_math import CONSTANTS, _exp_inplace

        k32, c = np.empty(n, np.int32), CONSTANTS[np.dtype(np.float32)]
        # in place, pass after pass: the values climb to the clamp, which costs what any value does
        times = timed(lambda: _exp_inplace(buf, k32, c), repeats, warmup=3)
    else:
        x = torch.from_numpy(buf)
        out = torch.empty_like(x)
        times = timed(lambda: torch.exp(x, out=out), repeats, warmup=3)
    return n / statistics.median(times)


def bench_generate(
    methods: list[str],
    frames: int = 196,
    steps: int | None = None,
    repeats: int = 7,
    timeline_repeats: int | None = None,
    rates: dict | None = None,
) -> dict:
    """Latency of ``generate`` per method: one ``frames``-long segment, a 10 s timeline (two
    5 s segments) and a 30 s timeline (three 10 s segments); parameters, FLOPs per generated
    second, peak memory. ``steps`` None: each method's own default (registry);
    ``timeline_repeats``: timed runs of each timeline (default ``repeats`` for 10 s, half
    of it, at least 3, for 30 s). ``rates``: the yardsticks of the floors, ``machine()``'s
    ``sgemm_gflops`` and ``exp_per_ns``, so that a report's floors follow from the rates
    it records (measured here when not given)."""
    import resource

    from ..inference.generation import generate, method_spec, row_name
    from ..inference.registry import load_method

    out: dict = {}
    text = BENCH_TEXT
    seconds = frames / 20.0
    rates = rates or {"sgemm_gflops": sgemm_gflops(), "exp_per_ns": exp_rate() / 1e9}
    sgemm, exps = rates["sgemm_gflops"], 1e9 * rates["exp_per_ns"]
    for spec in methods:
        m, sampler = method_spec(spec)
        model = load_method(m)  # checkpoint load is not part of generation latency
        run = functools.partial(generate, method=m, seed=0, steps=steps, sampler=sampler)
        times = timed(lambda run=run: run([(text, seconds)]), repeats)
        times10 = timed(lambda run=run: run(TIMELINE_10S), timeline_repeats or repeats, warmup=1)
        times30 = timed(
            lambda run=run: run(TIMELINE_30S),
            timeline_repeats or max(3, repeats // 2),
            warmup=1,
        )
        autoencoder_params = model.autoencoder_params()
        flops, updates = work_per_second_of_motion(m, seconds, steps, sampler)
        out[row_name(m, sampler)] = {
            "sampler": sampler,
            "median_ms": 1e3 * statistics.median(times),
            "p90_ms": _pct(times, 0.9),
            "runs": len(times),
            "timeline_10s_median_ms": 1e3 * statistics.median(times10),
            "timeline_10s_p90_ms": _pct(times10, 0.9),
            "timeline_30s_median_ms": 1e3 * statistics.median(times30),
            "timeline_30s_p90_ms": _pct(times30, 0.9),
            "denoiser_params": model.denoiser_params(sampler),
            "vae_params": autoencoder_params,
            "gflops_per_motion_second": (gfps := flops / 1e9),
            # the arithmetic alone at this machine's sgemm rate, and how far the run is from it
            "flop_floor_ms": (floor := 1e3 * gfps * seconds / sgemm),
            "times_flop_floor": 1e3 * statistics.median(times) / floor,
            # the scans' state updates, which the FLOPs leave out, at one exp each; with the
            # matmuls' floor, how far the run is from this machine's arithmetic, scans included
            "scan_updates_per_motion_second": updates,
            "scan_floor_ms": (scan_floor := 1e3 * updates * seconds / exps),
            "times_floor": 1e3 * statistics.median(times) / (floor + scan_floor),
            # process-wide peak resident memory so far (Linux reports KiB)
            "peak_rss_mib_after": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
        }
    if "baseline" in out:
        for m in out:
            if m != "baseline":
                out[m]["speedup_vs_baseline"] = out["baseline"]["median_ms"] / out[m]["median_ms"]
    return out


BATCH_TEXTS = [
    "a person walks forward",
    "a person waves with the right hand",
    "a person runs forward",
    "a person turns left",
    "a person jumps up",
    "a person raises both arms",
    "a person walks backwards",
    "a person kicks with the left leg",
]


def _peak_memory_mib(dev: torch.device) -> float:
    if dev.type == "cuda":
        return torch.cuda.max_memory_allocated(dev) / 2**20
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # process-wide, KiB on Linux


def bench_batch(
    methods: list[str],
    batches: tuple[int, ...] = (1, 32),
    frames: int = 196,
    steps: int | None = None,
    device: torch.device | str = "cpu",
    repeats: int = 5,
) -> dict:
    """Latency of ``generate_batch``: ``b`` different prompts of ``frames`` frames sampled as
    one batch on ``device``, for each b in ``batches``; per batch, per motion, motions per
    second and peak memory (the GPU's allocator peak for that batch; on the CPU the
    process's peak RSS so far)."""
    from ..inference.generation import generate_batch, method_spec, row_name
    from ..inference.registry import load_method

    dev = torch.device(device)
    out: dict = {}
    used: dict[str, str] = {}
    for spec in methods:
        m, sampler = method_spec(spec)
        load_method(m, dev)
        rows = {}
        for b in batches:
            texts = [BATCH_TEXTS[i % len(BATCH_TEXTS)] for i in range(b)]
            if dev.type == "cuda":
                torch.cuda.reset_peak_memory_stats(dev)
            # fewer repeats for big batches on a CPU (a batch of 32 takes tens of seconds there)
            reps = repeats if dev.type != "cpu" or b <= 4 else max(1, repeats // 2)
            times = timed(
                lambda m=m, texts=texts, s=sampler: generate_batch(
                    texts, frames / 20.0, m, seed=0, steps=steps, device=dev, sampler=s
                ),
                reps,
                warmup=1,
            )
            med = statistics.median(times)
            rows[str(b)] = {
                "median_ms": 1e3 * med,
                "p90_ms": _pct(times, 0.9),
                "runs": len(times),
                "ms_per_motion": 1e3 * med / b,
                "motions_per_s": b / med,
                "peak_memory_mib": _peak_memory_mib(dev),
            }
        out[row_name(m, sampler)] = rows
        used[row_name(m, sampler)] = sampler
    steps_used = steps or "method default"
    return {"device": str(dev), "frames": frames, "steps": steps_used, "by_method": out, "samplers": used}


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(prog="python -m motion_core.eval bench", description=__doc__.splitlines()[0])
    ap.add_argument("--scans", action="store_true", help="time the selective-scan implementations")
    ap.add_argument("--methods", default="motion_mamba,kmm,ftmomamba,baseline")
    ap.add_argument("--frames", type=int, default=196)
    ap.add_argument("--steps", type=int, default=None, help="sampling steps (default: each method's own)")
    ap.add_argument("--repeats", type=int, default=None, help="timed runs per figure (default 7; --blocks 50)")
    ap.add_argument(
        "--batch", default=None, help="only the batch benchmark, at these batch sizes (e.g. 1,32), on --device"
    )
    ap.add_argument("--device", default=None, help="device of the batch benchmark (default: cuda when present)")
    ap.add_argument("--ops", action="store_true", help="only ops and ms per sampling step (torch profiler)")
    ap.add_argument(
        "--blocks", action="store_true", help="only where one guided denoiser call goes, part by part (of --frames)"
    )
    args = ap.parse_args(argv)
    if not args.blocks:
        args.repeats = args.repeats or 7
    methods = args.methods.split(",")
    device = args.device or ("cuda" if torch.cuda.is_available() else "cpu")
    result: dict = {"machine": machine()}
    if args.scans:
        result["scans"] = bench_scans()
    elif args.ops:
        result["ops"] = bench_ops(methods, args.frames, repeats=args.repeats)
    elif args.blocks:
        # a part takes a millisecond or two: more runs than a whole motion's 7
        result["blocks"] = bench_blocks(methods, args.frames, repeats=args.repeats or 50)
    elif args.batch:
        sizes = tuple(int(b) for b in args.batch.split(","))
        result["batch"] = bench_batch(methods, sizes, args.frames, args.steps, device, min(args.repeats, 5))
    else:
        result["generate"] = bench_generate(methods, args.frames, args.steps, args.repeats, rates=result["machine"])
        result["settings"] = {"frames": args.frames, "steps": args.steps or "method default", "guidance": True}
        if device != "cpu":
            result["batch"] = bench_batch(methods, (1, 32), args.frames, args.steps, device, min(args.repeats, 5))
    print(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
