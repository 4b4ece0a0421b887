"""What a user study compares, read from a YAML or JSON file (a sample ships in configs/).

The researcher names the methods (at least two, from ``motion_core.methods()``), the prompts
with their lengths, the seeds, how many trials each participant sees, the criteria asked
besides the overall answer, and whether participants may type their own prompt.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from motion_core import InputError, UnknownMethod
from motion_core.inference.generation import validate
from motion_core.inference.registry import get_info

REPO = Path(__file__).resolve().parents[1]
SAMPLE_CONFIG = REPO / "configs" / "study-sample.yaml"
ANSWERS = ("A", "B", "tie", "both_bad")  # the overall question; A and B as the page labels them
CRITERION_ANSWERS = ("A", "B", "tie")


class StudyConfigError(ValueError):
    """A study configuration that cannot be run; the message says which field and why."""


@dataclass(frozen=True)
class Prompt:
    text: str
    seconds: float


@dataclass(frozen=True)
class StudyConfig:
    methods: tuple[str, ...]
    prompts: tuple[Prompt, ...]
    seeds: tuple[int, ...] = (0,)
    trials_per_participant: int = 6
    criteria: tuple[str, ...] = ("realism", "matches the text")
    allow_custom_prompts: bool = False
    custom_prompt_seconds: float = 4.0
    name: str = "study"
    title: str = "Which motion is better?"
    instructions: str = (
        "Watch both motions (they play in sync), then say which one is better overall for the prompt. "
        "Optionally answer per criterion. The motions come from different generators, shown in random order."
    )
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def pairs(self) -> list[tuple[str, str]]:
        """Every unordered method pair, each as a sorted tuple."""
        ms = sorted(self.methods)
        return [(a, b) for i, a in enumerate(ms) for b in ms[i + 1 :]]


def parse_config(data: dict[str, Any]) -> StudyConfig:
    """Validate a config mapping (as read from YAML/JSON); raises StudyConfigError."""
    if not isinstance(data, dict):
        raise StudyConfigError("a study config is a mapping (YAML or JSON object)")
    methods = tuple(str(m) for m in data.get("methods", ()))
    if len(set(methods)) < 2 or len(set(methods)) != len(methods):
        raise StudyConfigError("methods: name at least two different methods, each once")
    for m in methods:
        try:
            get_info(m)
        except UnknownMethod as e:
            raise StudyConfigError(f"methods: {e}") from None
    prompts = []
    for i, p in enumerate(data.get("prompts", ())):
        if isinstance(p, str):
            p = {"text": p, "seconds": data.get("seconds", 4.0)}
        try:
            prompt = Prompt(str(p["text"]).strip(), float(p.get("seconds", data.get("seconds", 4.0))))
            for m in methods:
                validate([(prompt.text, prompt.seconds)], m)
        except (KeyError, TypeError, ValueError, InputError) as e:
            raise StudyConfigError(f"prompts[{i}]: {e}") from None
        prompts.append(prompt)
    if not prompts and not data.get("allow_custom_prompts", False):
        raise StudyConfigError("prompts: give at least one prompt (or allow custom prompts)")
    seeds = tuple(int(s) for s in data.get("seeds", (0,)))
    if not seeds:
        raise StudyConfigError("seeds: give at least one seed")
    trials = int(data.get("trials_per_participant", 6))
    if not 1 <= trials <= 200:
        raise StudyConfigError("trials_per_participant: 1-200")
    criteria = tuple(str(c).strip() for c in data.get("criteria", ("realism", "matches the text")))
    if any(not c or len(c) > 60 for c in criteria) or len(set(criteria)) != len(criteria):
        raise StudyConfigError("criteria: distinct non-empty names of at most 60 characters")
    known = {
        "methods",
        "prompts",
        "seconds",
        "seeds",
        "trials_per_participant",
        "criteria",
        "allow_custom_prompts",
        "custom_prompt_seconds",
        "name",
        "title",
        "instructions",
    }
    kw: dict[str, Any] = {}
    for key in ("name", "title", "instructions"):
        if key in data:
            kw[key] = str(data[key])
    custom_seconds = float(data.get("custom_prompt_seconds", 4.0))
    if data.get("allow_custom_prompts", False):
        for m in methods:
            try:
                validate([("a person walks", custom_seconds)], m)
            except InputError as e:
                raise StudyConfigError(f"custom_prompt_seconds: {e}") from None
    return StudyConfig(
        methods=methods,
        prompts=tuple(prompts),
        seeds=seeds,
        trials_per_participant=trials,
        criteria=criteria,
        allow_custom_prompts=bool(data.get("allow_custom_prompts", False)),
        custom_prompt_seconds=custom_seconds,
        extra={k: v for k, v in data.items() if k not in known},
        **kw,
    )


def load_config(path: str | Path | None = None) -> StudyConfig:
    """Read a study config (.yaml/.yml/.json); default: $MMS_STUDY_CONFIG, else the sample."""
    path = Path(path or os.environ.get("MMS_STUDY_CONFIG") or SAMPLE_CONFIG)
    try:
        text = path.read_text(encoding="utf-8")
        data = json.loads(text) if path.suffix == ".json" else yaml.safe_load(text)
    except (OSError, ValueError, yaml.YAMLError) as e:
        raise StudyConfigError(f"cannot read the study config {path}: {e}") from None
    return parse_config(data)
