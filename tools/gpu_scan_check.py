"""On a GPU: the fused Triton scan against the reference loop (values and gradients), and
the forward + backward time of each GPU scan at the shapes the shipped denoisers scan.

    python tools/gpu_scan_check.py --out results/scan_check_gpu_h200.json

The CPU tests run the same kernels in Triton's interpreter (tests/test_scan_triton.py);
this is the compiled kernel on the device.
"""

from __future__ import annotations

import argparse
import json
import time

import torch

from motion_core.nn.scan_triton import scan_triton
from motion_core.nn.ssm import scan_chunked, scan_sequential

# (B, L, D, N, G, per_step): Motion Mamba's HTM (3 scans batched) and BSM, FTMoMamba's FreqSSM,
# at training batch 256
SHAPES = {
    "motion_mamba_htm": (256, 52, 640, 8, 5, False),
    "motion_mamba_bsm": (256, 256, 208, 4, 2, False),
    "ftmomamba_freq": (256, 52, 512, 8, 2, True),
}


def _inputs(bsz, L, d, n, g, per_step, dev, seed=0, decay=0.5, steep=False):
    gen = torch.Generator().manual_seed(seed)
    u = torch.randn(bsz, L, d, generator=gen)
    delta = torch.rand(bsz, L, d, generator=gen) * decay
    if steep:  # a trained model's: some steps decay by more than the chunked scan's range
        delta[:, ::7] *= 200
    shape = (bsz, L, d, n) if per_step else (d, n)
    A = -torch.rand(*shape, generator=gen) * 3 - 0.1
    Bm, Cm = torch.randn(bsz, L, g, n, generator=gen), torch.randn(bsz, L, g, n, generator=gen)
    D = torch.randn(d, generator=gen)
    return [t.to(dev).requires_grad_() for t in (u, delta, A, Bm, Cm, D)]


def _run(fn, args, dtype=torch.float32):
    args = [a.detach().to(dtype).requires_grad_() for a in args]
    y = fn(*args)
    grads = torch.autograd.grad((y * torch.cos(y)).sum(), args)
    return y.detach().double(), [g.double() for g in grads]


def _rel(a, b):
    return float((a - b).abs().max() / (1 + b.abs().max()))


def _time(fn, args, repeats=5):
    for _ in range(2):
        _run(fn, args)
    torch.cuda.synchronize()
    start = time.perf_counter()
    for _ in range(repeats):
        _run(fn, args)
    torch.cuda.synchronize()
    return (time.perf_counter() - start) / repeats


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out")
    args = ap.parse_args()
    dev = torch.device("cuda")
    report: dict = {"device": torch.cuda.get_device_name(), "torch": torch.__version__, "equal": [], "timing": []}
    for case in [(2, 7, 40, 4, 2, False), (3, 1, 8, 8, 1, False), (2, 19, 36, 4, 4, True), (4, 60, 96, 8, 2, True)]:
        for steep in (False, True):
            a = _inputs(*case, dev, seed=len(report["equal"]), steep=steep)
            y64, g64 = _run(scan_sequential, a, torch.float64)  # the truth
            y0, g0 = _run(scan_sequential, a)  # the float32 loop's error: the yardstick
            y1, g1 = _run(scan_triton, a)
            row = {
                "case": case,
                "steep": steep,
                "y": _rel(y1, y64),
                "y_loop": _rel(y0, y64),
                "grads": [_rel(p, q) for p, q in zip(g1, g64, strict=True)],
                "grads_loop": [_rel(p, q) for p, q in zip(g0, g64, strict=True)],
            }
            row["ok"] = row["y"] < max(1e-5, 4 * row["y_loop"]) and all(
                m < max(1e-4, 4 * r) for m, r in zip(row["grads"], row["grads_loop"], strict=True)
            )
            report["equal"].append(row)
            print(json.dumps(row), flush=True)
    for name, shape in SHAPES.items():
        a = _inputs(*shape, dev, steep=True)
        row = {"shape": name, "dims": shape}
        for impl, fn in (("triton", scan_triton), ("chunked", scan_chunked)):
            row[f"{impl}_s"] = _time(fn, a)
        report["timing"].append(row)
        print(json.dumps(row), flush=True)
    report["all_equal"] = all(r["ok"] for r in report["equal"])
    print("all equal within float32 rounding:", report["all_equal"])
    if args.out:
        with open(args.out, "w") as f:
            json.dump(report, f, indent=1)
    if not report["all_equal"]:
        raise SystemExit("the fused scan differs from the loop")


if __name__ == "__main__":
    main()
