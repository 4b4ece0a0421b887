"""Each method's measured figures, read from the shipped evaluation results, for the page.

The default method and the picker's labels come from here, not from constants: when a
retrained model's figures are written to results/, the page changes with them.

- text following: the automatic verifier's pass rate (``python -m motion_core.eval``), from every
  ``results/verifier*.json`` (procedural and motion-capture test prompts), pooled over their
  prompts (each file's top-level ``n``, a row per method with ``pass_rate``);
- time: ``results/bench.json``'s median wall time for a 10 s two-segment timeline here.

Each method's figures are those of the sampler a request gets by default: a method whose
default is its distilled student ("fast") is read from its ``NAME:fast`` rows (the bare row
is its own sampler, "quality").

MMS_RESULTS_DIR points at another results folder (tests use a temporary one).
"""

from __future__ import annotations

import json
import logging
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypedDict

REPO = Path(__file__).resolve().parents[1]
log = logging.getLogger("motion_mamba_studio")


def results_dir() -> Path:
    return Path(os.environ.get("MMS_RESULTS_DIR", REPO / "results"))


class MethodSummary(TypedDict):
    """One method as the API lists it."""

    name: str
    display_name: str
    description: str
    text_following: float | None  # share of test prompts whose motion passed the verifier
    test_prompts: int  # how many prompts that share is of
    timeline_10s_seconds: float | None  # median time for a 10 s timeline on the bench machine
    default: bool  # the method the page preselects (the best text following)
    samplers: list[str]  # "quality"; "fast" where a distilled student ships
    default_sampler: str  # what a request without a sampler gets


@dataclass(frozen=True)
class Figures:
    passed: float  # prompts passed, summed over the verifier files
    prompts: int
    sources: tuple[str, ...]  # the files' "source" ("procedural", "real")
    timeline_10s_s: float | None
    bench_machine: str = ""  # "2 CPUs, 1 thread", from bench.json
    # per file, in the sources' order: (source, prompts passed, prompts)
    parts: tuple[tuple[str, float, int], ...] = ()

    @property
    def pass_rate(self) -> float | None:
        return self.passed / self.prompts if self.prompts else None

    def source_rate(self, source: str) -> tuple[float, int] | None:
        """(pass rate, prompts) over the files of one source ("real": the captions of
        held-out real motion-capture clips), None where none was measured."""
        passed = sum(p for s, p, _ in self.parts if s == source)
        n = sum(k for s, _, k in self.parts if s == source)
        return (passed / n, n) if n else None


def _read(path: Path) -> dict[str, Any]:
    try:
        doc = json.loads(path.read_text())
    except (OSError, json.JSONDecodeError) as e:  # a broken file must not stop the page
        log.warning("ignoring %s: %s", path, e)
        return {}
    return doc if isinstance(doc, dict) else {}


def default_rows(infos: list[dict[str, Any]]) -> dict[str, str]:
    """Method name -> the results row of the sampler it samples with by default."""
    return {m["name"]: m["name"] + (":fast" if m.get("default_sampler") == "fast" else "") for m in infos}


def load_figures(
    names: list[str], folder: Path | None = None, rows: dict[str, str] | None = None
) -> dict[str, Figures]:
    """Figures for the methods ``names`` (a method without any measured row gets none);
    ``rows``: the results row to read for a method (``default_rows``; its name by default)."""
    folder = folder or results_dir()
    rows = rows or {}
    passed: dict[str, float] = {n: 0.0 for n in names}
    prompts: dict[str, int] = {n: 0 for n in names}
    sources: dict[str, list[str]] = {n: [] for n in names}
    parts: dict[str, list[tuple[str, float, int]]] = {n: [] for n in names}
    for path in sorted(folder.glob("verifier*.json")):
        doc = _read(path)
        n = doc.get("n")
        if not isinstance(n, int) or n <= 0:
            continue
        for name in names:
            row = doc.get(rows.get(name, name))
            rate = row.get("pass_rate") if isinstance(row, dict) else None
            if isinstance(rate, int | float):
                passed[name] += float(rate) * n
                prompts[name] += n
                sources[name].append(str(doc.get("source", path.stem)))
                parts[name].append((sources[name][-1], float(rate) * n, n))
    bench_doc = _read(folder / "bench.json")
    bench = bench_doc.get("generate") or {}
    machine = bench_doc.get("machine") or {}
    where = ""
    if isinstance(machine, dict) and machine.get("cpus"):
        gpu = "a GPU" if machine.get("cuda") else "CPU only"
        threads = machine.get("threads")
        where = f"{machine['cpus']} CPUs, {gpu}" + (
            f", {threads} torch thread" + "s" * (threads != 1) if threads else ""
        )
    out = {}
    for name in names:
        row = bench.get(rows.get(name, name))
        ms = row.get("timeline_10s_median_ms") if isinstance(row, dict) else None
        out[name] = Figures(
            passed=passed[name],
            prompts=prompts[name],
            sources=tuple(sources[name]),
            timeline_10s_s=float(ms) / 1000.0 if isinstance(ms, int | float) else None,
            bench_machine=where,
            parts=tuple(parts[name]),
        )
    return out


def best_method(names: list[str], figures: dict[str, Figures]) -> str | None:
    """The method with the highest measured pass rate; the registry's first when none is
    measured (ties keep the registry's order)."""
    if not names:
        return None
    measured = [n for n in names if figures.get(n) and figures[n].pass_rate is not None]
    if not measured:
        return names[0]
    return max(measured, key=lambda n: (figures[n].pass_rate, -names.index(n)))


def percent(rate: float) -> str:
    return f"{100 * rate:.0f}%"


def seconds_text(s: float) -> str:
    return f"{s * 1000:.0f} ms" if s < 0.95 else f"{s:.1f} s"


def known_actions(kinds: int | None) -> str:
    """What every test prompt is about, in a user's words: "the 35 actions it knows"."""
    return f"the {kinds} actions it knows" if kinds else "the actions it was trained on"


def choice_label(display_name: str, f: Figures | None, kinds: int | None = None) -> str:
    """The picker's entry: "KMM · follows 92% of prompts about the 35 actions it knows · 40 ms
    for 10 s". The test prompts are all about the corpus's kinds of action (``kinds``, from
    the core's prompt guide): a figure of "test prompts" alone read as what a user types."""
    parts = [display_name]
    if f is not None and f.pass_rate is not None:
        parts.append(f"follows {percent(f.pass_rate)} of prompts about {known_actions(kinds)}")
    else:
        parts.append("text following not measured")
    if f is not None and f.timeline_10s_s is not None:
        parts.append(f"{seconds_text(f.timeline_10s_s)} for 10 s")
    return " · ".join(parts)


SOURCE_WORDS = {
    "procedural": "captions of procedural test clips",
    "real": "captions of real motion-capture clips (the test split, unseen in training)",
}


def figures_note(f: Figures | None, kinds: int | None = None) -> str:
    """Where a method's figures come from, in a user's words, each test set's share on its own."""
    if f is None or f.pass_rate is None:
        return "Its text following has not been measured (no row in results/verifier*.json)."
    note = (
        f"Its motions passed the automatic verifier on {percent(f.pass_rate)} of {f.prompts} test prompts, all "
        f"about {known_actions(kinds)}"
    )
    split = [
        f"{percent(got[0])} of {got[1]} {SOURCE_WORDS.get(src, src + ' test prompts')}"
        for src in dict.fromkeys(f.sources)
        if (got := f.source_rate(src)) is not None
    ]
    if split:
        note += ": " + ", ".join(split)
    note += ". Prompts about other actions are followed less well, or not at all"
    if f.timeline_10s_s is not None:
        where = f.bench_machine or "bench machine"
        note += f". A 10 s timeline takes {seconds_text(f.timeline_10s_s)} (median, {where})"
    return note + "."


def summaries(infos: list[dict[str, Any]], folder: Path | None = None) -> list[MethodSummary]:
    names = [m["name"] for m in infos]
    figures = load_figures(names, folder, default_rows(infos))
    best = best_method(names, figures)
    return [
        MethodSummary(
            name=m["name"],
            display_name=m["display_name"],
            description=m["description"],
            text_following=figures[m["name"]].pass_rate,
            test_prompts=figures[m["name"]].prompts,
            timeline_10s_seconds=figures[m["name"]].timeline_10s_s,
            default=m["name"] == best,
            samplers=list(m.get("samplers", ["quality"])),
            default_sampler=m.get("default_sampler", "quality"),
        )
        for m in infos
    ]
