"""Training of the motion VAE (``python -m motion_core.train vae ...``): the latent space
the diffusion methods denoise in. Scored on validation clips (MPJPE) and, through the
verifier, on reconstructions of the validation prompts; the test split only reports.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
import torch
from tqdm import tqdm

from ..body.features import Normalizer, features_to_joints
from ..data.clips import Clip, length_batches, load_clips, normalized_features, pad_batch
from ..inference import checkpoints
from ..inference.checkpoints import WEIGHTS
from ..models.overrides import override_config
from ..models.vae import mpjpe_mm
from .distributed import device
from .recipe import check_resume, recipe
from .schedule import learning_rate
from .validation import reconstruction_pass_rate, validation_prompts


@torch.no_grad()
def evaluate_vae(vae: checkpoints.AnyVAE, clips: list[Clip], norm: Normalizer, batch: int = 64) -> dict[str, float]:
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
    feats = normalized_features(args.data, "train", norm, args.limit)
    val = load_clips(args.data, "val", 256)
    # the verifier's pass rate on reconstructions of the denoisers' validation prompts:
    # what a latent shape or loss weighting is chosen on (the test split only reports)
    val_prompts = validation_prompts(args.data, 200)
    print(f"loaded {len(feats)} train / {len(val)} val clips in {time.time() - t0:.0f} s")
    init_meta: dict = {}
    arch = getattr(args, "arch", None) or "transformer"
    init_ck = checkpoints.read(args.init) if getattr(args, "init", None) else None
    # a stage that goes on from a committed VAE checkpoint (float16 as shipped): its arch and
    # config are the starting point, --set may still change the loss weights
    from_vae = init_ck is not None and "state_dict" in init_ck
    if from_vae:
        init_meta = init_ck["meta"]
        arch = init_meta.get("arch", "transformer")
    cfg_cls = checkpoints.VAE_ARCHS[arch][1]
    base = cfg_cls(**init_meta["config"]) if from_vae else cfg_cls()
    cfg = override_config(base, getattr(args, "set", None) or [])
    vae = checkpoints.build_vae(arch, cfg.to_dict()).to(device())
    # recorded in the meta of a run that resumes as well as of one that starts
    tokeniser_steps = int(init_ck["meta"]["rvq_steps"]) if init_ck is not None and "rvq" in init_ck else None
    if init_ck is not None and not (out / "state.pt").is_file():
        if from_vae:
            vae.load_state_dict(checkpoints.float32_state(init_ck["state_dict"]))
            print(f"initialised from {args.init} ({init_meta.get('steps')} steps)")
        elif "rvq" in init_ck and hasattr(vae, "init_from_tokeniser"):
            # a temporal VAE starting from KMM's tokeniser's convolutions (a shipped kmm.pt)
            n = vae.init_from_tokeniser(checkpoints.float32_state(init_ck["rvq"]))
            print(f"initialised {n} convolution tensors from the tokeniser in {args.init} ({tokeniser_steps} steps)")
        else:
            raise SystemExit(f"{args.init}: neither a VAE checkpoint nor a kmm.pt for --arch conv")
    opt = torch.optim.AdamW(vae.parameters(), lr=args.lr, weight_decay=0.0)
    step = 0
    state_path = out / "state.pt"
    rng = np.random.default_rng(args.seed)
    run_recipe = recipe(args, ("lr", "batch", "seed"))
    if state_path.is_file():
        st = checkpoints.read_state(state_path)
        if "config" in st and st["config"] != cfg.to_dict():
            raise SystemExit(f"{state_path} was trained with another config: {st['config']}; use a new --out")
        check_resume(st, run_recipe, state_path)
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
            lr = learning_rate(args.lr, step, args.steps, warmup=200)
            for g in opt.param_groups:
                g["lr"] = lr
            x, mask = pad_batch([feats[i] for i in idx], cfg.downsample)
            x, mask = x.to(device()), mask.to(device())
            loss, parts = vae.loss(vae(x, mask), x, mask, norm)
            opt.zero_grad(set_to_none=True)
            loss.backward()
            torch.nn.utils.clip_grad_norm_(vae.parameters(), 1.0)
            opt.step()
            step += 1
            bar.update(1)
            bar.set_postfix(loss=f"{loss.item():.4f}", feat=f"{parts['feat']:.4f}")
            if step % args.save_every == 0 or step == args.steps:
                ev = evaluate_vae(vae, val, norm)
                ev["val_verifier"] = reconstruction_pass_rate(vae, norm, val_prompts)["pass_rate"]
                log.append({"step": step, **parts, **ev})
                bar.write(json.dumps(log[-1]))
                write_curve(out / "curve.json", cfg.to_dict(), log)
                checkpoints.write_state(
                    state_path,
                    model=vae.state_dict(),
                    opt=opt.state_dict(),
                    step=step,
                    rng=rng.bit_generator.state,
                    config=cfg.to_dict(),
                    recipe=run_recipe,
                )
    bar.close()
    test = load_clips(args.data, "test", 500)
    ev = evaluate_vae(vae, test, norm)
    meta = {
        "kind": "vae",
        "arch": arch,
        "config": cfg.to_dict(),
        # the whole lineage's steps: a stage started with --init adds its own to its start's
        "steps": step + int(init_meta.get("steps") or 0),
        "init": {"from": Path(args.init).name, "steps": init_meta.get("steps")} if init_meta else None,
        "tokeniser_init": {"from": Path(args.init).name, "steps": tokeniser_steps} if tokeniser_steps else None,
        "data": str(args.data),
        "test": ev,
        "mean": norm.mean.tolist(),
        "std": norm.std.tolist(),
    }
    res_path = out / "result.json"
    # a rerun that only ships (already at --steps) must not wipe the earlier run's log
    old_log = json.loads(res_path.read_text()).get("log", []) if res_path.is_file() else []
    res_path.write_text(json.dumps({"log": old_log + log, "test_500": ev}, indent=1))
    checkpoints.save_run(out / "vae.pt", vae, meta)
    print(json.dumps({"test_500": ev}))
    if getattr(args, "stage", None):
        checkpoints.ship(Path(args.stage), vae, meta)  # float16, as shipped: the next stage's --init
    if args.ship:
        checkpoints.ship(WEIGHTS / "vae.pt", vae, meta)
