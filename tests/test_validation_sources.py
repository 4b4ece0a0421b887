"""Validation pooled over both sources (train/validation.validation_pass_rate): what stages
and students are chosen on since the procedural prompts alone misled twice."""

from __future__ import annotations

import argparse

import pytest

from motion_core.train import validation


def test_the_pass_rate_is_pooled_over_the_sources_prompts_and_an_empty_source_is_left_out(monkeypatch):
    clips = {"procedural": ["p"] * 200, "real": ["r"] * 149}
    rates = {"p": (0.8, 0.9, 99), "r": (0.6, 0.5, 149)}

    def fake_prompts(data, n, source):
        return clips[source]

    def fake_rate(sampler, vae, norm, scale, prompts, seed, guidance, steps, **where):
        rate, direction, dn = rates[prompts[0]]
        return {"n": len(prompts), "pass_rate": rate, "direction_accuracy": direction, "direction_prompts": dn}

    monkeypatch.setattr(validation, "validation_prompts", fake_prompts)
    monkeypatch.setattr(validation, "verifier_pass_rate", fake_rate)
    res = validation.validation_pass_rate(None, None, None, 1.0, "data", 200)
    assert res["n"] == 349 and set(res["sources"]) == {"procedural", "real"}
    assert res["pass_rate"] == pytest.approx((0.8 * 200 + 0.6 * 149) / 349)
    assert res["direction_accuracy"] == pytest.approx((0.9 * 99 + 0.5 * 149) / 248)
    # a corpus built without --real: the procedural figures alone
    clips["real"] = []
    res = validation.validation_pass_rate(None, None, None, 1.0, "data", 200)
    assert res["n"] == 200 and res["pass_rate"] == pytest.approx(0.8) and set(res["sources"]) == {"procedural"}
    clips["procedural"] = []
    with pytest.raises(ValueError, match="no validation clips"):
        validation.validation_pass_rate(None, None, None, 1.0, "data", 200)


def test_val_source_names_the_sources():
    assert validation.val_sources(argparse.Namespace(val_source="both")) == ("procedural", "real")
    assert validation.val_sources(argparse.Namespace(val_source="real")) == ("real",)
    assert validation.val_sources(argparse.Namespace()) == ("procedural", "real")
