"""Bit-for-bit pins of ``generate`` on the shipped checkpoints: a refactor must not change
what a user gets for a given timeline, method and seed.

Each case's joints (and KMM's key frames and density) are hashed as raw float32 bytes and
kept in ``tests/pins/generate.json`` beside the sha256 of the checkpoints they came from.
Re-pin after shipping new weights (retrained ``motion_core/weights/*.pt``) or a deliberate
change of the arithmetic (a kernel that sums in another order: say how far the joints moved
in the commit), never to make a refactor pass::

    MMS_REPIN=1 .venv/bin/python -m pytest -q tests/test_generate_pins.py

A failure says whether the weights changed (re-pin) or the outputs did (a behaviour
change), and how far the outputs moved on a stored subsample of frames. Cases run on one
torch thread (float32 reductions round differently on another thread count). Another CPU
type rounds differently too (on the 2026-11-25 machine six of nine cases moved by
0.2-4 micrometres, the code unchanged), so the pins record the CPU they were taken on: on
that CPU a case must match bit for bit, on another its sampled frames must stay within
``OTHER_CPU_M`` (a behaviour change moves joints by millimetres or more). Pins without a
CPU record are refused: re-pin.
"""

from __future__ import annotations

import hashlib
import json
import os
import platform
from pathlib import Path

import numpy as np
import pytest
import torch

import motion_core
from motion_core.nn.text import get_text_encoder

PINS = Path(__file__).parent / "pins" / "generate.json"
WEIGHTS = Path(motion_core.__file__).parent / "weights"
REPIN = os.environ.get("MMS_REPIN") == "1"
OTHER_CPU_M = 1e-4  # 0.1 mm


def _cpu() -> str:
    """The CPU as float rounding sees it: model name and instruction-set flags, hashed."""
    info = Path("/proc/cpuinfo").read_text() if Path("/proc/cpuinfo").is_file() else platform.processor()
    lines = [ln for ln in info.splitlines() if ln.startswith(("model name", "flags"))][:2]
    return hashlib.sha256("\n".join(lines).encode()).hexdigest()[:16]


SEGMENTS = [("a person walks forward", 2.5), ("a person waves with the right hand", 2.0)]
BATCH_TEXTS = ["a person jumps up", "a person turns left"]
# few DDIM steps keep the test quick; KMM runs at its registry defaults (steps=None). The
# diffusion cases name their sampler: a default can change (Motion Mamba's became "fast")
QUALITY = {"sampler": "quality"}
CASES = {
    **{
        f"{m}/timeline": dict(
            method=m, segments=SEGMENTS, seed=7, **({"steps": None} if m == "kmm" else {"steps": 8, **QUALITY})
        )
        for m in ("motion_mamba", "kmm", "ftmomamba", "baseline")
    },
    "kmm/one_segment_guided": dict(method="kmm", segments=SEGMENTS[:1], seed=3, steps=3, guidance=2.0),
    "baseline/one_segment_unrigid": dict(
        method="baseline", segments=SEGMENTS[1:], seed=3, steps=6, rigid=False, **QUALITY
    ),
    "motion_mamba/batch": dict(method="motion_mamba", texts=BATCH_TEXTS, seconds=2.0, seed=5, steps=5, **QUALITY),
    # the shipped consistency student (weights/motion_mamba_fast.pt) at its default steps
    "motion_mamba/fast_timeline": dict(method="motion_mamba", segments=SEGMENTS, seed=7, sampler="fast"),
    # the baseline's consistency student (weights/baseline_fast.pt)
    "baseline/fast_timeline": dict(method="baseline", segments=SEGMENTS, seed=7, sampler="fast"),
    # FTMoMamba's consistency student (weights/ftmomamba_fast.pt)
    "ftmomamba/fast_timeline": dict(method="ftmomamba", segments=SEGMENTS, seed=7, sampler="fast"),
    "kmm/batch": dict(method="kmm", texts=BATCH_TEXTS, seconds=2.0, seed=5, steps=None),
}


def _sha(a: np.ndarray) -> str:
    return hashlib.sha256(np.ascontiguousarray(a).tobytes()).hexdigest()


def _weights_sha() -> dict[str, str]:
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest()[:16] for p in sorted(WEIGHTS.glob("*.pt"))}


def _run(case: dict) -> list[motion_core.Motion]:
    """The motions of one case: one for a timeline, one per text for a batch. The text
    encoder's cache is cleared first, so that a case does not depend on the ones before it."""
    get_text_encoder().clear_cache()
    case = dict(case)
    threads = torch.get_num_threads()
    torch.set_num_threads(1)  # float32 reductions round differently on another thread count
    try:
        if "texts" in case:
            return motion_core.generate_batch(case.pop("texts"), case.pop("seconds"), **case)
        return [motion_core.generate(case.pop("segments"), **case)]
    finally:
        torch.set_num_threads(threads)


def _record(motions: list[motion_core.Motion]) -> list[dict]:
    out = []
    for m in motions:
        rec = {
            "shape": list(m.joints.shape),
            "joints_sha256": _sha(m.joints.astype(np.float32)),
            "segments": [list(s) for s in m.segments],
            # every tenth frame kept in full, to say how far a changed output moved
            "sample": np.round(m.joints[::10].astype(np.float64), 7).tolist(),
        }
        if m.keyframes is not None:
            rec["keyframes"] = list(m.keyframes)
            rec["density_sha256"] = _sha(np.asarray([m.density[k] for k in ("d", "S", "gamma")], np.float64))
        out.append(rec)
    return out


@pytest.fixture(scope="module")
def pins() -> dict:
    if REPIN:
        PINS.parent.mkdir(exist_ok=True)
        data = {
            "weights": _weights_sha(),
            "cpu": _cpu(),
            "cases": {name: _record(_run(c)) for name, c in CASES.items()},
        }
        PINS.write_text(json.dumps(data, indent=1) + "\n")
    if not PINS.is_file():
        pytest.fail(f"{PINS} is missing: MMS_REPIN=1 writes it")
    return json.loads(PINS.read_text())


def test_pins_say_which_cpu_took_them(pins):
    assert "cpu" in pins, "the pins predate their CPU record: re-pin (see this module's docstring)"


def test_pins_were_taken_on_the_shipped_weights(pins):
    assert pins["weights"] == _weights_sha(), (
        "motion_core/weights/*.pt changed since the pins were taken; if new weights were shipped on purpose, "
        "re-pin: MMS_REPIN=1 .venv/bin/python -m pytest -q tests/test_generate_pins.py"
    )
    assert set(pins["cases"]) == set(CASES)


@pytest.mark.parametrize("name", sorted(CASES))
def test_generate_matches_its_pin_bit_for_bit(pins, name):
    want = pins["cases"][name]
    got = _record(_run(CASES[name]))
    assert len(got) == len(want)
    for g, w in zip(got, want, strict=True):
        assert g["shape"] == w["shape"] and g["segments"] == w["segments"]
        same_cpu = pins.get("cpu") == _cpu()
        if g["joints_sha256"] != w["joints_sha256"]:
            moved = np.abs(np.asarray(g["sample"]) - np.asarray(w["sample"])).max()
            if same_cpu or moved > OTHER_CPU_M:
                where = "on the CPU that took the pins" if same_cpu else "on another CPU than the pins'"
                pytest.fail(f"{name}: joints changed {where} (largest move on the sampled frames {moved:.3g} m)")
        assert g.get("keyframes") == w.get("keyframes")
        if same_cpu:
            assert g.get("density_sha256") == w.get("density_sha256")
