"""Shared test fixtures. Tests may read ../shared (CI has it beside the clone)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

os.environ.setdefault("HF_HUB_OFFLINE", "1")
os.environ.setdefault("TRANSFORMERS_OFFLINE", "1")

REPO = Path(__file__).resolve().parents[1]
SHARED = Path(os.environ.get("MMS_SHARED", REPO.parent / "shared"))
HML_FIXTURE = SHARED / "fixtures" / "humanml3d"


@pytest.fixture(scope="session")
def hml_fixture_dir() -> Path:
    if not (HML_FIXTURE / "new_joint_vecs" / "012314.npy").is_file():
        pytest.fail(f"the real HumanML3D fixture is missing under {HML_FIXTURE} (set MMS_SHARED)")
    return HML_FIXTURE


@pytest.fixture(scope="session")
def real_features(hml_fixture_dir: Path) -> np.ndarray:
    """(170, 263) float32: the real HumanML3D motion 012314."""
    return np.load(hml_fixture_dir / "new_joint_vecs" / "012314.npy")


@pytest.fixture(scope="session")
def text_encoder():
    from motion_core.text import get_text_encoder

    return get_text_encoder()


BANDAI_ARCHIVE = SHARED / "data" / "bandai-namco-motion.tar.xz"
BANDAI_CACHE = REPO / ".cache" / "bandai-namco"


@pytest.fixture(scope="session")
def bandai_dir() -> Path:
    """The real Bandai Namco BVH archive, unpacked once into .cache/ (gitignored, ~10 s)."""
    from motion_core.mocap import unpack_archive

    if not BANDAI_ARCHIVE.is_file():
        pytest.fail(f"the Bandai Namco archive is missing: {BANDAI_ARCHIVE} (set MMS_SHARED)")
    return unpack_archive(BANDAI_ARCHIVE, BANDAI_CACHE)
