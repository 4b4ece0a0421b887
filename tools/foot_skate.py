"""Foot skate before and after foot locking, with the verifier beside it.

    python tools/foot_skate.py --data data/corpus_real --split val --methods kmm,baseline
    python tools/foot_skate.py --data data/corpus_real --split test --out results/foot_skate.json

Generates one motion per prompt and method (n prompts of the split, seed = prompt index, as
``evaluate`` does; cached in --cache so that a sweep of lock settings costs seconds), then
scores each motion as generated and with ``motion_core.body.footlock.lock_feet``:

* planted-phase slide: for every phase the lock's contact detector finds on that motion,
  the largest horizontal distance of the toe from where the phase began (cm);
* floor-contact slide: the corpus's realism figure (``corpus.check.foot_slides``: every run
  of an ankle or toe within 2.5 cm of its flat-foot height), which also counts a foot that
  skims the floor while it swings;
* GMD's foot-skating ratio (frames where a toe below 5 cm moves over 2.5 cm);
* the verifier's pass rate, and the largest change of any bone's length.

Settings are chosen on the validation split; the test split only reports.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from motion_core.body.footlock import FootLockConfig, contact_phases, lock_feet
from motion_core.body.skeleton import HUMANML3D
from motion_core.data.clips import spread_clips
from motion_core.eval.metrics import foot_skating_ratio
from motion_core.verify.realism import foot_slides
from motion_core.verify.rules import verify


def motions(data: str, split: str, n: int, method: str, cache: Path) -> tuple[list, list[np.ndarray]]:
    prompts = spread_clips(data, split, n, "procedural")
    key = f"{method}_{split}_{n}_unlocked"
    store = dict(np.load(cache, allow_pickle=True)) if cache.is_file() else {}
    if key not in store:
        from motion_core import generate

        out = []
        for i, c in enumerate(prompts):
            motion = generate([(c.captions[0], c.frames / 20.0)], method=method, seed=i, foot_lock=False)
            out.append(motion.joints.astype(np.float32))
            print(f"\r{method} {i + 1}/{len(prompts)}", end="", file=sys.stderr, flush=True)
        print(file=sys.stderr)
        store[key] = np.array(out, dtype=object)
        cache.parent.mkdir(parents=True, exist_ok=True)
        np.savez(cache, **store)
    return prompts, [np.asarray(j, np.float64) for j in store[key]]


def planted_slides(j: np.ndarray, cfg: FootLockConfig) -> list[float]:
    out = []
    for _, toe in HUMANML3D.feet:
        for s, e in contact_phases(j, toe, cfg):
            out.append(float(np.linalg.norm(j[s:e, toe][:, [0, 2]] - j[s, toe][[0, 2]], axis=-1).max()))
    return out


def bones(j: np.ndarray) -> np.ndarray:
    return np.stack([np.linalg.norm(j[:, c] - j[:, p], axis=-1) for c, p in enumerate(HUMANML3D.parents) if p >= 0], 1)


def score(prompts: list, joints: list[np.ndarray], cfg: FootLockConfig, locked: bool) -> dict:
    planted, floor, ratio, passed, bone_change = [], [], [], [], 0.0
    for c, j in zip(prompts, joints, strict=True):
        k = lock_feet(j, cfg).joints if locked else j
        planted += planted_slides(k, cfg)
        floor += foot_slides(k)
        ratio.append(foot_skating_ratio(k))
        passed.append(verify(k, c.labels).passed)
        bone_change = max(bone_change, float(np.abs(bones(k) - bones(j)).max()))

    def cm(v: list[float], q: float | None = None) -> float:
        return round(100 * float(np.percentile(v, q) if q else np.mean(v)), 2) if v else 0.0

    return {
        "planted_phases": len(planted),
        "planted_slide_cm_mean": cm(planted),
        "planted_slide_cm_p95": cm(planted, 95),
        "floor_slide_cm_mean": cm(floor),
        "floor_slide_cm_p95": cm(floor, 95),
        "skate_ratio": round(float(np.mean(ratio)), 4),
        "verifier": round(float(np.mean(passed)), 4),
        "bone_change_mm": round(1000 * bone_change, 4),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", required=True)
    ap.add_argument("--methods", default="kmm,motion_mamba,ftmomamba,baseline")
    ap.add_argument("--split", default="val", choices=["val", "test"])
    ap.add_argument("--n", type=int, default=200)
    ap.add_argument("--cache", default="runs/foot_skate_motions.npz")
    ap.add_argument("--speed", type=float, action="append", help="lock settings to compare (m/s); default: the default")
    ap.add_argument("--out", default=None)
    args = ap.parse_args()
    speeds = args.speed or [FootLockConfig().speed]
    table: dict = {"split": args.split, "n": args.n, "settings": {}, "methods": {}}
    for m in args.methods.split(","):
        prompts, joints = motions(args.data, args.split, args.n, m, Path(args.cache))
        rows = {"as generated": score(prompts, joints, FootLockConfig(), locked=False)}
        for v in speeds:
            cfg = FootLockConfig(speed=v)
            table["settings"][f"locked, speed {v}"] = cfg.__dict__
            rows[f"locked, speed {v}"] = score(prompts, joints, cfg, locked=True)
        table["methods"][m] = rows
        for name, r in rows.items():
            print(m, name, json.dumps(r))
    if args.out:
        Path(args.out).write_text(json.dumps(table, indent=1))


if __name__ == "__main__":
    main()
