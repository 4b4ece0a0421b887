"""`train --set FIELD=VALUE` changes a config through override_config:
top-level fields and, with a dot, the fields of a nested config (an SSM's state or width)."""

from __future__ import annotations

from dataclasses import dataclass

import pytest

from motion_core.models.denoisers import MotionMambaConfig
from motion_core.models.kmm import KMMConfig
from motion_core.models.overrides import override_config
from motion_core.nn.ssm import SSMConfig


def test_nested_fields_are_set_with_a_dot_and_the_rest_of_the_config_is_kept():
    cfg = MotionMambaConfig(bsm_ssm=SSMConfig(expand=2.0, d_state=4))
    out = override_config(cfg, ["bsm_ssm.expand=1", "levels=2", "bsm_ssm.d_state=8", "htm_ssm.d_conv=2"])
    assert out.levels == 2 and out.bsm_ssm == SSMConfig(expand=1.0, d_state=8)
    assert out.htm_ssm == SSMConfig(**{**vars(cfg.htm_ssm), "d_conv": 2})
    assert isinstance(out.bsm_ssm.expand, float) and isinstance(out.bsm_ssm.d_state, int)
    assert cfg.bsm_ssm == SSMConfig(expand=2.0, d_state=4)  # a copy: the original is untouched


def test_an_optional_field_takes_its_annotated_type_and_none_restores_it():
    """dt_rank is None (from the width) by default: it could not be set at all."""
    out = override_config(MotionMambaConfig(), ["bsm_ssm.dt_rank=3"])
    assert out.bsm_ssm.dt_rank == 3 and isinstance(out.bsm_ssm.dt_rank, int)
    assert override_config(out, ["bsm_ssm.dt_rank=None"]).bsm_ssm.dt_rank is None


def test_a_bool_field_takes_the_usual_spellings_and_refuses_any_other():
    """KMM's ablation switches (align, word_pool, phase): "flase" once read as False."""
    for value, want in [("true", True), ("0", False), ("Off", False), ("yes", True)]:
        assert override_config(KMMConfig(), [f"phase={value}"]).phase is want
    with pytest.raises(ValueError, match=r"phase takes true or false .*got 'flase'"):
        override_config(KMMConfig(), ["phase=flase"])


def test_an_optional_bool_field_is_set_by_its_annotation():
    @dataclass
    class Switches:
        gate: bool | None = None

    assert override_config(Switches(), ["gate=on"]).gate is True
    assert override_config(Switches(gate=True), ["gate=none"]).gate is None
    with pytest.raises(ValueError, match="gate takes true or false"):
        override_config(Switches(), ["gate=2"])


@pytest.mark.parametrize(
    ("item", "message"),
    [
        ("bsm_ssm.nope=1", "bad override 'bsm_ssm.nope=1': expected bsm_ssm.FIELD=VALUE"),
        ("levels.x=1", "levels has no fields"),
        ("nope=1", "expected FIELD=VALUE with FIELD one of"),
        ("bsm_ssm=3", "bsm_ssm cannot be set"),
        ("bsm_ssm.dt_rank=wide", "bsm_ssm.dt_rank takes int values, got 'wide'"),
        ("bsm_ssm.dt_rank=0", "dt_rank must be >= 1"),
        ("levels=two", "levels takes int values"),
        ("bsm=sideways", "bsm must be one of"),
        ("levels", "bad override 'levels'"),
        ("bsm_ssm.scan=bogus", "scan must be one of"),
        ("htm_ssm.expand=0", "expand > 0"),
        ("bsm_ssm.dt_min=0.5", "dt_min < dt_max"),
    ],
)
def test_a_bad_override_names_what_is_wrong(item, message):
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(".", r"\.")):
        override_config(MotionMambaConfig(), [item])
