"""The shipped phrasebook: generated from the corpus catalogues, small, calibrated; its
warning figures in results/prompt_warning.json are what the shipped file gives."""

from __future__ import annotations

import json

import numpy as np
from conftest import REPO

from motion_core.corpus.actions import CATALOGUE
from motion_core.corpus.prompt_guide import (
    PHRASEBOOK,
    Phrasebook,
    _warning_figures,
    action_kinds,
    calibration_sets,
    phrasebook_captions,
)


def test_phrasebook_is_the_catalogue_s_captions_small_and_calibrated():
    assert PHRASEBOOK.stat().st_size < 5 * 2**20
    with np.load(PHRASEBOOK) as z:
        assert z["embeddings"].dtype == np.float16
        stored = [str(c) for c in z["captions"]]
        assert np.isfinite(float(z["threshold"]))
    captions, kinds = phrasebook_captions()
    assert stored == captions  # `prompt_guide build` regenerates exactly the shipped captions
    assert set(CATALOGUE) <= set(kinds) and len(set(captions)) == len(captions) > 2000
    titles = {k.kind for k in action_kinds()}
    assert set(CATALOGUE) <= titles


def test_warning_figures_are_reproduced_by_the_shipped_phrasebook():
    book = Phrasebook()
    report = json.loads((REPO / "results/prompt_warning.json").read_text())
    assert report["threshold"] == book.threshold
    sets = calibration_sets()
    for half in ("calibration", "test"):
        key = "cal" if half == "calibration" else "test"
        got = _warning_figures(book.best(sets[f"familiar_{key}"]), book.best(sets[f"unfamiliar_{key}"]), book.threshold)
        assert got == report[half]
    assert book.guide("asdf qwer zxcv").unfamiliar
    g = book.guide("a person waves with the right hand")
    assert not g.unfamiliar and "waves" in g.nearest[0].caption and len({m.kind for m in g.nearest}) == 3
