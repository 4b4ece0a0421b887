"""Downloads of a generated motion: GLB validates (Khronos) and plays back the motion; NPY."""

from __future__ import annotations

import json
import shutil
import subprocess

import numpy as np
import pytest
from conftest import REPO
from motion_helpers import random_fk_motion

from motion_core import Motion
from motion_core.body.features import features_to_joints
from motion_core.formats.export import export_all, export_files
from motion_core.formats.gltf import glb_bytes, read_glb_joints


def validate_gltf(*paths) -> list[dict]:
    """Reports of the Khronos glTF validator (npm gltf-validator) for each file."""
    node = shutil.which("node")
    script = REPO / "tools" / "validate_gltf.mjs"
    if node is None or not (REPO / "node_modules" / "gltf-validator").is_dir():
        pytest.fail("node and node_modules/gltf-validator are needed (bash scripts/setup.sh --dev)")
    res = subprocess.run([node, str(script), *map(str, paths)], capture_output=True, text=True, cwd=REPO)
    reports = [json.loads(line) for line in res.stdout.splitlines() if line.startswith("{")]
    assert len(reports) == len(paths), res.stderr
    return reports


@pytest.fixture
def motion() -> Motion:
    joints = random_fk_motion(80, seed=5).astype(np.float32)
    return Motion(joints, 20, [(0, 40, "a person walks"), (40, 80, "a person waves")], "baseline", 7)


def test_export_files_writes_the_glb_before_the_rest_and_equals_export_all(motion, tmp_path):
    """The page shows a motion as soon as its GLB exists: at the first yield no other file
    has been written yet; in the end the files are those ``export_all`` writes, byte for byte."""
    steps = export_files(motion, tmp_path / "steps", stem="m")
    kind, glb = next(steps)
    assert kind == "glb" and sorted(p.name for p in glb.parent.iterdir()) == ["m.glb"]
    got = {kind: glb, **dict(steps)}
    assert list(got) == ["glb", "bvh", "features", "joints"]
    whole = export_all(motion, tmp_path / "all", stem="m")
    for key, path in whole.items():
        assert path.read_bytes() == got[key].read_bytes(), key


def test_glb_validates_and_plays_back_the_joints(motion, tmp_path):
    paths = export_all(motion, tmp_path)
    (report,) = validate_gltf(paths["glb"])
    assert report["errors"] == 0 and report["warnings"] == 0, report["messages"]
    joints, extras = read_glb_joints(paths["glb"].read_bytes())
    assert np.abs(joints - motion.joints).max() < 1e-5
    assert extras["fps"] == 20 and extras["frames"] == 80
    assert [s["text"] for s in extras["segments"]] == ["a person walks", "a person waves"]
    assert extras["segments"][1] == {"text": "a person waves", "start": 40, "end": 80}


def test_glb_is_exact_even_for_stretching_bones():
    joints = random_fk_motion(30, seed=2) + np.random.default_rng(0).normal(0, 0.02, (30, 22, 3))
    back, _ = read_glb_joints(glb_bytes(joints, 20))
    assert np.abs(back - joints).max() < 1e-5


def test_npy_holds_humanml3d_features_and_joints(motion, tmp_path):
    paths = export_all(motion, tmp_path)
    feats = np.load(paths["features"])
    joints = np.load(paths["joints"])
    assert feats.shape == (79, 263) and feats.dtype == np.float32
    assert joints.shape == (80, 22, 3)
    # the features describe the same motion, up to the canonical placement they use
    rec = features_to_joints(feats.astype(np.float64))
    rel = rec - rec[:, :1]
    orig = joints[:-1] - joints[:-1, :1]  # features keep frames 0..T-2
    assert np.abs(np.linalg.norm(rel, axis=-1) - np.linalg.norm(orig, axis=-1)).max() < 1e-5


def test_glb_needs_two_frames():
    with pytest.raises(ValueError, match="2 frames"):
        glb_bytes(np.zeros((1, 22, 3)), 20)


def test_glb_carries_the_skinned_mannequin_and_is_written_with_pygltflib(motion, tmp_path):
    """The body: one skinned mesh bound to the skin, up to 4 weights per vertex
    summing to 1, sides tinted, the rest pose's mesh around the rest joints; the humanoid
    rig's GLB validates too."""
    import pygltflib

    from motion_core.body.skeleton import HUMANOID

    data = glb_bytes(motion.joints, 20)
    doc = pygltflib.GLTF2.load_from_bytes(data)
    assert doc.asset.generator == "motion_core.formats.gltf" and doc.scenes[0].extras["body"] == "mannequin"
    (mesh,) = doc.meshes
    body_node = next(n for n in doc.nodes if n.mesh == 0)
    assert body_node.skin == 0 and len(doc.skins[0].joints) == 22
    attrs = mesh.primitives[0].attributes
    blob = doc.binary_blob()

    def read(i: int, width: int, dtype: str) -> np.ndarray:
        a = doc.accessors[i]
        v = doc.bufferViews[a.bufferView]
        return np.frombuffer(blob, dtype, a.count * width, v.byteOffset or 0).reshape(a.count, width)

    weights = read(attrs.WEIGHTS_0, 4, "<f4")
    joints = read(attrs.JOINTS_0, 4, "<u2")
    assert len(weights) > 500 and attrs.COLOR_0 is not None
    np.testing.assert_allclose(weights.sum(1), 1.0, atol=1e-6)
    assert (weights > 0).sum(1).max() <= 4 and (weights > 0).sum(1).mean() > 1.5  # blended, not rigid
    assert int(joints.max()) < 22
    (tmp_path / "h.glb").write_bytes(glb_bytes(motion.joints, 20, skeleton=HUMANOID))
    (report,) = validate_gltf(tmp_path / "h.glb")
    assert report["errors"] == 0 and report["warnings"] == 0, report["messages"]
