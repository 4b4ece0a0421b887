"""Config fields set from the command line ("FIELD=VALUE", ``train ... --set``)."""

from __future__ import annotations

import dataclasses


def _value(field: str, cur, value: str):
    if isinstance(cur, bool):
        return value.lower() in ("1", "true", "yes", "on")
    if isinstance(cur, (int, float, str)):
        return type(cur)(value)
    raise ValueError(f"{field} cannot be set from the command line")


def override_config(cfg, assignments: list[str], _outer: str = ""):
    """A copy of a config dataclass with "field=value" assignments applied (the ablation arms,
    e.g. ``htm_order=flat``, ``bsm=single``, ``freq=off``, ``transform=fft``); values take
    the type of the field's current value. A field of a nested config is named with a dot
    (``bsm_ssm.expand=1``, ``htm_ssm.d_state=4``). Unknown fields are an error naming the
    known ones."""
    known = {f.name for f in dataclasses.fields(cfg)}
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
            changes[key] = _value(_outer + key, getattr(cfg, key), value)
    for head, items in nested.items():
        changes[head] = override_config(getattr(cfg, head), items, f"{_outer}{head}.")
    return dataclasses.replace(cfg, **changes)  # the configs' __post_init__ checks the values
