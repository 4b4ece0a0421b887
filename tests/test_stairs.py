"""Stairs: the staged kinds that climb (motion_core/corpus/kinds/stairs.py), the ground read
from the feet (motion_core/body/terrain.py), ``ground`` on steps and bit for bit as before on
flat motions, the verifier's feet on a tread, the steps in the GLB and in the viewer."""

from __future__ import annotations

import json
import zlib

import numpy as np
import pytest

from motion_core.body.features import canonicalize, features_to_joints, joints_to_features
from motion_core.body.ground import GroundConfig, ground, support_frames
from motion_core.body.skeleton import HUMANML3D
from motion_core.body.terrain import foot_plants, raised_plants, steps, surface
from motion_core.corpus import CATALOGUE, sample_clip
from motion_core.corpus.kinds import REGISTRY, all_kinds, staged_kinds
from motion_core.corpus.kinds.check import clips
from motion_core.verify.realism import realism
from motion_core.verify.rules import Measures, verify

STAIRS = ("walk_upstairs", "walk_downstairs", "step_up_onto")
FEET = [i for pair in HUMANML3D.feet for i in pair]
TOES = [toe for _, toe in HUMANML3D.feet]
FLAT = GroundConfig(terrain=False)


def stored(kind: str, seed: int) -> tuple[np.ndarray, dict]:
    """A clip as the corpus stores it: through the 263-dim features, canonical."""
    clip, spec = sample_clip(np.random.default_rng(seed), kind)
    return canonicalize(features_to_joints(joints_to_features(clip.joints))), spec.labels()


def inside(box: dict, xz: np.ndarray) -> np.ndarray:
    """(N,) whether points (N, 2) lie over the box's footprint."""
    d = xz - np.array(box["center"])
    s, c = np.sin(box["yaw"]), np.cos(box["yaw"])
    along, across = d[:, 0] * s + d[:, 1] * c, d[:, 0] * c - d[:, 1] * s
    return (np.abs(along) <= box["depth"] / 2) & (np.abs(across) <= box["width"] / 2)


# ---------------------------------------------------------------- the kinds


def test_stairs_kinds_are_staged_and_change_nothing_trained():
    assert set(STAIRS) <= set(staged_kinds()) and not set(STAIRS) & set(CATALOGUE)
    assert all(REGISTRY[k].family == "stairs" and not REGISTRY[k].trained for k in STAIRS)
    assert all_kinds()[: len(CATALOGUE)] == list(CATALOGUE)


@pytest.mark.parametrize("kind", STAIRS)
def test_the_clip_climbs_on_treads_it_never_goes_through(kind):
    """The feet stand on levels a step apart, the pelvis follows them up (or down), and no
    joint goes into a box that terrain.steps puts under the feet."""
    for seed in (0, 1, 2):
        clip, spec = sample_clip(np.random.default_rng(seed), kind)
        j = ground(clip.joints)
        boxes = steps(j)
        tops = sorted(b["top"] for b in boxes)
        if kind == "step_up_onto":
            assert len(boxes) == 1 and 0.19 < tops[0] < 0.39
        else:
            n = spec.count or len(boxes)
            assert len(boxes) == n >= 3, (spec, tops)
            rises = np.diff([0.0, *tops])
            assert np.all((rises > 0.14) & (rises < 0.2)), tops  # one step apart, 15-19 cm each
        # the pelvis ends a top's height above (below) where it started
        rise = j[-3:, 0, 1].mean() - j[:3, 0, 1].mean()
        assert abs(abs(rise) - tops[-1]) < 0.1 and (rise > 0) == (kind != "walk_downstairs")
        # nothing in a box: every joint over a box's footprint is no lower than its top
        for b in boxes:
            for k in range(HUMANML3D.n_joints):
                over = inside(b, j[:, k, [0, 2]])
                assert (j[over, k, 1] >= b["top"] - 0.005).all(), (kind, seed, HUMANML3D.joint_names[k])


def thigh_and_knee(j: np.ndarray) -> tuple[float, float]:
    """Highest forward thigh flexion (the knee in front of the hip, from hanging) and knee
    flexion, in degrees, either leg."""
    from motion_core.verify.kind_rules import _flexion

    m = Measures(j)
    thigh = []
    for s in ("left", "right"):
        v = m.body_frame(HUMANML3D.index(f"{s}_knee")) - m.body_frame(HUMANML3D.index(f"{s}_hip"))
        thigh.append(np.degrees(np.arctan2(v[:, 2], -v[:, 1])).max())
    return float(max(thigh)), float(max(_flexion(m, "left").max(), _flexion(m, "right").max()))


def test_going_up_the_knee_comes_up_higher_than_going_down():
    """Up: the knee comes up high in front (the thigh over 62 degrees forward, the knee bent
    90-120); down it comes up less."""
    up = [thigh_and_knee(stored("walk_upstairs", s)[0]) for s in range(4)]
    down = [thigh_and_knee(stored("walk_downstairs", s)[0]) for s in range(4)]
    assert all(t > 62 and 90 < k < 120 for t, k in up), up
    assert np.mean([t for t, _ in up]) > np.mean([t for t, _ in down]) + 5, (up, down)


def test_downstairs_reaches_down_with_the_toes():
    """Going down the leading foot points its toes down before it lands (the toe lower than
    the ankle by more than a flat foot's 5.9 cm)."""
    j, _ = stored("walk_downstairs", 1)
    drop = j[:, HUMANML3D.index("left_ankle"), 1] - j[:, HUMANML3D.index("left_foot"), 1]
    drop_r = j[:, HUMANML3D.index("right_ankle"), 1] - j[:, HUMANML3D.index("right_foot"), 1]
    assert max(drop.max(), drop_r.max()) > 0.09


def test_captions_use_the_real_phrasings():
    from motion_core.corpus.text import captions_for

    caps = {k: " | ".join(REGISTRY[k].captions) for k in STAIRS}
    for phrase in ("walks up the stairs", "walks upstairs", "climbs", "goes up the stairs"):
        assert phrase in caps["walk_upstairs"]
    for phrase in ("walks down the stairs", "walks downstairs", "goes downstairs"):
        assert phrase in caps["walk_downstairs"]
    assert "steps on a low platform" in caps["step_up_onto"] and "steps up onto" in caps["step_up_onto"]
    _, spec = sample_clip(np.random.default_rng(4), "step_up_onto")
    for c in captions_for(spec, np.random.default_rng(0), 5):
        assert ("right" if spec.side == "left" else "left") not in c


# ---------------------------------------------------------------- the rules


def test_rules_pass_their_own_clips_and_no_other_kind():
    """20 clips of each stairs kind pass their own rule; 5 clips of every kind (built-in and
    staged) fail every stairs rule given a stairs clip's labels."""
    for kind in STAIRS:
        own = clips(kind, 20, 3)
        assert all(verify(j, lab).passed for j, lab in own), kind
        labels = [lab for _, lab in own]
        for other in all_kinds():
            if other == kind:
                continue
            for i, (j, _) in enumerate(clips(other, 5, 3)):
                assert not verify(j, labels[i]).passed, (kind, other, i)


def test_a_wrong_count_or_foot_fails():
    j, lab = stored("walk_upstairs", 5)
    n = verify(j, lab).measures["levels"]
    assert verify(j, {**lab, "count": n}).passed and not verify(j, {**lab, "count": n + 1}).passed
    assert not verify(j, {**lab, "kind": "walk_downstairs"}).passed
    j, lab = stored("step_up_onto", 5)
    other = "left" if lab["side"] == "right" else "right"
    assert verify(j, lab).passed and not verify(j, {**lab, "side": other}).passed


def test_a_foot_on_a_tread_is_on_the_ground():
    """The generic foot rules read a foot standing on a tread as standing: no flight, contact
    phases (and their slide) on the treads, nothing below the floor the feet stand on. Read
    from y = 0 instead, the same clip would be in the air for seconds."""
    j, _ = stored("walk_upstairs", 6)
    m = Measures(j)
    assert m.ground is not None and m.flights() == []
    flat = Measures(j)
    flat._ground = None  # as the rules read it before stairs
    assert sum(b - a for a, b in flat.flights()) > 20
    r = realism(j)
    assert not r.violations(), r
    from motion_core.verify import realism as realism_module

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(realism_module, "surface", lambda joints: None)
        before = realism_module.realism(j)
    assert r.contact_phases > before.contact_phases + 6  # the plants on the treads count


def test_flat_clips_read_exactly_as_before():
    """No corpus clip of another kind has a raised level, so the verifier and the realism
    figures take the flat path for them (tools/terrain_check.py measures 40 clips a kind)."""
    for kind in all_kinds():
        if kind in STAIRS:
            continue
        for j, _ in clips(kind, 2, 5):
            assert surface(j) is None and Measures(j).ground is None, kind


# ---------------------------------------------------------------- terrain


def test_steps_of_a_flight_lie_one_after_another():
    clip, spec = sample_clip(np.random.default_rng(8), "walk_upstairs")
    j = ground(clip.joints)
    boxes = steps(j)
    assert len(boxes) == (spec.count or len(boxes))
    assert json.loads(json.dumps(boxes)) == boxes  # plain JSON for the GLB's extras
    yaw = boxes[0]["yaw"]
    assert all(abs(b["yaw"] - yaw) < 1e-9 for b in boxes)
    fwd = np.array([np.sin(yaw), np.cos(yaw)])
    along = [np.array(b["center"]) @ fwd for b in boxes]
    assert np.all(np.diff(along) > 0.2)  # up the stairs, higher boxes lie ahead
    # neighbouring boxes touch: the riser between them is where one ends and the next begins
    for a, b, pa, pb in zip(boxes, boxes[1:], along, along[1:], strict=False):
        assert abs((pa + a["depth"] / 2) - (pb - b["depth"] / 2)) < 1e-3
    # every raised plant's feet stand over its box
    for p in raised_plants(j):
        box = min(boxes, key=lambda b: abs(b["top"] - p.height))
        assert inside(box, p.xz).all() and abs(box["top"] - p.height) < 0.03


def test_held_feet_drift_and_the_floor_are_not_steps(real_features):
    """A foot held up (standing on one leg, hopping), a body that drifts up and down, a
    real walk: no raised level."""
    for kind in ("stand_on_one_leg", "hop", "kick", "march_in_place", "jump_up", "lie_down"):
        for seed in (0, 1):
            j, _ = stored(kind, seed)
            assert surface(j) is None and steps(j) == [], kind
    real = features_to_joints(real_features.astype(np.float64))
    drift = real.copy()
    drift[..., 1] += 0.15 * np.sin(np.linspace(0, np.pi, len(real)))[:, None]  # 15 cm of vertical drift
    for j in (real, drift):
        assert surface(j) is None and steps(j) == []


def test_surface_under_each_foot():
    j, _ = stored("walk_upstairs", 9)
    surf = surface(j)
    assert surf.shape == (len(j), 2)
    for p in foot_plants(j):
        if p.flat and p.bears_weight:
            # on a tread: its height; on the floor: 0
            assert np.allclose(surf[p.start : p.end, p.foot], p.height if p.height > 0.05 else 0.0)
    assert (np.diff(surf, axis=0) >= -1e-12).all()  # going up, the ground under a foot only rises
    assert (j[:, TOES, 1] - surf >= -1e-9).all()


# ---------------------------------------------------------------- ground


def lifted(j: np.ndarray, start: int, end: int, height: float) -> np.ndarray:
    out = j.copy()
    t = np.arange(len(j))
    bump = np.where((t >= start) & (t < end), np.sin(np.pi * (t - start) / (end - start)) ** 2, 0.0)
    out[..., 1] += height * bump[:, None]
    return out


def test_ground_keeps_the_steps_and_puts_a_hovering_stance_back_on_its_tread():
    j, _ = stored("walk_upstairs", 10)
    g = ground(j)
    assert np.abs(g - (j - np.array([0.0, j[:, FEET, 1].min(), 0.0]))).max() < 1e-6  # clean: as it was
    T = len(j)
    hover = lifted(j, T // 3, 2 * T // 3, 0.05)  # a decoder's 5 cm hover, mid-flight
    new, old = ground(hover), ground(hover, cfg=FLAT)
    surf = surface(new)
    on = support_frames(new, low=(new[:, FEET, 1] - np.repeat(surf, 2, axis=1)).min(1))
    mid = np.zeros(T, bool)
    mid[T // 3 + 4 : 2 * T // 3 - 4] = True
    low_new = (new[:, TOES, 1] - surf).min(1)[on & mid]
    assert len(low_new) > 10 and np.abs(low_new).max() < 0.01  # the stance toes back on their treads
    # the flat rule saw no support over the treads: the hover stayed
    assert (hover - old)[mid, 0, 1].max() < 0.01


@pytest.mark.parametrize("source", ["corpus", "real"])
def test_flat_motions_are_grounded_bit_for_bit_as_before(source, real_features):
    """Flat motions come out of ``ground`` exactly as from the rule before stairs: built-in
    and staged clips (as composed, and through the features, float32 too) and a real clip."""
    if source == "real":
        j = features_to_joints(real_features)
        motions = [j, j.astype(np.float64), lifted(j.astype(np.float64), 40, 80, 0.06)]
    else:
        motions = []
        for kind in all_kinds():
            if kind in STAIRS:
                continue
            clip, _ = sample_clip(np.random.default_rng([1, zlib.crc32(kind.encode())]), kind)
            motions += [clip.joints, features_to_joints(joints_to_features(clip.joints)).astype(np.float32)]
    for j in motions:
        a, b = ground(j), ground(j, cfg=FLAT)
        assert a.dtype == b.dtype and a.tobytes() == b.tobytes()


# ---------------------------------------------------------------- the GLB and the viewer


def test_the_glb_carries_the_steps_and_a_flat_one_does_not():
    from motion_core import Motion
    from motion_core.formats.export import motion_extras
    from motion_core.formats.gltf import glb_bytes, read_glb_joints

    clip, _ = sample_clip(np.random.default_rng(0), "walk_upstairs")
    j = ground(clip.joints).astype(np.float32)
    m = Motion(j, 20, [(0, len(j), "a person walks up the stairs")], "corpus", 0)
    ex = motion_extras(m)
    assert ex["steps"] == steps(j) and len(ex["steps"]) >= 3
    _, back = read_glb_joints(glb_bytes(j, 20, extras=ex))
    assert back["steps"] == ex["steps"]
    walk, _ = sample_clip(np.random.default_rng(0), "walk")
    flat = Motion(walk.joints.astype(np.float32), 20, [(0, len(walk.joints), "a person walks")], "corpus", 0)
    assert "steps" not in motion_extras(flat)


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    from conftest import run_app

    with run_app(tmp_path_factory.mktemp("outputs")) as srv:
        yield srv


def test_the_viewer_draws_the_steps_under_the_feet(browser, server):
    """A corpus clip of walking up the stairs (the models have not learned stairs) loaded
    straight into the viewer: one box a tread, where the file says, the figure on the top
    at the end; a flat motion gets none. Screenshot: docs/viewer-stairs.png."""
    from conftest import artifact, drawn

    from app.viewer import viewer_page_url
    from motion_core import Motion
    from motion_core.formats.export import export_glb

    clip, _ = sample_clip(np.random.default_rng(0), "walk_upstairs")
    j = ground(clip.joints).astype(np.float32)
    want = steps(j)
    d = server["out"] / "stairs"
    d.mkdir(exist_ok=True)
    glb = export_glb(Motion(j, 20, [(0, len(j), "a person walks up the stairs")], "corpus", 0), d / "stairs.glb")
    ctx = browser.new_context(viewport={"width": 900, "height": 600})
    pg = ctx.new_page()
    pg.goto(server["url"].rstrip("/") + viewer_page_url(glb) + "&autoplay=0&view=side")
    pg.wait_for_function("window.viewer && viewer.ready && viewer.loadedAt !== null")
    assert pg.evaluate("viewer.steps") == want
    boxes = pg.evaluate("viewer.stepBoxes()")
    assert len(boxes) == len(want) >= 3
    for got, b in zip(sorted(boxes, key=lambda x: x["max"][1]), sorted(want, key=lambda x: x["top"]), strict=True):
        assert abs(got["max"][1] - b["top"]) < 1e-3 and abs(got["min"][1]) < 1e-3 and got["visible"]
        centre = (np.array(got["min"]) + np.array(got["max"]))[[0, 2]] / 2
        assert np.abs(centre - np.array(b["center"])).max() < 1e-3
    # the last pose stands on the top box
    pg.evaluate(f"viewer.setTime({(len(j) - 1) / 20})")
    pose = np.array(pg.evaluate("viewer.jointPositions()"))
    assert abs(pose[TOES, 1].min() - max(b["top"] for b in want)) < 0.01
    # mid-climb, seen from the side (the flight in profile), for the picture
    with drawn(pg):
        pg.evaluate(f"viewer.setTime({0.62 * (len(j) - 1) / 20})")
    pg.screenshot(path=str(artifact("docs/viewer-stairs.png")))
    # a flat motion: no boxes
    walk, _ = sample_clip(np.random.default_rng(0), "walk")
    flat = Motion(walk.joints.astype(np.float32), 20, [(0, len(walk.joints), "a person walks")], "corpus", 0)
    flat = export_glb(flat, d / "flat.glb")
    pg.goto(server["url"].rstrip("/") + viewer_page_url(flat) + "&autoplay=0")
    pg.wait_for_function("window.viewer && viewer.ready && viewer.loadedAt !== null")
    assert pg.evaluate("viewer.steps") == [] and pg.evaluate("viewer.stepBoxes()") == []
    ctx.close()
