"""Where ``body.terrain`` finds ground that is not flat, and proof that flat motions are
grounded bit for bit as before stairs.

    python tools/terrain_check.py [--corpus 40] [--bandai DIR] [--cmu DIR] [--generated 40] \\
        [--out results/terrain_check.json]

For every motion: whether ``terrain.surface`` finds a raised level, how many step boxes
``terrain.steps`` makes, and whether ``ground`` (terrain-aware, the default) gives exactly the
bytes of ``ground`` with ``terrain=False`` (the rule before stairs). Sources:

* ``--corpus N``: N clips of every corpus kind, built-in and staged (``kinds.check.clips``,
  seed 0: through the 263-dim features), and the same clips as composed (before features);
* ``--bandai DIR``: every clip of the Bandai Namco archive unpacked in DIR (``data.mocap``);
* ``--cmu DIR``: the CMU BVH files of the iClone conversion in DIR (``*.bvh``, a T-pose first
  frame, dropped), retargeted with the map below: real walks on uneven terrain and playground
  climbing among them. Only counts are written: the data stays out of the repository;
* ``--generated N``: N prompts a method (real captions that ask for stairs, then one caption
  of every built-in kind and of every staged kind), each method's default sampler, seed 0:
  the joints ``generate`` hands to ``on_floor``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import zlib
from pathlib import Path
from unittest import mock

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from motion_core.body.ground import GroundConfig, ground
from motion_core.body.skeleton import HUMANML3D
from motion_core.body.terrain import steps, surface
from motion_core.formats.retarget import JointMap

FLAT = GroundConfig(terrain=False)


def _sided(hml: str, src: str) -> dict[str, str]:
    return {f"left_{hml}": f"CC_Base_L_{src}", f"right_{hml}": f"CC_Base_R_{src}"}


# the CMU database as converted for iClone (CC_Base_* bones)
ICLONE_CMU = JointMap(
    name="CMU (iClone conversion)",
    direct={
        "pelvis": "CC_Base_Hip",
        "neck": "CC_Base_NeckTwist01",
        "head": "CC_Base_Head",
        **_sided("hip", "Thigh"),
        **_sided("knee", "Calf"),
        **_sided("ankle", "Foot"),
        **_sided("foot", "ToeBase"),
        **_sided("collar", "Clavicle"),
        **_sided("shoulder", "Upperarm"),
        **_sided("elbow", "Forearm"),
        **_sided("wrist", "Hand"),
    },
    spine_chain=("CC_Base_Hip", "CC_Base_Waist", "CC_Base_Spine01", "CC_Base_Spine02", "CC_Base_NeckTwist01"),
)


def reading(j: np.ndarray) -> dict:
    """One motion: raised level found, step boxes, ground unchanged from the flat rule."""
    j = np.asarray(j)
    feet = [i for pair in HUMANML3D.feet for i in pair]
    found = surface(j - np.array([0.0, j[:, feet, 1].min(), 0.0], dtype=j.dtype)) is not None  # as ground reads it
    same = bool(np.array_equal(ground(j), ground(j, cfg=FLAT)))
    return {"raised": found, "boxes": len(steps(j)), "ground_as_flat": same}


def summary(rows: dict[str, dict]) -> dict:
    raised = sorted(k for k, r in rows.items() if r["raised"])
    flat = [r for r in rows.values() if not r["raised"]]
    return {
        "motions": len(rows),
        "raised": len(raised),
        "raised_motions": raised[:50],
        "flat_grounded_as_before": sum(r["ground_as_flat"] for r in flat),
        "flat": len(flat),
    }


def corpus(n: int) -> dict:
    from motion_core.corpus.compose import sample_clip
    from motion_core.corpus.kinds import all_kinds
    from motion_core.corpus.kinds.check import clips

    out = {}
    for k in all_kinds():
        rows, raw = {}, {}
        for i, (j, _) in enumerate(clips(k, n, 0)):
            rows[f"{k}/{i}"] = reading(j)
        for i in range(n):
            clip, _ = sample_clip(np.random.default_rng([0, 7919, zlib.crc32(k.encode()), i]), k)
            raw[f"{k}/{i}"] = reading(clip.joints)
        out[k] = {"features": summary(rows), "composed": summary(raw)}
    return out


def bandai(root: Path) -> dict:
    from motion_core.data.mocap import bvh_files, import_clip

    return summary({f.name: reading(import_clip(f).joints) for f in bvh_files(root)})


def cmu(root: Path) -> dict:
    from motion_core.formats.bvh import read_bvh
    from motion_core.formats.retarget import retarget

    rows = {}
    for f in sorted(root.glob("*.bvh")):
        rows[f.name] = reading(retarget(read_bvh(f), ICLONE_CMU)[1:])
    return summary(rows)


def prompts(n: int) -> list[tuple[str, float]]:
    from motion_core.corpus.actions import Spec, sample_spec
    from motion_core.corpus.kinds import REGISTRY
    from motion_core.corpus.text import TEMPLATES, captions_for

    out = []
    rng = np.random.default_rng(0)
    for kind in TEMPLATES:
        out.append((captions_for(Spec(kind), rng, 1)[0], 4.0))
    for kind in REGISTRY:  # the staged kinds (the models have not learned them)
        out.append((captions_for(sample_spec(rng, kind), rng, 1)[0], 4.0))
    stairs = [
        "a person walks up the stairs",
        "a person walks down the stairs",
        "a person climbs stairs",
        "a human walks upstairs",
        "somebody walks downstairs",
        "a person steps on a low platform",
        "a person walks forward and goes up the stairs",
    ]
    out = [(t, 5.0) for t in stairs] + out
    return out[:n]


def generated(n: int, methods: list[str]) -> dict:
    import torch

    from motion_core.inference.generation import generate

    torch.set_num_threads(1)
    seen: list[np.ndarray] = []

    def record(j: np.ndarray) -> np.ndarray:
        seen.append(np.array(j, copy=True))
        return ground(j)

    out = {}
    with (
        mock.patch("motion_core.inference.base.on_floor", record),
        mock.patch("motion_core.inference.latent_diffusion.on_floor", record),
        mock.patch("motion_core.inference.masked.on_floor", record),
    ):
        for m in methods:
            rows = {}
            for text, secs in prompts(n):
                seen.clear()
                generate([(text, secs)], method=m, seed=0)
                for k, j in enumerate(seen):
                    rows[f"{text}#{k}"] = reading(j)
            out[m] = summary(rows)
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--corpus", type=int, default=0, help="clips per corpus kind")
    ap.add_argument("--bandai", type=Path, help="the unpacked Bandai Namco archive")
    ap.add_argument("--cmu", type=Path, help="a folder of CMU BVH files (iClone conversion)")
    ap.add_argument("--generated", type=int, default=0, help="prompts per method")
    ap.add_argument("--methods", default="motion_mamba,kmm,ftmomamba,baseline")
    ap.add_argument("--out", type=Path)
    a = ap.parse_args(argv)
    res: dict = {}
    t = time.time()
    if a.corpus:
        res["corpus"] = corpus(a.corpus)
    if a.bandai:
        res["bandai"] = bandai(a.bandai)
    if a.cmu:
        res["cmu"] = cmu(a.cmu)
    if a.generated:
        res["generated"] = generated(a.generated, a.methods.split(","))
    res["seconds"] = round(time.time() - t, 1)
    text = json.dumps(res, indent=1)
    if a.out:
        a.out.write_text(text + "\n")
    print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
