"""Training of the latent denoisers (Motion Mamba, the transformer baseline) on a frozen VAE.

The VAE encodes every training clip once (posterior mean and log-variance, cached in the
run directory); each step then draws z ~ q(z|x), scales it to unit variance with the
data set's latent std (stored in the checkpoint), noises it and regresses epsilon. The
sentence embeddings of all captions are cached the same way, so a step costs only the
denoiser's forward and backward pass.
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

from .data.clips import load_clips, pad_batch
from .diffusion import Diffusion, DiffusionConfig
from .features import Normalizer
from .registry import build_denoiser, default_config, load_vae, override_config
from .text import get_text_encoder
from .train import WEIGHTS, device, save_state, ship


def encode_texts(args: argparse.Namespace, clips: list | None = None) -> dict[str, np.ndarray]:
    """Sentence embeddings of every training caption, cached beside the VAE run (the
    denoisers of all methods share them)."""
    cache = Path(args.vae) / "texts.npz"
    if cache.is_file():
        return dict(np.load(cache))
    clips = clips if clips is not None else load_clips(args.data, "train", args.limit)
    enc = get_text_encoder()
    caps = [c.captions for c in clips]
    t0 = time.time()
    emb = enc.encode([t for cs in caps for t in cs]).numpy().astype(np.float32)
    print(f"encoded {len(emb)} captions in {time.time() - t0:.0f} s")
    data = {
        "text": emb,
        "text_clip": np.repeat(np.arange(len(clips)), [len(cs) for cs in caps]),
        "empty": enc.encode([""]).numpy().astype(np.float32)[0],
    }
    np.savez(cache, **data)
    return data


@torch.no_grad()
def encode_corpus(args: argparse.Namespace) -> dict[str, np.ndarray]:
    """Posterior moments of the training clips under the VAE, plus caption embeddings
    (both cached in the VAE's run directory)."""
    cache = Path(args.vae) / "latents.npz"
    clips = None
    if not cache.is_file():
        vae, _ = load_vae(Path(args.vae) / "vae.pt")
        norm = Normalizer.load(args.data)
        clips = load_clips(args.data, "train", args.limit)
        order = np.argsort([c.frames for c in clips])  # similar lengths per batch: less padding
        mu_all = np.zeros((len(clips), vae.cfg.latent_tokens, vae.cfg.latent_dim), np.float32)
        lv_all = np.zeros_like(mu_all)
        for i in tqdm(range(0, len(clips), 128), desc="encode motions"):
            idx = order[i : i + 128]
            x, mask = pad_batch([norm.normalize(clips[j].features) for j in idx], vae.cfg.downsample)
            mu, lv = vae.encode(x, mask)
            mu_all[idx], lv_all[idx] = mu.numpy(), lv.numpy()
        np.savez(cache, mu=mu_all, logvar=lv_all, frames=np.array([c.frames for c in clips], np.int64))
    return {**dict(np.load(cache)), **encode_texts(args, clips)}


def train_denoiser(args: argparse.Namespace) -> None:
    out = Path(args.out or f"runs/{args.what}")
    out.mkdir(parents=True, exist_ok=True)
    torch.manual_seed(args.seed)
    data = encode_corpus(args)
    mu, logvar = torch.from_numpy(data["mu"]), torch.from_numpy(data["logvar"])
    scale = float(mu.std())  # latents scaled to unit std, as latent diffusion does
    frames = torch.from_numpy(data["frames"])
    text = torch.from_numpy(data["text"])
    empty = torch.from_numpy(data["empty"])
    text_clip = torch.from_numpy(data["text_clip"])
    cfg = override_config(default_config(args.what), getattr(args, "set", None) or [])
    model = build_denoiser(args.what, cfg).to(device())
    diff = Diffusion(DiffusionConfig())
    opt = torch.optim.AdamW(model.parameters(), lr=args.lr, weight_decay=0.01)
    step = 0
    state_path = out / "state.pt"
    g = torch.Generator().manual_seed(args.seed)
    if state_path.is_file():
        st = torch.load(state_path, weights_only=False)
        model.load_state_dict(st["model"])
        opt.load_state_dict(st["opt"])
        step = st["step"]
        g.set_state(st["rng"])
        print(f"resumed at step {step}")
    n_params = sum(p.numel() for p in model.parameters())
    print(f"{args.what}: {n_params / 1e6:.2f} M parameters, latent scale {scale:.3f}")
    bar = tqdm(total=args.steps, initial=step, desc=args.what, dynamic_ncols=True)
    ema = None
    while step < args.steps:
        lr = args.lr * min(1.0, (step + 1) / 500) * (0.1 + 0.9 * 0.5 * (1 + math.cos(math.pi * step / args.steps)))
        for grp in opt.param_groups:
            grp["lr"] = lr
        cap = torch.randint(0, len(text_clip), (args.batch,), generator=g)
        clip = text_clip[cap]
        z0 = (mu[clip] + torch.randn(mu[clip].shape, generator=g) * torch.exp(0.5 * logvar[clip])) / scale
        cond = text[cap].clone()
        drop = torch.rand(args.batch, generator=g) < diff.cfg.cond_drop
        cond[drop] = empty
        t = torch.randint(0, diff.cfg.train_steps, (args.batch,), generator=g)
        noise = torch.randn(z0.shape, generator=g)
        zt = diff.add_noise(z0, noise, t)
        pred = model(zt.to(device()), t.to(device()), cond.to(device()), frames[clip].to(device()))
        loss = torch.nn.functional.mse_loss(pred, noise.to(device()))
        opt.zero_grad(set_to_none=True)
        loss.backward()
        torch.nn.utils.clip_grad_norm_(model.parameters(), 1.0)
        opt.step()
        step += 1
        ema = loss.item() if ema is None else 0.98 * ema + 0.02 * loss.item()
        bar.update(1)
        bar.set_postfix(loss=f"{ema:.4f}")
        if step % args.save_every == 0 or step == args.steps:
            save_state(state_path, model=model.state_dict(), opt=opt.state_dict(), step=step, rng=g.get_state())
    bar.close()
    _, vae_meta = load_vae(Path(args.vae) / "vae.pt")
    meta = {
        "kind": args.what,
        "config": cfg.to_dict(),
        "steps": step,
        "batch": args.batch,
        "final_loss_ema": ema,
        "latent_scale": scale,
        "params": n_params,
        "data": str(args.data),
        "vae_steps": vae_meta.get("steps"),
    }
    torch.save({"state_dict": model.state_dict(), "meta": meta}, out / f"{args.what}.pt")
    (out / "result.json").write_text(json.dumps(meta, indent=1))
    if args.ship:
        ship(WEIGHTS / f"{args.what}.pt", model, meta)
        vae, vmeta = load_vae(Path(args.vae) / "vae.pt")
        if not (WEIGHTS / "vae.pt").is_file():
            ship(WEIGHTS / "vae.pt", vae, vmeta)
