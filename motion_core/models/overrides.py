"""Config fields set from the command line ("FIELD=VALUE", ``train ... --set``)."""

from __future__ import annotations

import dataclasses


def override_config(cfg, assignments: list[str]):
    """A copy of a config dataclass with "field=value" assignments applied (the ablation arms,
    e.g. ``htm_order=flat``, ``bsm=single``, ``freq=off``, ``transform=fft``); values take
    the type of the field's current value. Unknown fields are an error naming the known ones."""
    known = {f.name for f in dataclasses.fields(cfg)}
    changes: dict = {}
    for item in assignments:
        key, sep, value = item.partition("=")
        if not sep or key not in known:
            raise ValueError(f"bad override {item!r}: expected FIELD=VALUE with FIELD one of {sorted(known)}")
        cur = getattr(cfg, key)
        if isinstance(cur, bool):
            changes[key] = value.lower() in ("1", "true", "yes", "on")
        elif isinstance(cur, (int, float, str)):
            changes[key] = type(cur)(value)
        else:
            raise ValueError(f"{key} cannot be set from the command line")
    return dataclasses.replace(cfg, **changes)  # the configs' __post_init__ checks the values
