"""How long a motion should last, from its text: the network behind the estimate a segment
gets when its seconds are left blank.

MoMask predicts a motion's length from its text with a classifier over length bins. Ours is
a small regressor on the frozen sentence embedding: an MLP predicting the log of the
duration in seconds, trained with an L1 loss (the median, not the mean, of the durations a
caption may have), clipped to the demo's 1-10 s. Log seconds because a duration's error
matters relative to it (half a second is a lot for a 1 s clap, not for a 9 s walk).
Trained by ``python -m motion_core.train length``; its checkpoint is about 330 KB.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
import torch
from torch import nn

MIN_SECONDS, MAX_SECONDS = 1.0, 10.0


@dataclass
class LengthConfig:
    text_dim: int = 384
    hidden: int = 256
    dropout: float = 0.1

    def to_dict(self) -> dict:
        return asdict(self)


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
