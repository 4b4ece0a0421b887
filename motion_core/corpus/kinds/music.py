"""Playing an instrument (air guitar, air violin): the hands where the instrument would put them.

Both hands are held on targets by the arm IK: a guitar's strumming hand over the strings at
the belly and its fretting hand out along the neck; a violin's holding hand out at shoulder
height in front, the chin turned onto the instrument, and the bowing hand drawing the bow
across in long strokes.
"""

from __future__ import annotations

import numpy as np

from ..actions import Spec, Timeline, _sides
from ..rig import SIGN, J
from .base import Kind, body_point, register
from .channels import extra
from .gestures import UP, _gesture

NAME = {"l": "left", "r": "right"}


def play_guitar(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """``side`` strums at the belly (quick down-up strokes), the other hand holds the neck out to
    its side at chest height, sliding now and then to a new chord; the head looks down."""
    n = t1 - t0
    r = tl.rng
    fps = tl.fps
    s = _sides(spec.side or "right")[0]
    o = "r" if s == "l" else "l"
    hz = r.uniform(2.5, 4.0)
    stroke = r.uniform(0.06, 0.08)
    strum = stroke * np.sin(2 * np.pi * hz * np.arange(n) / fps)
    chord = np.cumsum(r.uniform(-1, 1, n) * (r.random(n) < 1.0 / fps))  # a slide about once a second
    chord = 0.015 * np.tanh(np.convolve(chord, np.ones(5) / 5, mode="same"))
    s_up, s_fwd, s_lat = r.uniform(0.1, 0.15), r.uniform(0.2, 0.24), r.uniform(0.0, 0.04)
    f_up, f_fwd, f_lat = r.uniform(0.26, 0.32), r.uniform(0.26, 0.32), r.uniform(0.3, 0.36)

    def where(ch, j, side, sl):
        pel = j[sl, 0]
        if side == s:
            return body_point(ch, sl, pel, SIGN[s] * s_lat, s_up + strum, s_fwd + 0.15 * strum)
        return body_point(ch, sl, pel, SIGN[o] * (f_lat + chord), f_up + 0.3 * chord, f_fwd)

    def pole(f, left, side):
        return SIGN[side] * left - 0.4 * f - (0.2 if side == s else 0.8) * UP

    w = _gesture(tl, t0, t1, (s, o), where, pole, 0.15, 0.03, 0.97)
    tl.ch.neck_pitch[t0:t1] += 0.3 * w
    tl.ch.spine_bend[t0:t1] += 0.06 * w
    tl.ch.pelvis_y[t0:t1] -= 0.012 * w * (1 + np.sin(2 * np.pi * hz / 2 * np.arange(n) / fps))  # keeping time


def play_violin(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """The other hand holds the violin's neck out in front at shoulder height, the chin turned
    onto it; ``side`` draws the bow across in long strokes, from by the chin out to its side."""
    n = t1 - t0
    r = tl.rng
    fps = tl.fps
    s = _sides(spec.side or "right")[0]  # the bowing hand
    o = "r" if s == "l" else "l"
    per = r.uniform(0.7, 1.1)  # seconds per stroke
    t = np.arange(n) / fps
    bow = 0.5 - 0.5 * np.cos(np.pi * t / per)  # 0 at the frog, 1 at the tip, eased at each turn
    h_fwd, h_lat, h_up = r.uniform(0.3, 0.36), r.uniform(0.12, 0.17), r.uniform(-0.02, 0.04)

    def where(ch, j, side, sl):
        if side == o:
            return body_point(ch, sl, j[sl, J(f"{NAME[o]}_shoulder")], SIGN[o] * h_lat, h_up, h_fwd)
        sh = j[sl, J(f"{NAME[s]}_shoulder")]
        frog = np.array([-SIGN[s] * 0.3, -0.08, 0.28])  # (lateral, up, forward) from the bowing shoulder
        tip = np.array([SIGN[s] * 0.12, -0.22, 0.3])
        p = frog[None] + bow[:, None] * (tip - frog)[None]
        return body_point(ch, sl, sh, p[:, 0], p[:, 1], p[:, 2])

    def pole(f, left, side):
        return SIGN[side] * left - (1.0 if side == o else 0.6) * UP

    w = _gesture(tl, t0, t1, (s, o), where, pole, 0.18, 0.03, 0.97)
    tl.ch.neck_pitch[t0:t1] += 0.3 * w
    extra(tl).neck_yaw[t0:t1] += SIGN[o] * 0.45 * w  # the chin onto the violin
    tl.ch.spine_side[t0:t1] += SIGN[o] * 0.05 * w
    tl.ch.spine_twist[t0:t1] += SIGN[o] * 0.04 * w * (bow - 0.5)  # the body gives a little with the bow


register(
    Kind(
        name="play_guitar",
        family="music",
        catalogue={"variants": [{"side": "right"}, {"side": "left"}], "dur": (3.0, 6.0)},
        generate=play_guitar,
        captions=(
            "{who} plays the guitar, strumming with {arm}",
            "{who} plays air guitar",
            "{who} strums a guitar with {arm}",
            "{who} is playing a guitar",
            "{who} holds a guitar and plays it, strumming with {arm}",
            "{who} pretends to play the guitar",
        ),
        looks=(
            "the strumming hand goes quickly up and down at the belly, the other holds the neck "
            "out to its side at chest height"
        ),
    )
)
register(
    Kind(
        name="play_violin",
        family="music",
        catalogue={"variants": [{"side": "right"}, {"side": "left"}], "dur": (3.0, 6.0)},
        generate=play_violin,
        captions=(
            "{who} plays the violin, bowing with {arm}",
            "{who} plays the air violin",
            "{who} is playing a violin",
            "{who} holds a violin under the chin and draws the bow with {arm}",
            "{who} performs the movements of a violin player",
            "{who} plays a few notes on a violin",
        ),
        looks=(
            "the holding hand out in front at shoulder height, the head turned onto the violin, "
            "the bowing hand draws long strokes across"
        ),
    )
)
