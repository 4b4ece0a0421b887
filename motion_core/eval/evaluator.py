"""Our T2M-style evaluator: a motion encoder and a text encoder trained contrastively.

    python -m motion_core.train evaluator --data DIR [--steps N] [--out runs/evaluator] [--ship]
    python -m motion_core.eval evaluator-check --data DIR     # R-precision on the test split

Role and shape follow Guo et al. (2022): a movement encoder (two strided Conv1d, x4
temporal downsampling) feeding a bidirectional GRU gives a motion embedding; texts get an
embedding of the same size; matched pairs are pulled together. Where we depart, and why:

* Text side: the frozen sentence embedding of our text encoder (all-MiniLM-L6-v2, 384-d)
  through a 2-layer MLP, not a BiGRU over GloVe word vectors with part-of-speech tags
  (GloVe is not available offline here, and the sentence encoder is what every generator
  is conditioned on anyway).
* Loss: symmetric InfoNCE with a learnable temperature over the batch, not the margin loss
  on shifted negatives; one stage, the movement encoder trained jointly, not pre-trained.
* Embeddings are L2-normalised (D = 512), so distances lie in [0, 2]: MM-Dist and Diversity
  are on that scale, not the papers' (about 3-10). Numbers from this evaluator compare our
  methods with each other and with the Real row, never with the papers' tables.

Input: HumanML3D features (T, 263), normalised with the training split's Mean/Std stored in
the checkpoint. Motions shorter than 8 frames are padded; longer than 200 are cropped.
"""

from __future__ import annotations

import argparse
import json
import math
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import torch
import torch.nn.functional as F
from torch import nn

from ..body.features import Normalizer
from ..data.clips import Clip, load_clips, pad_batch
from ..inference import checkpoints
from ..inference.checkpoints import WEIGHTS

CHECKPOINT = WEIGHTS / "evaluator.pt"


@dataclass(frozen=True)
class EvaluatorConfig:
    feature_dim: int = 263
    text_dim: int = 384
    hidden: int = 256
    embed_dim: int = 512


class MotionEncoder(nn.Module):
    """(B, T, 263) normalised features + (B, T) mask -> (B, D) unit embeddings."""

    def __init__(self, cfg: EvaluatorConfig) -> None:
        super().__init__()
        h = cfg.hidden
        self.movement = nn.Sequential(
            nn.Conv1d(cfg.feature_dim, h, 4, stride=2, padding=1),
            nn.LeakyReLU(0.2),
            nn.Conv1d(h, h, 4, stride=2, padding=1),
            nn.LeakyReLU(0.2),
        )
        self.gru = nn.GRU(h, h, batch_first=True, bidirectional=True)
        self.out = nn.Sequential(nn.Linear(2 * h, h), nn.LeakyReLU(0.2), nn.Linear(h, cfg.embed_dim))

    def forward(self, x: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
        y = self.movement(x.transpose(1, 2)).transpose(1, 2)  # (B, T/4, h)
        m = mask[:, ::4][:, : y.shape[1]].float()  # a token is real when its first frame is
        y, _ = self.gru(y)
        pooled = (y * m[..., None]).sum(1) / m.sum(1, keepdim=True).clamp(min=1.0)
        return F.normalize(self.out(pooled), dim=-1)


class TextHead(nn.Module):
    """(B, 384) sentence embeddings -> (B, D) unit embeddings."""

    def __init__(self, cfg: EvaluatorConfig) -> None:
        super().__init__()
        self.mlp = nn.Sequential(
            nn.Linear(cfg.text_dim, cfg.embed_dim), nn.LeakyReLU(0.2), nn.Linear(cfg.embed_dim, cfg.embed_dim)
        )

    def forward(self, t: torch.Tensor) -> torch.Tensor:
        return F.normalize(self.mlp(t), dim=-1)


class Evaluator(nn.Module):
    def __init__(self, cfg: EvaluatorConfig, normalizer: Normalizer) -> None:
        super().__init__()
        self.cfg = cfg
        self.normalizer = normalizer
        self.motion = MotionEncoder(cfg)
        self.text = TextHead(cfg)
        self.log_temp = nn.Parameter(torch.tensor(math.log(0.07)))

    def loss(self, x: torch.Tensor, mask: torch.Tensor, t: torch.Tensor) -> torch.Tensor:
        zm, zt = self.motion(x, mask), self.text(t)
        logits = zt @ zm.T / self.log_temp.exp().clamp(min=0.01)
        target = torch.arange(len(zm))
        return 0.5 * (F.cross_entropy(logits, target) + F.cross_entropy(logits.T, target))

    @torch.no_grad()
    def embed_motions(self, features: list[np.ndarray], batch: int = 64) -> np.ndarray:
        """Un-normalised features, each (T_i, 263) -> (N, D) embeddings (float32)."""
        self.eval()
        out = []
        for i in range(0, len(features), batch):
            arrs = [self.normalizer.normalize(f[:200].astype(np.float32)) for f in features[i : i + batch]]
            arrs = [np.pad(a, ((0, max(0, 8 - len(a))), (0, 0))) for a in arrs]
            x, mask = pad_batch(arrs, multiple=4)
            out.append(self.motion(x, mask).numpy())
        return np.concatenate(out).astype(np.float32)

    @torch.no_grad()
    def embed_texts(self, texts: list[str]) -> np.ndarray:
        from ..nn.text import get_text_encoder

        self.eval()
        sent = torch.as_tensor(np.asarray(get_text_encoder().encode(list(texts))), dtype=torch.float32)
        return self.text(sent).numpy().astype(np.float32)


def save_evaluator(path: Path, model: Evaluator, meta: dict) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    checkpoints.write(
        path,
        {
            "state_dict": checkpoints.float16_state(model.state_dict()),
            "config": asdict(model.cfg),
            "mean": model.normalizer.mean,
            "std": model.normalizer.std,
            "meta": meta,
        },
    )


def load_evaluator(path: str | Path = CHECKPOINT) -> Evaluator:
    ck = checkpoints.read(path)
    model = Evaluator(EvaluatorConfig(**ck["config"]), Normalizer(ck["mean"], ck["std"]))
    model.load_state_dict(checkpoints.float32_state(ck["state_dict"]))
    model.meta = ck.get("meta", {})  # type: ignore[attr-defined]
    return model.eval()


def test_pairs(clips: list[Clip], rng: np.random.Generator) -> tuple[list[np.ndarray], list[str]]:
    """One (motion, caption) pair per clip, the caption drawn at random."""
    return [c.features for c in clips], [c.captions[rng.integers(len(c.captions))] for c in clips]


def r_precision_report(model: Evaluator, clips: list[Clip], repeats: int = 20) -> dict:
    """The Real row: R-precision top-1/2/3 and MM-Dist of real (motion, caption) pairs."""
    from .metrics import r_precision

    motions, _ = test_pairs(clips, np.random.default_rng(0))
    zm = model.embed_motions(motions)
    rows = []
    for r in range(repeats):
        _, caps = test_pairs(clips, np.random.default_rng(r))
        zt = model.embed_texts(caps)
        top, mm = r_precision(zt, zm, rng=np.random.default_rng(r))
        rows.append([*top, mm])
    a = np.asarray(rows)
    mean, half = a.mean(0), 1.96 * a.std(0) / math.sqrt(repeats)
    names = ["top1", "top2", "top3", "mm_dist"]
    return {n: [float(mean[i]), float(half[i])] for i, n in enumerate(names)} | {"clips": len(clips)}


def check(args: argparse.Namespace) -> None:
    model = load_evaluator(args.checkpoint)
    clips = load_clips(args.data, "test", limit=args.limit)
    report = {"all": r_precision_report(model, clips)}
    for source in ("procedural", "real"):
        sub = [c for c in clips if c.labels.get("source", "procedural") == source]
        if len(sub) >= 32:
            report[source] = r_precision_report(model, sub)
    print(json.dumps(report, indent=1))
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text(json.dumps(report, indent=1) + "\n")
