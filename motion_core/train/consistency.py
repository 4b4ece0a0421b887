"""Latent consistency distillation of a trained denoiser (MotionLCM; ``nn/consistency.py``).

    python -m motion_core.train lcm --teacher motion_core/weights/motion_mamba.pt --data DIR --vae RUN \\
        --out runs/motion_mamba_lcm [--steps N] [--ship]

The teacher is a denoiser checkpoint and its guided DDIM sampler; the student starts as a
copy of the teacher's network (or, with ``--student-from``, another network of its kind and
latent: ``build_student``) with a guidance-scale embedding (``GuidedStudent``) and
learns to jump from any point of the teacher's coarse DDIM grid to the clean latent in one
call. Each step: a training clip's latent z_0 and caption, a guidance scale w ~ U[5, 15] (or --guidance-range),
a grid step t_{n+1} and the noisy x_{t_{n+1}}; the guided teacher takes one DDIM step to
t_n; the loss is the pseudo-Huber distance between the student's f(x_{t_{n+1}}) and the
target network's f(x_{t_n}) (an EMA of the student, no gradient). ``--val-every`` scores
the student's few-step samples on the validation prompts, as the denoisers' curves do; at
the end the teacher's own sampler (guided DDIM at the registry's steps) is scored on the
same prompts, and both rates go into the student's meta ("validation"): the registry makes
the student a method's default sampler only where it passed within 2 points of its teacher.

The latents and captions come from the same caches as the teacher's training
(``train/denoiser.encode_corpus``, refused when stale); ``--vae`` must be the run
directory of the teacher's VAE (its ``vae.pt``).
"""

from __future__ import annotations

import argparse
import copy
import dataclasses
import json
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import torch
from tqdm import tqdm

from ..inference import checkpoints
from ..inference.checkpoints import WEIGHTS, load_vae
from ..inference.registry import DIFFUSION_STEPS, sampling_scale
from ..inference.samplers import ConsistencySampler, GuidedDDIM, LatentSampler
from ..models.consistency import GuidedStudent
from ..models.latent_denoisers import build_denoiser, config_from_dict
from ..nn.consistency import (
    ConsistencyConfig,
    consistency_fn,
    consistency_unroll,
    pseudo_huber,
    sample_timesteps,
    solver_grid,
)
from ..nn.diffusion import Diffusion, DiffusionConfig
from .denoiser import draw_latents, training_caches
from .device_steps import LOG_EVERY, LossAverage, lerp_weights, to_device
from .distributed import ALL_ROWS, init_world
from .recipe import check_resume, recipe
from .schedule import learning_rate
from .teachers import STUDENT_KEYS, load_teacher
from .validation import pooled_rates, score_run

# what a resumed student must keep (its distillation settings are added to it)
STUDENT_RECIPE = ("lr", "batch", "warmup", "decay", "seed")


def teacher_scale(args: argparse.Namespace, fallback: float) -> float:
    """The guidance scale the teacher's method samples at (the registry's, chosen on
    validation prompts), which the student learns to match; ``fallback`` where there is no
    teacher file or its kind is not a registered method."""
    path = getattr(args, "teacher", None)
    if not path or not Path(path).is_file():
        return fallback
    return sampling_scale(checkpoints.read_float32(path)["meta"].get("kind", ""), fallback)


def guidance_range(args: argparse.Namespace, default: tuple[float, float]) -> tuple[float, float]:
    """The scales a student learns: ``--guidance-range MIN MAX``, else ``default``; refused
    unless 0 < MIN <= MAX (both student kinds)."""
    lo, hi = getattr(args, "guidance_range", None) or default
    if not 0 < lo <= hi:
        raise SystemExit(f"--guidance-range wants 0 < MIN <= MAX, got {lo:g} {hi:g}")
    return lo, hi


def distillation_loss(
    student: GuidedStudent,
    target: GuidedStudent,
    teacher: torch.nn.Module,
    diffusion: Diffusion,
    cfg: ConsistencyConfig,
    z0: torch.Tensor,
    cond: torch.Tensor,
    empty: torch.Tensor,
    frames: torch.Tensor,
    generator: torch.Generator,
    rows: slice = ALL_ROWS,
) -> torch.Tensor:
    """One batch's consistency distillation loss. z0: (B, n_z, d) scaled clean latents,
    cond: (B, 384) captions' embeddings, empty: (384,) the empty text's, frames: (B,): the
    global batch, of which this process takes ``rows`` (``World.shard``) after every draw."""
    b, dev = z0.shape[0], z0.device
    grid = torch.tensor(solver_grid(diffusion, cfg))
    skip = diffusion.cfg.train_steps // cfg.solver_steps
    # every draw on the CPU generator (one stream on every device and process), then moved
    t = grid[torch.randint(0, len(grid), (b,), generator=generator)]
    t_prev = (t - skip).clamp(min=0)  # the grid's lowest step goes to t = 0, the clean latent
    w = cfg.guidance_min + (cfg.guidance_max - cfg.guidance_min) * torch.rand(b, generator=generator)
    noise = torch.randn(z0.shape, generator=generator)
    z0, cond, frames, t, t_prev, w, noise = (x[rows] for x in (z0, cond, frames, t, t_prev, w, noise))
    b = z0.shape[0]
    t, t_prev, w, noise = (to_device(x, dev) for x in (t, t_prev, w, noise))
    x_t = diffusion.add_noise(z0, noise, t)
    uncond = empty.expand(b, -1)

    def x0_of(net: GuidedStudent):
        return lambda x, tt: diffusion.split(net(x, tt, cond, frames, w), x, tt)[1]

    pred = consistency_fn(x0_of(student), x_t, t, cfg)
    with torch.no_grad():
        x_prev = teacher_step(teacher, diffusion, x_t, t, t_prev, cond, uncond, frames, w)
        tgt = consistency_fn(x0_of(target), x_prev, t_prev, cfg)
    return pseudo_huber(pred, tgt, cfg.huber_c)


def trajectory_loss(
    student: GuidedStudent,
    teacher: torch.nn.Module,
    diffusion: Diffusion,
    cfg: ConsistencyConfig,
    z0: torch.Tensor,
    cond: torch.Tensor,
    empty: torch.Tensor,
    frames: torch.Tensor,
    generator: torch.Generator,
) -> torch.Tensor:
    """The trajectory objective (``nn/consistency.py``): from one start noise per sample,
    the student's ``cfg.sample_steps``-step sample (trained through, at its own guidance
    ``cfg.guidance``) against the guided teacher's DDIM sample at ``DIFFUSION_STEPS`` and
    the same scale, as its method samples. z0: (B, n_z, d) only gives the shape (and so
    the padding, which the networks zero from ``frames`` (B,)); cond: (B, 384); empty: (384,)."""
    b, dev = z0.shape[0], z0.device
    n = len(sample_timesteps(diffusion, cfg, cfg.sample_steps))
    draws = [to_device(torch.randn(z0.shape, generator=generator), dev) for _ in range(n)]
    w = torch.full((b,), cfg.guidance, device=dev)
    uncond = empty.expand(b, -1)

    def eps_fn(x, t, guided):  # at w = 1 the sampler asks for the conditional pass alone
        if guided:
            return teacher(x, t, torch.cat([cond, uncond]), torch.cat([frames, frames]))
        return teacher(x, t, cond, frames)

    with torch.no_grad():
        tgt = diffusion.sample(eps_fn, tuple(z0.shape), generator, DIFFUSION_STEPS, cfg.guidance, x_init=draws[0])

    def x0_fn(x, t):
        return diffusion.split(student(x, t, cond, frames, w), x, t)[1]

    pred = consistency_unroll(x0_fn, diffusion, cfg, draws[0], draws[1:])
    return pseudo_huber(pred, tgt, cfg.huber_c)


@torch.no_grad()
def teacher_step(
    teacher: torch.nn.Module,
    diffusion: Diffusion,
    x_t: torch.Tensor,
    t: torch.Tensor,
    t_prev: torch.Tensor,
    cond: torch.Tensor,
    uncond: torch.Tensor,
    frames: torch.Tensor,
    w: torch.Tensor,
) -> torch.Tensor:
    """The guided teacher's DDIM step from x_t (B, n_z, d) at steps t (B,) to t_prev (B,),
    with per-sample guidance scales w (B,): the conditional and unconditional passes as one
    batch of 2B, as the teacher's own sampler runs them."""
    o_c, o_u = teacher(
        torch.cat([x_t, x_t]), torch.cat([t, t]), torch.cat([cond, uncond]), torch.cat([frames, frames])
    ).chunk(2)
    return diffusion.ddim_step(diffusion.guide(o_c, o_u, w), x_t, t, t_prev)


@dataclass
class StudentTraining:
    """What differs between the two kinds of student ``train_student`` distils.

    ``loss(student, target, teacher, diffusion, z0, cond, empty, frames, g, rows)``: the loss
    on ``rows`` of one batch (``student`` may be its DistributedDataParallel wrapper);
    ``target``: the EMA network (consistency) or None (guidance distillation trains the
    student alone and ships it); ``sampler(net, diffusion)``: the student's sampler, for
    validation; ``meta_key`` / ``settings``: the kind's name and config in the student's
    meta (``inference.samplers.student_kind`` reads them back); ``suffix``: OUT/<kind>_<suffix>.pt."""

    meta_key: str
    settings: Any  # a config dataclass with to_dict()
    suffix: str
    loss: Callable[..., torch.Tensor]
    sampler: Callable[[GuidedStudent, Diffusion], LatentSampler]
    sample_steps: int
    ema: float | None  # the target network's decay; None: no target network


def init_settings(path: str | Path, meta_key: str) -> dict:
    """The distillation settings an ``--init`` student recorded under ``meta_key`` (its
    kind's: "consistency", "guidance_distillation"), for a rescoring that takes no step."""
    meta = checkpoints.read_float32(path)["meta"]
    if meta_key not in meta:
        raise SystemExit(f"--init {path} is not a {meta_key} student: its meta has no {meta_key!r} settings")
    return meta[meta_key]


def say_ignored(args: argparse.Namespace, *flags: str) -> None:
    """Tell the user which of their ``flags`` a no-step rescoring leaves as the init had them."""
    given = [f"--{f.replace('_', '-')}" for f in flags if getattr(args, f, None) is not None]
    if given:
        print(f"{', '.join(given)} ignored: with --steps 0 the --init student is rescored as it was distilled")


def consistency_training(args: argparse.Namespace) -> StudentTraining:
    # MotionLCM's w range, widened to take in the teacher's own scale (it samples at 2-4 here,
    # below MotionLCM's 5), which is the student's default; --guidance-range narrows it (a
    # student of the one scale its method samples at spends no capacity on the others)
    sample_steps = getattr(args, "sample_steps", None)
    if getattr(args, "init", None) and getattr(args, "steps", None) == 0:
        # no step taken: a rescoring (and ship) of the init as it was distilled, its solver
        # grid, scales, objective and re-noising; only its default sampling steps may change
        say_ignored(args, "guidance_range", "solver_steps", "objective", "renoise", "huber_c")
        prior = ConsistencyConfig(**init_settings(args.init, "consistency"))
        cfg = dataclasses.replace(prior, sample_steps=sample_steps or prior.sample_steps)
        objective, lo, hi = cfg.objective, cfg.guidance_min, cfg.guidance_max
    else:
        w = teacher_scale(args, ConsistencyConfig.guidance)
        lo, hi = guidance_range(args, (min(ConsistencyConfig.guidance_min, w), max(ConsistencyConfig.guidance_max, w)))
        # the flags' defaults are None so that a no-step rescoring can tell what was given
        given = getattr(args, "objective", None)
        objective = "consistency" if given is None else given
        solver_steps = getattr(args, "solver_steps", None)
        solver_steps = ConsistencyConfig.solver_steps if solver_steps is None else solver_steps
        if solver_steps < 1:
            raise SystemExit(f"--solver-steps wants a positive number of DDIM steps, got {solver_steps}")
        renoise = getattr(args, "renoise", None)
        huber_c = getattr(args, "huber_c", None)
        cfg = ConsistencyConfig(
            huber_c=ConsistencyConfig.huber_c if huber_c is None else huber_c,
            solver_steps=solver_steps,
            sample_steps=sample_steps or ConsistencyConfig.sample_steps,
            guidance=min(max(w, lo), hi),
            guidance_min=lo,
            guidance_max=hi,
            objective=objective,
            renoise=ConsistencyConfig.renoise if renoise is None else renoise,
        )
    if objective == "trajectory" and lo != hi:
        # the teacher's sample is taken at one scale: the student learns that one
        raise SystemExit("--objective trajectory trains one guidance scale: give --guidance-range W W")

    def loss(student, target, teacher, diffusion, z0, cond, empty, frames, g, rows=ALL_ROWS):
        if objective == "trajectory":  # one process (train_student refuses torchrun)
            return trajectory_loss(student, teacher, diffusion, cfg, z0, cond, empty, frames, g)
        return distillation_loss(student, target, teacher, diffusion, cfg, z0, cond, empty, frames, g, rows)

    return StudentTraining(
        "consistency",
        cfg,
        "lcm",
        loss,
        lambda net, diffusion: ConsistencySampler(net, diffusion, cfg),
        cfg.sample_steps,
        cfg.ema,
    )


def train_consistency(args: argparse.Namespace) -> None:
    train_student(args, consistency_training(args))


def train_student(args: argparse.Namespace, kind: StudentTraining) -> None:
    """Distil ``args.teacher`` into a ``GuidedStudent`` of ``kind``; resumable from OUT/state.pt.
    Under torchrun, data-parallel (``distributed``): every process draws the whole batch and
    computes the loss on its rows of it, so N processes take the steps one would (up to the
    order of float sums) where the student has no dropout; with dropout each process's rows
    draw masks from the same seeded stream, as the denoisers' do, so they differ from one
    process's. The first process validates, saves and scores the teacher."""
    world = init_world()
    rows = world.shard(args.batch)  # refused here, before minutes of loading, where it does not divide
    if world.size > 1 and getattr(kind.settings, "objective", None) == "trajectory":
        # the student is unrolled through several calls before one backward, which
        # DistributedDataParallel's one gradient reduction per backward does not allow
        raise SystemExit("--objective trajectory runs in one process: run it without torchrun")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    teacher, tmeta = load_teacher(args.teacher)
    name = tmeta["kind"]
    _, vmeta = load_vae(Path(args.vae) / "vae.pt")
    if tmeta.get("vae_steps") != vmeta.get("steps"):
        raise SystemExit(
            f"{args.teacher} was trained on a VAE of {tmeta.get('vae_steps')} steps, {args.vae} has "
            f"{vmeta.get('steps')}: distil on the teacher's VAE"
        )
    data = world.first(lambda: training_caches(args))
    mu, logvar = torch.from_numpy(data["mu"]), torch.from_numpy(data["logvar"])
    frames_all = torch.from_numpy(data["frames"])
    text, empty = torch.from_numpy(data["text"]), torch.from_numpy(data["empty"])
    text_clip = torch.from_numpy(data["text_clip"])
    scale = float(tmeta["latent_scale"])
    diffusion = Diffusion(DiffusionConfig(**tmeta.get("diffusion", {})))
    torch.manual_seed(args.seed)
    start = build_student(args, teacher, tmeta, kind.meta_key)
    student, student_from = start.student, start.student_from
    init_steps = int(start.init_meta.get("steps", 0)) if start.init_meta is not None else 0
    for p in student.parameters():
        p.requires_grad_(True)
    student.train()
    target = None
    if kind.ema is not None:
        target = copy.deepcopy(student).eval()
        for p in target.parameters():
            p.requires_grad_(False)
    # on the device before the optimiser exists: a resumed state's moments follow the parameters
    dev = world.device
    teacher, student = teacher.to(dev), student.to(dev)
    target = target.to(dev) if target is not None else None
    opt = torch.optim.AdamW(student.parameters(), lr=args.lr, weight_decay=0.0)
    g = torch.Generator().manual_seed(args.seed)
    step = 0
    ema_loss, losses = None, LossAverage()
    state_path = out / "state.pt"
    settings = kind.settings.to_dict()
    if settings.get("objective") != "trajectory":
        # only how the student samples and is scored: free to change on a rerun, as --val-every is
        settings.pop("sample_steps", None)
    # a resume must go on with the network it started: another --student-from is another run
    net_record = {"student network": (student_from or {}).get("fingerprint")}
    run_recipe = recipe(args, STUDENT_RECIPE, **{"distillation settings": settings}, **net_record)
    if state_path.is_file():
        st = checkpoints.read_state(state_path)
        if st.get("recipe") is not None:
            # a state from before --student-from was recorded began as a copy of the teacher:
            # a resume may not claim another start, even one of the same shape
            st["recipe"].setdefault("student network", None)
        check_resume(st, run_recipe, state_path)
        student.load_state_dict(st["model"])
        if target is not None:
            target.load_state_dict(st["target"])
        opt.load_state_dict(st["opt"])
        step = st["step"]
        g.set_state(st["rng"])
        torch.set_rng_state(st["torch_rng"])  # the student's dropout draws from the global generator (CPU)
        # a run resumed only to be shipped takes no step: its meta keeps the last loss
        ema_loss = st.get("loss_ema")
        if world.main:
            print(f"resumed at step {step}")
    if world.main and world.size > 1:
        print(f"{name} {kind.suffix}: {world.size} processes, {args.batch // world.size} rows each")
    net = world.wrap(student)
    bar = tqdm(total=args.steps, initial=step, desc=f"{name} {kind.suffix}", dynamic_ncols=True, disable=not world.main)
    limit = getattr(args, "time_limit", None)
    started = time.monotonic()
    while step < args.steps:
        for grp in opt.param_groups:
            grp["lr"] = learning_rate(args.lr, step, args.steps, args.warmup, args.decay)
        cap, clip, z0 = draw_latents(mu, logvar, text_clip, scale, args.batch, g)
        loss = kind.loss(
            net,
            target,
            teacher,
            diffusion,
            to_device(z0, dev),
            to_device(text[cap], dev),
            to_device(empty, dev),
            to_device(frames_all[clip], dev),
            g,
            rows,
        )
        opt.zero_grad(set_to_none=True)
        loss.backward()
        torch.nn.utils.clip_grad_norm_(student.parameters(), 1.0)
        opt.step()
        if target is not None:
            lerp_weights(target, student, kind.ema)
        step += 1
        losses.add(loss)  # on the device: read every LOG_EVERY steps (device_steps)
        bar.update(1)
        # decided by all processes together (any one's clock): one leaving alone would hang DDP
        out_of_time = world.any(limit is not None and time.monotonic() - started > limit)
        saving = step % args.save_every == 0 or step == args.steps or out_of_time
        validating = bool(args.val_every) and (step % args.val_every == 0 or step == args.steps or out_of_time)
        if step % LOG_EVERY == 0 or saving or validating:  # every process: mean() may all-reduce
            ema_loss = world.mean(losses.tensor)
            bar.set_postfix(loss=f"{ema_loss:.4f}")
        if world.main and saving:
            extra = {"target": target.state_dict()} if target is not None else {}
            checkpoints.write_state(
                state_path,
                model=student.state_dict(),
                opt=opt.state_dict(),
                step=step,
                rng=g.get_state(),
                torch_rng=torch.get_rng_state(),
                loss_ema=ema_loss,
                recipe=run_recipe,
                **extra,
            )
        # the network that ships: LCM's EMA target, else the student itself
        shipped = target if target is not None else student
        if world.main and validating:
            try:
                with torch.random.fork_rng(devices=[]):  # the VAE built there draws from it; dropout does too
                    curve = _validate(args, kind, shipped, diffusion, scale, step, ema_loss)
                bar.write(json.dumps(curve[-1]))
            except Exception as err:  # a score lost must not lose the steps (nothing is saved yet)
                bar.write(f"validation failed at step {step}, training goes on: {type(err).__name__}: {err}")
        if saving or validating:
            world.barrier()  # the others wait while the first saves and validates
        if out_of_time:  # the last step, saved and validated as the last of --steps would be
            if world.main:  # tqdm's write ignores the bar's disable
                bar.write(f"time limit: stopping at step {step} of {args.steps}")
            break
    bar.close()
    world.barrier()
    if not world.main:
        return
    shipped = (target if target is not None else student).cpu().eval()
    if args.val_every and _last_validated(args) != step:
        # a run stopped between validations (killed after a save) and resumed to ship: score
        # the network it ships, so that the meta records its validation beside the teacher's
        with torch.random.fork_rng(devices=[]):
            _validate(args, kind, shipped, diffusion, scale, step, ema_loss)
    with torch.random.fork_rng(devices=[]):
        validation = _compare_with_teacher(args, teacher, shipped, diffusion, scale, kind, step)
    meta = {
        **{k: tmeta[k] for k in ("kind", "latent_scale", "vae_steps", "diffusion", "prediction", "data") if k in tmeta},
        "config": start.config,  # the student's network, which may be smaller than its teacher's
        **({"student_from": student_from} if student_from else {}),
        kind.meta_key: kind.settings.to_dict(),
        "teacher": {
            "from": Path(args.teacher).name,
            "steps": tmeta.get("steps"),
            "fingerprint": checkpoints.weights_fingerprint(teacher.state_dict()),
        },
        "steps": init_steps + step,
        **({"init": {"from": Path(args.init).name, "steps": init_steps}} if init_steps else {}),
        "batch": args.batch,
        "lr": args.lr,
        "final_loss_ema": ema_loss,
        "processes": world.size,  # data-parallel processes sharing each batch of --batch rows
        "params": sum(p.numel() for p in student.parameters()),
    }
    if init_steps and step == 0:
        # no step taken (``--steps 0``: rescore and ship, e.g. with other --sample-steps): the
        # network is the init's, so is the record of how it was trained
        prior = start.init_meta
        meta.update({k: prior[k] for k in ("batch", "lr", "final_loss_ema", "data", "processes") if k in prior})
        if "init" in prior:
            meta["init"] = prior["init"]
        else:
            meta.pop("init", None)
    if validation is not None:
        meta["validation"] = validation
    checkpoints.save_run(out / f"{name}_{kind.suffix}.pt", shipped, meta)
    (out / "result.json").write_text(json.dumps(meta, indent=1))
    if args.ship:
        teacher_shipped = checkpoints.read_float32(WEIGHTS / f"{name}.pt")["state_dict"]
        if checkpoints.weights_fingerprint(teacher_shipped) != meta["teacher"]["fingerprint"]:
            raise SystemExit(f"not shipped: {args.teacher} is not the shipped {name}.pt; ship the teacher first")
        checkpoints.ship(WEIGHTS / f"{name}_fast.pt", shipped, meta)


# what a student network must share with its teacher to learn the teacher's latents
_SHARED_LATENT = ("kind", "latent_scale", "vae_steps", "diffusion", "prediction")
_SHARED_CONFIG = ("latent_tokens", "latent_dim", "z_width", "frames_per_token", "text_dim")


@dataclass
class StudentStart:
    """What ``build_student`` starts a distillation from: the student (weights loaded), its
    network's config, where that network came from (``--student-from``'s record, kept by an
    ``--init`` of such a student) and the ``--init`` checkpoint's meta (None without one)."""

    student: GuidedStudent
    config: dict
    student_from: dict | None
    init_meta: dict | None


def build_student(args: argparse.Namespace, teacher: torch.nn.Module, tmeta: dict, meta_key: str) -> StudentStart:
    """The student to distil into.

    MotionLCM's student is a copy of its teacher, and so is ours by default. ``--student-from
    PATH`` departs from that: the student's network is built from PATH (a denoiser of the
    teacher's kind and latent, or a student of another teacher) with PATH's weights, so a
    smaller, faster network of the same method can learn the larger teacher's guided sampler.
    A student file's meta records its own config, which is what the method loads it by
    (``checkpoints.load_student``), so the registry needs nothing more. ``--init`` goes on
    from a ``meta_key`` student of this teacher (e.g. the shipped ``<kind>_fast.pt``: how a
    later run, or a lent GPU, goes on from what is in git; a run's ``state.pt`` is not
    kept), rebuilt from its own config."""
    init, source = getattr(args, "init", None), getattr(args, "student_from", None)
    if init and source:
        raise SystemExit("--init goes on from a student as it was built: --student-from starts a new one")
    if source:
        return _student_from(source, tmeta)
    config, init_ck = tmeta["config"], None
    if init:
        # checked before anything is built: a student of another teacher or kind is refused by
        # name, not by a config its teacher's kind cannot read
        init_ck = checkpoints.read_float32(init)
        if meta_key not in init_ck["meta"]:
            raise SystemExit(f"--init {init} is not a {meta_key} student")
        if not checkpoints.distilled_from(init_ck["meta"], teacher.state_dict()):
            raise SystemExit(f"--init {init} was distilled from other teacher weights")
        config = init_ck["meta"]["config"]
    # a copy of the teacher unless the init was distilled into another network
    student = (
        GuidedStudent(copy.deepcopy(teacher)) if config == tmeta["config"] else _fresh_student(tmeta["kind"], config)
    )
    if init_ck is None:
        return StudentStart(student, config, None, None)
    student.load_state_dict(init_ck["state_dict"])
    return StudentStart(student, config, init_ck["meta"].get("student_from"), init_ck["meta"])


def _student_from(source: str, tmeta: dict) -> StudentStart:
    """``--student-from``: a new student of ``source``'s network and weights, refused unless
    it shares the teacher's latent."""
    ck = checkpoints.read_float32(source)
    meta = ck["meta"]
    wrong = [k for k in _SHARED_LATENT if meta.get(k) != tmeta.get(k)]
    wrong += [f"config.{k}" for k in _SHARED_CONFIG if meta["config"].get(k) != tmeta["config"].get(k)]
    if wrong:
        raise SystemExit(f"--student-from {source} does not share the teacher's latent: {', '.join(wrong)} differ")
    student = _fresh_student(meta["kind"], meta["config"])
    if any(k in meta for k in STUDENT_KEYS):
        student.load_state_dict(ck["state_dict"])  # its w-embedding too: a student of another teacher
    else:
        student.net.load_state_dict(ck["state_dict"])
    fingerprint = checkpoints.weights_fingerprint(ck["state_dict"])  # the file's weights, as read
    record = {"from": Path(source).name, "steps": meta.get("steps"), "fingerprint": fingerprint}
    return StudentStart(student, meta["config"], record, None)


def _fresh_student(kind: str, config: dict) -> GuidedStudent:
    """A student network of ``config``. Its denoiser is built without drawing from the global
    generator (its weights are loaded next, and the run's dropout draws from that generator on
    the CPU), so the run draws what it would with a student copied from its teacher."""
    with torch.random.fork_rng(devices=[]):
        net = build_denoiser(kind, config_from_dict(kind, config))
    return GuidedStudent(net)


def _last_validated(args: argparse.Namespace) -> int | None:
    """The step of OUT/curve.json's last entry, None where nothing was validated."""
    path = Path(args.out) / "curve.json"
    curve = json.loads(path.read_text()) if path.is_file() else []
    return curve[-1]["step"] if curve else None


def _compare_with_teacher(
    args: argparse.Namespace,
    teacher: torch.nn.Module,
    student: torch.nn.Module,
    diffusion: Diffusion,
    scale: float,
    kind: StudentTraining,
    step: int,
) -> dict | None:
    """Both samplers' validation pass rates, which decide the method's default sampler
    (``registry.default_sampler``): the student's (``student``, the network that ships) and
    the teacher's guided DDIM at ``DIFFUSION_STEPS``, on the same prompts and seeds: seed 0
    by default, ``--val-seeds`` pools each over those seeds (the student's seed 0 is the
    curve's last score, OUT/curve.json). One seed of 349 prompts is a few points of noise
    against the 2-point rule: FTMoMamba's 1-step student was 2.3 points behind its teacher at
    seed 0 and 0.6 pooled over four (2026-11-27). None without ``--val-every`` (nothing
    measured, nothing claimed)."""
    path = Path(args.out) / "curve.json"
    if not args.val_every or not path.is_file():
        return None
    last = json.loads(path.read_text())[-1]
    if last["step"] != step:
        return None
    seeds = list(getattr(args, "val_seeds", None) or [0])
    w = teacher_scale(args, diffusion.cfg.guidance)  # the teacher's sampler as its method runs it
    keys = ("pass_rate", "direction_accuracy")
    res = _pool(
        [
            score_run(
                args, lambda net: GuidedDDIM(net, diffusion), teacher, scale, steps=DIFFUSION_STEPS, guidance=w, seed=s
            )
            for s in seeds
        ]
    )
    # seed 0 is the curve's last score: the same figure, not a second sampling of it; the
    # other seeds are scored where the curve's were, not on the CPU the student ships from
    on_device = copy.deepcopy(student).to(next(teacher.parameters()).device) if seeds != [0] else student
    fast = _pool(
        [
            last if s == 0 else score_run(args, lambda net: kind.sampler(net, diffusion), on_device, scale, seed=s)
            for s in seeds
        ]
    )
    out = {
        "prompts": res["n"],
        "sources": sorted(res["sources"]),
        **({"seeds": seeds} if seeds != [0] else {}),
        "fast": {"steps": kind.sample_steps, "guidance": kind.settings.guidance, **{k: fast[k] for k in keys}},
        "quality": {"steps": DIFFUSION_STEPS, "guidance": w, **{k: res[k] for k in keys}},
    }
    print(json.dumps({"validation": out}))
    return out


def _pool(runs: list[dict]) -> dict:
    """One sampler's scores at several seeds, pooled over their samples; ``n`` stays the
    prompts (the same at every seed). One seed's own figures as they are."""
    if len(runs) == 1:
        return runs[0]
    return {**pooled_rates(runs), "n": runs[0]["n"], "sources": runs[0]["sources"]}


def _validate(
    args: argparse.Namespace,
    kind: StudentTraining,
    student: GuidedStudent,
    diffusion: Diffusion,
    scale: float,
    step: int,
    loss: float | None,
) -> list:
    """Append the verifier pass rate on ``--val-n`` validation prompts of ``student`` (the
    network that ships), at its default steps and guidance, to OUT/curve.json and return
    the curve."""
    path = Path(args.out) / "curve.json"
    curve = json.loads(path.read_text()) if path.is_file() else []
    curve = [c for c in curve if c["step"] < step]
    res = score_run(args, lambda net: kind.sampler(net, diffusion), student, scale)
    curve.append({"step": step, "loss_ema": loss, "sample_steps": kind.sample_steps, **res})
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps(curve, indent=1))
    tmp.replace(path)
    return curve
