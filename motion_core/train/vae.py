"""Training CLI.

    python -m motion_core.train vae --data DIR [--steps N] [--out runs/vae]
    python -m motion_core.train motion_mamba --data DIR [--vae runs/vae] [--steps N]
    python -m motion_core.train baseline --data DIR [--vae runs/vae] [--steps N]
    python -m motion_core.train ... --ship      # also write the inference checkpoint to motion_core/weights/
    python -m motion_core.train motion_mamba ... --set htm_order=flat --set bsm=single   # an ablation arm

Runs on the GPU when one is present, else the CPU. Every ``--save-every`` steps the whole
training state (model, optimiser, step, RNG) goes to OUT/state.pt; running the same command
again resumes from it. Progress is a tqdm bar with the running loss.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np
import torch
from tqdm import tqdm

from .data.clips import Clip, length_batches, load_clips, pad_batch
from .features import Normalizer, features_to_joints
from .models.vae import MotionVAE, VAEConfig, mpjpe_mm, vae_loss
from .registry import override_config
from .validation import reconstruction_pass_rate, validation_prompts

WEIGHTS = Path(__file__).parent / "weights"


def device() -> torch.device:
    return torch.device("cuda" if torch.cuda.is_available() else "cpu")


def save_state(path: Path, **state) -> None:
    tmp = path.with_suffix(".tmp")
    torch.save(state, tmp)
    tmp.replace(path)  # atomic: a kill mid-save never leaves a broken state file


def float16_state(sd: dict) -> dict:
    """A state dict as shipped: floating tensors in float16 (half the size; inference casts
    back to float32), integer buffers as they are."""
    return {k: (v.half() if v.is_floating_point() else v) for k, v in sd.items()}


def ship(path: Path, model: torch.nn.Module, meta: dict) -> None:
    """Inference checkpoint: float16 weights and the configs needed to rebuild the model."""
    path.parent.mkdir(parents=True, exist_ok=True)
    torch.save({"state_dict": float16_state(model.state_dict()), "meta": meta}, path)


# ---------------------------------------------------------------------------------------
# VAE
# ---------------------------------------------------------------------------------------


@torch.no_grad()
def evaluate_vae(vae: MotionVAE, clips: list[Clip], norm: Normalizer, batch: int = 64) -> dict[str, float]:
    """Reconstruction MPJPE (mm) of global joint positions, and of root-relative ones."""
    vae.eval()
    tot, tot_rel, n = 0.0, 0.0, 0
    for i in range(0, len(clips), batch):
        part = clips[i : i + batch]
        x, mask = pad_batch([norm.normalize(c.features) for c in part], vae.cfg.downsample)
        rec, _, _ = vae(x, mask)
        jr = features_to_joints(norm.denormalize(rec))
        jx = features_to_joints(norm.denormalize(x))
        w = float(mask.sum())
        tot += mpjpe_mm(jr, jx, mask) * w
        tot_rel += mpjpe_mm(jr - jr[:, :, :1], jx - jx[:, :, :1], mask) * w
        n += w
    vae.train()
    return {"mpjpe_mm": tot / n, "mpjpe_root_relative_mm": tot_rel / n}


def write_curve(path: Path, config: dict, log: list[dict]) -> None:
    """A VAE run's validation figures so far (atomically: a kill leaves the last one)."""
    old = json.loads(path.read_text())["log"] if path.is_file() else []
    steps = {e["step"] for e in log}
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps({"config": config, "log": [e for e in old if e["step"] not in steps] + log}, indent=1))
    tmp.replace(path)


def train_vae(args: argparse.Namespace) -> None:
    out = Path(args.out or "runs/vae")
    out.mkdir(parents=True, exist_ok=True)
    torch.manual_seed(args.seed)
    norm = Normalizer.load(args.data)
    t0 = time.time()
    train = load_clips(args.data, "train", args.limit)
    val = load_clips(args.data, "val", 256)
    # the verifier's pass rate on reconstructions of the denoisers' validation prompts:
    # what a latent shape or loss weighting is chosen on (the test split only reports)
    val_prompts = validation_prompts(args.data, 200)
    print(f"loaded {len(train)} train / {len(val)} val clips in {time.time() - t0:.0f} s")
    feats = [norm.normalize(c.features).astype(np.float32) for c in train]
    init_meta: dict = {}
    base = VAEConfig()
    if getattr(args, "init", None):
        # a stage that goes on from a committed checkpoint (float16 as shipped): its config
        # is the starting point, --set may still change the loss weights
        ck = torch.load(args.init, map_location="cpu", weights_only=False)
        init_meta = ck["meta"]
        base = VAEConfig(**init_meta["config"])
    cfg = override_config(base, getattr(args, "set", None) or [])
    vae = MotionVAE(cfg).to(device())
    if init_meta and not (out / "state.pt").is_file():
        vae.load_state_dict({k: v.float() if v.is_floating_point() else v for k, v in ck["state_dict"].items()})
        print(f"initialised from {args.init} ({init_meta.get('steps')} steps)")
    opt = torch.optim.AdamW(vae.parameters(), lr=args.lr, weight_decay=0.0)
    step = 0
    state_path = out / "state.pt"
    rng = np.random.default_rng(args.seed)
    if state_path.is_file():
        st = torch.load(state_path, weights_only=False)
        if "config" in st and st["config"] != cfg.to_dict():
            raise SystemExit(f"{state_path} was trained with another config: {st['config']}; use a new --out")
        vae.load_state_dict(st["model"])
        opt.load_state_dict(st["opt"])
        step = st["step"]
        rng.bit_generator.state = st["rng"]
        print(f"resumed at step {step}")
    bar = tqdm(total=args.steps, initial=step, desc="vae", dynamic_ncols=True)
    lengths = [len(f) for f in feats]
    log = []
    while step < args.steps:
        for idx in length_batches(lengths, args.batch, rng):
            if step >= args.steps:
                break
            lr = args.lr * min(1.0, (step + 1) / 200) * (0.1 + 0.9 * 0.5 * (1 + math.cos(math.pi * step / args.steps)))
            for g in opt.param_groups:
                g["lr"] = lr
            x, mask = pad_batch([feats[i] for i in idx], cfg.downsample)
            x, mask = x.to(device()), mask.to(device())
            loss, parts = vae_loss(vae(x, mask), x, mask, norm, cfg)
            opt.zero_grad(set_to_none=True)
            loss.backward()
            torch.nn.utils.clip_grad_norm_(vae.parameters(), 1.0)
            opt.step()
            step += 1
            bar.update(1)
            bar.set_postfix(loss=f"{loss.item():.4f}", joint=f"{parts['joint']:.4f}")
            if step % args.save_every == 0 or step == args.steps:
                ev = evaluate_vae(vae, val, norm)
                ev["val_verifier"] = reconstruction_pass_rate(vae, norm, val_prompts)["pass_rate"]
                log.append({"step": step, **parts, **ev})
                bar.write(json.dumps(log[-1]))
                write_curve(out / "curve.json", cfg.to_dict(), log)
                save_state(
                    state_path,
                    model=vae.state_dict(),
                    opt=opt.state_dict(),
                    step=step,
                    rng=rng.bit_generator.state,
                    config=cfg.to_dict(),
                )
    bar.close()
    test = load_clips(args.data, "test", 500)
    ev = evaluate_vae(vae, test, norm)
    meta = {
        "kind": "vae",
        "config": cfg.to_dict(),
        # the whole lineage's steps: a stage started with --init adds its own to its start's
        "steps": step + int(init_meta.get("steps") or 0),
        "init": {"from": Path(args.init).name, "steps": init_meta.get("steps")} if init_meta else None,
        "data": str(args.data),
        "test": ev,
        "mean": norm.mean.tolist(),
        "std": norm.std.tolist(),
    }
    res_path = out / "result.json"
    # a rerun that only ships (already at --steps) must not wipe the earlier run's log
    old_log = json.loads(res_path.read_text()).get("log", []) if res_path.is_file() else []
    res_path.write_text(json.dumps({"log": old_log + log, "test_500": ev}, indent=1))
    torch.save({"state_dict": vae.state_dict(), "meta": meta}, out / "vae.pt")
    print(json.dumps({"test_500": ev}))
    if args.ship:
        ship(WEIGHTS / "vae.pt", vae, meta)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(prog="python -m motion_core.train", description=__doc__.splitlines()[0])
    ap.add_argument("what", choices=["vae", "motion_mamba", "baseline", "ftmomamba"])
    ap.add_argument("--data", required=True, help="HumanML3D-format directory (e.g. the built-in corpus)")
    ap.add_argument("--out", default=None)
    ap.add_argument("--vae", default="runs/vae", help="run directory of the trained VAE (denoisers)")
    ap.add_argument("--steps", type=int, default=None)
    ap.add_argument("--batch", type=int, default=None)
    ap.add_argument("--lr", type=float, default=None)
    ap.add_argument("--limit", type=int, default=None, help="use only the first N training clips")
    ap.add_argument("--save-every", type=int, default=500)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--ship", action="store_true", help="write the inference checkpoint to motion_core/weights/")
    ap.add_argument(
        "--prediction",
        default="epsilon",
        choices=["epsilon", "sample", "v"],
        help="denoisers: the network's target (diffusion.DiffusionConfig.prediction)",
    )
    ap.add_argument("--init", default=None, help="vae: start from this checkpoint's weights (fresh optimiser)")
    ap.add_argument("--val-every", type=int, default=0, help="denoisers: score validation prompts every N steps")
    ap.add_argument("--val-n", type=int, default=200, help="denoisers: validation prompts per score")
    ap.add_argument("--val-guidance", type=float, default=7.5, help="denoisers: guidance scale when scoring")
    ap.add_argument(
        "--set",
        action="append",
        metavar="FIELD=VALUE",
        help="change one config field: the VAE's (latent_tokens=8, relative_joint_weight=2) or a denoiser's "
        "(ablation arms, e.g. htm_order=flat, bsm=single, freq=off)",
    )
    args = ap.parse_args(argv)
    if args.what == "vae":
        args.steps = args.steps or 6000
        args.batch = args.batch or 64
        args.lr = args.lr or 4e-4
        train_vae(args)
    else:
        from .train_denoiser import train_denoiser

        args.steps = args.steps or 20000
        args.batch = args.batch or 256
        args.lr = args.lr or 3e-4
        train_denoiser(args)


if __name__ == "__main__":
    main()
