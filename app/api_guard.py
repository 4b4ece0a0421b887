"""The HTTP API's front door, shared by the demo and the study: each endpoint's arguments are
checked against its function's type hints before the function runs, and each refused request
gets a message saying what to change and leaves one line in the log.

``gr.api`` passes a client's JSON values through as they come: a number where a string goes
reached ``json.loads`` and came back as "The upstream Gradio app has raised an exception",
and every ``gr.Error`` printed a traceback. Here a wrong type, a number out of range or a
value too big is refused before the function sees it (``ArgumentError``, named by the
parameter); a ``gr.Error`` the function raises is logged as one line and passed on without a
traceback; anything else is a real failure, logged with its traceback, and the client gets a
plain "something went wrong" (the server's exception text stays in its log).
"""

from __future__ import annotations

import functools
import inspect
import logging
import math
import types
import typing
from collections.abc import Callable
from typing import Any, Literal, Union

import gradio as gr

from .runtime import configure_log

log = logging.getLogger("motion_mamba_studio.api")

MAX_CHARS = 50_000  # characters in one string argument (a 10-segment timeline JSON is ~4,000)
MAX_ITEMS = 1_000  # items in one list or object argument
MAX_INT = 2**63 - 1  # any integer argument, unless its endpoint gives a narrower range


class ArgumentError(ValueError):
    """An API argument of the wrong type, out of range or too big; the message names it."""


def _what(value: Any) -> str:
    """A JSON value in a client's words: "a number (3.5)", "null", "a list of 3 items"."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return f"{str(value).lower()} (a boolean)"
    if isinstance(value, int | float):
        text = repr(value) if len(repr(value)) <= 24 else f"{repr(value)[:20]}... ({len(repr(value))} digits)"
        return f"a number ({text})"
    if isinstance(value, str):
        return f"a string of {len(value):,} characters" if len(value) > 40 else f"the string {value!r}"
    if isinstance(value, list | tuple):
        return f"a list of {len(value):,} items"
    if isinstance(value, dict):
        return f"an object of {len(value):,} keys"
    return type(value).__name__


def _expect(hint: Any) -> str:
    """What a type hint asks for, in a client's words."""
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if hint is Any:
        return "any JSON value"
    if hint is type(None):
        return "null"
    if origin in (Union, types.UnionType):
        return " or ".join(_expect(a) for a in args)
    if origin is Literal:
        return "one of " + ", ".join(repr(a) for a in args)
    if hint is str:
        return "a string"
    if hint is bool:
        return "true or false"
    if hint is int:
        return "an integer"
    if hint is float:
        return "a number"
    if origin is list:
        return f"a list (of {_expect(args[0])})" if args and args[0] is not Any else "a list"
    if origin is dict:
        return "an object"
    return getattr(hint, "__name__", str(hint))


def coerce(value: Any, hint: Any, name: str) -> Any:
    """``value`` as ``hint`` asks (an integral float as an int), or ArgumentError."""
    origin, args = typing.get_origin(hint), typing.get_args(hint)

    def wrong() -> ArgumentError:
        return ArgumentError(f"{name} must be {_expect(hint)}, got {_what(value)}")

    if hint is Any:
        return value
    if hint is type(None):
        if value is None:
            return None
        raise wrong()
    if origin in (Union, types.UnionType):
        problems = []
        for option in args:
            try:
                return coerce(value, option, name)
            except ArgumentError as e:
                problems.append(str(e))
        # the right type but a bad value (a string too long) says so; else the types offered
        right_type = [p for p in problems if "must be" not in p]
        raise ArgumentError(right_type[0]) if right_type else wrong()
    if origin is Literal:
        for choice in args:
            if type(value) is type(choice) and value == choice:
                return value
        if isinstance(value, str) and len(value) <= 100:
            raise ArgumentError(f"unknown {name} {value!r}: {name} must be {_expect(hint)}")
        raise wrong()
    if hint is str:
        if not isinstance(value, str):
            raise wrong()
        if len(value) > MAX_CHARS:
            raise ArgumentError(f"{name} is {len(value):,} characters long (at most {MAX_CHARS:,})")
        return value
    if hint is bool:
        if not isinstance(value, bool):
            raise wrong()
        return value
    if hint is int:
        if isinstance(value, float) and math.isfinite(value) and value.is_integer():
            value = int(value)
        if not isinstance(value, int) or isinstance(value, bool):
            raise wrong()
        if abs(value) > MAX_INT:
            raise ArgumentError(f"{name} is too large ({_what(value)}; at most {MAX_INT})")
        return value
    if hint is float:
        if not isinstance(value, int | float) or isinstance(value, bool):
            raise wrong()
        if not math.isfinite(value) or abs(value) > 1e15:
            raise ArgumentError(f"{name} must be a finite number of reasonable size, got {_what(value)}")
        return float(value)
    if origin is list:
        if not isinstance(value, list):
            raise wrong()
        if len(value) > MAX_ITEMS:
            raise ArgumentError(f"{name} has {len(value):,} items (at most {MAX_ITEMS:,})")
        item = args[0] if args else Any
        return [coerce(v, item, f"{name}[{i}]") for i, v in enumerate(value)]
    if origin is dict or hint is dict:
        if not isinstance(value, dict):
            raise wrong()
        if len(value) > MAX_ITEMS:
            raise ArgumentError(f"{name} has {len(value):,} keys (at most {MAX_ITEMS:,})")
        item = args[1] if len(args) == 2 else Any
        return {str(k): coerce(v, item, f"{name}[{k!r}]") for k, v in value.items()}
    raise TypeError(f"api_guard cannot check {name}'s type hint {hint!r}")


def _checked(value: Any, limit: tuple[float, float] | None, name: str) -> Any:
    """Within the endpoint's range for that parameter (when it gives one), or ArgumentError."""
    if limit is not None and isinstance(value, int | float) and not isinstance(value, bool):
        low, high = limit
        if not low <= value <= high:
            whole = float(low).is_integer() and float(high).is_integer()
            span = f"{int(low):,} to {int(high):,}" if whole else f"{low} to {high}"
            raise ArgumentError(f"{name} must be {span}, got {_what(value)}")
    return value


def refuse(api_name: str, title: str, message: str) -> gr.Error:
    """The one log line of a refused request, and the error its client gets (no traceback)."""
    log.info("refused /%s: %s: %s", api_name, title, message)
    return gr.Error(message, title=title, print_exception=False)


def endpoint(fn: Callable, api_name: str, ranges: dict[str, tuple[float, float]] | None = None, **api_kwargs) -> Any:
    """``gr.api(fn, api_name=...)`` with every argument checked against ``fn``'s type hints
    (and ``ranges``: {parameter: (lowest, highest)}) before ``fn`` runs, and each refusal
    logged as one line. ``fn``'s hints must be final (a module's __future__ strings resolve)."""
    configure_log()
    hints = typing.get_type_hints(fn)
    signature = inspect.signature(fn)
    checked = [p for p in signature.parameters if p in hints and hints[p] is not gr.Request and p != "return"]
    ranges = ranges or {}

    @functools.wraps(fn)
    def guarded(*args: Any, **kwargs: Any) -> Any:
        try:
            bound = signature.bind_partial(*args, **kwargs)
            for name in checked:
                if name in bound.arguments:
                    value = coerce(bound.arguments[name], hints[name], name)
                    bound.arguments[name] = _checked(value, ranges.get(name), name)
        except ArgumentError as e:
            raise refuse(api_name, "Please check the arguments", str(e)) from None
        except TypeError as e:  # too many arguments for the function
            raise refuse(api_name, "Please check the arguments", str(e)) from None
        try:
            return fn(*bound.args, **bound.kwargs)
        except gr.Error as e:
            if not e.print_exception:  # refused and logged already
                raise
            raise refuse(api_name, e.title, e.message) from None
        except Exception:
            log.exception("/%s failed", api_name)
            raise gr.Error(
                "the server failed on this request (its log has the details)",
                title="Something went wrong",
                print_exception=False,
            ) from None

    return gr.api(guarded, api_name=api_name, **api_kwargs)
