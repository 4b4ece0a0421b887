"""Training the length estimator (``models.length``) on the corpus's caption durations.

    python -m motion_core.train length --data data/corpus_real [--ship]

The step kept is the one with the lowest error on the validation captions; the test split
is only reported, beside the error of always guessing the training median.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import torch

from ..body.skeleton import HUMANML3D
from ..inference import checkpoints
from ..models.length import MAX_SECONDS, MIN_SECONDS, LengthEstimator
from ..nn.text import get_text_encoder


def captions_and_seconds(data: str | Path, split: str) -> tuple[list[str], np.ndarray]:
    """Every caption of a split with its clip's duration (frames / fps, capped like the
    clips the generators train on)."""
    root = Path(data)
    texts, secs = [], []
    for mid in (root / f"{split}.txt").read_text().split():
        frames = np.load(root / "new_joint_vecs" / f"{mid}.npy", mmap_mode="r").shape[0]
        s = min(frames, 200) / HUMANML3D.fps
        for line in (root / "texts" / f"{mid}.txt").read_text().splitlines():
            if line.strip():
                texts.append(line.split("#")[0].strip())
                secs.append(s)
    return texts, np.asarray(secs, np.float64)


def errors(pred: np.ndarray, truth: np.ndarray) -> dict[str, float]:
    err = np.abs(pred - np.clip(truth, MIN_SECONDS, MAX_SECONDS))
    return {"mae_s": float(err.mean()), "median_ae_s": float(np.median(err)), "p90_ae_s": float(np.percentile(err, 90))}


def train_length(data: str, out: Path, steps: int, seed: int, ship: bool) -> dict:
    torch.manual_seed(seed)
    enc = get_text_encoder()
    split = {s: captions_and_seconds(data, s) for s in ("train", "val", "test")}
    emb = {s: enc.encode(t) for s, (t, _) in split.items()}
    y = torch.log(torch.from_numpy(np.clip(split["train"][1], MIN_SECONDS, MAX_SECONDS))).float()
    model = LengthEstimator()
    opt = torch.optim.AdamW(model.parameters(), lr=1e-3, weight_decay=1e-4)
    g = torch.Generator().manual_seed(seed)
    best, best_state, log = float("inf"), None, []
    for step in range(1, steps + 1):
        model.train()
        idx = torch.randint(len(y), (512,), generator=g)
        loss = (model(emb["train"][idx]) - y[idx]).abs().mean()
        opt.zero_grad(set_to_none=True)
        loss.backward()
        opt.step()
        if step % 250 == 0 or step == steps:
            val = errors(model.seconds(emb["val"]), split["val"][1])
            log.append({"step": step, "loss": float(loss), **{f"val_{k}": v for k, v in val.items()}})
            print(json.dumps(log[-1]))
            if val["mae_s"] < best:  # the step kept is chosen on validation captions
                best, best_state = val["mae_s"], {k: v.clone() for k, v in model.state_dict().items()}
    model.load_state_dict(best_state)
    median = float(np.median(np.clip(split["train"][1], MIN_SECONDS, MAX_SECONDS)))
    result = {
        "test": errors(model.seconds(emb["test"]), split["test"][1]),
        "test_constant_median": errors(np.full(len(split["test"][1]), median), split["test"][1]),
        "val": errors(model.seconds(emb["val"]), split["val"][1]),
        "captions": {s: len(t) for s, (t, _) in split.items()},
        "train_median_s": median,
        "log": log,
    }
    out.mkdir(parents=True, exist_ok=True)
    meta = {"kind": "length", "config": model.cfg.to_dict(), "data": str(data), "steps": steps, "test": result["test"]}
    (out / "result.json").write_text(json.dumps(result, indent=1))
    if ship:
        checkpoints.ship(checkpoints.WEIGHTS / "length.pt", model, meta)
    return result
