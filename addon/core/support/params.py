"""Numeric parameters of the public API, checked in one place.

Every public function passes its numbers through :func:`integer` or :func:`number` before
using them, so that all of them accept the same things and fail the same way:

- Python and NumPy numbers are accepted alike (``np.float32(0.5)``, ``np.int64(3)``);
- booleans are refused (``ratio=True`` is a mistake, not 1);
- the range is checked on the value as given, before any conversion (``seed=2**64`` fails with
  a message instead of overflowing into the engine's 64-bit integer);
- NaN is refused; infinity only where the range allows it;
- the message names the parameter, the range and the value as given;
- arrays (:func:`array`: points, directions, matrices) must have the shape asked for and hold
  finite numbers; :func:`real_array` refuses strings, complex numbers and objects in any array
  parameter (guidance too), which NumPy would otherwise convert or truncate silently.

Every refusal is a :class:`ParameterError`, a :class:`~.errors.TopStocError` (so a ValueError).
"""

from __future__ import annotations

import math
import numbers
import reprlib
from typing import Optional

import numpy as np

from .errors import TopStocError


class ParameterError(TopStocError):
    """A parameter of the wrong type, shape or range; the message names it and its value."""


#: Seeds are 64-bit unsigned integers in the engine.
SEED_MAX = 2**64 - 1


def _shown(value) -> str:
    """The value for a message: its repr, with the NumPy type named (np.float32(0.5) reads as 0.5)."""
    if isinstance(value, np.generic):
        return f"{value.item()!r} ({type(value).__name__})"
    return repr(value)


def _is_bool(value) -> bool:
    return isinstance(value, (bool, np.bool_))


def _range_text(low, high, low_open: bool, high_open: bool) -> str:
    left = "(" if low_open or low is None else "["
    right = ")" if high_open or high is None else "]"
    return f"{left}{'-inf' if low is None else low}, {'inf' if high is None else high}{right}"


def optional_integer(name: str, value, low: Optional[int] = None, high: Optional[int] = None) -> Optional[int]:
    """None, or integer(name, value, low, high)."""
    return None if value is None else integer(name, value, low, high)


def integer(name: str, value, low: Optional[int] = None, high: Optional[int] = None, *,
            expected: Optional[str] = None) -> int:
    """``value`` as a Python int in [low, high] (None: unbounded); ValueError otherwise.
    ``expected`` replaces the range in the message ("must be {expected}, got ...")."""
    if _is_bool(value) or not isinstance(value, (numbers.Integral, np.integer)):
        raise ParameterError(f"{name} must be {expected or 'an integer'}, got {_shown(value)}")
    exact = int(value)  # arbitrary precision: the comparison below cannot overflow
    if (low is not None and exact < low) or (high is not None and exact > high):
        wanted = f"be {expected}" if expected else f"lie in {_range_text(low, high, False, False)}"
        raise ParameterError(f"{name} must {wanted}, got {_shown(value)}")
    return exact


def number(name: str, value, low: Optional[float] = None, high: Optional[float] = None, *,
           low_open: bool = False, high_open: bool = False, finite: bool = True,
           expected: Optional[str] = None) -> float:
    """``value`` as a Python float in the range given (open ends when low_open / high_open;
    None: unbounded) and finite unless ``finite=False``; ValueError for anything else, NaN
    included. ``expected`` replaces the range in the message ("must be {expected}, got ...")."""
    if _is_bool(value) or not isinstance(value, (numbers.Real, np.integer, np.floating)):
        raise ParameterError(f"{name} must be {expected or 'a number'}, got {_shown(value)}")
    try:
        real = float(value)
    except OverflowError:  # an int beyond the double range
        raise ParameterError(f"{name} is too large: {_shown(value)}") from None
    below = low is not None and (real < low or (low_open and real == low))
    above = high is not None and (real > high or (high_open and real == high))
    if math.isnan(real) or below or above or (finite and math.isinf(real)):
        wanted = f"be {expected}" if expected else f"lie in {_range_text(low, high, low_open, high_open)}"
        raise ParameterError(f"{name} must {wanted}, got {_shown(value)}")
    return real


def seed(value, name: str = "seed") -> int:
    """A decimation seed: an integer in [0, 2**64 - 1]."""
    return integer(name, value, 0, SEED_MAX)


def real_array(name: str, value, expected: str, *, booleans: bool = False) -> np.ndarray:
    """``value`` (numbers of any shape) as a float64 array; ParameterError for strings, complex
    numbers, objects, ragged lists (and booleans unless ``booleans``). ``expected`` says what
    the parameter must be ("3 numbers") in the message."""
    try:
        data = np.asarray(value)
    except Exception:  # noqa: BLE001 - ragged nested lists and the like
        raise ParameterError(f"{name} must be {expected}, got {reprlib.repr(value)}") from None
    if data.dtype.kind not in ("iufb" if booleans else "iuf"):
        what = "booleans" if data.dtype.kind == "b" else f"{data.dtype} values"
        raise ParameterError(f"{name} must be {expected}, got {what}: {reprlib.repr(value)}")
    return data.astype(np.float64)


def array(name: str, value, shape: tuple, *, nonzero: bool = False) -> np.ndarray:
    """``value`` (a sequence or array of numbers) as a float64 array of exactly ``shape``, every
    entry finite (and not all zero when ``nonzero``); ParameterError otherwise."""
    expected = f"{shape[0]} numbers" if len(shape) == 1 else "a " + " x ".join(map(str, shape)) + " matrix"
    data = real_array(name, value, expected)
    if data.shape != tuple(shape):
        raise ParameterError(f"{name} must be {expected}, got shape {data.shape}")
    if not np.isfinite(data).all():
        where = tuple(int(i) for i in np.argwhere(~np.isfinite(data))[0])
        raise ParameterError(f"{name} must hold finite numbers, got {data[where]} at [{', '.join(map(str, where))}]")
    if nonzero and not data.any():
        raise ParameterError(f"{name} must not be zero")
    return data
