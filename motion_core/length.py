"""How long a motion should last, from its text: the estimate a segment gets when its
seconds are left blank.

    python -m motion_core.length train --data data/corpus_real [--ship]

MoMask predicts a motion's length from its text with a classifier over length bins. Ours is
a small regressor on the frozen sentence embedding: an MLP predicting the log of the
duration in seconds, trained with an L1 loss (the median, not the mean, of the durations a
caption may have), clipped to the demo's 1-10 s. Log seconds because a duration's error
matters relative to it (half a second is a lot for a 1 s clap, not for a 9 s walk).
Its checkpoint is a few hundred KB and ships beside the generators.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import torch
from torch import nn

from .skeleton import HUMANML3D

WEIGHTS = Path(__file__).parent / "weights" / "length.pt"
MIN_SECONDS, MAX_SECONDS = 1.0, 10.0


@dataclass
class LengthConfig:
    text_dim: int = 384
    hidden: int = 256
    dropout: float = 0.1


class LengthEstimator(nn.Module):
    """(B, text_dim) sentence embeddings -> (B,) log seconds."""

    def __init__(self, cfg: LengthConfig | None = None) -> None:
        super().__init__()
        self.cfg = cfg = cfg or LengthConfig()
        self.net = nn.Sequential(
            nn.Linear(cfg.text_dim, cfg.hidden),
            nn.GELU(),
            nn.Dropout(cfg.dropout),
            nn.Linear(cfg.hidden, cfg.hidden),
            nn.GELU(),
            nn.Linear(cfg.hidden, 1),
        )

    def forward(self, emb: torch.Tensor) -> torch.Tensor:
        return self.net(emb)[:, 0]

    @torch.no_grad()
    def seconds(self, emb: torch.Tensor) -> np.ndarray:
        """(B,) seconds, clipped to the demo's range and rounded to 0.1 s."""
        self.eval()
        s = torch.exp(self(emb.float())).clamp(MIN_SECONDS, MAX_SECONDS)
        return np.round(s.numpy().astype(np.float64), 1)


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


_loaded: LengthEstimator | None = None


def load_estimator(path: Path = WEIGHTS) -> LengthEstimator:
    """The shipped estimator, loaded once per process."""
    global _loaded
    if _loaded is None:
        ck = torch.load(path, map_location="cpu", weights_only=False)
        m = LengthEstimator(LengthConfig(**ck["meta"]["config"]))
        m.load_state_dict({k: v.float() for k, v in ck["state_dict"].items()})
        _loaded = m.eval()
    return _loaded


def estimate_seconds(texts: list[str]) -> list[float]:
    """Seconds for each text (1-10 s, 0.1 s steps)."""
    from .text import get_text_encoder

    return load_estimator().seconds(get_text_encoder().encode(list(texts))).tolist()


def train(data: str, out: Path, steps: int, seed: int, ship: bool) -> dict:
    from .text import get_text_encoder

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
    meta = {"kind": "length", "config": asdict(model.cfg), "data": str(data), "steps": steps, "test": result["test"]}
    (out / "result.json").write_text(json.dumps(result, indent=1))
    if ship:
        sd = {k: v.half() for k, v in model.state_dict().items()}
        torch.save({"state_dict": sd, "meta": meta}, WEIGHTS)
    return result


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(prog="python -m motion_core.length", description=__doc__.splitlines()[0])
    ap.add_argument("what", choices=["train"])
    ap.add_argument("--data", required=True)
    ap.add_argument("--out", default="runs/length")
    ap.add_argument("--steps", type=int, default=3000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--ship", action="store_true")
    args = ap.parse_args(argv)
    r = train(args.data, Path(args.out), args.steps, args.seed, args.ship)
    print(json.dumps({k: r[k] for k in ("test", "test_constant_median", "val")}))


if __name__ == "__main__":
    main()
