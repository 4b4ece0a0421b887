"""Narrow the feed-forward of a denoiser's attention layers to ``--ff`` hidden units, keeping
the units that carry most: a trained network's start for a cheaper arm.

    python tools/prune_ff.py --checkpoint stages/equal_speed/motion_mamba.pt --ff 512 \\
        --out runs/es_ff512_init.pt

How the equal-speed design (``stages/equal_speed``) got its 512-unit mixer without training
afresh: a narrower ``--set ff=N`` network started from a trained one's weights. Each
``nn.TransformerEncoderLayer``'s hidden unit j (row j of ``linear1``, column j of ``linear2``)
is scored by ||W1[j, :]|| * ||W2[:, j]||, the size of
the path through it (the layer's input is layer-normalised, so the rows' norms compare),
and the ``--ff`` best are kept in their order. The result is a checkpoint of the same kind
with ``config.ff`` set, which ``train KIND --init`` goes on from like any other; its meta
records what it was pruned from. It is a start, not a network to ship: the dropped units'
share of the output is gone until training makes it up.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from motion_core.inference.checkpoints import read_float32, ship, weights_fingerprint
from motion_core.models.latent_denoisers import build_denoiser, config_from_dict


def layer_prefixes(state: dict) -> list[str]:
    """The state-dict prefixes of the attention layers (those with linear1 and linear2)."""
    return sorted(k[: -len("linear1.weight")] for k in state if k.endswith("linear1.weight"))


def unit_scores(state: dict, prefix: str) -> torch.Tensor:
    """(ff,) the size of each hidden unit's path: ||W1[j, :]|| * ||W2[:, j]||."""
    return state[prefix + "linear1.weight"].norm(dim=1) * state[prefix + "linear2.weight"].norm(dim=0)


def prune_state(state: dict, ff: int) -> tuple[dict, dict[str, float]]:
    """The state dict with every attention layer's feed-forward cut to its ``ff`` best units
    (kept in their order), and per layer the share of the summed unit scores kept."""
    out = dict(state)
    kept: dict[str, float] = {}
    for p in layer_prefixes(state):
        scores = unit_scores(state, p)
        if ff > scores.numel():
            raise SystemExit(f"{p}linear1 has {scores.numel()} units; cannot keep {ff}")
        keep = scores.topk(ff).indices.sort().values
        out[p + "linear1.weight"] = state[p + "linear1.weight"][keep].clone()
        out[p + "linear1.bias"] = state[p + "linear1.bias"][keep].clone()
        out[p + "linear2.weight"] = state[p + "linear2.weight"][:, keep].clone()
        kept[p.rstrip(".")] = float(scores[keep].sum() / scores.sum())
    return out, kept


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--checkpoint", required=True, help="a denoiser checkpoint (a stage or shipped weights)")
    ap.add_argument("--ff", type=int, required=True, help="hidden units to keep in each attention layer")
    ap.add_argument("--out", required=True)
    args = ap.parse_args(argv)
    if args.ff < 1:
        raise SystemExit("--ff must be at least 1")
    ck = read_float32(args.checkpoint)
    meta = dict(ck["meta"])
    kind = meta.get("kind")
    if "ff" not in meta.get("config", {}):
        raise SystemExit(f"{args.checkpoint} ({kind}) has no attention feed-forward width (config.ff) to cut")
    state, kept = prune_state(ck["state_dict"], args.ff)
    meta["config"] = {**meta["config"], "ff": args.ff}
    # the pruned weights must build and load as their config says, or --init would fail later
    net = build_denoiser(kind, config_from_dict(kind, meta["config"]))
    net.load_state_dict(state)
    meta["params"] = sum(p.numel() for p in net.parameters())
    # the source's loss belongs to the network before the cut
    meta.pop("final_loss_ema", None)
    meta["pruned"] = {
        "from": Path(args.checkpoint).name,
        "fingerprint": weights_fingerprint(ck["state_dict"]),
        "ff_from": int(ck["meta"]["config"]["ff"]),
        "ff": args.ff,
        "score_kept": kept,
    }
    if ck["meta"].get("pruned"):  # a second cut keeps the first in its record
        meta["pruned"]["earlier"] = ck["meta"]["pruned"]
    ship(Path(args.out), net, meta)
    shares = ", ".join(f"{k} {v:.1%}" for k, v in kept.items())
    print(f"{args.out}: ff {meta['pruned']['ff_from']} -> {args.ff}; unit score kept: {shares}")


if __name__ == "__main__":
    main()
