"""Config fields set from the command line ("FIELD=VALUE", ``train ... --set``)."""

from __future__ import annotations

import dataclasses

_SCALARS = {"int": int, "float": float, "str": str, "bool": bool}
_BOOLS = {"1": True, "true": True, "yes": True, "on": True, "0": False, "false": False, "no": False, "off": False}


def _value(field: str, cur, value: str, annotation: str):
    """``value`` as the field's type: its current value's, or, for an optional field now None
    (an SSM's ``dt_rank``, whose None means "from the width"), the type its annotation names;
    "none" sets an optional field back to None."""
    optional = "None" in annotation
    if optional and value.lower() == "none":
        return None
    kind = type(cur) if isinstance(cur, (int, float, str)) else None
    if cur is None and optional:
        kind = _SCALARS.get(annotation.replace("| None", "").replace("None |", "").strip())
    if kind is None:
        raise ValueError(f"{field} cannot be set from the command line")
    if kind is bool:
        # a misspelt "flase" must not quietly read as False and train the wrong arm
        if value.lower() not in _BOOLS:
            raise ValueError(f"{field} takes true or false (1/0, yes/no, on/off), got {value!r}")
        return _BOOLS[value.lower()]
    try:
        return kind(value)
    except ValueError:
        raise ValueError(f"{field} takes {kind.__name__} values, got {value!r}") from None


def override_config(cfg, assignments: list[str], _outer: str = ""):
    """A copy of a config dataclass with "field=value" assignments applied (the ablation arms,
    e.g. ``htm_order=flat``, ``bsm=single``, ``freq=off``, ``transform=fft``); values take
    the type of the field's current value. A field of a nested config is named with a dot
    (``bsm_ssm.expand=1``, ``htm_ssm.d_state=4``); an optional field takes "none"
    (``bsm_ssm.dt_rank=2``, ``bsm_ssm.dt_rank=none``). Unknown fields are an error naming the
    known ones."""
    annotations = {f.name: str(f.type) for f in dataclasses.fields(cfg)}
    known = set(annotations)
    changes: dict = {}
    nested: dict[str, list[str]] = {}
    for item in assignments:
        key, sep, value = item.partition("=")
        head, dot, rest = key.partition(".")
        if not sep or head not in known:
            raise ValueError(
                f"bad override {_outer + item!r}: expected {_outer}FIELD=VALUE with FIELD one of {sorted(known)}"
            )
        if dot:
            if not dataclasses.is_dataclass(getattr(cfg, head)):
                raise ValueError(f"bad override {_outer + item!r}: {_outer + head} has no fields")
            nested.setdefault(head, []).append(f"{rest}={value}")
        else:
            changes[key] = _value(_outer + key, getattr(cfg, key), value, annotations[key])
    for head, items in nested.items():
        changes[head] = override_config(getattr(cfg, head), items, f"{_outer}{head}.")
    return dataclasses.replace(cfg, **changes)  # the configs' __post_init__ checks the values
