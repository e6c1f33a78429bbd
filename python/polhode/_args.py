"""Checks of the public functions' arguments written in Python: a wrong type is a
``TypeError`` naming the function, the argument and what it takes, as the extension's own
functions word it (``python/src/errors.rs``)::

    montecarlo(): runs must be a number of runs (int), got str '10'
"""

import numbers
import os

__all__ = ["integer", "is_path", "optional_import", "type_error"]

# Longest repr of a wrong argument quoted in a message (characters).
_REPR_CHARS = 60


def type_error(function, argument, expected, value):
    """``TypeError("function(): argument must be expected, got <type> <repr>")``."""
    shown = repr(value)
    if len(shown) > _REPR_CHARS:
        shown = shown[:_REPR_CHARS] + "…"
    return TypeError(
        f"{function}(): {argument} must be {expected}, got {type(value).__name__} {shown}"
    )


# The largest integer the extension takes (an unsigned 64-bit integer).
_U64_MAX = 2**64 - 1


def integer(function, argument, expected, value, minimum):
    """``value`` as an int (Python's or numpy's, not a bool), from ``minimum`` to 2**64 - 1;
    None stays None. ``TypeError`` for another type, ``ValueError`` out of that range."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise type_error(function, argument, expected, value)
    value = int(value)
    if value < minimum:
        raise ValueError(f"{function}(): {argument} must be at least {minimum}, got {value}")
    if value > _U64_MAX:
        raise ValueError(f"{function}(): {argument} must be at most 2**64 - 1, got {value}")
    return value


def is_path(value):
    """Whether ``value`` is a file path: a str or an ``os.PathLike`` naming a str path."""
    return isinstance(value, str) or (
        isinstance(value, os.PathLike) and isinstance(os.fspath(value), str)
    )


def optional_import(module, what):
    """``module`` imported, or an ``ImportError`` saying that ``what`` needs it and how to
    install it (alone, or with every optional dependency of polhode)."""
    try:
        return __import__(module, fromlist=["_"])
    except ImportError as e:
        package = module.split(".")[0]
        raise ImportError(
            f"{what} needs {package}, which is not installed: `pip install {package}`, or "
            f'every optional dependency of polhode with `pip install "./python[all]"` from '
            f"the repository ({e})"
        ) from e
