"""Training command line: one program, one subcommand per network.

    python -m motion_core.train vae --data DIR [--steps N] [--out runs/vae]
    python -m motion_core.train motion_mamba|ftmomamba|baseline --data DIR [--vae runs/vae] [--steps N]
    python -m motion_core.train ... --ship      # also write the inference checkpoint to motion_core/weights/
    python -m motion_core.train motion_mamba ... --set htm_order=flat --set bsm=single   # an ablation arm
    python -m motion_core.train kmm-rvq|kmm-generator|kmm-extract-rvq|kmm-swap-decoder ...   # KMM (train/kmm.py)
    python -m motion_core.train evaluator --data DIR [--ship]    # the metric suite's evaluator
    python -m motion_core.train length --data DIR [--ship]       # seconds from text (blank durations)
    python -m motion_core.train step-time [--batch 64 256] [--tokens 2 --width 256]   # s/step table
    python -m motion_core.train pack --data DIR --vae RUN --out FILE   # caches for a machine without the corpus
    python -m motion_core.train motion_mamba --pack FILE --vae RUN --time-limit S ...   # trained there
    python -m motion_core.train lcm --teacher CKPT --data DIR --vae RUN [--ship]   # consistency student
    python -m motion_core.train guidance --teacher CKPT --data DIR --vae RUN [--ship]   # guidance-distilled student

Runs on the GPU when one is present, else the CPU (the denoisers and the students
data-parallel under torchrun). Every ``--save-every`` steps the whole training state
(model, optimiser, step, RNG, and the recipe: ``train/recipe.py``) goes to OUT/state.pt;
running the same command again resumes from it, and a changed recipe is refused there. Flags are checked as they are
parsed: a value that cannot be meant, or a flag the chosen network does not read, is refused
by name before a cache is built.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from ..inference import checkpoints
from ..inference.checkpoints import WEIGHTS
from ..nn.allocator import keep_training_memory

LATENT = ("vae", "motion_mamba", "baseline", "ftmomamba")
KMM = ("kmm-rvq", "kmm-generator", "kmm-extract-rvq", "kmm-swap-decoder")
VAL_N = 200  # validation prompts per source unless --val-n says


def _at_least(low: int):
    """An argparse type: an int of at least ``low``. ``--steps 0`` once read as "the default"
    (20,000 steps) and ``--save-every 0`` divided by zero after the caches were built."""

    def parse(text: str) -> int:
        value = int(text)  # a ValueError reads "invalid int value" in argparse's message
        if value < low:
            raise argparse.ArgumentTypeError(f"must be {low} or more, got {value}")
        return value

    parse.__name__ = "int"
    return parse


def _positive(text: str) -> float:
    """An argparse type: a float above 0 (a time limit)."""
    value = float(text)
    if not value > 0:  # also refuses nan
        raise argparse.ArgumentTypeError(f"must be above 0, got {text}")
    return value


def _finite_positive(text: str) -> float:
    """An argparse type: a finite float above 0 (a loss's scale: inf would make it nan)."""
    value = _positive(text)
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"must be finite, got {text}")
    return value


def _rate(text: str) -> float:
    """An argparse type: a learning rate, 0 or more (0 holds the weights where they start)."""
    value = float(text)
    if not value >= 0:  # also refuses nan
        raise argparse.ArgumentTypeError(f"must be 0 or more, got {text}")
    return value


def _share(text: str) -> float:
    """An argparse type: a probability, 0 to 1."""
    value = float(text)
    if not 0 <= value <= 1:
        raise argparse.ArgumentTypeError(f"must be 0 to 1, got {text}")
    return value


def _part(text: str) -> float:
    """An argparse type: a share above 0, up to 1 (0 would be the option off)."""
    value = float(text)
    if not 0 < value <= 1:
        raise argparse.ArgumentTypeError(f"must be above 0 and at most 1, got {text}")
    return value


def _seed(text: str) -> int:
    """An argparse type: a sampling seed, 0 to 2**63 - 1 (torch's generators take no more;
    a negative one would alias a large one)."""
    value = int(text)
    if not 0 <= value < 2**63:
        raise argparse.ArgumentTypeError(f"must be 0 to 2**63 - 1, got {text}")
    return value


def _decay(text: str) -> float:
    """An argparse type: a moving average's decay, 0 (off) to below 1."""
    value = float(text)
    if not 0 <= value < 1:
        raise argparse.ArgumentTypeError(f"must be 0 (no average) or more and below 1, got {text}")
    return value


def _validation_needs_val_every(ap: argparse.ArgumentParser, args: argparse.Namespace, flags: dict[str, str]) -> None:
    """Validation settings given without --val-every would be dropped without a word: refused.
    ``flags`` maps an attribute to its flag; each defaults to None so that a given one shows."""
    given = [flag for attr, flag in flags.items() if getattr(args, attr, None) is not None]
    if given and not args.val_every:
        ap.error(f"{', '.join(given)} set how validation scores: give --val-every N too, or leave them out")
    if getattr(args, "val_n", None) is None:
        args.val_n = VAL_N
    if getattr(args, "val_source", None) is None:
        args.val_source = "both"


def latent(argv: list[str]) -> None:
    """vae | motion_mamba | ftmomamba | baseline: the latent diffusion methods' networks."""
    ap = argparse.ArgumentParser(prog="python -m motion_core.train", description=latent.__doc__)
    ap.add_argument("what", choices=["vae", "motion_mamba", "baseline", "ftmomamba"])
    ap.add_argument("--data", default=None, help="HumanML3D-format directory (e.g. the built-in corpus)")
    ap.add_argument("--out", default=None)
    ap.add_argument("--vae", default="runs/vae", help="run directory of the trained VAE (denoisers)")
    ap.add_argument(
        "--pack",
        default=None,
        help="denoisers: train on this pack of the caches (python -m motion_core.train pack) instead of --data",
    )
    ap.add_argument(
        "--time-limit",
        type=_positive,
        default=None,
        help="denoisers: stop after this many seconds of steps and write what --steps would (a lent GPU's minutes)",
    )
    ap.add_argument("--tf32", action="store_true", help="denoisers on a GPU: float32 matmuls on TF32 tensor cores")
    ap.add_argument("--steps", type=_at_least(1), default=None)
    ap.add_argument("--batch", type=_at_least(1), default=None)
    ap.add_argument("--lr", type=_rate, default=None)
    ap.add_argument("--limit", type=_at_least(1), default=None, help="use only the first N training clips")
    ap.add_argument("--save-every", type=_at_least(1), default=500)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--ship", action="store_true", help="write the inference checkpoint to motion_core/weights/")
    ap.add_argument(
        "--stage",
        default=None,
        help="denoisers and the VAE: also write the float16 checkpoint here (a stage in stages/ that the next "
        "run --init's); rerun a stopped run with --steps at its saved step to write it",
    )
    ap.add_argument(
        "--stage-best",
        action="store_true",
        help="denoisers: the stage is the best pooled validation so far, written as each is scored (needs "
        "--val-every), not the last step (--ship still ships the last)",
    )
    ap.add_argument(
        "--prediction",
        default=None,
        choices=["epsilon", "sample", "v"],
        help="denoisers: the network's target (diffusion.DiffusionConfig.prediction; default epsilon)",
    )
    ap.add_argument(
        "--init",
        default=None,
        help="vae: start from this VAE checkpoint's weights (fresh optimiser), or with --arch conv from a "
        "kmm.pt's tokeniser convolutions; denoisers: from this denoiser checkpoint's weights (a stage)",
    )
    ap.add_argument(
        "--arch",
        default=None,
        choices=["transformer", "conv"],
        help="vae: MLD-style latent tokens (transformer, the default) or a latent per 4 frames (conv); an --init VAE "
        "keeps its arch",
    )
    ap.add_argument(
        "--warmup",
        type=_at_least(0),
        default=None,
        help="denoisers: linear warm-up steps (default 500; 0 for a stage that goes on)",
    )
    ap.add_argument(
        "--decay",
        default=None,
        choices=["cosine", "constant"],
        help="denoisers: cosine to a tenth of --lr over --steps (the default), or --lr held (stages before the last)",
    )
    ap.add_argument(
        "--val-every", type=_at_least(0), default=None, help="denoisers: score validation prompts every N steps"
    )
    ap.add_argument(
        "--val-n", type=_at_least(1), default=None, help=f"denoisers: validation prompts per score and source ({VAL_N})"
    )
    ap.add_argument(
        "--val-source",
        default=None,
        choices=["both", "procedural", "real"],
        help="denoisers: which validation clips are scored (default both: pooled, what stages are chosen on)",
    )
    ap.add_argument(
        "--val-guidance",
        type=float,
        default=None,
        help="denoisers: guidance scale when scoring (default: its method's)",
    )
    ap.add_argument(
        "--ema",
        type=_decay,
        default=None,
        help="denoisers: decay of the moving average of the weights that is scored, staged and shipped "
        "(default 0.999; 0: the raw weights; a held rate's raw checkpoints scored up to 7 points apart, "
        "docs/training-log.md)",
    )
    ap.add_argument(
        "--val-steps",
        type=_at_least(1),
        default=None,
        help="denoisers: DDIM steps when scoring (default: the schedule's 50; 10 cost a fifth and scored within "
        "a point on the temporal Motion Mamba, results/ddim_steps_val_temporal.json)",
    )
    ap.add_argument(
        "--teacher",
        default=None,
        help="denoisers: also learn this denoiser checkpoint's predictions (same kind, VAE and prediction; "
        "e.g. a smaller network taught by the shipped one)",
    )
    ap.add_argument(
        "--teacher-share",
        type=_part,
        default=None,
        help="denoisers with --teacher: the share of the target that is the teacher's prediction (default 1: "
        "the teacher's alone; the rest is the data's)",
    )
    ap.add_argument(
        "--set",
        action="append",
        metavar="FIELD=VALUE",
        help="change one config field: the VAE's (latent_tokens=8, relative_joint_weight=2) or a denoiser's "
        "(ablation arms, e.g. htm_order=flat, bsm=single, freq=off)",
    )
    args = ap.parse_args(argv)
    _one_networks_flags(ap, args)
    _validation_needs_val_every(ap, args, _LATENT_VAL_FLAGS)
    if args.data is None and not (args.pack and args.what != "vae" and _pack_validates(args)):
        ap.error(
            "--data is required (a denoiser may train on --pack instead, and validate with --val-every where "
            "the pack holds the validation prompts: train pack --val-n N)"
        )
    _validation_is_there(ap, args)
    if args.what == "vae":
        _defaults(args, steps=6000, batch=64, lr=4e-4)
        from .vae import train_vae

        train_vae(args)
    else:
        from .denoiser import train_denoiser

        _defaults(args, steps=20000, batch=256, lr=3e-4)
        train_denoiser(args)


_LATENT_VAL_FLAGS = {"val_n": "--val-n", "val_source": "--val-source", "val_guidance": "--val-guidance"}
_LATENT_VAL_FLAGS |= {"val_steps": "--val-steps"}
# flags only the denoisers read (the VAE trains on its own schedule, no average; --stage aside);
# each defaults to None (or False) so that a given one shows
_DENOISER_FLAGS = {"pack": "--pack", "time_limit": "--time-limit", "tf32": "--tf32", "stage": "--stage"}
_DENOISER_FLAGS |= {"stage_best": "--stage-best", "prediction": "--prediction", "warmup": "--warmup"}
_DENOISER_FLAGS |= {"decay": "--decay", "ema": "--ema", "val_every": "--val-every"}
_DENOISER_FLAGS |= {"teacher": "--teacher", "teacher_share": "--teacher-share"}


def _given(value) -> bool:
    """Whether a flag defaulting to None (or a store_true one) was given."""
    return value is not None and value is not False


def _one_networks_flags(ap: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    """Refuse the flags the chosen network would not read (they were dropped without a
    word), then fill the unset ones with their defaults."""
    if args.what == "vae":
        # the VAE is not scored on prompts as it trains; it does write a --stage
        flags = {k: v for k, v in (_DENOISER_FLAGS | _LATENT_VAL_FLAGS).items() if k != "stage"}
        given = [flag for attr, flag in flags.items() if _given(getattr(args, attr))]
        if given:
            ap.error(f"{', '.join(given)}: the denoisers' settings; the VAE trains without them")
        args.arch = args.arch or "transformer"
    else:
        if args.arch is not None:
            ap.error("--arch is the VAE's: a denoiser's latent shape is its --vae's")
        _no_limit_on_a_pack(ap, args)
        if args.teacher_share is not None and args.teacher is None:
            ap.error("--teacher-share is the share of a --teacher's prediction: give --teacher")
        _defaults(args, prediction="epsilon", warmup=500, decay="cosine", ema=0.999)
        if args.teacher is not None:
            _defaults(args, teacher_share=1.0)
    if args.val_every is None:
        args.val_every = 0


def _no_limit_on_a_pack(ap: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    """--limit with --pack was dropped while the meta named the data: refused (denoisers and students)."""
    if args.pack and args.limit is not None:
        ap.error("--limit picks --data's first clips: a --pack holds the clips it was made from")


def _defaults(args: argparse.Namespace, **defaults) -> None:
    """Fill the flags left unset (None) with the subcommand's defaults."""
    for name, value in defaults.items():
        if getattr(args, name) is None:
            setattr(args, name, value)


def kmm(what: str, argv: list[str]) -> None:
    """kmm-rvq | kmm-generator | kmm-extract-rvq | kmm-swap-decoder: KMM's tokeniser and generator."""
    ap = argparse.ArgumentParser(prog=f"python -m motion_core.train kmm-{what}", description=kmm.__doc__)
    ap.add_argument(
        "--from", dest="source", default=None, help="extract-rvq / swap-decoder: the kmm.pt to read (the shipped one)"
    )
    ap.add_argument("--data")
    ap.add_argument("--out", required=True)
    ap.add_argument(
        "--rvq", default=None, help="generator / swap-decoder: run directory of the trained tokeniser (runs/kmm_rvq)"
    )
    ap.add_argument("--steps", type=_at_least(1), default=None)
    ap.add_argument("--batch", type=_at_least(1), default=None)
    ap.add_argument("--lr", type=_rate, default=None)
    ap.add_argument("--limit", type=_at_least(1), default=None)
    ap.add_argument("--save-every", type=_at_least(1), default=None, help="default 500")
    ap.add_argument("--seed", type=int, default=None, help="default 0")
    ap.add_argument("--mask", choices=["keyframe", "random"], default=None, help="generator: default keyframe")
    ap.add_argument("--no-align", action="store_true", help="train without the contrastive alignment loss")
    ap.add_argument(
        "--pair-prob", type=_share, default=None, help="generator: share of two-segment training samples (0.5)"
    )
    ap.add_argument("--d-model", type=_at_least(1), default=None, help="generator width (default: KMMConfig's)")
    ap.add_argument(
        "--layers", type=_at_least(1), default=None, help="generator depth, bidirectional layers (default: KMMConfig's)"
    )
    ap.add_argument(
        "--word-pool",
        action="store_true",
        help="generator: also pool the captions' token embeddings (KMMConfig.word_pool); --init may lack those weights",
    )
    ap.add_argument(
        "--phase",
        action="store_true",
        help="generator: also read each token's place in its segment (KMMConfig.phase); --init may lack those "
        "weights, and an --init that has them keeps them without this flag",
    )
    ap.add_argument(
        "--stop-at", type=_at_least(1), default=None, help="generator: stop after this step, lr as for --steps"
    )
    ap.add_argument(
        "--init", help="start from these weights: a shipped kmm.pt, or an rvq.pt / state.pt of the same stage"
    )
    ap.add_argument(
        "--decoder-only",
        action="store_true",
        help="rvq: fine-tune the decoder of the --init tokeniser; its codes, and a generator trained on them, stay",
    )
    ap.add_argument("--ship", action="store_true")
    ap.add_argument(
        "--stage",
        default=None,
        help="rvq: also write the float16 tokeniser here (a stage in stages/ that the next kmm-rvq --init's); "
        "generator: the float16 kmm.pt (tokeniser and generator) that the next kmm-generator --init's",
    )
    ap.add_argument(
        "--set",
        action="append",
        metavar="FIELD=VALUE",
        help="rvq: change one of the tokeniser's loss weights (position_weight=12, upper_detail_weight=3, "
        "foot_weight=2, root_weight, velocity_weight, trajectory_weight, commitment); an --init carries the "
        "weights it was trained with",
    )
    args = ap.parse_args(argv)
    if args.set and what != "rvq":
        ap.error("--set changes the tokeniser's loss weights (kmm-rvq)")
    args.what = what
    if what in ("rvq", "extract-rvq") and args.rvq is not None:
        ap.error(f"--rvq names a trained tokeniser to read; kmm-{what} writes one to --out")
    args.rvq = args.rvq or "runs/kmm_rvq"
    if args.what in ("extract-rvq", "swap-decoder"):
        # they copy weights between files: a training flag given to them was dropped without a word
        if given := [f for a, f in (_TRAINING_FLAGS | _GENERATOR_FLAGS).items() if _given(getattr(args, a))]:
            ap.error(f"{', '.join(given)}: training settings; kmm-{what} only copies weights between files")
        args.source = args.source or str(WEIGHTS / "kmm.pt")
    else:
        if args.source is not None:
            ap.error(f"--from is read by kmm-extract-rvq and kmm-swap-decoder; kmm-{what} starts from --init")
        if not args.data:
            ap.error("--data is required")
        _defaults(args, save_every=500, seed=0)
    # a flag of the other stage was dropped without a word
    if args.what == "rvq" and (given := [f for a, f in _GENERATOR_FLAGS.items() if _given(getattr(args, a))]):
        ap.error(f"{', '.join(given)}: the generator's settings (kmm-generator); kmm-swap-decoder ships a tokeniser")
    if args.what == "generator" and args.decoder_only:
        ap.error("--decoder-only fine-tunes a tokeniser's decoder (kmm-rvq), not a generator")
    if args.what == "generator":
        _defaults(args, mask="keyframe", pair_prob=0.5)
    from .kmm import train_generator, train_rvq

    if args.what == "extract-rvq":
        print(checkpoints.extract_rvq(args.source, args.out))
    elif args.what == "swap-decoder":  # --out: the kmm.pt to write (motion_core/weights/kmm.pt ships it)
        print(checkpoints.swap_decoder(args.source, args.rvq, args.out))
    else:
        _defaults(args, steps=4000, batch=64, lr=2e-4)  # the tokeniser's and the generator's alike
        (train_rvq if args.what == "rvq" else train_generator)(args)


# the training flags both trainers read (and the file commands do not)
_TRAINING_FLAGS = {"data": "--data", "steps": "--steps", "batch": "--batch", "lr": "--lr", "limit": "--limit"}
_TRAINING_FLAGS |= {"save_every": "--save-every", "seed": "--seed", "init": "--init", "decoder_only": "--decoder-only"}
_TRAINING_FLAGS |= {"stage": "--stage"}
# kmm-generator's own flags, which kmm-rvq does not read
_GENERATOR_FLAGS = {"ship": "--ship", "stop_at": "--stop-at", "mask": "--mask", "no_align": "--no-align"}
_GENERATOR_FLAGS |= {"pair_prob": "--pair-prob", "d_model": "--d-model", "layers": "--layers"}
_GENERATOR_FLAGS |= {"word_pool": "--word-pool", "phase": "--phase"}


def evaluator(argv: list[str]) -> None:
    """evaluator: the T2M-style evaluator's motion and text encoders."""
    ap = argparse.ArgumentParser(prog="python -m motion_core.train evaluator", description=evaluator.__doc__)
    ap.add_argument("--data", required=True)
    ap.add_argument("--out", default="runs/evaluator")
    ap.add_argument("--steps", type=int, default=3000)
    ap.add_argument("--batch", type=int, default=128)
    ap.add_argument("--lr", type=float, default=1e-3)
    ap.add_argument("--limit", type=int, default=None)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--ship", action="store_true")
    from .evaluator import train

    train(ap.parse_args(argv))


def length(argv: list[str]) -> None:
    """length: the estimator of a segment's seconds from its text."""
    ap = argparse.ArgumentParser(prog="python -m motion_core.train length", description=length.__doc__)
    ap.add_argument("--data", required=True)
    ap.add_argument("--out", default="runs/length")
    ap.add_argument("--steps", type=int, default=3000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--ship", action="store_true")
    args = ap.parse_args(argv)
    from .length import train_length

    r = train_length(args.data, Path(args.out), args.steps, args.seed, args.ship)
    print(json.dumps({k: r[k] for k in ("test", "test_constant_median", "val")}))


def _student_parser(name: str, doc: str, steps: int, lr: float, warmup: int) -> argparse.ArgumentParser:
    """The arguments both kinds of fast student take (``lcm``, ``guidance``)."""
    ap = argparse.ArgumentParser(prog=f"python -m motion_core.train {name}", description=doc)
    ap.add_argument("--teacher", required=True, help="a denoiser checkpoint (shipped, a stage or a run's)")
    ap.add_argument("--data", default=None, help="HumanML3D-format directory (needed to validate)")
    ap.add_argument("--pack", default=None, help="train on this pack of the caches (train pack) instead of --data")
    ap.add_argument(
        "--time-limit", type=_positive, default=None, help="stop after this many seconds of steps (a lent GPU's time)"
    )
    ap.add_argument("--vae", default="runs/vae", help="run directory of the teacher's VAE (its vae.pt)")
    ap.add_argument("--out", required=True)
    ap.add_argument(
        "--steps", type=_at_least(0), default=steps, help="0 with --init: rescore (and ship) that student as it is"
    )
    ap.add_argument("--batch", type=_at_least(1), default=64)
    ap.add_argument("--lr", type=_rate, default=lr)
    ap.add_argument("--warmup", type=_at_least(0), default=warmup)
    ap.add_argument("--decay", default="cosine", choices=["cosine", "constant"])
    ap.add_argument("--limit", type=_at_least(1), default=None)
    ap.add_argument("--save-every", type=_at_least(1), default=250)
    ap.add_argument("--val-every", type=_at_least(0), default=0)
    ap.add_argument("--val-n", type=_at_least(1), default=None, help=f"validation prompts per source ({VAL_N})")
    ap.add_argument("--val-source", default=None, choices=["both", "procedural", "real"])
    ap.add_argument(
        "--val-seeds",
        type=_seed,
        nargs="+",
        default=None,
        help="sampling seeds the last score pools for both samplers, the student's and its teacher's, which "
        "decide the method's default (default: 0 alone, the curve's)",
    )
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--ship", action="store_true", help="write weights/<kind>_fast.pt (the fast sampler's student)")
    ap.add_argument(
        "--init",
        default=None,
        help="start from this student checkpoint of the same kind and teacher (e.g. the shipped <kind>_fast.pt)",
    )
    ap.add_argument(
        "--student-from",
        default=None,
        help="build the student from this checkpoint (a denoiser of the teacher's kind and latent, or a student of "
        "another teacher) instead of a copy of the teacher: a smaller network learning a larger teacher",
    )
    ap.add_argument(
        "--guidance-range",
        type=float,
        nargs=2,
        default=None,
        metavar=("MIN", "MAX"),
        help="the scales w is drawn from (MIN = MAX: a student of one scale, which refuses any other; default: "
        "lcm MotionLCM's 5-15 widened to the teacher's scale, guidance 1-15)",
    )
    return ap


def _student_args(ap: argparse.ArgumentParser, argv: list[str]) -> argparse.Namespace:
    args = ap.parse_args(argv)
    if args.steps == 0 and not args.init:
        # a student of no steps would be an untrained one, and --ship would replace the shipped
        ap.error("--steps 0 rescores an --init student as it was distilled: name one with --init, or take steps")
    _validation_needs_val_every(
        ap, args, {"val_n": "--val-n", "val_source": "--val-source", "val_seeds": "--val-seeds"}
    )
    if args.val_seeds is not None and len(set(args.val_seeds)) != len(args.val_seeds):
        ap.error(f"--val-seeds {' '.join(map(str, args.val_seeds))}: a seed given twice would count twice")
    _no_limit_on_a_pack(ap, args)
    if args.data is None and not (args.pack and _pack_validates(args)):
        ap.error(
            "--data is required (a student may train on --pack instead, and validate with --val-every where "
            "the pack holds the validation prompts: train pack --val-n N)"
        )
    _validation_is_there(ap, args)
    for flag in ("teacher", "init", "student_from"):
        # a usage error, after the others, rather than a traceback once the caches are built
        path = getattr(args, flag)
        if path is not None and not Path(path).is_file():
            ap.error(f"--{flag.replace('_', '-')} {path}: no such checkpoint file")
    return args


def _validation_is_there(ap: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    """With --val-every, the sources --val-source names must have prompts where the scores
    read them (--data, else the pack): found now, not at the first score, where a denoiser
    went on unscored and a student's run failed after its last step without its checkpoint."""
    if not args.val_every:
        return
    from .latent_pack import read_validation
    from .validation import val_sources, validation_prompts

    sources = val_sources(args)
    if args.data is not None:
        if not Path(args.data).is_dir():
            ap.error(f"--data {args.data}: no such corpus directory")
        held = [s for s in sources if validation_prompts(args.data, args.val_n, s)]
    else:
        held = [s for s in sources if read_validation(args.pack, s) is not None]
    if not held:
        where = args.data if args.data is not None else args.pack
        ap.error(f"--val-source {args.val_source}: {where} holds no {' or '.join(sources)} validation prompts")


def _pack_validates(args: argparse.Namespace) -> bool:
    """Whether a --pack run without --data can do what it was asked: no validation, or a
    pack that holds the validation prompts."""
    if not args.val_every:
        return True
    from .latent_pack import read_validation
    from .validation import VAL_SOURCES

    if not Path(args.pack).is_file():
        return False
    held = [v for v in (read_validation(args.pack, s) for s in VAL_SOURCES) if v is not None]
    if held and any(v["n"] != args.val_n for v in held):
        # found now, not at the first score: a lent machine's run would lose its steps there
        raise SystemExit(f"{args.pack} holds the validation prompts of --val-n {held[0]['n']}, not {args.val_n}")
    return bool(held)


def lcm_parser() -> argparse.ArgumentParser:
    """``train lcm``'s flags. --solver-steps, --objective, --huber-c and --renoise default to
    None, so that a no-step rescoring (--init S --steps 0) can name the ones it ignores."""
    ap = _student_parser("lcm", lcm.__doc__ or "", steps=4000, lr=2e-4, warmup=500)
    ap.add_argument("--solver-steps", type=int, default=None, help="the teacher's DDIM grid (default MotionLCM's 10)")
    ap.add_argument(
        "--sample-steps",
        type=_at_least(1),
        default=None,
        help="the student's default sampling steps (1-4; default 2, or the --init student's own with --steps 0)",
    )
    ap.add_argument(
        "--objective",
        default=None,
        choices=["consistency", "trajectory"],
        help="MotionLCM's consistency loss (default), or the student's whole sample against the teacher's from "
        "the same noise (a fine-tune: start from a consistency student with --init, one --guidance-range W W)",
    )
    ap.add_argument(
        "--huber-c",
        type=_finite_positive,
        default=None,
        help="the pseudo-Huber loss's c (default MotionLCM's 0.5): smaller is closer to L1, a median of the "
        "teacher's targets rather than their mean",
    )
    ap.add_argument(
        "--renoise",
        default=None,
        choices=["random", "ddim"],
        help="how the student's sampler re-noises between steps: fresh noise (LCM, default) or the noise its x_t "
        "and x_0 imply (deterministic, as the teacher's DDIM); recorded in the student's meta, which its sampler "
        "follows",
    )
    return ap


def lcm(argv: list[str]) -> None:
    """lcm: distil a denoiser checkpoint into a few-step consistency student (MotionLCM)."""
    from .consistency import train_consistency

    train_consistency(_student_args(lcm_parser(), argv))


def guidance(argv: list[str]) -> None:
    """guidance: distil a denoiser checkpoint's guided pair into one pass (guidance distillation)."""
    from ..inference.registry import DIFFUSION_STEPS

    ap = _student_parser("guidance", guidance.__doc__ or "", steps=2000, lr=1e-4, warmup=100)
    ap.add_argument(
        "--sample-steps",
        type=_at_least(1),
        default=None,
        help=f"the student's default DDIM steps (default {DIFFUSION_STEPS}, the teacher's, or the --init student's "
        "own with --steps 0)",
    )
    ap.add_argument(
        "--loss-weight",
        default=None,
        choices=["uniform", "inverse_w2"],
        help="each sample's MSE as it is (default), or over w^2 (plain MSE is mostly the largest scales' error)",
    )
    from .guidance_distillation import train_guidance

    train_guidance(_student_args(ap, argv))


def pack(argv: list[str]) -> None:
    """pack: a denoiser's training caches in one small file, for a machine without the corpus."""
    ap = argparse.ArgumentParser(prog="python -m motion_core.train pack", description=pack.__doc__)
    ap.add_argument("--data", required=True)
    ap.add_argument("--vae", required=True, help="run directory of the VAE (its vae.pt; caches built there)")
    ap.add_argument("--limit", type=int, default=None)
    ap.add_argument("--out", required=True, help="the pack (.npz)")
    ap.add_argument(
        "--val-n", type=int, default=200, help="validation prompts per source packed with their embeddings (0: none)"
    )
    args = ap.parse_args(argv)
    from ..inference.checkpoints import load_vae
    from ..nn.text import get_text_encoder
    from .denoiser import encode_corpus, latents_fingerprint
    from .latent_pack import write_pack
    from .validation import VAL_SOURCES, validation_prompts

    data = encode_corpus(args)
    vae, _ = load_vae(Path(args.vae) / "vae.pt")
    validation = {}
    for source in VAL_SOURCES if args.val_n else ():
        prompts = validation_prompts(args.data, args.val_n, source)
        if prompts:
            captions = [c.captions[0] for c in prompts]
            validation[source] = {
                "n": args.val_n,
                "captions": captions,
                "frames": [c.frames for c in prompts],
                "labels": [c.labels for c in prompts],
                "embeddings": get_text_encoder().encode(captions).numpy(),
            }
    out = write_pack(data, latents_fingerprint(args), vae.frames_per_token, args.out, validation)
    held = ", ".join(f"{len(v['captions'])} {k}" for k, v in validation.items()) or "none"
    print(f"{out}: {out.stat().st_size / 2**20:.1f} MiB; validation prompts: {held}")


def step_time(argv: list[str]) -> None:
    """step-time: seconds per training step of each denoiser at the given latent shape."""
    ap = argparse.ArgumentParser(prog="python -m motion_core.train step-time", description=step_time.__doc__)
    ap.add_argument("--kinds", nargs="+", default=["motion_mamba", "ftmomamba", "baseline"])
    ap.add_argument("--batch", type=int, nargs="+", default=[64, 256])
    ap.add_argument("--tokens", type=int, default=2, help="latent tokens (2: the MLD VAE; 56: the temporal one)")
    ap.add_argument("--width", type=int, default=256, help="latent channels per token")
    ap.add_argument("--frames-per-token", type=int, default=0, help="4 for a temporal latent")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument(
        "--scans",
        nargs="+",
        default=["compiled"],
        choices=["compiled", "eager", "chunked", "sequential"],
        help="compiled: the dispatcher's choice; eager: without the compiled scan; chunked / sequential: forced",
    )
    ap.add_argument("--device", default="cpu", help="cpu or cuda")
    ap.add_argument("--profile", action="store_true", help="also print where one step of each arm spends its time")
    ap.add_argument("--tf32", action="store_true", help="on a GPU: float32 matmuls on TF32 tensor cores")
    ap.add_argument("--out", default=None, help="also write the rows to this JSON file")
    args = ap.parse_args(argv)
    from .step_time import step_seconds

    if args.tf32:
        from .distributed import allow_tf32

        allow_tf32()
    rows = step_seconds(
        args.kinds,
        args.batch,
        args.tokens,
        args.width,
        args.frames_per_token,
        args.repeats,
        tuple(args.scans),
        args.device,
        args.profile,
    )
    for row in rows:
        print(json.dumps(row))
    if args.out:
        Path(args.out).write_text(
            json.dumps({"command": "python -m motion_core.train step-time " + " ".join(argv), "rows": rows}, indent=1)
        )


def main(argv: list[str] | None = None) -> None:
    argv = list(sys.argv[1:] if argv is None else argv)
    what = argv[0] if argv else ""
    keep_training_memory()  # large training tensors from the heap, not fresh pages (nn/allocator.py)
    if what in KMM:
        kmm(what.removeprefix("kmm-"), argv[1:])
    elif what == "evaluator":
        evaluator(argv[1:])
    elif what == "length":
        length(argv[1:])
    elif what == "step-time":
        step_time(argv[1:])
    elif what == "pack":
        pack(argv[1:])
    elif what == "lcm":
        lcm(argv[1:])
    elif what == "guidance":
        guidance(argv[1:])
    elif what in ("-h", "--help"):
        print(__doc__)
    elif what in LATENT:
        latent(argv)
    else:
        choices = ",".join((*LATENT, *KMM, "evaluator", "length", "step-time", "pack", "lcm", "guidance"))
        sys.exit(f"usage: python -m motion_core.train {{{choices}}} ... (--help after one of them)")


if __name__ == "__main__":
    main()
