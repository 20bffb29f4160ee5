"""Errors raised for bad case data (and the field error that study declarations share)."""

from __future__ import annotations

import math


class FieldError(ValueError):
    """A value a field cannot hold; the message names the source, the field path and the value.

    Parameters
    ----------
    field : str
        The field path (``"train.mass_t"``, ``"algorithms[0].pop_size"``).
    value : object
        The offending value.
    reason : str
        What is wrong with it.
    source : str, optional
        The file or object it came from.
    """

    def __init__(self, field: str, value: object, reason: str, source: str | None = None):
        self.field = field
        self.value = value
        self.reason = reason
        self.source = source
        where = f"{source}: " if source else ""
        super().__init__(f"{where}field '{field}' = {value!r}: {reason}")


class CaseError(FieldError):
    """A case file or case object holds a value the model cannot use.

    The message always names the source (file or object), the field and the offending value,
    so a user can find and fix the entry.
    """


class InfeasibleCaseError(CaseError):
    """The case asks for something the train cannot do (e.g. a planned time below the minimum)."""


def check_number(field: str, value: object, *, positive: bool = False, nonneg: bool = False,
                 upper: float | None = None, optional: bool = False, source: str | None = None) -> float | None:
    """``value`` as a float after checking its type and range; :class:`CaseError` naming ``field``.

    Booleans and strings are refused (TOML ``true`` or ``"80"`` are not numbers), as are NaN and
    infinities: nothing is coerced.
    """
    if value is None:
        if optional:
            return None
        raise CaseError(field, value, "is required", source)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise CaseError(field, value, f"must be a finite number, not {type(value).__name__}", source)
    if not math.isfinite(value):
        raise CaseError(field, value, "must be a finite number", source)
    if positive and value <= 0:
        raise CaseError(field, value, "must be > 0 (positive)", source)
    if nonneg and value < 0:
        raise CaseError(field, value, "must be >= 0", source)
    if upper is not None and value > upper:
        raise CaseError(field, value, f"must be <= {upper}", source)
    return float(value)
