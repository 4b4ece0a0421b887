"""Data-parallel training across processes (``torchrun --nproc_per_node N``).

One process stays the default: without torchrun's environment every call here is a no-op
and the training loops run as before. Under torchrun each process joins one process
group (gloo on the CPU, nccl on GPUs, one GPU per local rank), wraps its model in
DistributedDataParallel, and takes its slice of a global batch that every process draws
identically from the same seeded generator. DDP averages the gradients, so N processes
with slices of B/N take the same optimiser steps as one process with B (up to the order
of float sums): the global batch and learning rate mean the same at any N.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TypeVar

import torch
import torch.distributed as dist

T = TypeVar("T")

# a single process's rows of a batch: all of them
ALL_ROWS = slice(None)


@dataclass(frozen=True)
class World:
    rank: int = 0
    size: int = 1
    device: torch.device = field(default_factory=lambda: torch.device("cpu"))

    @property
    def main(self) -> bool:
        """The process that writes files and prints progress."""
        return self.rank == 0

    def shard(self, batch: int) -> slice:
        """This process's rows of a global batch of ``batch`` rows."""
        if batch % self.size:
            raise SystemExit(f"--batch {batch} must be a multiple of the {self.size} processes")
        b = batch // self.size
        return slice(self.rank * b, (self.rank + 1) * b)

    def wrap(self, model: torch.nn.Module) -> torch.nn.Module:
        if self.size == 1:
            return model
        # BSM's delta projection is (2, 1, 8) (dt_rank 1): autograd gives its gradient the
        # strides (8, 1, 1), DDP's bucket view (8, 8, 1). Both are the same contiguous
        # memory (a size-1 dimension's stride is arbitrary), so the check's warning is moot.
        warnings.filterwarnings("ignore", message="Grad strides do not match bucket view strides")
        ids = [self.device.index] if self.device.type == "cuda" else None
        return torch.nn.parallel.DistributedDataParallel(model, device_ids=ids)

    def mean(self, value: torch.Tensor) -> float:
        """A scalar averaged over the processes (the global batch's loss, for logs)."""
        if self.size == 1:
            return float(value.detach())
        v = value.detach().clone()
        dist.all_reduce(v)
        return float(v) / self.size

    def any(self, flag: bool) -> bool:
        """True on every process when it is True on any (a decision all must take together:
        one process leaving the loop alone would leave the others in DDP's all-reduce)."""
        if self.size == 1:
            return flag
        v = torch.tensor([1.0 if flag else 0.0], device=self.device)
        dist.all_reduce(v, op=dist.ReduceOp.MAX)
        return bool(v.item())

    def barrier(self) -> None:
        if self.size > 1:
            dist.barrier()

    def first(self, build: Callable[[], T]) -> T:
        """``build()`` on the first process, then on the others once it has finished: what
        builds a missing cache builds it once, and the others read it."""
        value = build() if self.main else None
        self.barrier()
        return value if self.main else build()


def init_world() -> World:
    """The process group torchrun asked for, or the single process."""
    size = int(os.environ.get("WORLD_SIZE", "1"))
    cuda = torch.cuda.is_available()
    if size == 1:
        return World(device=torch.device("cuda" if cuda else "cpu"))
    if not dist.is_initialized():
        dist.init_process_group("nccl" if cuda else "gloo")
    local = int(os.environ.get("LOCAL_RANK", "0"))
    dev = torch.device("cuda", local) if cuda else torch.device("cpu")
    if cuda:
        torch.cuda.set_device(dev)
    return World(dist.get_rank(), dist.get_world_size(), dev)


def unwrap(model: torch.nn.Module) -> torch.nn.Module:
    """The module inside a DistributedDataParallel wrapper (its state dict has no prefix)."""
    return model.module if isinstance(model, torch.nn.parallel.DistributedDataParallel) else model


def device() -> torch.device:
    """A single-process run's device: the GPU when one is present, else the CPU."""
    return torch.device("cuda" if torch.cuda.is_available() else "cpu")


def allow_tf32() -> None:
    """float32 matmuls on a GPU's TF32 tensor cores (10-bit mantissa): Motion Mamba's GPU
    step is mostly fp32 batched matmuls and products (results/step_time_gpu_h200.json)."""
    torch.backends.cuda.matmul.allow_tf32 = True
    torch.backends.cudnn.allow_tf32 = True
