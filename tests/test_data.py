import json
import shutil

import numpy as np
import pytest

from motion_core.data import (
    BabelSegments,
    Caption,
    DatasetError,
    HumanML3DDataset,
    MotionSample,
    Segment,
    write_babel,
    write_sample,
    write_splits,
)


@pytest.fixture
def hml_dir(tmp_path, hml_fixture_dir, real_features):
    """A HumanML3D-format directory in the real layout, built around the real motion."""
    root = tmp_path / "HumanML3D"
    (root / "new_joint_vecs").mkdir(parents=True)
    (root / "texts").mkdir()
    shutil.copy(hml_fixture_dir / "new_joint_vecs" / "012314.npy", root / "new_joint_vecs" / "012314.npy")
    shutil.copy(hml_fixture_dir / "Mean.npy", root)
    shutil.copy(hml_fixture_dir / "Std.npy", root)
    (root / "texts" / "012314.txt").write_text(
        "a person walks forward and turns around#a/DET person/NOUN walk/VERB forward/ADV#0.0#0.0\n"
        "someone steps ahead then turns#someone/PRON step/VERB ahead/ADV#2.5#6.0\n"
    )
    np.save(root / "new_joint_vecs" / "M012314.npy", real_features[::-1].copy())  # mirrored id, as the set has
    (root / "texts" / "M012314.txt").write_text("a person walks#a/DET person/NOUN walk/VERB#nan#nan\n")
    write_splits(root, {"train": ["012314", "M012314"], "val": [], "test": ["012314"]})
    return root


def test_read_real_format(hml_dir, real_features):
    ds = HumanML3DDataset(hml_dir, "train")
    assert len(ds) == 2
    s = ds[0]
    assert s.id == "012314" and s.features.shape == (170, 263)
    assert np.array_equal(s.features, real_features)
    assert s.captions[0].text == "a person walks forward and turns around"
    assert s.captions[0].tokens[:2] == ["a/DET", "person/NOUN"]
    assert (s.captions[1].start, s.captions[1].end) == (2.5, 6.0)
    m = ds.load("M012314")
    assert (m.captions[0].start, m.captions[0].end) == (0.0, 0.0)  # nan means whole clip
    assert [x.id for x in ds] == ["012314", "M012314"]
    assert ds.normalizer().dim == 263
    assert len(HumanML3DDataset(hml_dir, "val")) == 0


def test_write_then_read_round_trip(tmp_path, real_features):
    sample = MotionSample("c00001", real_features[:60], [Caption("a person jumps", ["a/DET"], 0.0, 0.0)])
    write_sample(tmp_path, sample)
    write_splits(tmp_path, {"test": ["c00001"]})
    back = HumanML3DDataset(tmp_path, "test")[0]
    assert np.array_equal(back.features, sample.features)
    assert back.captions[0].text == "a person jumps"


def test_clear_errors(hml_dir, tmp_path):
    with pytest.raises(DatasetError, match="does not exist"):
        HumanML3DDataset(tmp_path / "nope")
    with pytest.raises(DatasetError, match="no new_joint_vecs"):
        HumanML3DDataset(tmp_path)
    with pytest.raises(DatasetError, match="unknown split"):
        HumanML3DDataset(hml_dir, "dev")
    # corrupt .npy
    (hml_dir / "new_joint_vecs" / "012314.npy").write_bytes(b"\x93NUMPY garbage")
    with pytest.raises(DatasetError, match="corrupt"):
        HumanML3DDataset(hml_dir, "test")[0]
    # mismatched feature dimension: a HumanML3D file read as KIT
    with pytest.raises(DatasetError, match=r"expected shape \(T, 251\)"):
        HumanML3DDataset(hml_dir, "train", skeleton="kit").load("M012314")
    (hml_dir / "texts" / "M012314.txt").write_text("no hashes here\n")
    with pytest.raises(DatasetError, match="caption#tokens#start#end"):
        HumanML3DDataset(hml_dir, "train").load("M012314")


def test_babel_segments(tmp_path, real_features):
    np.save(tmp_path / "seq1.npy", real_features)
    write_babel(
        tmp_path / "babel" / "train.json",
        [("seq1", "../seq1.npy", 8.5, [Segment(0.0, 3.0, "walk forward"), Segment(3.0, 8.5, "turn left")])],
    )
    b = BabelSegments(tmp_path / "babel" / "train.json")
    (m,) = list(b)
    assert [s.text for s in m.segments] == ["walk forward", "turn left"]
    assert m.segment_frames() == [(0, 60, "walk forward"), (60, 170, "turn left")]


def test_babel_real_layout_and_errors(tmp_path, real_features):
    np.save(tmp_path / "a.npy", real_features)
    raw = {
        "7": {
            "feat_p": "a.npy",
            "dur": 8.5,
            "frame_ann": None,
            "seq_ann": {"labels": [{"raw_label": "dance", "proc_label": "dance"}]},
        },
        "8": {
            "feat_p": "a.npy",
            "dur": 8.5,
            "frame_ann": {
                "labels": [
                    {"raw_label": "kick", "proc_label": "kick", "start_t": 4.0, "end_t": 5.0},
                    {"raw_label": "stand", "proc_label": "stand", "start_t": 0.0, "end_t": 4.0},
                ]
            },
        },
    }
    (tmp_path / "ann.json").write_text(json.dumps(raw))
    b = BabelSegments(tmp_path / "ann.json")
    assert [(s.start, s.end, s.text) for s in b.load("7").segments] == [(0.0, 8.5, "dance")]
    assert [s.text for s in b.load("8").segments] == ["stand", "kick"]  # sorted by start
    (tmp_path / "bad.json").write_text("{not json")
    with pytest.raises(DatasetError, match="not valid JSON"):
        BabelSegments(tmp_path / "bad.json")
    raw["8"]["frame_ann"]["labels"][0]["end_t"] = 3.0
    (tmp_path / "ann.json").write_text(json.dumps(raw))
    with pytest.raises(DatasetError, match="ending before"):
        BabelSegments(tmp_path / "ann.json").load("8")
