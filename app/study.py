"""The user study's logic: participants, balanced trials, anonymised motions, votes.

No Gradio here: ``study_ui`` puts a page and an HTTP API on top, tests drive it directly.

Anonymity: what a participant receives (``TrialView``) holds the prompt, its length and two
file URLs in a fresh random directory named ``a.glb`` and ``b.glb``. The GLBs carry only the
animation, fps, frame count and the prompt: no method, seed or key frames (key frames would
give KMM away). Generation times stay in the database. The method pair, the left/right order
the timings, and the sampler that made each motion are stored with the trial for the
results view.

Balance: each new trial takes a (method pair, prompt, seed) combination that this participant
has not seen (same pair and prompt): the pair this participant has had least, among those the
one that keeps a method out of the most trials in a row, then the pair and the combination
with the fewest trials so far in the whole study, ties broken at random. So every
participant's first trials cover the pairs evenly (with four methods, the first six trials
are the six pairs, no method in more than two trials in a row), not only the study as a
whole; A/B order is random per trial. The same prompt, length and seed go to both sides.
The choice and its record happen under a per-process lock; replicas sharing one database
each hold their own, so two choosing at the same moment may take the same combination: the
counts then stay within about one trial per replica of each other (docs/hosting.md).
Motions are deterministic in (method, prompt, seconds, seed), so generated GLBs are cached
in memory and shared by every trial that shows the same one (the trial records whether its
motions came from the cache and how long they took to generate the first time).
"""

from __future__ import annotations

import logging
import random
import secrets
import threading
import time
from collections import Counter, OrderedDict
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import motion_core
from motion_core import InputError
from motion_core.formats.gltf import glb_bytes
from motion_core.inference.generation import validate
from motion_core.inference.registry import default_sampler, get_info, samplers

from .study_config import ANSWERS, CRITERION_ANSWERS, StudyConfig
from .study_store import NewTrial, StudyStore, VoteRejected
from .viewer import OUTPUT_ROOT, file_url

log = logging.getLogger(__name__)

# (method, text, seconds, seed, sampler) -> (GLB, seconds it took, the sampler that made it)
GenerateFn = Callable[[str, str, float, int, str | None], tuple[bytes, float, str]]
# method -> (its default sampler, the samplers it offers)
SamplersFn = Callable[[str], tuple[str, tuple[str, ...]]]
MotionKey = tuple[str, str, float, int, str]


def _streak(pair: tuple[str, str], history: list[str]) -> int:
    """How many trials in a row one of ``pair``'s methods would have been in, with ``pair``
    next after ``history`` (a participant's pairs, "m1|m2", in trial order)."""
    longest = 0
    for method in pair:
        run = 1
        for earlier in reversed(history):
            if method not in earlier.split("|"):
                break
            run += 1
        longest = max(longest, run)
    return longest


class StudyError(ValueError):
    """Something a participant (or a client) did that the study cannot accept."""


def generate_glb(
    method: str, text: str, seconds: float, seed: int, sampler: str | None = None
) -> tuple[bytes, float, str]:
    """An anonymous GLB of one generated motion (``sampler``: None for the method's default),
    the seconds it took to generate and the sampler's name."""
    t0 = time.perf_counter()
    m = motion_core.generate([(text, seconds)], method=method, seed=seed, sampler=sampler)
    took = time.perf_counter() - t0
    extras = {
        "fps": m.fps,
        "frames": m.frames,
        "segments": [{"text": t, "start": int(s), "end": int(e)} for s, e, t in m.segments],
    }
    return glb_bytes(m.joints, m.fps, extras=extras), took, m.sampler


def method_samplers(method: str) -> tuple[str, tuple[str, ...]]:
    """(the method's default sampler, the samplers it offers) on this server."""
    info = get_info(method)
    return default_sampler(info), samplers(info)


@dataclass
class TrialView:
    """What the participant's browser gets for one trial (no method identity)."""

    participant: str
    trial: str
    number: int  # 1-based
    of: int
    prompt: str
    seconds: float
    a: str  # URL of motion A (left)
    b: str  # URL of motion B (right)
    criteria: list[str] = field(default_factory=list)

    def as_dict(self) -> dict[str, Any]:
        return {"done": False, **self.__dict__}


class StudyService:
    def __init__(
        self,
        config: StudyConfig,
        store: StudyStore,
        output_root: Path = OUTPUT_ROOT,
        generate: GenerateFn = generate_glb,
        samplers_of: SamplersFn = method_samplers,
        cache_size: int = 256,
        rng: random.Random | None = None,
    ) -> None:
        self.config = config
        self.store = store
        self.output_root = Path(output_root)
        self._generate = generate
        self._samplers_of = samplers_of
        self._cache: OrderedDict[MotionKey, tuple[bytes, float, str]] = OrderedDict()
        self._cache_size = cache_size
        self._key_locks: dict[MotionKey, threading.Lock] = {}
        self._lock = threading.Lock()
        self._assign_lock = threading.Lock()
        self._rng = rng or random.Random(secrets.randbits(64))

    # ---------------------------------------------------------------- motions
    def _motion(
        self, method: str, text: str, seconds: float, seed: int, sampler: str | None = None
    ) -> tuple[bytes, float, bool, str]:
        """(GLB, seconds it took when generated, whether it came from the cache, sampler).
        ``sampler`` None: the method's default (a new trial's); a resumed trial names the one
        it recorded, so that a default changed since does not change the motion voted on.
        Keyed by the sampler's name, so each motion has one cache entry and one lock."""
        if sampler is None:
            sampler = self._samplers_of(method)[0]
        key: MotionKey = (method, text, float(seconds), int(seed), sampler)
        with self._lock:
            if key in self._cache:
                self._cache.move_to_end(key)
                glb, took, made_by = self._cache[key]
                return glb, took, True, made_by
            key_lock = self._key_locks.setdefault(key, threading.Lock())
        with key_lock:  # two participants asking for the same motion generate it once
            with self._lock:
                if key in self._cache:
                    glb, took, made_by = self._cache[key]
                    return glb, took, True, made_by
            glb, took, made_by = self._generate(method, text, seconds, seed, sampler)
            with self._lock:
                self._cache[key] = (glb, took, made_by)
                while len(self._cache) > self._cache_size:
                    self._cache.popitem(last=False)
                self._key_locks.pop(key, None)
        return glb, took, False, made_by

    # ---------------------------------------------------------------- assignment
    def _choose(self, participant: str, custom: str | None) -> tuple[tuple[str, str], str, float, int]:
        cfg = self.config
        progress = self.store.progress(participant)
        history: list[str] = progress["pairs"]  # this participant's pairs, in trial order
        own = Counter(history)
        pair_counts = self.store.pair_counts(cfg.name)

        def pair_rank(pair: tuple[str, str]) -> tuple[int, int, int]:
            # the participant's own balance first, then no method in many trials in a row,
            # then the study's balance over all participants
            key = "|".join(pair)
            return own[key], _streak(pair, history), pair_counts.get(key, 0)

        if custom is not None:
            best = min(pair_rank(p) for p in cfg.pairs)
            pair = self._rng.choice([p for p in cfg.pairs if pair_rank(p) == best])
            return pair, custom, cfg.custom_prompt_seconds, self._rng.choice(cfg.seeds)
        counts = self.store.combo_counts(cfg.name)
        combos = [(pair, pr, seed) for pair in cfg.pairs for pr in cfg.prompts for seed in cfg.seeds]
        fresh = [c for c in combos if ("|".join(c[0]), c[1].text) not in progress["seen"]] or combos

        def rank(c: tuple[tuple[str, str], Any, int]) -> tuple[tuple[int, int, int], int]:
            return pair_rank(c[0]), counts.get(("|".join(c[0]), c[1].text, c[2]), 0)

        best_rank = min(rank(c) for c in fresh)
        pair, prompt, seed = self._rng.choice([c for c in fresh if rank(c) == best_rank])
        return pair, prompt.text, prompt.seconds, seed

    def _custom_prompt(self, text: str | None) -> str | None:
        text = (text or "").strip()
        if not text:
            return None
        if not self.config.allow_custom_prompts:
            raise StudyError("this study does not take participants' own prompts")
        try:
            for m in self.config.methods:
                validate([(text, self.config.custom_prompt_seconds)], m)
        except InputError as e:
            raise StudyError(str(e)) from None
        return text

    def _new_trial(self, participant: str, custom_prompt: str | None = None) -> TrialView:
        custom = self._custom_prompt(custom_prompt)
        with self._assign_lock:  # balanced choice and its record in one step (per process)
            pair, text, seconds, seed = self._choose(participant, custom)
            swapped = self._rng.random() < 0.5
            ma, mb = (pair[1], pair[0]) if swapped else pair
            ga, ta, ca, sa = self._motion(ma, text, seconds, seed)
            gb, tb, cb, sb = self._motion(mb, text, seconds, seed)
            token, position = self.store.add_trial(
                participant,
                NewTrial(
                    text,
                    seconds,
                    seed,
                    ma,
                    mb,
                    swapped,
                    ta,
                    tb,
                    ca,
                    cb,
                    custom_prompt=custom is not None,
                    sampler_a=sa,
                    sampler_b=sb,
                ),
            )
        return self._view(participant, token, position, text, seconds, ga, gb)

    def _view(
        self, participant: str, token: str, position: int, text: str, seconds: float, ga: bytes, gb: bytes
    ) -> TrialView:
        folder = self.output_root / secrets.token_hex(16)  # fresh names: URLs never repeat
        folder.mkdir(parents=True)
        (folder / "a.glb").write_bytes(ga)
        (folder / "b.glb").write_bytes(gb)
        return TrialView(
            participant=participant,
            trial=token,
            number=position + 1,
            of=self.config.trials_per_participant,
            prompt=text,
            seconds=seconds,
            a=file_url(folder / "a.glb"),
            b=file_url(folder / "b.glb"),
            criteria=list(self.config.criteria),
        )

    # ---------------------------------------------------------------- API
    def start(self, custom_prompt: str | None = None) -> dict[str, Any]:
        """A new anonymous participant and their first trial."""
        custom = self._custom_prompt(custom_prompt)  # checked before anything is stored
        participant = self.store.new_participant(self.config.name)
        return self._new_trial(participant, custom).as_dict()

    def resume(self, participant: str) -> dict[str, Any]:
        """Where a returning participant (a reload, a server restart) goes on: their open trial
        again (same pair, order, prompt and seed, fresh file URLs), else the next one, else done."""
        try:
            progress = self.store.progress(participant)
        except VoteRejected as e:
            raise StudyError(str(e)) from None
        if progress["votes"] >= self.config.trials_per_participant:
            return {
                "done": True,
                "participant": participant,
                "votes": progress["votes"],
                "of": self.config.trials_per_participant,
            }
        t = self.store.open_trial(participant)
        if t is None:
            return self._new_trial(participant).as_dict()
        # the samplers the trial recorded; one no longer offered (its student removed) gives
        # way to the method's default, and the trial records that. None (a trial from before
        # samplers were recorded): today's default, and the record stays None (unknown)
        chosen = []
        for method, recorded in ((t.method_a, t.sampler_a), (t.method_b, t.sampler_b)):
            default, offered = self._samplers_of(method)
            if recorded is not None and recorded not in offered:
                log.warning("trial %s: %s no longer offers sampler %r; showing %r", t.token, method, recorded, default)
                chosen.append(default)
            else:
                chosen.append(recorded)
        ga, took_a, cached_a, _ = self._motion(t.method_a, t.prompt, t.seconds, t.seed, chosen[0])
        gb, took_b, cached_b, _ = self._motion(t.method_b, t.prompt, t.seconds, t.seed, chosen[1])
        if chosen != [t.sampler_a, t.sampler_b]:
            # a side that fell back shows another motion: its timing and cache flag follow it
            self.store.set_samplers(
                t.token,
                (t.sampler_a, t.sampler_b),
                chosen[0],
                chosen[1],
                (took_a, cached_a) if chosen[0] != t.sampler_a else None,
                (took_b, cached_b) if chosen[1] != t.sampler_b else None,
            )
        return self._view(participant, t.token, t.position, t.prompt, t.seconds, ga, gb).as_dict()

    def vote(
        self,
        participant: str,
        trial: str,
        answer: str,
        criteria: dict[str, str] | None = None,
        watched: tuple[bool | None, bool | None] = (None, None),
        next_prompt: str | None = None,
    ) -> dict[str, Any]:
        """Store a vote, then return the next trial, or {"done": True, ...} after the last."""
        if answer not in ANSWERS:
            raise StudyError(f"answer must be one of {', '.join(ANSWERS)}")
        criteria = {k: v for k, v in (criteria or {}).items() if v}
        custom = self._custom_prompt(next_prompt)
        try:
            votes = self.store.record_vote(
                participant,
                trial,
                answer,
                criteria,
                watched,
                allowed_answers=ANSWERS,
                allowed_criteria={c: CRITERION_ANSWERS for c in self.config.criteria},
            )
        except VoteRejected as e:
            raise StudyError(str(e)) from None
        if votes >= self.config.trials_per_participant:
            return {
                "done": True,
                "participant": participant,
                "votes": votes,
                "of": self.config.trials_per_participant,
            }
        return self._new_trial(participant, custom).as_dict()
