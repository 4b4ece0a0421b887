"""The process's runtime set-up, shared by the demo and the study: torch threads and warm-up."""

from __future__ import annotations

import logging
import os
from collections.abc import Sequence

import motion_core

log = logging.getLogger("motion_mamba_studio")


def warm_up(methods: Sequence[str] | None = None) -> None:
    """Load the text encoder, the methods' weights (default: all), the length estimator and the
    exports' mannequins, then generate one short motion per method (its default sampler), so
    the first click is fast: the first body alone took 1.4 s, and on a fresh install the
    first motion compiles the CPU kernels (numba: the fused scans, the rig fit), 9 s for the
    demo's first click before this generation moved it here. Their disk cache makes a
    later start load them in about a second."""
    from motion_core.body.mannequin import build_mannequin
    from motion_core.corpus.prompt_guide import get_phrasebook
    from motion_core.formats.export import RIGS
    from motion_core.inference.length import length_estimator
    from motion_core.inference.registry import load_method
    from motion_core.nn.text import get_text_encoder

    try:
        get_text_encoder().encode(["a person walks forward", ""])
        get_phrasebook()
        length_estimator()
        for skeleton in RIGS.values():
            build_mannequin(skeleton.rest_joints(), skeleton)
        for name in methods if methods is not None else [m["name"] for m in motion_core.methods()]:
            load_method(name)
            motion_core.generate([("a person walks forward", 1.0)], method=name, seed=0)
    except Exception:  # a failed warm-up must not stop the page; the click will report it
        log.exception("warm-up failed")


def configure_torch() -> None:
    """One intra-op thread per request (MMS_TORCH_THREADS overrides).

    The models run many small operations; with two threads on a 2-core machine, any other
    busy process (a browser drawing the viewer, a second request) makes OpenMP threads wait
    on each other: Motion Mamba took 11-12 s instead of 3 s for a 6 s motion with one core
    busy, and 2.8-3.1 s with one thread. Parallel requests use the other cores instead.
    """
    import torch

    torch.set_num_threads(int(os.environ.get("MMS_TORCH_THREADS", "1")))


def configure_log() -> None:
    """One line per event on stderr for the app's logger ("motion_mamba_studio" and its
    children): a refused request is one info line, a traceback only for real failures.
    Without a handler Python would drop the info lines. Idempotent (the demo's page sets up
    the same handler)."""
    if not log.handlers:
        handler = logging.StreamHandler()
        handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s"))
        log.addHandler(handler)
        log.setLevel(logging.INFO)
        log.propagate = False
