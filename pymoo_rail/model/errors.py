"""Errors raised for bad case data (and the field error that study declarations share)."""

from __future__ import annotations

import math
import numbers


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
                 upper: float | None = None, optional: bool = False, source: str | None = None,
                 error: type[FieldError] | None = None) -> float | None:
    """``value`` as a float after checking its type and range, else an error naming ``field``.

    The one number check of the package: case fields, solver and controller settings.
    Booleans and strings are refused (TOML ``true`` or ``"80"`` are not numbers), as are NaN and
    infinities: nothing is coerced. Python and numpy numbers are accepted.

    Parameters
    ----------
    field : str
        The field path or parameter name the message names.
    value : object
    positive, nonneg : bool
        Require ``value > 0`` or ``value >= 0``.
    upper : float, optional
        Require ``value <= upper``.
    optional : bool
        ``None`` is allowed (and returned).
    source : str, optional
        The file or object the value came from.
    error : FieldError subclass, optional
        The exception raised (default :class:`CaseError`; a setting that is not case data
        raises :class:`FieldError`).

    Returns
    -------
    float or None
    """
    error = CaseError if error is None else error
    if value is None:
        if optional:
            return None
        raise error(field, value, "is required", source)
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise error(field, value, f"must be a finite number, not {type(value).__name__}", source)
    if not math.isfinite(value):
        raise error(field, value, "must be a finite number", source)
    if positive and value <= 0:
        raise error(field, value, "must be > 0 (positive)", source)
    if nonneg and value < 0:
        raise error(field, value, "must be >= 0", source)
    if upper is not None and value > upper:
        raise error(field, value, f"must be <= {upper}", source)
    return float(value)
