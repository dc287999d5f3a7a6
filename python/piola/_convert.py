"""Conversions from friendly Python values to what the C extension takes.

Every function raises TypeError (wrong kind of value) or ValueError (wrong shape or range)
with a message naming the argument, so that no bad value ever reaches the C library."""
import math
import numbers

import numpy as np


def float_array(value, what, shape):
    """A C-ordered float64 copy-or-view of value with the given shape (-1: any size).
    Integers and float32 convert; complex, object and string arrays are refused."""
    a = np.asarray(value)
    if a.dtype.kind not in "biuf":
        raise TypeError(f"{what} must be real numbers, got dtype {a.dtype}")
    a = np.ascontiguousarray(a, dtype=np.float64)
    check_shape(a, what, shape)
    return a


def integer_array(value, what, shape):
    """value as an integer array of the given shape (an empty float array counts as integers);
    TypeError for any other kind of number."""
    a = np.asarray(value)
    if a.size == 0 and a.dtype.kind == "f":
        a = a.astype(np.int64)
    if a.dtype.kind not in "iu":
        raise TypeError(f"{what} must be integers, got dtype {a.dtype}")
    check_shape(a, what, shape)
    return a


def index_array(value, what, shape):
    """A C-ordered int32 array of non-negative indices below 2**31."""
    a = integer_array(value, what, shape)
    if a.size and (a.min() < 0 or a.max() > np.iinfo(np.int32).max):
        raise ValueError(f"{what} must be indices in [0, 2**31)")
    return np.ascontiguousarray(a, dtype=np.int32)


def int32_array(value, what, shape):
    """A C-ordered int32 array of any values that fit (region ids: -1 marks a tet no region
    covers, as the Vega and TetGen readers give it)."""
    a = integer_array(value, what, shape)
    info = np.iinfo(np.int32)
    if a.size and (a.min() < info.min or a.max() > info.max):
        raise ValueError(f"{what} must fit in 32-bit signed integers")
    return np.ascontiguousarray(a, dtype=np.int32)


def check_shape(a, what, shape):
    ok = a.ndim == len(shape) and all(s < 0 or s == d for s, d in zip(shape, a.shape))
    if not ok:
        want = "(" + ", ".join("n" if s < 0 else str(s) for s in shape) + ")"
        raise ValueError(f"{what} must have shape {want}, got {a.shape}")


def number(value, what):
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{what} must be a number, got {type(value).__name__}")
    return float(value)


def finite_number(value, what):
    x = number(value, what)
    if not math.isfinite(x):
        raise ValueError(f"{what} must be finite, got {x}")
    return x


def finite_array(value, what, shape):
    a = float_array(value, what, shape)
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{what} must be finite")
    return a


def integer(value, what):
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{what} must be an integer, got {type(value).__name__}")
    return int(value)


def vec3(value, what):
    a = float_array(value, what, (3,))
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{what} must be finite")
    return (float(a[0]), float(a[1]), float(a[2]))


def track(value, what):
    """A keyframable scalar: a number, {"keys": [[t0, v0], ...]} or a list of (t, v) pairs.
    Returns a float or a (times, values) pair for the extension."""
    if isinstance(value, dict):
        if set(value) != {"keys"}:
            raise ValueError(f"{what}: a keyframed value is {{'keys': [[t0, v0], ...]}}")
        value = value["keys"]
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        if not math.isfinite(value):
            raise ValueError(f"{what} must be finite")
        return float(value)
    if isinstance(value, (list, tuple, np.ndarray)):
        keys = float_array(value, what, (-1, 2))
        if not 1 <= len(keys) <= 64:
            raise ValueError(f"{what}: 1 to 64 keys, got {len(keys)}")
        return (keys[:, 0].tolist(), keys[:, 1].tolist())
    raise TypeError(f"{what} must be a number or keyframes [[t, v], ...], got {type(value).__name__}")


def tracks3(value, what):
    if isinstance(value, (list, tuple)) and len(value) == 3 and not all(
            isinstance(v, numbers.Real) for v in value):
        return tuple(track(v, f"{what}[{i}]") for i, v in enumerate(value))
    v = vec3(value, what)
    return v


def check_keys(d, allowed, what):
    if not isinstance(d, dict):
        raise TypeError(f"{what} must be a dict, got {type(d).__name__}")
    unknown = sorted(set(d) - set(allowed))
    if unknown:
        raise ValueError(f"{what}: unknown key {unknown[0]!r} (allowed: {', '.join(sorted(allowed))})")


def float_stack(value, what, tail):
    """A C-ordered float64 array of shape (..., *tail): any number of leading dimensions."""
    a = np.asarray(value)
    if a.dtype.kind not in "biuf":
        raise TypeError(f"{what} must be real numbers, got dtype {a.dtype}")
    if a.ndim < len(tail) or a.shape[a.ndim - len(tail):] != tuple(tail):
        want = "(..., " + ", ".join(map(str, tail)) + ")"
        raise ValueError(f"{what} must have shape {want}, got {a.shape}")
    return np.ascontiguousarray(a, dtype=np.float64)
