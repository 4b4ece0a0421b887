"""Training of the T2M-style evaluator (``python -m motion_core.train evaluator ...``): the
motion and text encoders of ``eval.evaluator``, trained contrastively on caption pairs."""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np
import torch
from torch import nn
from tqdm import tqdm

from ..body.features import Normalizer
from ..data.clips import Clip, length_batches, load_clips, pad_batch
from ..eval.evaluator import CHECKPOINT, Evaluator, EvaluatorConfig, r_precision_report, save_evaluator


def _caption_embeddings(clips: list[Clip]) -> tuple[np.ndarray, np.ndarray]:
    """(N_captions, 384) sentence embeddings and the clip index of each caption."""
    from ..nn.text import get_text_encoder

    texts, owner = [], []
    for i, c in enumerate(clips):
        for cap in c.captions:
            if cap:
                texts.append(cap)
                owner.append(i)
    enc = get_text_encoder()
    emb = np.concatenate([np.asarray(enc.encode(texts[i : i + 512])) for i in range(0, len(texts), 512)])
    return emb.astype(np.float32), np.asarray(owner)


def train(args: argparse.Namespace) -> None:
    torch.manual_seed(args.seed)
    rng = np.random.default_rng(args.seed)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.time()
    clips = load_clips(args.data, "train", limit=args.limit)
    val = load_clips(args.data, "val")
    norm = Normalizer.load(args.data)
    caps, owner = _caption_embeddings(clips)
    print(f"{len(clips)} train clips, {len(caps)} captions, loaded in {time.time() - t0:.0f} s")
    model = Evaluator(EvaluatorConfig(), norm)
    opt = torch.optim.AdamW(model.parameters(), lr=args.lr, weight_decay=1e-4)
    warm = max(1, args.steps // 20)  # linear warm-up, then cosine decay to 0
    sched = torch.optim.lr_scheduler.LambdaLR(
        opt, lambda s: min(1.0, (s + 1) / warm) * 0.5 * (1 + math.cos(math.pi * min(s, args.steps) / args.steps))
    )
    by_clip: dict[int, list[int]] = {}
    for k, i in enumerate(owner):
        by_clip.setdefault(int(i), []).append(k)
    usable = [i for i in range(len(clips)) if i in by_clip]
    lengths = [clips[i].frames for i in usable]
    batches: list[np.ndarray] = []
    bar = tqdm(range(args.steps), desc="evaluator", mininterval=5)
    avg = None
    for _ in bar:
        if not batches:
            batches = length_batches(lengths, args.batch, rng)
        idx = [usable[j] for j in batches.pop()]
        if len(idx) < 2:
            continue
        arrs = [norm.normalize(clips[i].features) for i in idx]
        arrs = [np.pad(a, ((0, max(0, 8 - len(a))), (0, 0))) for a in arrs]
        x, mask = pad_batch(arrs, multiple=4)
        t = torch.from_numpy(caps[[by_clip[i][rng.integers(len(by_clip[i]))] for i in idx]])
        model.train()
        loss = model.loss(x, mask, t)
        opt.zero_grad()
        loss.backward()
        nn.utils.clip_grad_norm_(model.parameters(), 1.0)
        opt.step()
        sched.step()
        avg = loss.item() if avg is None else 0.98 * avg + 0.02 * loss.item()
        bar.set_postfix(loss=f"{avg:.3f}", temp=f"{model.log_temp.exp().item():.3f}")
    report = r_precision_report(model, val, repeats=5)
    meta = {
        "data": str(args.data),
        "steps": args.steps,
        "batch": args.batch,
        "train_clips": len(clips),
        "val": report,
        "minutes": round((time.time() - t0) / 60, 1),
    }
    save_evaluator(out / "evaluator.pt", model, meta)
    (out / "meta.json").write_text(json.dumps(meta, indent=1))
    print(json.dumps(meta, indent=1))
    if args.ship:
        save_evaluator(CHECKPOINT, model, meta)
        print(f"shipped {CHECKPOINT} ({CHECKPOINT.stat().st_size / 2**20:.1f} MiB)")
