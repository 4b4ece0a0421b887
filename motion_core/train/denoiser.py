"""Training of the latent denoisers (Motion Mamba, the transformer baseline) on a frozen VAE.

The VAE encodes every training clip once (posterior mean and log-variance, cached in the
run directory); each step then draws z ~ q(z|x), scales it to unit variance with the
data set's latent std (stored in the checkpoint), noises it and regresses the target of
``--prediction`` (epsilon, x_0 or v; see ``diffusion``). The sentence embeddings of all
captions are cached the same way, so a step costs only the denoiser's forward and
backward pass.

``--teacher`` trains on another denoiser's predictions as well (knowledge distillation, as
diffusion-model compression does it): the regression target becomes
``share * teacher(z_t, t, c) + (1 - share) * target``, with ``share`` = ``--teacher-share``,
on the same noisy latents, steps and captions (the dropped ones too, so the teacher's
unconditional branch is taught with its conditional one). That mean of the two targets has
the gradient of ``share`` times the loss on the teacher's plus ``1 - share`` times the loss
on the data's. The teacher's prediction of x_0 is a deterministic function of z_t, where
the data's target is one draw of it, so the student learns from a target of far lower
variance: how a smaller network (the equal-speed Motion Mamba) catches up with the
shipped one in fewer steps than from the data alone. The teacher must be a denoiser of the
same kind, prediction, VAE and latent scale; it never leaves eval mode.

Both caches carry a fingerprint of what they were built from (the training split's clip
ids, file sizes and captions; for the latents also the VAE checkpoint's bytes). A cache
whose fingerprint differs from the current corpus or VAE is refused: a stale cache pairs
captions with the wrong clips, and nothing downstream would notice.
"""

from __future__ import annotations

import argparse
import copy
import dataclasses
import json
import shutil
import time
from pathlib import Path

import numpy as np
import torch
from tqdm import tqdm

from ..data.clips import load_clips, pad_batch
from ..inference import checkpoints
from ..inference.checkpoints import WEIGHTS, load_vae, vae_normalizer
from ..inference.registry import sampling_scale
from ..inference.samplers import GuidedDDIM
from ..models.latent_denoisers import DenoiserConfig, build_denoiser, config_from_dict, default_config
from ..models.overrides import override_config
from ..nn.diffusion import Diffusion, DiffusionConfig
from ..nn.text import get_text_encoder
from .caches import cached, corpus_fingerprint, file_fingerprint, write_cache
from .device_steps import LOG_EVERY, LossAverage, lerp_weights, to_device
from .distributed import World, allow_tf32, init_world
from .recipe import check_resume, recipe
from .schedule import learning_rate
from .teachers import load_teacher

# what a resumed run must keep: the flags that set its recipe (--steps, the stops and scores may change)
DENOISER_RECIPE = ("lr", "batch", "warmup", "decay", "ema", "prediction", "seed")


def latents_fingerprint(args: argparse.Namespace) -> str:
    """What the latent cache is built from: the training split (``corpus_fingerprint``) and
    the VAE file's bytes, in that order (a pack keeps it; ``read_pack`` checks its VAE part)."""
    return corpus_fingerprint(args.data, args.limit) + file_fingerprint(Path(args.vae) / "vae.pt")


def encode_texts(args: argparse.Namespace, clips: list | None = None) -> dict[str, np.ndarray]:
    """Sentence embeddings of every training caption, cached beside the VAE run (the
    denoisers of all methods share them). text_clip[i] is the index, in the training
    split's order, of the clip caption i describes."""
    cache = Path(args.vae) / "texts.npz"
    fp = corpus_fingerprint(args.data, args.limit)
    if (data := cached(cache, fp)) is not None:
        return data
    clips = clips if clips is not None else load_clips(args.data, "train", args.limit)
    enc = get_text_encoder()
    caps = [c.captions for c in clips]
    t0 = time.time()
    emb = enc.encode([t for cs in caps for t in cs]).numpy().astype(np.float32)
    print(f"encoded {len(emb)} captions in {time.time() - t0:.0f} s")
    data = {
        "text": emb,
        "text_clip": np.repeat(np.arange(len(clips)), [len(cs) for cs in caps]),
        "empty": enc.encode([""]).numpy().astype(np.float32)[0],
    }
    write_cache(cache, data, fp)
    return data


@torch.no_grad()
def encode_corpus(args: argparse.Namespace) -> dict[str, np.ndarray]:
    """Posterior moments of the training clips under the VAE, plus caption embeddings
    (both cached in the VAE's run directory)."""
    cache = Path(args.vae) / "latents.npz"
    fp = latents_fingerprint(args)
    clips = None
    if (lat := cached(cache, fp)) is None:
        vae, vmeta = load_vae(Path(args.vae) / "vae.pt")
        # the VAE's own feature statistics, as at inference: the data directory's can differ
        # (a denoiser trained on another corpus than its VAE's got latents of mis-scaled input)
        norm = vae_normalizer(vmeta)
        clips = load_clips(args.data, "train", args.limit)
        order = np.argsort([c.frames for c in clips])  # similar lengths per batch: less padding
        mu_all = np.zeros((len(clips), *vae.latent_shape), np.float32)
        lv_all = np.zeros_like(mu_all)
        for i in tqdm(range(0, len(clips), 128), desc="encode motions"):
            idx = order[i : i + 128]
            x, mask = pad_batch([norm.normalize(clips[j].features) for j in idx], vae.cfg.downsample)
            mu, lv = vae.encode(x, mask)
            mu_all[idx], lv_all[idx] = mu.numpy(), lv.numpy()
        lat = {"mu": mu_all, "logvar": lv_all, "frames": np.array([c.frames for c in clips], np.int64)}
        write_cache(cache, lat, fp)
    return {**lat, **encode_texts(args, clips)}


def training_caches(args: argparse.Namespace) -> dict[str, np.ndarray]:
    """What a denoiser or a student trains on: ``encode_corpus``'s arrays, from ``args.pack``
    (the caches packed for a machine without the corpus, ``latent_pack``) when one is given,
    else built or read beside ``args.vae``."""
    if getattr(args, "pack", None):
        from .latent_pack import read_pack

        return read_pack(args.pack, file_fingerprint(Path(args.vae) / "vae.pt"))
    return encode_corpus(args)


def draw_latents(
    mu: torch.Tensor, logvar: torch.Tensor, text_clip: torch.Tensor, scale: float, batch: int, g: torch.Generator
) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """A training batch from the caches: ``batch`` captions drawn uniformly (cap (B,)), their
    clips (clip (B,)) and a draw from each clip's posterior, scaled to unit std (z0 (B, n_z,
    d)). mu, logvar: (N, n_z, d); text_clip: (M,) each caption's clip."""
    cap = torch.randint(0, len(text_clip), (batch,), generator=g)
    clip = text_clip[cap]
    z0 = (mu[clip] + torch.randn(mu[clip].shape, generator=g) * torch.exp(0.5 * logvar[clip])) / scale
    return cap, clip, z0


class WeightAverage:
    """An exponential moving average of a network's weights (the diffusion models' usual
    EMA): decay min(``decay``, (1 + n) / (10 + n)) at the n-th update, so a short stage
    averages its own last steps rather than its start. ``net``: the averaged copy (B, ...)
    shapes as the network's; buffers are copied, not averaged."""

    def __init__(self, model: torch.nn.Module, decay: float) -> None:
        self.net = copy.deepcopy(model).eval()
        for p in self.net.parameters():
            p.requires_grad_(False)
        self.decay, self.updates = decay, 0

    @torch.no_grad()
    def update(self, model: torch.nn.Module) -> None:
        d = min(self.decay, (1 + self.updates) / (10 + self.updates))
        lerp_weights(self.net, model, d)
        for ba, bm in zip(self.net.buffers(), model.buffers(), strict=True):
            ba.copy_(bm)
        self.updates += 1

    def state_dict(self) -> dict:
        return {"net": self.net.state_dict(), "updates": self.updates}

    def load_state_dict(self, st: dict) -> None:
        self.net.load_state_dict(st["net"])
        self.updates = st["updates"]


def train_denoiser(args: argparse.Namespace) -> None:
    """Train (or resume) one denoiser; under torchrun, data-parallel (``distributed``)."""
    world = init_world()
    if getattr(args, "tf32", False):
        allow_tf32()
    out = Path(args.out or f"runs/{args.what}")
    out.mkdir(parents=True, exist_ok=True)
    diff = Diffusion(DiffusionConfig(prediction=args.prediction))
    # a teacher of another kind, VAE or schedule is refused before minutes of caching
    teacher, teacher_meta = _read_teacher(args, diff)
    if getattr(args, "pack", None):
        data = training_caches(args)
    else:
        data = world.first(lambda: encode_corpus(args))
    mu, logvar = torch.from_numpy(data["mu"]), torch.from_numpy(data["logvar"])
    frames = torch.from_numpy(data["frames"])
    vae, _ = load_vae(Path(args.vae) / "vae.pt")
    fpt = vae.frames_per_token
    if fpt and args.prediction != "sample":
        # the denoiser zeroes its prediction past a clip's tokens: right for x_0 only
        raise SystemExit("a temporal-latent VAE's denoisers train with --prediction sample")
    # latents scaled to unit std, as latent diffusion does (a temporal latent's padding left out)
    real = torch.arange(mu.shape[1])[None] < ((frames + fpt - 1) // fpt)[:, None] if fpt else None
    scale = float(mu[real].std() if real is not None else mu.std())
    text = torch.from_numpy(data["text"])
    empty = torch.from_numpy(data["empty"])
    text_clip = torch.from_numpy(data["text_clip"])
    cfg = override_config(default_config(args.what), getattr(args, "set", None) or [])
    # the denoiser's token count is the VAE's: a VAE of another latent shape needs no --set
    cfg = dataclasses.replace(cfg, latent_tokens=int(mu.shape[1]))
    if fpt:
        cfg = dataclasses.replace(cfg, z_width=int(mu.shape[2]), frames_per_token=fpt)
    cfg, model, init_meta = _network(args, cfg, world, resuming=(out / "state.pt").is_file())
    teacher, taught = _taught(args, teacher, teacher_meta, scale, world)
    opt = torch.optim.AdamW(model.parameters(), lr=args.lr, weight_decay=0.01)
    step = 0
    state_path = out / "state.pt"
    g = torch.Generator().manual_seed(args.seed)
    # the network as --set made it, not the strings (dropout=0 and dropout=0.0 are one net)
    # a teacher's weights and share are the recipe; its file's name and steps only say where they came from
    taught_recipe = {k: taught[k] for k in ("fingerprint", "share")} if taught else None
    run_recipe = recipe(args, DENOISER_RECIPE, **{"network config": cfg.to_dict(), "teacher": taught_recipe})
    if state_path.is_file():
        st = checkpoints.read_state(state_path)
        if st.get("recipe") is not None:
            # a state from before --teacher was recorded was trained without one: it may not gain one
            st["recipe"].setdefault("teacher", None)
        check_resume(st, run_recipe, state_path)
        model.load_state_dict(st["model"])
        opt.load_state_dict(st["opt"])
        step = st["step"]
        g.set_state(st["rng"])
        if "torch_rng" in st:  # dropout draws from the global generator: a resumed run repeats it (on a CPU)
            torch.set_rng_state(st["torch_rng"])
        print(f"resumed at step {step}")
    decay = getattr(args, "ema", 0.0) or 0.0
    # the average starts at the stage's first weights (a resumed state without one: its own)
    averaged = WeightAverage(model, decay) if decay else None
    if averaged is not None and state_path.is_file() and "ema" in st:
        averaged.load_state_dict(st["ema"])
    n_params = sum(p.numel() for p in model.parameters())
    if world.main:
        print(f"{args.what}: {n_params / 1e6:.2f} M parameters, latent scale {scale:.3f}, {world.size} process(es)")
    net = world.wrap(model)
    rows = world.shard(args.batch)
    dev = world.device
    bar = tqdm(total=args.steps, initial=step, desc=args.what, dynamic_ncols=True, disable=not world.main)
    ema, losses = None, LossAverage()
    if getattr(args, "stage_best", False) and not (args.stage and args.val_every):
        raise SystemExit("--stage-best needs --stage and --val-every")
    # --stage-best: the best pooled validation pass rate so far (a resumed run's, from its curve)
    curve_so_far = out / "curve.json"
    scores = json.loads(curve_so_far.read_text()) if curve_so_far.is_file() else []
    best = max((c["pass_rate"] for c in scores if c["step"] <= step), default=-1.0)
    # the meta alone: building the VAE would draw from the global generator, which dropout
    # draws from too (a resumed run would then differ from one that never stopped)
    vae_meta = checkpoints.read_float32(Path(args.vae) / "vae.pt")["meta"]

    def run_meta(step: int, ema: float | None) -> dict:
        """The checkpoint's meta after ``step`` steps of this run."""
        return {
            "kind": args.what,
            "config": cfg.to_dict(),
            # the whole lineage's steps: a stage started with --init adds its own to its start's
            "steps": step + int(init_meta.get("steps") or 0),
            "stage_steps": step,
            "init": _init_record(args, init_meta),
            "batch": args.batch,
            "lr": args.lr,
            "schedule": {"warmup": getattr(args, "warmup", 500), "decay": getattr(args, "decay", "cosine")},
            "processes": world.size,  # data-parallel processes sharing each batch of --batch rows
            "weights_ema": decay or None,  # the shipped weights are this moving average (None: the raw ones)
            "final_loss_ema": ema,
            "latent_scale": scale,
            "params": n_params,
            "data": str(args.data or f"pack {Path(args.pack).name}"),
            "vae_steps": vae_meta.get("steps"),
            "diffusion": diff.cfg.to_dict(),
            "prediction": diff.cfg.prediction,
            **({"teacher": taught} if taught else {}),
        }

    limit = getattr(args, "time_limit", None)
    started = time.monotonic()
    while step < args.steps:
        lr = learning_rate(args.lr, step, args.steps, getattr(args, "warmup", 500), getattr(args, "decay", "cosine"))
        for grp in opt.param_groups:
            grp["lr"] = lr
        cap, clip, z0 = draw_latents(mu, logvar, text_clip, scale, args.batch, g)
        cond = text[cap].clone()
        drop = torch.rand(args.batch, generator=g) < diff.cfg.cond_drop
        cond[drop] = empty
        t = torch.randint(0, diff.cfg.train_steps, (args.batch,), generator=g)
        noise = torch.randn(z0.shape, generator=g)
        zt = diff.add_noise(z0, noise, t)
        # every process drew the whole batch from the same generator and takes its rows
        target = to_device(diff.target(z0, noise, t)[rows], dev)
        inputs = tuple(to_device(x[rows], dev) for x in (zt, t, cond, frames[clip]))
        if teacher is not None:
            with torch.no_grad():
                target = torch.lerp(target, teacher(*inputs), args.teacher_share)
        pred = net(*inputs)
        loss = torch.nn.functional.mse_loss(pred, target)
        opt.zero_grad(set_to_none=True)
        loss.backward()
        torch.nn.utils.clip_grad_norm_(model.parameters(), 1.0)
        opt.step()
        if averaged is not None:
            averaged.update(model)
        step += 1
        losses.add(loss)  # on the device: read every LOG_EVERY steps (device_steps)
        bar.update(1)
        # a lent machine's minutes are counted: past the limit this step is the last, and it
        # is saved and validated as the last of --steps would be (the lr schedule was planned
        # for --steps). Decided once per step, and by all processes together (any one's clock)
        out_of_time = world.any(limit is not None and time.monotonic() - started > limit)
        last = step == args.steps or out_of_time
        saving = step % args.save_every == 0 or last
        validating = bool(args.val_every) and (step % args.val_every == 0 or last)
        if step % LOG_EVERY == 0 or saving or validating:  # every process: mean() may all-reduce
            ema = world.mean(losses.tensor)
            bar.set_postfix(loss=f"{ema:.4f}")
        if world.main and saving:
            extra = {"ema": averaged.state_dict()} if averaged is not None else {}
            checkpoints.write_state(
                state_path,
                model=model.state_dict(),
                opt=opt.state_dict(),
                step=step,
                rng=g.get_state(),
                torch_rng=torch.get_rng_state(),
                recipe=run_recipe,
                **extra,
            )
        if world.main and validating:
            scored = averaged.net if averaged is not None else model
            try:
                with torch.random.fork_rng(devices=[]):  # the VAE built there draws from it; dropout does too
                    curve = _validate(args, scored, diff, scale, step, ema)
            except Exception as err:  # a score lost must not lose the steps (nothing is saved yet)
                bar.write(f"validation failed at step {step}, training goes on: {type(err).__name__}: {err}")
                curve = None
            if curve is not None:
                bar.write(json.dumps(curve[-1]))
            if curve is not None and getattr(args, "stage_best", False) and curve[-1]["pass_rate"] >= best:
                # the best validated weights so far are the stage, written now: a run cut off
                # (a lent machine's limit) keeps them
                best = curve[-1]["pass_rate"]
                meta = {**run_meta(step, ema), "validation": {k: curve[-1][k] for k in ("n", "pass_rate", "sources")}}
                checkpoints.ship(Path(args.stage), scored, meta)
                bar.write(f"stage: step {step}, the best validation so far ({best:.3f})")
        if out_of_time:
            if world.main:
                bar.write(f"time limit: stopping at step {step} of {args.steps}")
            break
    bar.close()
    world.barrier()
    if not world.main:
        return
    if averaged is not None:  # the averaged weights are what is scored, staged and shipped
        model = averaged.net
    curve_path = out / "curve.json"
    if ema is None and curve_path.is_file():  # a finished run rerun to --ship: its last logged loss
        ema = json.loads(curve_path.read_text())[-1]["loss_ema"]
    meta = run_meta(step, ema)
    checkpoints.save_run(out / f"{args.what}.pt", model, meta)
    (out / "result.json").write_text(json.dumps(meta, indent=1))
    if getattr(args, "stage", None) and not (getattr(args, "stage_best", False) and best >= 0):
        # float16 like the shipped weights, for stages/; with --stage-best only when no score
        # succeeded (the last weights then, rather than none)
        checkpoints.ship(Path(args.stage), model, meta)
    if args.ship:
        WEIGHTS.mkdir(parents=True, exist_ok=True)
        if getattr(args, "stage_best", False) and best >= 0:
            # the best-scored weights, as staged, not the last ones
            shutil.copyfile(args.stage, WEIGHTS / f"{args.what}.pt")
        else:
            checkpoints.ship(WEIGHTS / f"{args.what}.pt", model, meta)
        vae, vmeta = load_vae(Path(args.vae) / "vae.pt")
        if not (WEIGHTS / "vae.pt").is_file():
            checkpoints.ship(WEIGHTS / "vae.pt", vae, vmeta)


def _init_record(args: argparse.Namespace, init_meta: dict) -> dict | None:
    """What a stage's meta keeps of the checkpoint it went on from: its file and steps, its
    teacher where it was taught (the lineage's steps count those, so its record must not
    say they were learned from the data alone), its pruning where ``tools/prune_ff.py`` cut
    it, and that checkpoint's own init record, so the whole lineage travels and not only its
    last hand-over. None from fresh weights."""
    if not init_meta:
        return None
    record = {"from": Path(args.init).name, "steps": init_meta.get("steps")}
    for key in ("teacher", "pruned", "init"):
        if init_meta.get(key):
            record[key] = init_meta[key]
    return record


# the noise schedule a teacher's prediction belongs to: another one predicts for another
# noise level at the same step
_SCHEDULE = ("train_steps", "beta_start", "beta_end", "schedule", "prediction")


def _read_teacher(args: argparse.Namespace, diff: Diffusion) -> tuple[torch.nn.Module | None, dict | None]:
    """``--teacher``'s frozen network and meta, (None, None) without one. Refused unless the
    teacher predicts what this run's network does: the same kind, VAE and noise schedule
    (its latent scale is checked by ``_taught`` once the data gives this run's)."""
    if not getattr(args, "teacher", None):
        return None, None
    net, tmeta = load_teacher(args.teacher)
    # an older meta kept the prediction beside its schedule, not in it
    schedule = DiffusionConfig(**{"prediction": tmeta.get("prediction", "epsilon"), **tmeta.get("diffusion", {})})
    vae_steps = checkpoints.read_float32(Path(args.vae) / "vae.pt")["meta"].get("steps")
    _refuse_teacher(
        args,
        [
            f"{what} {theirs!r}, this run {ours!r}"
            for what, theirs, ours in (
                ("kind", tmeta.get("kind"), args.what),
                ("VAE steps", tmeta.get("vae_steps"), vae_steps),
                *((name, getattr(schedule, name), getattr(diff.cfg, name)) for name in _SCHEDULE),
            )
            if theirs != ours
        ],
    )
    return net, tmeta


def _taught(
    args: argparse.Namespace, net: torch.nn.Module | None, tmeta: dict | None, scale: float, world: World
) -> tuple[torch.nn.Module | None, dict | None]:
    """The teacher on the run's device and what the run records of it (its file, steps,
    weights' fingerprint and share: part of the recipe a resume must keep, so a run cannot
    gain, lose or swap its teacher unseen, and of the checkpoint's meta); (None, None)
    without one. Refused unless it was trained on latents of this run's ``scale``."""
    if net is None or tmeta is None:
        return None, None
    if abs(float(tmeta.get("latent_scale", 0.0)) - scale) > 1e-4 * scale:
        _refuse_teacher(args, [f"latent scale {tmeta.get('latent_scale')}, this run {scale:.6f}"])
    taught = {
        "from": Path(args.teacher).name,
        "steps": tmeta.get("steps"),
        "fingerprint": checkpoints.weights_fingerprint(net.state_dict()),
        "share": args.teacher_share,
    }
    return net.to(world.device), taught


def _refuse_teacher(args: argparse.Namespace, wrong: list[str]) -> None:
    if wrong:
        raise SystemExit(f"--teacher {args.teacher} does not teach this run: " + "; ".join(wrong))


def _network(
    args: argparse.Namespace, cfg: DenoiserConfig, world: World, resuming: bool
) -> tuple[DenoiserConfig, torch.nn.Module, dict]:
    """The denoiser to train, on the run's device: fresh from ``cfg``, or (``--init``) from a
    committed checkpoint's weights and config, with ``--set`` on top. Returns (config,
    network, the --init checkpoint's meta or {})."""
    # seeded here, after the caches: building them loads the text encoder, whose
    # construction draws from the global generator, so a run's initial weights depended on
    # whether its caches already existed
    torch.manual_seed(args.seed)
    model = build_denoiser(args.what, cfg).to(world.device)
    init_meta: dict = {}
    if getattr(args, "init", None):
        # a stage that goes on from committed weights (float16 as shipped, fresh optimiser):
        # the network's config is the checkpoint's, the schedule this stage's own
        ck = checkpoints.read_float32(args.init)
        init_meta = ck["meta"]
        if init_meta.get("kind") != args.what:
            raise SystemExit(f"{args.init} holds a {init_meta.get('kind')} denoiser, not {args.what}")
        # --set applies on top of it: a switch that adds zero-initialised layers (FTMoMamba's
        # cond=broadcast) goes on from the same function; those layers are the only weights
        # the checkpoint may lack
        cfg = override_config(config_from_dict(args.what, init_meta["config"]), getattr(args, "set", None) or [])
        model = build_denoiser(args.what, cfg).to(world.device)
        if not resuming:  # a resumed stage loads its own state afterwards
            added = set(model.state_dict()) - set(
                build_denoiser(args.what, config_from_dict(args.what, init_meta["config"])).state_dict()
            )
            missing, unexpected = model.load_state_dict(ck["state_dict"], strict=False)
            if unexpected or set(missing) - added:
                raise SystemExit(
                    f"{args.init} does not fit this network: missing {sorted(set(missing) - added)}, "
                    f"unexpected {sorted(unexpected)}"
                )
            if world.main:
                print(
                    f"initialised from {args.init} ({init_meta.get('steps')} steps)"
                    + (f", {len(missing)} new tensors" if missing else "")
                )
    return cfg, model, init_meta


def _validate(args: argparse.Namespace, model: torch.nn.Module, diff: Diffusion, scale: float, step: int, loss) -> list:
    """Append the verifier pass rate on ``--val-n`` validation prompts to OUT/curve.json (the
    training curve) and return the whole curve. Validation only: settings are chosen on it,
    the test split is for reporting."""
    from .validation import score_run

    path = Path(args.out or f"runs/{args.what}") / "curve.json"
    curve = json.loads(path.read_text()) if path.is_file() else []
    curve = [c for c in curve if c["step"] < step]  # a resumed run overwrites what it redoes
    # sampled where the network trains (a GPU: seconds), decoded and verified on the CPU;
    # the prompts from --data, or from a pack that holds them (a machine without the corpus)
    steps = getattr(args, "val_steps", None)
    # the method's own scale where it is one (the registry's), unless --val-guidance says
    guidance = args.val_guidance if args.val_guidance is not None else sampling_scale(args.what, diff.cfg.guidance)
    res = score_run(args, lambda net: GuidedDDIM(net, diff), model, scale, steps=steps, guidance=guidance)
    curve.append({"step": step, "loss_ema": loss, "ddim_steps": steps or diff.cfg.sample_steps, **res})
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps(curve, indent=1))
    tmp.replace(path)  # a reader (or a kill) mid-write never sees half a file
    return curve
