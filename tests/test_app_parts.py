"""The app's pure parts: timeline editing and JSON, plots, the viewer's HTML."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest
from motion_helpers import random_fk_motion

from app.plots import density_figure, kinematics_figure, motion_figure
from app.timeline import EXAMPLES, check_rows, download_stem, edit, from_json, from_rows, strip_html, to_json
from motion_core import InputError, Motion

REPO = Path(__file__).resolve().parents[1]


def test_edit_operations():
    segs = [("a", 1.0), ("b", 2.0), ("c", 3.0)]
    assert edit(segs, "up", 1) == [("b", 2.0), ("a", 1.0), ("c", 3.0)]
    assert edit(segs, "down", 1) == [("a", 1.0), ("c", 3.0), ("b", 2.0)]
    assert edit(segs, "up", 0) == segs and edit(segs, "down", 2) == segs
    assert edit(segs, "remove", 0) == [("b", 2.0), ("c", 3.0)]
    assert edit(segs, "add")[-1] == ("", 3.0)
    with pytest.raises(InputError, match="at most 10"):
        edit([("x", 1.0)] * 10, "add")
    with pytest.raises(InputError, match="at least one"):
        edit([("x", 1.0)], "remove", 0)


def test_rows_and_strip():
    segs = from_rows(2, ["walk", "wave", "unused"], [4, None, 9])
    assert segs == [("walk", 4.0), ("wave", None)]  # a blank box is blank, not 0 s
    html = strip_html([("walk <fast>", 3.0), ("wave", 1.0)])
    assert "width:75.000%" in html and "walk &lt;fast&gt;" in html and "total 4 s" in html
    assert "empty timeline" in strip_html([])


def test_check_rows_names_the_row_and_the_field():
    ok = ("a person walks", 3.0)
    cases = [
        ([ok, ("", 3.0)], (2, "text", "Segment 2: text"), "the text is empty"),
        ([("a" * 301, 3.0)], (1, "text", "Segment 1: text"), "301 characters"),
        ([("a person runs", 0.0)], (1, "seconds", "Segment 1: seconds"), "duration 0 s is outside 1-10 s"),
        ([ok, ("a person runs", 10.5)], (2, "seconds", "Segment 2: seconds"), "10.5 s"),
        ([("a person walks", 9.0)] * 7, (None, "timeline", "Timeline too long"), "lasts 63 s"),
    ]
    for segs, (row, field, title), words in cases:
        p = check_rows(segs, "kmm")
        assert (p.row, p.field, p.title) == (row, field, title) and words in p.message, p
        assert not p.message.startswith("segment ")  # the title names the row once
    # a blank seconds box is not a problem: the length estimator fills it
    assert check_rows([ok, ok, ("a person runs", None)], "kmm") is None
    assert check_rows([ok, ok], "kmm") is None
    assert "60 s: shorten" in strip_html([("a", 9.0)] * 7) and "mms-over" in strip_html([("a", 9.0)] * 7)


def test_json_round_trip_and_errors():
    segs = EXAMPLES["4-segment story"]
    doc = json.loads(to_json(segs))
    assert doc["lengths"] == [round(s * 20) for _, s in segs]
    assert from_json(to_json(segs)) == segs
    assert from_json('{"text": ["a"], "lengths": [50]}') == [("a", 2.5)]  # FlowMDM frames
    # null: the length estimator's pick, as a blank seconds box
    assert from_json('{"text": ["a", "b"], "seconds": [null, 2]}') == [("a", None), ("b", 2.0)]
    assert from_json('{"text": ["a"], "lengths": [null]}') == [("a", None)]
    for bad, msg in [
        ("{", "does not parse"),
        ("[]", "needs a"),
        ('{"text": ["a"]}', "lengths"),
        ('{"text": ["a", "b"], "seconds": [1]}', "2 texts but 1 durations"),
        ('{"text": [1], "seconds": [1]}', "segment 1"),
        ('{"text": ["a"], "seconds": [true]}', "segment 1"),
        ('{"text": ["a"], "seconds": ["3"]}', "segment 1"),
    ]:
        with pytest.raises(InputError, match=msg):
            from_json(bad)


def _motion(**kw) -> Motion:
    return Motion(random_fk_motion(60).astype(np.float32), 20, [(0, 30, "a"), (30, 60, "b")], "x", 0, **kw)


def test_plots_pick_what_is_meaningful():
    fig = motion_figure(_motion())
    assert "KMM" in fig.layout.title.text
    assert [t.name for t in fig.data] == ["root speed (m/s)", "left foot contact", "right foot contact"]
    assert len(fig.data[0].x) == 60
    assert kinematics_figure(_motion()).layout.title.text == fig.layout.title.text
    tok = np.arange(15)
    density = {"frame": tok * 4, "d": np.ones(15), "S": np.linspace(0, 1, 15), "gamma": np.linspace(0, 1, 15),
               "selected_tokens": [3, 9]}  # fmt: skip
    fig = density_figure(_motion(keyframes=[12, 36], density=density))
    keys = [t for t in fig.data if t.name == "key frames"]
    assert len(keys) == 1 and list(keys[0].x) == [12 / 20, 36 / 20]
    assert len([s for s in fig.layout.shapes if s.type == "line"]) == 3  # one boundary x three rows


INJECTION = "<script>alert(1)</script><img src=x onerror=alert(2)>"


def test_user_text_is_escaped_wherever_the_page_shows_it():
    html = strip_html([(INJECTION, 3.0)])
    assert "<script>" not in html and "<img" not in html and "&lt;script&gt;" in html
    m = Motion(random_fk_motion(40).astype(np.float32), 20, [(0, 40, INJECTION)], "x", 0)
    notes = [a.text for a in motion_figure(m).layout.annotations]
    assert notes and all("<script>" not in t and "<img" not in t for t in notes)


def test_download_names_say_prompt_method_and_seed():
    assert download_stem("A person walks forward!", "kmm", 3) == "a-person-walks-forward_kmm_seed3"
    assert download_stem("  ", "motion_mamba", 0) == "motion_motion-mamba_seed0"
    assert download_stem("../../etc/passwd <x>", "kmm", 1) == "etc-passwd-x_kmm_seed1"
    assert len(download_stem("a" * 300, "kmm", 0)) <= 48 + len("_kmm_seed0")


def test_plots_explain_themselves_and_leave_room_for_segment_titles():
    tok = np.arange(15)
    density = {"frame": tok * 4, "d": np.ones(15), "S": np.ones(15), "gamma": np.ones(15), "selected_tokens": [3]}
    for fig in (kinematics_figure(_motion()), density_figure(_motion(keyframes=[12], density=density))):
        assert fig.layout.margin.t >= 80  # the note, then the segment titles, above the plots
        assert fig.layout.title.yanchor == "top" and fig.layout.title.xanchor == "left"
        titles = [a for a in fig.layout.annotations if a.text in ("a", "b")]
        assert len(titles) == 2 and all(a.yanchor == "bottom" and a.y == 1.0 for a in titles)
    assert "density d = how many tokens look alike" in density_figure(_motion(density=density)).layout.title.text
    assert "each foot is planted" in kinematics_figure(_motion()).layout.title.text


def test_share_query_round_trips_and_rejects_damaged_links():
    from urllib.parse import parse_qsl

    from app.share import Shared, from_query, to_query

    s = Shared([("a person walks & waves <x>", 3.0), ("ü", 2.5)], "kmm", 12, 1.0, 4)
    assert from_query(dict(parse_qsl(to_query(s)))) == s
    fast = Shared([("a person jumps", 2.0)], "baseline", 3, 7.5, 2, "fast")
    assert from_query(dict(parse_qsl(to_query(fast)))) == fast
    # a link from before samplers existed names none: it was a "quality" motion
    old = dict(parse_qsl(to_query(fast)))
    del old["sampler"]
    assert from_query(old).sampler == "quality"
    assert from_query({}) is None
    with pytest.raises(InputError, match="cannot be read"):
        from_query({"timeline": '[["a person walks", 3.0'})


def test_the_model_card_names_each_fast_sampler_its_rates_and_whether_it_is_the_default():
    from app.ui import sampler_lines

    def info(name, fast_rate, quality_rate, default):
        opts = {
            "quality": {"label": "quality: 5 sampling steps (DDIM)", "validation_pass_rate": quality_rate},
            "fast": {"label": "fast: 2 consistency steps (distilled student)", "validation_pass_rate": fast_rate},
        }
        samplers = ["quality", "fast"]
        return {"display_name": name, "samplers": samplers, "sampler_options": opts, "default_sampler": default}

    lines = sampler_lines(
        [
            info("Motion Mamba", 0.883, 0.917, "quality"),
            info("Baseline", 0.94, 0.945, "fast"),
            {"display_name": "KMM", "samplers": ["quality"], "sampler_options": {}, "default_sampler": "quality"},
        ]
    )
    assert len(lines) == 2
    assert "Motion Mamba's fast sampler**, 2 consistency steps" in lines[0]
    assert "quality stays the default" in lines[0] and "88%" in lines[0] and "92%" in lines[0]
    assert ": the default." in lines[1]


def test_generate_yields_the_viewers_file_first_then_every_download():
    """Generate's first update carries only the GLB (the viewer starts fetching it), the
    second every download and the export time; both belong to the same motion. The time
    the caller spends between the two (the page drawing its first update) is not counted."""
    import time

    from app.ui import generation_steps

    steps = generation_steps([("a person walks forward", 2.0)], "kmm", 3)
    motion, files, wall = next(steps)
    assert list(files) == ["glb"] and files["glb"].is_file()
    assert not any(p.suffix in (".bvh", ".npy") for p in files["glb"].parent.iterdir())
    assert "export" not in motion.timings
    time.sleep(0.5)
    (done,) = list(steps)
    assert done[0] is motion and list(done[1]) == ["glb", "bvh", "features", "joints"]
    assert done[1]["glb"] == files["glb"] and all(p.is_file() for p in done[1].values())
    assert 0 < motion.timings["export"] < 0.5 and wall < done[2] < wall + 0.5


def test_a_failed_export_after_the_glb_keeps_the_motion_and_empties_the_other_downloads(monkeypatch):
    """The GLB is written and on show when the other files fail (a full disk, say): the
    page gets one message, the summary and the GLB's button, and the BVH and NPY buttons
    are emptied rather than left offering the previous motion's files."""
    import gradio as gr

    import app.ui as ui
    from motion_core.formats.export import export_files as real_export

    def failing_export(motion, out_dir, **kw):
        writing = real_export(motion, out_dir, **kw)
        yield next(writing)  # the GLB
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(ui, "export_files", failing_export)
    told = []
    monkeypatch.setattr(ui.gr, "Warning", lambda message, **kw: told.append(message))
    infos = ui.motion_core.methods()
    figures = ui.load_figures([m["name"] for m in infos], rows=ui.default_rows(infos))
    with gr.Blocks():
        page = ui._generate_tab(infos, figures, "kmm", ui.from_env("generate", 20, 10))
        page.last_motion = gr.State(None)
        on_generate = ui._wire_generation(page)
    data = {c: c.value for c in page.form}
    data.update({page.n_rows: 1, page.texts[0]: "a person walks forward", page.secs[0]: 2, page.method: "kmm"})
    data.update({page.seed: 3, page.guidance: None, page.steps: None, page.sampler: None})
    first, second, *more = on_generate(data, None, progress=lambda *a, **k: None)
    assert not more
    assert first[0].endswith(".glb")
    viewer, summary, motion, glb, bvh, feat, joints = second[:7]
    assert viewer == gr.skip() and motion.frames == 40 and "40 frames" in summary
    glb_path = glb.value["path"]  # the file the viewer was sent
    assert glb.interactive and glb_path.endswith(".glb") and first[0].endswith(glb_path.split("/")[-1])
    assert all(b.value is None and b.interactive is False for b in (bvh, feat, joints))
    assert len(told) == 1 and "No space left on device" in told[0]


def test_warm_up_compiles_the_cpu_kernels_a_first_motion_needs():
    """In a fresh process nothing is compiled until a motion is generated (numba compiles,
    or loads from its disk cache, at a kernel's first call): the warm-up generates one
    short motion per method, so the page's first click does not pay for it."""
    import subprocess
    import sys

    code = (
        "from app.runtime import warm_up\n"
        "from motion_core.body import rig_compiled\n"
        "from motion_core.nn import ssm_fused\n"
        "assert not rig_compiled._fit_rotations.signatures\n"
        "warm_up(['kmm'])\n"
        "print(len(rig_compiled._fit_rotations.signatures), len(ssm_fused._KERNEL[False].signatures))\n"
    )
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=REPO, env=env)
    assert out.returncode == 0, out.stderr[-2000:]
    rig, fused = (int(n) for n in out.stdout.split()[-2:])
    assert rig >= 1 and fused >= 1


def test_guide_names_the_unknown_part_and_stays_quiet_on_a_known_prompt():
    from app.guide import generation_notes, guide_markdown

    note = guide_markdown(1, "a person picks up a box")
    assert "picks up a box" in note and "nearest" in note
    assert "not learned" not in guide_markdown(1, "a person waves with the right hand")
    assert "⚠️" not in guide_markdown(1, "a person waves with the right hand")
    after = generation_notes(["a person walks forward", "someone does push-ups"])
    assert "Segment 2" in after and "push-ups" in after and "Segment 1" not in after
    assert "⚠️" in guide_markdown(1, "the quarterly tax report is due friday")
