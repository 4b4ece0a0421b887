"""The user-study page (``MMS_MODE=study python app.py``): anonymised A/B trials and results.

A page of its own, not a tab of the demo: a Gradio page's config holds every component's
value, so a study tab beside the demo's method picker would ship the method names to every
participant. Nothing this page or its API sends names a method (tested over every payload).

HTTP API (``gradio_client``), the same functions the page uses:
* ``/study_start(prompt="")``: a new anonymous participant and their first trial.
* ``/study_vote(participant, trial, answer, criteria="{}", watched="[]", next_prompt="")``:
  store the vote, get the next trial (or ``{"done": true}``).
* ``/study_resume(participant)``: the open trial again (after a reload or a restart).
* ``/study_results(token)``: the results (admin token; exists only when MMS_ADMIN_TOKEN is set).
"""

from __future__ import annotations

import hmac
import html
import json
import logging
import math
import os
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal

import gradio as gr
import plotly.graph_objects as go

from .api_guard import endpoint
from .limits import RateLimited, from_env
from .study import StudyError, StudyService
from .study_config import ANSWERS, StudyConfig
from .study_stats import summarise, votes_csv
from .viewer import STATIC, file_url, new_output_dir, static_paths, three_missing_html

log = logging.getLogger("motion_mamba_studio.study")
STUDY_CONCURRENCY = 2

ANSWER_LABELS = [("A is better", "A"), ("B is better", "B"), ("About the same", "tie"), ("Both are bad", "both_bad")]
CRITERION_LABELS = [("A", "A"), ("B", "B"), ("Same", "tie")]

CSS = """
.mms-pair { display: grid; grid-template-columns: 1fr 1fr; gap: 10px; }
.mms-side { display: flex; flex-direction: column; align-items: center; }
.mms-side-label { font: 700 22px sans-serif; color: #fff; background: #333; border-radius: 6px;
  padding: 2px 14px; margin-bottom: 6px; }
.mms-side iframe { width: 100%; height: 420px; border: 0; border-radius: 8px; }
"""


def pair_template() -> str:
    """Two viewers labelled A (left) and B (right); sources set by PAIR_JS with a sync id."""
    if (missing := three_missing_html()) is not None:
        return missing
    src = html.escape(file_url(STATIC / "viewer.html"))
    sides = "".join(
        f"<div class='mms-side'><div class='mms-side-label'>{s}</div>"
        f"<iframe class='mms-study-viewer' data-side='{s}' data-src='{src}' title='motion {s}'></iframe></div>"
        for s in ("A", "B")
    )
    return f"<div class='mms-pair'>{sides}</div>"


# Gives both viewers one random BroadcastChannel id (viewer.js ?sync=: any control is
# mirrored, A leads the clock), and forwards each new trial's two GLB URLs.
PAIR_JS = """
const frames = Array.from(element.querySelectorAll('iframe.mms-study-viewer'));
const channel = Math.random().toString(36).slice(2);
frames.forEach((f, i) => {
  f.src = f.dataset.src + '?keyframes=0&fullscreen=0&sync=' + channel + (i === 0 ? '&lead=1' : '');
});
const send = () => {
  let v = null;
  try { v = props.value ? JSON.parse(props.value) : null; } catch (e) { v = null; }
  if (!v) return;
  [v.a, v.b].forEach((url, i) => {
    const w = frames[i] && frames[i].contentWindow;
    if (url && w) w.postMessage({type: 'mms-load', glb: url}, window.location.origin);
  });
};
frames.forEach((f) => f.addEventListener('load', send));
watch('value', send);
send();
"""

# Before a vote is sent: whether each viewer played its motion through at least once.
WATCHED_JS = """
(...args) => {
  const frames = document.querySelectorAll('iframe.mms-study-viewer');
  const watched = Array.from(frames).map((f) => {
    try { const v = f.contentWindow.viewer; return !!(v && v.ready && v.plays >= 1); } catch (e) { return null; }
  });
  args[args.length - 1] = JSON.stringify(watched);
  return args;
}
"""


def _parse_watched(text: str | list | None) -> tuple[bool | None, bool | None]:
    """[played A through, played B through] as the page reports it (a JSON string, or a list
    from an API client); anything else records "unknown" for both."""
    if isinstance(text, list):
        w = text
    else:
        try:
            w = json.loads(text or "[]")
        except (TypeError, ValueError):
            return None, None
    if not isinstance(w, list) or len(w) != 2:
        return None, None
    return tuple(x if isinstance(x, bool) else None for x in w)  # type: ignore[return-value]


def _parse_criteria(text: str | dict | None) -> dict[str, str]:
    if isinstance(text, dict):
        data = text
    else:
        try:
            data = json.loads(text or "{}")
        except (TypeError, ValueError):
            raise StudyError("criteria must be a JSON object {criterion: 'A' | 'B' | 'tie'}") from None
    if not isinstance(data, dict):
        raise StudyError("criteria must be a JSON object {criterion: 'A' | 'B' | 'tie'}")
    return {str(k): str(v) for k, v in data.items() if v}


def results_figures(summary: dict[str, Any]) -> tuple[go.Figure, go.Figure]:
    """Win rate per pair (decisive votes, Wilson 95%) and the Bradley-Terry ranking."""
    pairs = [p for p in summary["pairs"] if p["win_rate_1"] is not None]
    wr = go.Figure(
        go.Bar(
            x=[p["win_rate_1"] for p in pairs],
            y=[f"{p['method_1']} vs {p['method_2']}" for p in pairs],
            orientation="h",
            error_x={
                "type": "data",
                "symmetric": False,
                "array": [p["ci95_1"][1] - p["win_rate_1"] for p in pairs],
                "arrayminus": [p["win_rate_1"] - p["ci95_1"][0] for p in pairs],
            },
            text=[f"{p['wins_1']}:{p['wins_2']} (ties {p['ties']}, both bad {p['both_bad']})" for p in pairs],
        )
    )
    wr.add_vline(x=0.5, line_dash="dot")
    wr.update_layout(
        title="Win rate of the first method (decisive votes, 95% Wilson CI)",
        xaxis={"range": [0, 1]},
        height=120 + 50 * max(len(pairs), 1),
        margin={"l": 10, "r": 10, "t": 50, "b": 30},
    )
    rk = summary["ranking"]
    bt = go.Figure(
        go.Scatter(
            x=[r["score"] for r in rk],
            y=[r["method"] for r in rk],
            mode="markers",
            marker={"size": 12},
            error_x={
                "type": "data",
                "symmetric": False,
                "array": [r["ci95"][1] - r["score"] for r in rk],
                "arrayminus": [r["score"] - r["ci95"][0] for r in rk],
            },
        )
    )
    bt.update_layout(
        title="Bradley-Terry score (Elo scale, bootstrap 95% CI)",
        yaxis={"autorange": "reversed"},
        height=120 + 50 * max(len(rk), 1),
        margin={"l": 10, "r": 10, "t": 50, "b": 30},
    )
    return wr, bt


def _count(n: int, noun: str) -> str:
    """ "1 participant", "2 participants"."""
    return f"{n} {noun}{'' if n == 1 else 's'}"


def welcome_back(progress: dict[str, Any] | None, trials_per_participant: int) -> str:
    """What a returning participant is told before they press Start."""
    if not progress or progress.get("study") is None:
        return ""
    votes = progress["votes"]
    if votes >= trials_per_participant:
        return f"Welcome back: you have answered all {trials_per_participant} trials. Thank you!"
    if progress.get("open"):
        return (
            f"Welcome back: you have answered {votes} of {trials_per_participant}. Press **Resume**: your open "
            f"trial (trial {votes + 1}) resumes where you left off, with the same two motions."
        )
    return f"Welcome back: you have answered {votes} of {trials_per_participant}. Press **Resume** to go on."


def results_markdown(summary: dict[str, Any]) -> str:
    lines = [
        f"**{_count(summary['votes'], 'vote')}** from {_count(summary['participants'], 'participant')}; answers "
        + ", ".join(f"{k} {v}" for k, v in summary["answers"].items())
        + f"; both motions played through before {summary['watched_both']} votes; median decision time "
        + (
            f"{summary['median_decision_seconds']:.1f} s." if summary["median_decision_seconds"] is not None else "n/a."
        ),
        "",
        "| pair | votes | wins | ties | both bad | win rate of the first (95% CI) |",
        "|---|---|---|---|---|---|",
    ]
    for p in summary["pairs"]:
        rate = (
            "n/a" if p["win_rate_1"] is None else f"{p['win_rate_1']:.2f} ({p['ci95_1'][0]:.2f}-{p['ci95_1'][1]:.2f})"
        )
        lines.append(
            f"| {p['method_1']} vs {p['method_2']} | {p['n']} | {p['wins_1']}:{p['wins_2']} | {p['ties']} | "
            f"{p['both_bad']} | {rate} |"
        )
    lines += ["", "| rank | method | Bradley-Terry score (95% CI) | votes |", "|---|---|---|---|"]
    for r in summary["ranking"]:
        lines.append(
            f"| {r['rank']} | {r['method']} | {r['score']:.0f} ({r['ci95'][0]:.0f}-{r['ci95'][1]:.0f}) | {r['votes']} |"
        )
    if summary["criteria"]:
        lines += ["", "| criterion | pair | votes | wins | same |", "|---|---|---|---|---|"]
        for c in summary["criteria"]:
            lines.append(
                f"| {html.escape(c['criterion'])} | {c['method_1']} vs {c['method_2']} | {c['n']} | "
                f"{c['wins_1']}:{c['wins_2']} | {c['ties']} |"
            )
    return "\n".join(lines)


@dataclass
class StudyApi:
    """The study's HTTP API (also what the page's buttons call), rate-limited per session;
    wrong admin tokens are limited per client address and in all besides."""

    start: Callable[..., dict]
    vote: Callable[..., dict]
    resume: Callable[..., dict]
    results: Callable[..., dict]
    check_token: Callable[[str, Any], None]


#: the shortest admin token the study starts with (a guessable one would open the results)
MIN_ADMIN_TOKEN_CHARS = 16


def check_admin_token(token: str | None) -> None:
    """ValueError for a token too short to be safe (None: no results view, fine)."""
    if token is not None and len(token) < MIN_ADMIN_TOKEN_CHARS:
        raise ValueError(
            f"the admin token is {len(token)} characters long; use at least {MIN_ADMIN_TOKEN_CHARS} (a random "
            "one: python -c 'import secrets; print(secrets.token_urlsafe(24))'), or unset it for no results view"
        )


def client_address(request: gr.Request | None) -> str:
    """Where a request came from: the last X-Forwarded-For hop when a proxy in front (a
    hosted space's) adds one, else the connection's peer. A client can write the header
    itself, so the limit over all addresses backs this one up."""
    if request is None:
        return "unknown"
    forwarded = (request.headers.get("x-forwarded-for") or "").split(",")[-1].strip()
    return forwarded or getattr(getattr(request, "client", None), "host", None) or "unknown"


def _study_api(service: StudyService, admin_token: str | None, bootstrap_rounds: int) -> StudyApi:
    check_admin_token(admin_token)
    cfg = service.config
    start_limit = from_env("study_start", 6, 3)
    vote_limit = from_env("study_vote", 40, 10)
    admin_limit = from_env("study_results", 10, 5)
    # wrong admin tokens: a new session costs nothing, so they are counted per client
    # address (5, then one more every 12 s) and over all clients (30, then one every 2 s)
    wrong_per_address = from_env("admin_failures", 5, 5)
    wrong_in_all = from_env("admin_failures_total", 30, 30)

    def guarded(limiter, request: gr.Request | None, what: str) -> None:
        try:
            limiter.check(getattr(request, "session_hash", None), what)
        except RateLimited as e:
            raise gr.Error(str(e), title="Slow down") from None

    def api_start(prompt: str = "", request: gr.Request = None) -> dict:  # type: ignore[assignment]
        """Join the study: returns an anonymous participant id and the first trial."""
        guarded(start_limit, request, "new participants")
        try:
            return service.start(prompt or None)
        except StudyError as e:
            raise gr.Error(str(e), title="Please check") from None

    def api_vote(
        participant: str,
        trial: str,
        answer: Literal["A", "B", "tie", "both_bad"],
        criteria: str | dict[str, str] = "{}",
        watched: str | list[bool | None] = "[]",
        next_prompt: str = "",
        request: gr.Request = None,  # type: ignore[assignment]
    ) -> dict:
        """Answer a trial with A, B, tie or both_bad (criteria: {criterion: A|B|tie}, as JSON
        or an object; watched: [played A through, played B through], as JSON or a list);
        returns the next trial, or {"done": true} after the last."""
        guarded(vote_limit, request, "votes")
        try:
            return service.vote(
                participant, trial, answer, _parse_criteria(criteria), _parse_watched(watched), next_prompt or None
            )
        except StudyError as e:
            raise gr.Error(str(e), title="Vote not stored") from None

    def api_resume(participant: str, request: gr.Request = None) -> dict:  # type: ignore[assignment]
        """Go on with a study after a reload or a restart: the open trial again, or the next."""
        guarded(vote_limit, request, "requests")
        try:
            return service.resume(participant)
        except StudyError as e:
            raise gr.Error(str(e), title="Please check") from None

    def check_token(token: str, request: gr.Request | None) -> None:
        guarded(admin_limit, request, "results requests")
        address = client_address(request)
        # refused before the token is compared: a refusal tells a guesser nothing
        for limiter, key, where in ((wrong_per_address, address, "from this address"), (wrong_in_all, "all", "")):
            if (wait := limiter.wait(key)) > 0:
                raise gr.Error(
                    f"too many wrong admin tokens {where or 'lately'}: try again in {math.ceil(wait)} s",
                    title="Slow down",
                )
        if not admin_token or not hmac.compare_digest(str(token or "").encode(), admin_token.encode()):
            wrong_per_address.take(address)
            wrong_in_all.take("all")
            raise gr.Error("wrong admin token", title="Results")

    def api_results(token: str, request: gr.Request = None) -> dict:  # type: ignore[assignment]
        """The study's results (admin token)."""
        check_token(token, request)
        return summarise(service.store.votes(cfg.name), cfg.methods, cfg.criteria, rounds=bootstrap_rounds)

    return StudyApi(api_start, api_vote, api_resume, api_results, check_token)


def build_study(service: StudyService, admin_token: str | None = None, bootstrap_rounds: int = 1000) -> gr.Blocks:
    """The study page; the Results tab (and /study_results) exist only with an admin token
    (ValueError for one shorter than MIN_ADMIN_TOKEN_CHARS)."""
    gr.set_static_paths(static_paths())
    cfg = service.config
    api = _study_api(service, admin_token, bootstrap_rounds)
    with gr.Blocks(title="Motion study", delete_cache=(1800, 3600)) as demo:
        gr.Markdown(f"# {html.escape(cfg.title)}\n{html.escape(cfg.instructions)}", elem_id="study-intro")
        # the anonymous id stays in the browser, so a reload goes on with the same participant
        participant = gr.BrowserState("", storage_key="mms-study-participant")
        trial = gr.State("")
        with gr.Tabs():
            with gr.Tab("Study"):
                page = _study_tab(cfg)
            if admin_token:
                with gr.Tab("Results"):
                    results = _results_tab()
        _wire_study(demo, service, api, page, participant, trial)
        # each argument checked against the functions' type hints, each refusal one log line
        endpoint(api.start, "study_start", concurrency_id="study")
        endpoint(api.vote, "study_vote", concurrency_id="study")
        endpoint(api.resume, "study_resume", concurrency_id="study")
        if admin_token:
            _wire_results(service, api, results, bootstrap_rounds)
            endpoint(api.results, "study_results")
    return demo


def _study_tab(cfg: StudyConfig) -> dict[str, Any]:
    """The intro (optional first prompt, start) and the trial (two viewers, answers, submit)."""
    with gr.Column(visible=True) as intro:
        first_prompt = gr.Textbox(
            label="Your own prompt for the first trial (optional)",
            max_lines=2,
            visible=cfg.allow_custom_prompts,
            elem_id="study-first-prompt",
        )
        welcome = gr.Markdown("", elem_id="study-welcome")
        start_btn = gr.Button("Start", variant="primary", elem_id="study-start")
    with gr.Column(visible=False) as trial_box:
        counter = gr.Markdown("", elem_id="study-counter")
        prompt = gr.Textbox(label="Prompt", interactive=False, elem_id="study-prompt")
        pair = gr.HTML(value="", html_template=pair_template(), js_on_load=PAIR_JS, padding=False, elem_id="study-pair")
        answer = gr.Radio(ANSWER_LABELS, label="Overall, which motion is better?", elem_id="study-answer")
        crit_radios = [
            gr.Radio(CRITERION_LABELS, label=f"{c} (optional)", elem_id=f"study-criterion-{i}")
            for i, c in enumerate(cfg.criteria)
        ]
        next_prompt = gr.Textbox(
            label="Your own prompt for the next trial (optional)",
            max_lines=2,
            visible=cfg.allow_custom_prompts,
            elem_id="study-next-prompt",
        )
        watched = gr.Textbox(visible=False)
        submit = gr.Button("Submit and continue", variant="primary", elem_id="study-submit")
    done = gr.Markdown("", visible=False, elem_id="study-done")
    return {
        "intro": intro,
        "first_prompt": first_prompt,
        "welcome": welcome,
        "start_btn": start_btn,
        "trial_box": trial_box,
        "counter": counter,
        "prompt": prompt,
        "pair": pair,
        "answer": answer,
        "crit_radios": crit_radios,
        "next_prompt": next_prompt,
        "watched": watched,
        "submit": submit,
        "done": done,
    }


def _results_tab() -> dict[str, Any]:
    """The admin's view: token, summary, plots and downloads."""
    token_box = gr.Textbox(label="Admin token", type="password", elem_id="results-token")
    show_btn = gr.Button("Show results", elem_id="results-show")
    summary_md = gr.Markdown("", elem_id="results-summary")
    with gr.Row():
        wr_plot = gr.Plot(label="win rates")
        bt_plot = gr.Plot(label="ranking")
    with gr.Row():
        dl_csv = gr.DownloadButton("votes.csv", interactive=False, size="sm", elem_id="results-csv")
        dl_json = gr.DownloadButton("results.json", interactive=False, size="sm", elem_id="results-json")
    return {
        "token_box": token_box,
        "show_btn": show_btn,
        "outputs": [summary_md, wr_plot, bt_plot, dl_csv, dl_json],
    }


def _tell(err: gr.Error, n_outputs: int) -> list[Any]:
    """A page handler's refusal: one titled warning, one log line, the outputs left as they
    were. (A raised gr.Error would put a red "Error" badge over every output of the event,
    there after the message has gone: the wrong admin token left two, over the plots.)"""
    log.info("refused: %s: %s", err.title, err.message)
    gr.Warning(f"<strong>{html.escape(err.title)}</strong>: {html.escape(str(err.message))}", title=err.title)
    return [gr.skip()] * n_outputs


def _wire_study(demo: gr.Blocks, service: StudyService, api: StudyApi, page: dict, participant, trial) -> None:
    """Start or resume, show a trial, submit a vote and go on to the next."""
    cfg = service.config
    crit_radios = page["crit_radios"]

    def on_load(known: str):
        progress = None
        if known:
            try:
                progress = service.store.progress(known)
            except Exception:  # not in this study's database: a new participant
                progress = None
        note = welcome_back(progress, cfg.trials_per_participant)
        return note, gr.Button(value="Resume" if note else "Start")

    demo.load(on_load, participant, [page["welcome"], page["start_btn"]], api_visibility="private")

    def show(view: dict[str, Any], resumed: bool = False) -> list[Any]:
        if view.get("done"):
            return [
                view["participant"],
                "",
                gr.Column(visible=False),
                gr.Column(visible=False),
                gr.Markdown(f"Thank you: your {view['votes']} answers are stored.", visible=True),
                "",
                "",
                "",
                None,
                *[None] * len(crit_radios),
            ]
        return [
            view["participant"],
            view["trial"],
            gr.Column(visible=False),
            gr.Column(visible=True),
            gr.Markdown(visible=False),
            f"Trial {view['number']} of {view['of']}" + (" (resumed where you left off)" if resumed else ""),
            view["prompt"],
            json.dumps({"a": view["a"], "b": view["b"]}),
            None,
            *[None] * len(crit_radios),
        ]

    outputs = [
        participant,
        trial,
        page["intro"],
        page["trial_box"],
        page["done"],
        page["counter"],
        page["prompt"],
        page["pair"],
        page["answer"],
        *crit_radios,
    ]

    def on_start(text: str, known: str, request: gr.Request):
        if known:
            try:
                return show(service.resume(known), resumed=True)
            except StudyError:
                pass  # not in this study's database (e.g. a new study): start afresh
        try:
            return show(api.start(text, request))
        except gr.Error as e:
            return _tell(e, len(outputs))

    # the request first: Gradio injects it only into positional parameters
    def on_vote(request: gr.Request, p: str, t: str, a: str | None, *rest: Any):
        crit_values, nxt, w = rest[: len(crit_radios)], rest[-2], rest[-1]
        try:
            if a not in ANSWERS:
                raise gr.Error("choose an overall answer first", title="Vote not stored")
            crit = {c: v for c, v in zip(cfg.criteria, crit_values, strict=True) if v}
            return show(api.vote(p, t, a, json.dumps(crit), w, nxt or "", request))
        except gr.Error as e:
            return _tell(e, len(outputs))

    page["start_btn"].click(
        on_start,
        [page["first_prompt"], participant],
        outputs,
        concurrency_limit=STUDY_CONCURRENCY,
        concurrency_id="study",
        api_visibility="private",
    )
    page["submit"].click(
        on_vote,
        [participant, trial, page["answer"], *crit_radios, page["next_prompt"], page["watched"]],
        outputs,
        js=WATCHED_JS,
        concurrency_limit=STUDY_CONCURRENCY,
        concurrency_id="study",
        api_visibility="private",
    )


def _wire_results(service: StudyService, api: StudyApi, results: dict, bootstrap_rounds: int) -> None:
    """Show results: the summary, its plots and the votes as downloads (admin token)."""
    cfg = service.config

    def on_results(token: str, request: gr.Request):
        try:
            api.check_token(token, request)
        except gr.Error as e:
            return _tell(e, len(results["outputs"]))
        votes = service.store.votes(cfg.name)
        summary = summarise(votes, cfg.methods, cfg.criteria, rounds=bootstrap_rounds)
        out = new_output_dir()
        (out / "votes.csv").write_text(votes_csv(votes), encoding="utf-8")
        (out / "results.json").write_text(json.dumps({"summary": summary, "votes": votes}, indent=1))
        wr, bt = results_figures(summary)
        return (
            results_markdown(summary),
            wr,
            bt,
            gr.DownloadButton(value=str(out / "votes.csv"), interactive=True),
            gr.DownloadButton(value=str(out / "results.json"), interactive=True),
        )

    results["show_btn"].click(on_results, results["token_box"], results["outputs"], api_visibility="private")


def admin_token_from_env() -> str | None:
    """$MMS_ADMIN_TOKEN (None when unset or blank); ValueError for one too short to be safe."""
    token = os.environ.get("MMS_ADMIN_TOKEN", "").strip() or None
    check_admin_token(token)
    return token
