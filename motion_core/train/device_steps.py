"""Pieces of a training step that keep an accelerator busy.

A GPU runs what the CPU queues; anything that reads a device value on the host (a loss
as a float) or copies a batch from pageable memory makes the CPU wait for the queue to
drain before it can queue the next step. A Motion Mamba step at batch 256 on an H200 took
0.22 s in the loop against 0.15 s measured alone, which is what these remove (it was not
where that time went: the trained weights' steep decays cut the chunked scan short, which
``nn/scan_triton.py`` fixed). On a CPU they cost nothing extra. Under torchrun the loop
still all-reduces once a step (``World.any``, the time limit), so there each step waits.
"""

from __future__ import annotations

import torch

# steps between host readings of the loss (each waits for the device's queue)
LOG_EVERY = 25


def to_device(x: torch.Tensor, dev: torch.device) -> torch.Tensor:
    """A batch drawn on the CPU, sent to ``dev`` without waiting for the device (through
    pinned memory); on a CPU, ``x`` itself."""
    if dev.type != "cuda":
        return x.to(dev)
    return x.pin_memory().to(dev, non_blocking=True)


@torch.no_grad()
def lerp_weights(average: torch.nn.Module, model: torch.nn.Module, decay: float) -> None:
    """average <- decay * average + (1 - decay) * model, over all parameters in one fused
    update (per tensor it was two kernels each: a few hundred launches a step)."""
    mine = list(average.parameters())
    theirs = [p.detach() for p in model.parameters()]
    if len(mine) != len(theirs):
        raise ValueError(f"the averaged network has {len(mine)} parameter tensors, the trained one {len(theirs)}")
    torch._foreach_lerp_(mine, theirs, 1 - decay)


class LossAverage:
    """A moving average of the loss (0.98 per step) kept on the loss's device; ``value()``
    reads it on the host, which waits for the device: call it every ``LOG_EVERY`` steps
    and where a step is saved or validated."""

    def __init__(self) -> None:
        self._avg: torch.Tensor | None = None

    def add(self, loss: torch.Tensor) -> None:
        loss = loss.detach()
        self._avg = loss if self._avg is None else 0.98 * self._avg + 0.02 * loss

    @property
    def tensor(self) -> torch.Tensor | None:
        return self._avg

    def value(self) -> float | None:
        return None if self._avg is None else float(self._avg)
