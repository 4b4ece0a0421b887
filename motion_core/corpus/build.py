"""Build the corpus on disk in the HumanML3D directory format, plus BABEL-style sequences.

Layout written under OUT::

    new_joint_vecs/<id>.npy  texts/<id>.txt  train.txt val.txt test.txt  Mean.npy Std.npy
    labels.jsonl                 one line per clip: id, split, source, labels, captions, frames
    babel/motions/<id>.npy       multi-segment sequences (features)
    babel/{train,val,test}.json  BABEL-style segment annotations
    babel/{split}_labels.jsonl   per-segment structured labels and captions
    (with chains) new_joint_vecs/c<i>.npy  2-3 actions in one clip under one sentence (chain.py)
    corpus.json                  build settings, counts, time

Clip i is generated from ``np.random.default_rng([seed, i])`` (sequences from
``[seed, 1, i]``, chains from ``[seed, 2, i]``), so the output does not depend on the number of workers. The rare clip
whose realism figures fall outside the check's bounds (about 0.1%: the gait scheduler can
let a foot lag on a fast diagonal start, and the pelvis then sinks to reach it) is
regenerated from the sub-stream ``[seed, i, k]``; the count is reported in corpus.json.

``staged=True`` draws the single clips and chains from every registered kind, the staged ones
too (``kinds.all_kinds()``): the corpus the models are retrained on before a staged kind
becomes a trained one. The default build draws from CATALOGUE alone and is unchanged by it.
"""

from __future__ import annotations

import hashlib
import json
import multiprocessing
import os
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..body.features import HML_LAYOUT, Normalizer, features_to_joints, joints_to_features
from ..data.babel import Segment, write_babel
from ..data.humanml3d import Caption, MotionSample, write_sample, write_splits
from ..verify.realism import realism
from .chain import chain_captions, chain_labels, sample_chain
from .compose import sample_clip, sample_sequence
from .text import captions_for

SPLIT_ORDER = ("train", "val", "test")


@dataclass
class BuildConfig:
    out: Path
    train: int = 20000
    val: int = 1000
    test: int = 2000
    seq_train: int = 1000
    seq_val: int = 50
    seq_test: int = 100
    seed: int = 0
    workers: int = 2
    captions_per_clip: int = 3
    real_archive: Path | None = None  # the Bandai Namco BVH archive (CC BY-NC 4.0), or None
    real_cache: Path = Path(".cache/bandai-namco")  # where it is unpacked (never into git)
    real_limit: int | None = None  # every k-th clip so that about this many are imported (tests)
    staged: bool = False  # draw from the staged kinds too (the corpus to retrain on)
    chain_train: int = 0  # clips of 2-3 actions under one sentence (chain.py)
    chain_val: int = 0
    chain_test: int = 0


MAX_ATTEMPTS = 8


def _realistic(feats: np.ndarray) -> bool:
    return not realism(features_to_joints(feats)).violations()


def _kinds(staged: bool) -> list[str] | None:
    from .kinds import all_kinds

    return all_kinds(staged=True) if staged else None


def _write_clip(out: str, cid: str, split: str, feats: np.ndarray, labels: dict, caps: list[str], k: int) -> dict:
    """Write one procedural clip (features (T, 263) and captions); its labels.jsonl record,
    with the training split's feature moments for the normaliser."""
    write_sample(out, MotionSample(cid, feats, [Caption(c) for c in caps]))
    f64 = feats.astype(np.float64)
    return {
        "id": cid,
        "split": split,
        "source": "procedural",
        "labels": labels,
        "captions": caps,
        "frames": len(feats),
        "rejected": k,
        "moments": (f64.sum(0), (f64**2).sum(0), len(f64)) if split == "train" else None,
    }


def _clip_job(args: tuple[str, int, int, str, int, bool]) -> dict:
    out, seed, i, split, n_caps, staged = args
    kinds = _kinds(staged)
    # Rejection sampling on the realism bounds only (never on the verifier, whose pass rate
    # must stay a measurement): attempt k > 0 draws from the sub-stream [seed, i, k].
    for k in range(MAX_ATTEMPTS):
        rng = np.random.default_rng([seed, i] if k == 0 else [seed, i, k])
        clip, spec = sample_clip(rng, kinds=kinds)
        feats = joints_to_features(clip.joints)
        if _realistic(feats):
            break
    return _write_clip(out, f"{i:06d}", split, feats, spec.labels(), captions_for(spec, rng, n_caps), k)


def _seq_job(args: tuple[str, int, int, str]) -> dict:
    out, seed, i, split = args
    for k in range(MAX_ATTEMPTS):
        rng = np.random.default_rng([seed, 1, i] if k == 0 else [seed, 1, i, k])
        n_seg = int(rng.integers(3, 7))
        comp = sample_sequence(rng, n_seg)
        feats = joints_to_features(comp.joints)
        if _realistic(feats):
            break
    sid = f"s{i:05d}"
    path = Path(out) / "babel" / "motions" / f"{sid}.npy"
    path.parent.mkdir(parents=True, exist_ok=True)
    np.save(path, feats)
    segs = []
    for a, b, spec in comp.segments:
        caps = captions_for(spec, rng, 3)
        segs.append(
            {
                "start_frame": a,
                "end_frame": min(b, len(feats)),
                "text": caps[0],
                "captions": caps,
                "labels": spec.labels(),
            }
        )
    return {"id": sid, "split": split, "frames": len(feats), "fps": comp.fps, "segments": segs, "rejected": k}


def _chain_job(args: tuple[str, int, int, str, int, bool]) -> dict:
    out, seed, i, split, n_caps, staged = args
    kinds = _kinds(staged)
    for k in range(MAX_ATTEMPTS):
        rng = np.random.default_rng([seed, 2, i] if k == 0 else [seed, 2, i, k])
        # Two actions more often than three, as in real multi-action captions.
        comp = sample_chain(rng, 2 if rng.random() < 0.6 else 3, kinds)
        feats = joints_to_features(comp.joints)
        if _realistic(feats):
            break
    caps = chain_captions([spec for _, _, spec in comp.segments], rng, n_caps)
    return _write_clip(out, f"c{i:05d}", split, feats, chain_labels(comp), caps, k)


def real_split(clip_id: str) -> str:
    """Whole real clips to splits by a hash of their id: ~10% test, ~5% val, the rest train."""
    h = int(hashlib.sha1(clip_id.encode()).hexdigest(), 16) % 100
    return "test" if h < 10 else "val" if h < 15 else "train"


def _real_job(args: tuple[str, str]) -> dict:
    """Import one real clip; clips whose claimed side or turn the motion contradicts are skipped."""
    from ..data.mocap import VERIFIER_LABELS, clip_texts, import_clip

    out, path = args
    clip = import_clip(path)
    n = clip.name
    row = {"id": n.clip_id, "source": "real", "content": n.content, "style": n.style, "file": Path(path).name}
    if not clip.directions.agrees:
        return {**row, "skipped": f"claims {clip.directions.claimed}, the motion shows {clip.directions.measured}"}
    feats = joints_to_features(clip.joints)
    caps = clip_texts(n.content, n.style, clip.directions.measured)
    write_sample(out, MotionSample(n.clip_id, feats, [Caption(c) for c in caps]))
    split = real_split(n.clip_id)
    labels = {**VERIFIER_LABELS.get(n.content, {"kind": f"real:{n.content}"}), "source": "real", "style": n.style}
    f64 = feats.astype(np.float64)
    return {
        **row,
        "split": split,
        "labels": labels,
        "captions": caps,
        "frames": len(feats),
        "rejected": 0,
        "moments": (f64.sum(0), (f64**2).sum(0), len(f64)) if split == "train" else None,
    }


def build(cfg: BuildConfig, progress: bool = True) -> dict:
    """Write the whole corpus; returns the summary also saved as corpus.json."""
    t0 = time.time()
    out = Path(cfg.out)
    out.mkdir(parents=True, exist_ok=True)
    counts = {"train": cfg.train, "val": cfg.val, "test": cfg.test}
    jobs = []
    i = 0
    for split in SPLIT_ORDER:
        for _ in range(counts[split]):
            jobs.append((str(out), cfg.seed, i, split, cfg.captions_per_clip, cfg.staged))
            i += 1
    chain_counts = {"train": cfg.chain_train, "val": cfg.chain_val, "test": cfg.chain_test}
    chain_jobs = []
    c = 0
    for split in SPLIT_ORDER:
        for _ in range(chain_counts[split]):
            chain_jobs.append((str(out), cfg.seed, c, split, cfg.captions_per_clip, cfg.staged))
            c += 1
    seq_counts = {"train": cfg.seq_train, "val": cfg.seq_val, "test": cfg.seq_test}
    seq_jobs = []
    k = 0
    for split in SPLIT_ORDER:
        for _ in range(seq_counts[split]):
            seq_jobs.append((str(out), cfg.seed, k, split))
            k += 1

    from tqdm import tqdm

    workers = max(1, cfg.workers)
    results: list[dict] = []
    seqs: list[dict] = []
    with process_pool(workers) if workers > 1 else _Inline() as ex:
        it = ex.map(_clip_job, jobs, chunksize=64)
        for r in tqdm(it, total=len(jobs), desc="clips", disable=not progress, mininterval=2):
            results.append(r)
        if chain_jobs:
            it = ex.map(_chain_job, chain_jobs, chunksize=16)
            for r in tqdm(it, total=len(chain_jobs), desc="chains", disable=not progress, mininterval=2):
                results.append(r)
        it = ex.map(_seq_job, seq_jobs, chunksize=8)
        for r in tqdm(it, total=len(seq_jobs), desc="sequences", disable=not progress, mininterval=2):
            seqs.append(r)
        skipped: list[dict] = []
        if cfg.real_archive is not None:
            from ..data.mocap import bvh_files, unpack_archive

            root = unpack_archive(cfg.real_archive, cfg.real_cache)
            files = bvh_files(root)
            if cfg.real_limit:
                files = files[:: max(1, len(files) // cfg.real_limit)]
            real_jobs = [(str(out), str(f)) for f in files]
            it = ex.map(_real_job, real_jobs, chunksize=16)
            for r in tqdm(it, total=len(real_jobs), desc="real clips", disable=not progress, mininterval=2):
                (skipped if "skipped" in r else results).append(r)

    splits = {s: [r["id"] for r in results if r["split"] == s] for s in SPLIT_ORDER}
    write_splits(out, splits)
    s1 = sum(r["moments"][0] for r in results if r["moments"] is not None)
    s2 = sum(r["moments"][1] for r in results if r["moments"] is not None)
    n = sum(r["moments"][2] for r in results if r["moments"] is not None)
    if n:
        Normalizer.from_moments(s1, s2, n, HML_LAYOUT).save(out)
    with open(out / "labels.jsonl", "w", encoding="utf-8") as f:
        for r in results:
            f.write(json.dumps({k: v for k, v in r.items() if k != "moments"}) + "\n")
    for split in SPLIT_ORDER:
        mine = [s for s in seqs if s["split"] == split]
        write_babel(
            out / "babel" / f"{split}.json",
            [
                (
                    s["id"],
                    f"motions/{s['id']}.npy",
                    s["frames"] / s["fps"],
                    [Segment(g["start_frame"] / s["fps"], g["end_frame"] / s["fps"], g["text"]) for g in s["segments"]],
                )
                for s in mine
            ],
        )
        with open(out / "babel" / f"{split}_labels.jsonl", "w", encoding="utf-8") as f:
            for s in mine:
                f.write(json.dumps(s) + "\n")
    summary = {
        "seed": cfg.seed,
        "clips": {
            s: sum(r["split"] == s and r.get("source") != "real" and r["labels"]["kind"] != "chain" for r in results)
            for s in SPLIT_ORDER
        },
        "sequences": {s: seq_counts[s] for s in SPLIT_ORDER},
        **({"staged": cfg.staged, "chains": chain_counts} if chain_jobs or cfg.staged else {}),
        "distinct_actions": len({_action_key(r["labels"]) for r in results if r["labels"]["kind"] != "chain"}),
        "frames": int(sum(r["frames"] for r in results if r.get("source") != "real")),
        "sequence_seconds": float(sum(s["frames"] / s["fps"] for s in seqs)),
        "rejected_for_realism": {
            "clips": int(sum(r["rejected"] for r in results)),
            "sequences": int(sum(q["rejected"] for q in seqs)),
        },
        "build_seconds": round(time.time() - t0, 1),
        "workers": workers,
        "source": "procedural" if cfg.real_archive is None else "procedural+real",
    }
    if cfg.real_archive is not None:
        from ..data.mocap import LICENCE

        real = [r for r in results if r.get("source") == "real"]
        summary["real"] = {
            "clips": {s: sum(r["split"] == s for r in real) for s in SPLIT_ORDER},
            "frames": int(sum(r["frames"] for r in real)),
            "skipped_direction_disagreement": [f"{r['file']}: {r['skipped']}" for r in skipped],
            "licence": LICENCE,
        }
    (out / "corpus.json").write_text(json.dumps(summary, indent=1))
    return summary


def _action_key(labels: dict) -> str:
    tag = labels.get("side") or labels.get("direction") or ""
    return f"{labels['kind']}:{tag}"


class _Inline:
    """A stand-in executor for workers=1 (easier to debug and profile)."""

    def __enter__(self) -> _Inline:
        return self

    def __exit__(self, *exc: object) -> None:
        return None

    def map(self, fn, items, chunksize: int = 1):
        return map(fn, items)


def default_workers() -> int:
    return max(1, min(os.cpu_count() or 1, 8))


def process_pool(workers: int) -> ProcessPoolExecutor:
    """A pool whose workers are spawned, not forked: the workers use torch, and forking a
    parent whose torch/OpenMP thread pool is already running can deadlock the children
    (seen in the test suite, where earlier tests had used torch)."""
    return ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"))
