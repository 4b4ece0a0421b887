"""A denoiser's training data in one small file, for a machine without the corpus.

The denoisers train on two caches beside the VAE run (``denoiser.encode_corpus``): the
posterior moments of every training clip (22,575 x 50 x 16 twice, 145 MB) and the
embedding of every caption (67,725 x 384, 105 MB). A lent GPU machine takes a 64 MiB
working tree and has neither the 3.3 GB corpus nor the text encoder, so the pack keeps
what a step reads, smaller:

- ``mu``: float16, only each clip's own tokens (a temporal latent's padding is never read:
  the cache holds it as mu 0, log-variance -30, and so does ``read_pack``), concatenated;
  ``tokens`` says how many each clip has. Rounding to float16 moves a latent by under 5e-4
  of its own size (0.0075 at most here; the latents' std is 1.08).
- ``logvar``: the same tokens, quantised to 1/8 on [-30, 1.875] (uint8; values outside
  it are refused). That moves a posterior std by at most 3.2% (exp(1/32)), and the
  posterior std is about 1% of the latent's, so a draw moves by about 0.03% of its scale.
- ``text``: the distinct caption embeddings (7,188 of 67,725 here; the corpus's captions
  repeat), float16, and ``text_row``: each caption's row in it.

``read_pack`` returns the arrays ``encode_corpus`` does (float32, padded), so the training
loop is the same either way. The pack keeps the caches' fingerprint, and reading it checks
the VAE part against the VAE it is trained with.

A pack may also hold the validation prompts of each source (``validation``): their first
captions, lengths and the verifier's labels as JSON, and the captions' embeddings (float32,
as the text encoder gives them). With them a machine without the text encoder scores
``--val-every`` on the same prompts as this one (``read_validation``).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

LOGVAR_MIN, LOGVAR_STEP = -30.0, 0.125


def write_pack(
    data: dict[str, np.ndarray],
    fingerprint: str,
    frames_per_token: int,
    out: str | Path,
    validation: dict[str, dict] | None = None,
) -> Path:
    """Write ``encode_corpus``'s arrays (mu, logvar (N, T, C); frames (N,); text (M, 384),
    text_clip (M,), empty (384,)) to ``out`` (npz, compressed). ``validation``: per source,
    {"n": prompts asked for, "captions": [str], "frames": [int], "labels": [dict],
    "embeddings": (P, 384)}."""
    mu, lv, frames = data["mu"], data["logvar"], data["frames"]
    n_tok = mu.shape[1]
    tokens = np.minimum((frames + frames_per_token - 1) // frames_per_token, n_tok) if frames_per_token else None
    if tokens is None:  # a latent of a few tokens per clip (no padding): every token is the clip's
        tokens = np.full(len(mu), n_tok, np.int64)
    keep = np.arange(n_tok)[None] < tokens[:, None]
    top = LOGVAR_MIN + 255 * LOGVAR_STEP
    if keep.any() and (lv[keep].max() > top + LOGVAR_STEP / 2 or lv[keep].min() < LOGVAR_MIN - LOGVAR_STEP / 2):
        raise ValueError(f"log-variances outside [{LOGVAR_MIN:g}, {top:g}] do not fit the pack's quantisation")
    q = np.clip(np.rint((lv[keep] - LOGVAR_MIN) / LOGVAR_STEP), 0, 255).astype(np.uint8)
    uniq, row = np.unique(data["text"], axis=0, return_inverse=True)
    extra: dict[str, np.ndarray] = {}
    for source, v in (validation or {}).items():
        prompts = [{"caption": c, "labels": lab} for c, lab in zip(v["captions"], v["labels"], strict=True)]
        extra[f"val_{source}_prompts"] = np.array(json.dumps(prompts))
        extra[f"val_{source}_frames"] = np.asarray(v["frames"], np.int32)
        extra[f"val_{source}_emb"] = np.asarray(v["embeddings"], np.float32)
        extra[f"val_{source}_n"] = np.array(int(v["n"]))
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)  # the README's `--out .pack/temporal.npz` on a fresh clone
    np.savez_compressed(
        out,
        **extra,
        mu=mu[keep].astype(np.float16),
        logvar_q=q,
        tokens=tokens.astype(np.int32),
        shape=np.array(mu.shape, np.int64),
        frames=frames.astype(np.int64),
        text=uniq.astype(np.float16),
        text_row=row.reshape(-1).astype(np.int32),
        text_clip=data["text_clip"].astype(np.int32),
        empty=data["empty"].astype(np.float32),
        fingerprint=np.array(fingerprint),
    )
    return out


def read_pack(path: str | Path, vae_fingerprint: str | None = None) -> dict[str, np.ndarray]:
    """The arrays ``encode_corpus`` returns, rebuilt from a pack: mu, logvar (N, T, C)
    float32 with the padding tokens as the cache has them (mu 0, log-variance -30); frames
    (N,); text (M, 384), text_clip (M,), empty (384,). With ``vae_fingerprint`` (the VAE
    file's sha256), a pack built on another VAE is refused."""
    p = np.load(path)
    fp = str(p["fingerprint"])
    if vae_fingerprint is not None and not fp.endswith(vae_fingerprint):
        raise SystemExit(f"{path} was packed from latents of another VAE (fingerprint ...{fp[-12:]})")
    shape = tuple(int(s) for s in p["shape"])
    keep = np.arange(shape[1])[None] < p["tokens"][:, None]
    mu = np.zeros(shape, np.float32)
    lv = np.full(shape, LOGVAR_MIN, np.float32)
    mu[keep] = p["mu"].astype(np.float32)
    lv[keep] = p["logvar_q"].astype(np.float32) * LOGVAR_STEP + LOGVAR_MIN
    return {
        "mu": mu,
        "logvar": lv,
        "frames": p["frames"],
        "text": p["text"].astype(np.float32)[p["text_row"]],
        "text_clip": p["text_clip"].astype(np.int64),
        "empty": p["empty"],
        "fingerprint": np.array(fp),
    }


def read_validation(path: str | Path, source: str) -> dict | None:
    """A pack's validation prompts of ``source``: {"n": prompts asked for, "captions",
    "frames", "labels", "embeddings" (P, 384) float32, "empty" (384,)}; None when the pack
    holds none (packed before they were added, or from a corpus without that source)."""
    p = np.load(path)
    if f"val_{source}_prompts" not in p.files:
        return None
    prompts = json.loads(str(p[f"val_{source}_prompts"]))
    return {
        "n": int(p[f"val_{source}_n"]),
        "captions": [q["caption"] for q in prompts],
        "frames": [int(f) for f in p[f"val_{source}_frames"]],
        "labels": [q["labels"] for q in prompts],
        "embeddings": p[f"val_{source}_emb"].astype(np.float32),
        "empty": p["empty"].astype(np.float32),
    }


def has_validation(path: str | Path) -> bool:
    """Whether the pack holds validation prompts (of any source)."""
    return any(k.startswith("val_") and k.endswith("_prompts") for k in np.load(path).files)
