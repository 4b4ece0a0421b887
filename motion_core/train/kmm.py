"""Training of KMM: the residual VQ-VAE tokeniser, then the masked bidirectional Mamba generator.

    python -m motion_core.train kmm-rvq --data DIR --out runs/kmm_rvq [--steps N]
    python -m motion_core.train kmm-generator --data DIR --rvq runs/kmm_rvq --out runs/kmm [--steps N]
        [--mask keyframe|random] [--no-align] [--init WEIGHTS] [--ship]
    python -m motion_core.train kmm-extract-rvq --from motion_core/weights/kmm.pt --out runs/kmm_rvq
    python -m motion_core.train kmm-rvq --data DIR --out runs/kmm_dec --init runs/kmm_rvq/rvq.pt --decoder-only
    python -m motion_core.train kmm-swap-decoder --rvq runs/kmm_dec --out motion_core/weights/kmm.pt

The tokeniser trains on random 64-frame windows (MoMask's window). The generator stage
tokenises every training clip once (codes, plus each clip's key-frame order from
``keyframes.density_peaks`` on its continuous latents; cached in the run directory) and the
caption embeddings, so a step costs only the generator's forward and backward pass.
``--mask random`` and ``--no-align`` are the paper's Table 4 ablations. Both stages resume
from OUT/state.pt like the other ``train`` programs; ``--ship`` writes weights/kmm.pt (float16:
tokeniser + generator + feature statistics). ``extract-rvq`` writes the tokeniser of a
shipped kmm.pt as a run directory, and ``--init`` starts the generator from the weights of a
shipped kmm.pt or a state.pt (fresh optimiser and schedule), so the shipped generator can be
trained further on its own tokens without retraining the tokeniser.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np
import torch
from tqdm import tqdm

from ..body.features import Normalizer, features_to_joints
from ..data.clips import Clip, load_clips, normalized_features, pad_batch
from ..inference import checkpoints
from ..inference.checkpoints import WEIGHTS, generator_config, load_rvq
from ..models.keyframes import density_peaks
from ..models.kmm import KMMConfig, KMMGenerator
from ..models.overrides import override_config
from ..models.rvq import RVQVAE, RVQConfig
from ..models.vae import mpjpe_mm
from .caches import cached, corpus_fingerprint, file_fingerprint, write_cache
from .distributed import device
from .recipe import check_resume, recipe
from .schedule import learning_rate

WINDOW = 64


@torch.no_grad()
def evaluate_rvq(model: RVQVAE, clips: list[Clip], norm: Normalizer, batch: int = 64) -> dict:
    """Reconstruction MPJPE (mm; global and root-relative) with all quantisers, MPJPE with the
    first one alone, and per-layer codebook usage (share of codes used, perplexity)."""
    model.eval()
    q = model.cfg.quantizers
    tot = {"all": 0.0, "rel": 0.0, "base": 0.0}
    n = 0.0
    counts = torch.zeros(q, model.cfg.codebook_size)
    for i in range(0, len(clips), batch):
        part = clips[i : i + batch]
        x, mask = pad_batch([norm.normalize(c.features) for c in part], model.cfg.downsample)
        codes, _ = model.encode(x, mask)
        tok_mask = mask[:, :: model.cfg.downsample]
        for layer in range(q):
            counts[layer] += torch.bincount(codes[..., layer][tok_mask], minlength=model.cfg.codebook_size).float()
        jx = features_to_joints(norm.denormalize(x))
        jr = features_to_joints(norm.denormalize(model.decode(codes)[:, : x.shape[1]]))
        jb = features_to_joints(norm.denormalize(model.decode(codes[..., :1])[:, : x.shape[1]]))
        w = float(mask.sum())
        tot["all"] += mpjpe_mm(jr, jx, mask) * w
        tot["rel"] += mpjpe_mm(jr - jr[:, :, :1], jx - jx[:, :, :1], mask) * w
        tot["base"] += mpjpe_mm(jb, jx, mask) * w
        n += w
    model.train()
    p = counts / counts.sum(1, keepdim=True)
    perplexity = torch.exp(-(p * torch.log(p.clamp(min=1e-12))).sum(1))
    return {
        "mpjpe_mm": tot["all"] / n,
        "mpjpe_root_relative_mm": tot["rel"] / n,
        "mpjpe_first_quantizer_mm": tot["base"] / n,
        "codebook_usage": [float((c > 0).float().mean()) for c in counts],
        "codebook_perplexity": [float(v) for v in perplexity],
    }


def _windows(feats: list[np.ndarray], batch: int, rng: np.random.Generator) -> tuple[torch.Tensor, torch.Tensor]:
    """A batch of random WINDOW-frame crops (shorter clips padded, mask False on padding)."""
    out = []
    for i in rng.integers(0, len(feats), batch):
        f = feats[i]
        s = int(rng.integers(0, max(1, len(f) - WINDOW + 1)))
        out.append(f[s : s + WINDOW])
    return pad_batch(out, 4)


# what a resumed run must keep, besides its network's config (the mask, alignment and size)
RVQ_RECIPE = ("lr", "batch", "seed", "decoder_only")
GENERATOR_RECIPE = ("lr", "batch", "seed", "pair_prob")


def _save(state_path: Path, model, opt, step: int, rng: np.random.Generator, config: dict, run_recipe: dict) -> None:
    """A resumable training state (``_resume``); ``config`` records the network's size, so a
    generator's state can be rebuilt without its command line (``generator_config``)."""
    state = {"model": model.state_dict(), "opt": opt.state_dict(), "step": step, "rng": rng.bit_generator.state}
    checkpoints.write_state(state_path, **state, config=config, recipe=run_recipe)


def _resume(state_path: Path, model, opt, rng: np.random.Generator, run_recipe: dict) -> int:
    """The step a run resumes at (0 without a state); a state of another recipe or network
    (``--mask random`` on a keyframe run's state) is refused rather than switched mid-run."""
    if not state_path.is_file():
        return 0
    st = checkpoints.read_state(state_path)
    check_resume(st, run_recipe, state_path)
    model.load_state_dict(st["model"])
    opt.load_state_dict(st["opt"])
    rng.bit_generator.state = st["rng"]
    print(f"resumed at step {st['step']}")
    return int(st["step"])


def _lr(base: float, step: int, total: int, warmup: int = 200) -> float:
    return learning_rate(base, step, total, warmup)


def train_rvq(args: argparse.Namespace) -> None:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    torch.manual_seed(args.seed)
    norm = Normalizer.load(args.data)
    t0 = time.time()
    feats = normalized_features(args.data, "train", norm, args.limit)
    val = load_clips(args.data, "val", 256)
    print(f"loaded {len(feats)} train / {len(val)} val clips in {time.time() - t0:.0f} s")
    cfg = rvq_config(args.init, getattr(args, "set", None) or [])
    model = RVQVAE(cfg).to(device())
    if args.decoder_only and not args.init:
        raise SystemExit("--decoder-only fine-tunes a trained tokeniser: give it --init")
    if args.decoder_only:
        # encoder and codebooks frozen, so every clip keeps its codes and a generator trained
        # on them stays valid; only the decoder learns to turn them back into motion
        for p in [*model.encoder.parameters(), *model.quantizer.parameters()]:
            p.requires_grad_(False)
    params = [p for p in model.parameters() if p.requires_grad]
    opt = torch.optim.AdamW(params, lr=args.lr, betas=(0.9, 0.99), weight_decay=0.0)
    rng = np.random.default_rng(args.seed)
    state_path = out / "state.pt"
    run_recipe = recipe(args, RVQ_RECIPE, **{"network config": cfg.to_dict()})
    step = _resume(state_path, model, opt, rng, run_recipe)
    init_steps = _init_once(out, step, args.init, lambda path: checkpoints.init_rvq(model, path), "tokeniser")
    log = []
    bar = tqdm(total=args.steps, initial=step, desc="rvq", dynamic_ncols=True)
    while step < args.steps:
        for g in opt.param_groups:
            g["lr"] = _lr(args.lr, step, args.steps)
        x, mask = _windows(feats, args.batch, rng)
        model.train()
        if args.decoder_only:
            model.quantizer.eval()  # no EMA updates of the codebooks
        res = model(x.to(device()), mask.to(device()))
        opt.zero_grad(set_to_none=True)
        res["loss"].backward()
        torch.nn.utils.clip_grad_norm_(params, 1.0)
        opt.step()
        step += 1
        bar.update(1)
        bar.set_postfix(rec=f"{res['rec_loss'].item():.4f}", commit=f"{res['commit'].item():.3f}")
        if step % args.save_every == 0 or step == args.steps:
            ev = evaluate_rvq(model, val, norm)
            log.append({"step": step, "loss": res["loss"].item(), **ev})
            bar.write(json.dumps({k: v for k, v in log[-1].items() if "codebook" not in k}))
            _save(state_path, model, opt, step, rng, cfg.to_dict(), run_recipe)
    bar.close()
    test = evaluate_rvq(model, load_clips(args.data, "test", 500), norm)
    meta = {
        "kind": "rvq",
        "config": cfg.to_dict(),
        "steps": init_steps + step,
        "init": {"from": str(args.init), "steps": init_steps} if args.init else None,
        # the whole lineage's decoder-only steps: the --init weights' own plus this run's
        "decoder_only_steps": (checkpoints.decoder_only_steps(args.init) if args.init else 0)
        + (step if args.decoder_only else 0),
        "data": str(args.data),
        "test_500": test,
        "mean": norm.mean.tolist(),
        "std": norm.std.tolist(),
    }
    res_path = out / "result.json"
    old_log = json.loads(res_path.read_text()).get("log", []) if res_path.is_file() else []
    res_path.write_text(json.dumps({"log": old_log + log, "test_500": test}, indent=1))
    checkpoints.save_run(out / "rvq.pt", model, meta)
    if getattr(args, "stage", None):
        checkpoints.ship(Path(args.stage), model, meta)  # float16: the next stage's --init
    print(json.dumps({"test_500": test}))


# the fields --set may change: the loss's weights, which leave the network's shape (and so an
# --init's weights) as they are
RVQ_LOSS_FIELDS = ("position_weight", "upper_detail_weight", "foot_weight", "root_weight", "velocity_weight")
RVQ_LOSS_FIELDS += ("trajectory_weight", "commitment")


def rvq_config(init: str | None, assignments: list[str]) -> RVQConfig:
    """The tokeniser's config: the ``--init`` weights' own (``checkpoints.rvq_config_of``), so a
    stage trained with a heavier position weight goes on with it; the defaults without --init
    or where none is recorded; with ``--set`` loss weights on top."""
    base = (checkpoints.rvq_config_of(init) if init else None) or RVQConfig()
    bad = [a for a in assignments if a.partition("=")[0] not in RVQ_LOSS_FIELDS]
    if bad:
        known = ", ".join(RVQ_LOSS_FIELDS)
        raise SystemExit(f"--set {bad[0]}: the tokeniser's --set takes a loss weight, one of {known}")
    try:
        return override_config(base, assignments)
    except ValueError as e:
        raise SystemExit(f"--set: {e}") from None


def _init_once(out: Path, step: int, init: str | None, load, what: str) -> int:
    """``--init``: load the initial weights (``load(path)`` -> the steps they had) on a fresh
    run and record them in OUT/init.json; a resumed run (step > 0) already holds them plus its
    own steps, so only the record is read. Returns the initial weights' steps (0 without --init)."""
    if not init:
        return 0
    if step:
        return int(json.loads((out / "init.json").read_text())["steps"])
    steps = load(init)
    (out / "init.json").write_text(json.dumps({"from": str(init), "steps": steps}))
    print(f"{what} initialised from {init} ({steps} steps)")
    return steps


@torch.no_grad()
def tokenize_corpus(args: argparse.Namespace) -> dict[str, np.ndarray]:
    """Codes (all clips concatenated, with offsets) and the key-frame rank of every token
    (0 = highest gamma), cached as RVQ_RUN/tokens.npz; caption embeddings shared with the
    diffusion methods' cache when a VAE run is given, else encoded here."""
    cache = Path(args.rvq) / "tokens.npz"
    # a smoke run's --limit, another corpus or a retrained tokeniser must not be trained on
    fp = corpus_fingerprint(args.data, args.limit) + file_fingerprint(Path(args.rvq) / "rvq.pt")
    if (data := cached(cache, fp, "corpus, --limit or tokeniser")) is not None:
        return data
    from ..nn.text import get_text_encoder

    model, meta = load_rvq(Path(args.rvq) / "rvq.pt")
    norm = Normalizer(np.asarray(meta["mean"]), np.asarray(meta["std"]))
    clips = load_clips(args.data, "train", args.limit)
    codes: list = [None] * len(clips)
    ranks: list = [None] * len(clips)
    # clips of equal length go through together: no padding, so each is encoded exactly as alone
    by_len: dict[int, list[int]] = {}
    for i, c in enumerate(clips):
        by_len.setdefault(c.frames, []).append(i)
    groups = [idx[k : k + 256] for idx in by_len.values() for k in range(0, len(idx), 256)]
    for idx in tqdm(groups, desc="tokenise (batches of equal length)"):
        x = torch.from_numpy(np.stack([norm.normalize(clips[i].features) for i in idx]).astype(np.float32))
        cd, z = model.encode(x)
        for j, i in enumerate(idx):
            _, _, gamma = density_peaks(z[j].numpy())
            order = np.argsort(-gamma, kind="stable")
            rank = np.empty_like(order)
            rank[order] = np.arange(len(order))
            codes[i] = cd[j].numpy().astype(np.int16)
            ranks[i] = rank.astype(np.int16)
    lengths = [len(cd) for cd in codes]
    enc = get_text_encoder()
    caps = [c.captions for c in clips]
    emb = enc.encode([t for cs in caps for t in cs]).numpy().astype(np.float32)
    data = {
        "codes": np.concatenate(codes),
        "ranks": np.concatenate(ranks),
        "offsets": np.concatenate([[0], np.cumsum(lengths)]).astype(np.int64),
        "text": emb,
        "text_clip": np.repeat(np.arange(len(clips)), [len(cs) for cs in caps]),
        "empty": enc.encode([""]).numpy().astype(np.float32)[0],
    }
    write_cache(cache, data, fp)
    return data


@torch.no_grad()
def caption_words(args: argparse.Namespace) -> dict[str, np.ndarray]:
    """Token embeddings of the training captions for word pooling, cached as RVQ_RUN/words.npz:
    "tokens" (U + 1, L, D) float16 and "mask" (U + 1, L) for the U distinct captions and, last,
    the empty text; "index" (captions,) maps ``tokenize_corpus``'s caption order to their rows."""
    cache = Path(args.rvq) / "words.npz"
    fp = corpus_fingerprint(args.data, args.limit)
    if (data := cached(cache, fp, "corpus or --limit")) is not None:
        return data
    from ..nn.text import get_text_encoder

    caps = [t for c in load_clips(args.data, "train", args.limit) for t in c.captions]
    uniq = list(dict.fromkeys(caps))
    row = {t: i for i, t in enumerate(uniq)}
    tokens, mask = get_text_encoder().encode_words([*uniq, ""])
    data = {
        "tokens": tokens.numpy().astype(np.float16),
        "mask": mask.numpy(),
        "index": np.array([row[t] for t in caps], dtype=np.int64),
    }
    write_cache(cache, data, fp)
    return data


def _batch(data: dict, cfg: KMMConfig, batch: int, pair_prob: float, rng: np.random.Generator) -> dict:
    """A training batch: each sample one clip (a random caption of it) or, with probability
    ``pair_prob``, two clips one after the other with their own captions (a two-segment
    timeline, so the model learns to condition spans on their own texts)."""
    off, text_clip = data["offsets"], data["text_clip"]
    seqs = []
    for _ in range(batch):
        parts = []
        for _ in range(2 if rng.random() < pair_prob else 1):
            cap = int(rng.integers(0, len(text_clip)))
            c = int(text_clip[cap])
            sl = slice(int(off[c]), int(off[c + 1]))
            n = sl.stop - sl.start
            key = data["ranks"][sl] < max(1, math.ceil(cfg.keyframe_ratio * n))
            parts.append((data["codes"][sl], key, cap))
        seqs.append(parts)
    n_max = max(sum(len(p[0]) for p in parts) for parts in seqs)
    codes = np.zeros((batch, n_max, cfg.quantizers), np.int64)
    is_key = np.zeros((batch, n_max), bool)
    valid = np.zeros((batch, n_max), bool)
    seg_ids = np.zeros((batch, n_max), np.int64)
    caps = []
    for b, parts in enumerate(seqs):
        s = 0
        for cd, key, cap in parts:
            n = len(cd)
            codes[b, s : s + n], is_key[b, s : s + n], valid[b, s : s + n] = cd, key, True
            seg_ids[b, s : s + n] = len(caps)
            caps.append(cap)
            s += n
    return {
        "codes": torch.from_numpy(codes),
        "is_key": torch.from_numpy(is_key),
        "valid": torch.from_numpy(valid),
        "seg_ids": torch.from_numpy(seg_ids),
        "caps": np.array(caps),
    }


def train_generator(args: argparse.Namespace) -> None:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    torch.manual_seed(args.seed)
    # a trained generator's scan decays reach subnormal floats in the backward pass, which
    # made a step about 1.3x slower on our CPU; flushing to zero drops only |x| < 1.2e-38
    torch.set_flush_denormal(True)
    data = tokenize_corpus(args)
    text = torch.from_numpy(data["text"])
    empty = torch.from_numpy(data["empty"])
    # width and depth: options so that a wider generator can be tried (the default, d 128 x 4
    # layers, is sized for the 150 ms target); --init and a resumed state must match them
    size = {k: v for k, v in (("d_model", args.d_model), ("layers", args.layers)) if v}
    # a generator that reads segment phase cannot drop it: --init from one keeps the term
    phase = args.phase or bool(args.init and generator_config(args.init).phase)
    cfg = KMMConfig(mask=args.mask, align=not args.no_align, word_pool=args.word_pool, phase=phase, **size)
    words = caption_words(args) if cfg.word_pool else None
    if words is not None and len(words["index"]) != len(data["text_clip"]):
        raise RuntimeError(f"{args.rvq}/words.npz and tokens.npz hold different captions: delete words.npz")
    model = KMMGenerator(cfg).to(device())
    opt = torch.optim.AdamW(model.parameters(), lr=args.lr, betas=(0.9, 0.99), weight_decay=0.01)
    rng = np.random.default_rng(args.seed)
    g = torch.Generator().manual_seed(args.seed)
    state_path = out / "state.pt"
    run_recipe = recipe(args, GENERATOR_RECIPE, **{"network config": cfg.to_dict()})
    step = _resume(state_path, model, opt, rng, run_recipe)
    init_steps = _init_once(out, step, args.init, lambda path: checkpoints.init_generator(model, path), "generator")
    n_params = sum(p.numel() for p in model.parameters())
    print(f"kmm generator: {n_params / 1e6:.2f} M parameters, {len(data['offsets']) - 1} clips")
    log, ema = [], {}
    # --stop-at: end early on the schedule of --steps (ablation arms compared at equal steps)
    stop = min(args.steps, args.stop_at or args.steps)
    bar = tqdm(total=stop, initial=step, desc="kmm", dynamic_ncols=True)
    while step < stop:
        for grp in opt.param_groups:
            grp["lr"] = _lr(args.lr, step, args.steps)
        bt = _batch(data, cfg, args.batch, args.pair_prob, rng)
        seg_text = text[bt["caps"]].clone()
        drop = torch.from_numpy(rng.random(len(seg_text)) < cfg.cond_drop)
        seg_text[drop] = empty
        caps = bt["caps"]
        same = torch.from_numpy(data["text"][caps] @ data["text"][caps].T > 0.9999)
        seg_words = seg_word_mask = None
        if words is not None:
            row = np.where(drop.numpy(), len(words["mask"]) - 1, words["index"][caps])
            seg_word_mask = torch.from_numpy(words["mask"][row])
            width = int(seg_word_mask.sum(1).max())
            seg_word_mask = seg_word_mask[:, :width]
            seg_words = torch.from_numpy(words["tokens"][row, :width].astype(np.float32))
        res = model.loss(
            bt["codes"], bt["is_key"], bt["valid"], bt["seg_ids"], seg_text, drop, same, g, seg_words, seg_word_mask
        )
        opt.zero_grad(set_to_none=True)
        res["loss"].backward()
        torch.nn.utils.clip_grad_norm_(model.parameters(), 1.0)
        opt.step()
        step += 1
        for k, v in res.items():
            ema[k] = v.item() if k not in ema else 0.98 * ema[k] + 0.02 * v.item()
        bar.update(1)
        bar.set_postfix(ce=f"{ema['ce_base']:.3f}", acc=f"{ema['acc_base']:.3f}", align=f"{ema.get('align', 0):.3f}")
        if step % args.save_every == 0 or step == stop:
            log.append({"step": step, **{k: round(v, 4) for k, v in ema.items()}})
            bar.write(json.dumps(log[-1]))
            _save(state_path, model, opt, step, rng, cfg.to_dict(), run_recipe)
    bar.close()
    rvq, rvq_meta = load_rvq(Path(args.rvq) / "rvq.pt")
    res_path = out / "result.json"
    old_log = json.loads(res_path.read_text()).get("log", []) if res_path.is_file() else []
    if not ema and old_log:  # a finished run rerun (to --ship it): its last logged losses
        ema = {k: v for k, v in old_log[-1].items() if k != "step"}
    meta = {
        "kind": "kmm",
        "config": cfg.to_dict(),
        "rvq_config": rvq_meta["config"],
        "rvq_test_500": rvq_meta.get("test_500"),
        "rvq_steps": rvq_meta["steps"],
        "rvq_decoder_only_steps": rvq_meta.get("decoder_only_steps", 0),
        "steps": init_steps + step,
        "init": {"from": str(args.init), "steps": init_steps} if args.init else None,
        "batch": args.batch,
        "params": n_params,
        "final": ema,
        "data": str(args.data),
        "mean": rvq_meta["mean"],
        "std": rvq_meta["std"],
    }
    res_path.write_text(json.dumps({"log": old_log + log, "meta": meta}, indent=1))
    checkpoints.save_kmm(out / "kmm.pt", model, rvq, meta)
    if args.stage:  # float16, as shipped: a stage in stages/ that the next run --init's
        checkpoints.save_kmm(Path(args.stage), model, rvq, meta, half=True)
    if args.ship:
        checkpoints.save_kmm(WEIGHTS / "kmm.pt", model, rvq, meta, half=True)
