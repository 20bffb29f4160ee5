"""Errors raised for bad case data."""

from __future__ import annotations


class CaseError(ValueError):
    """A case file or case object holds a value the model cannot use.

    The message always names the source (file or object), the field and the offending value,
    so a user can find and fix the entry.
    """

    def __init__(self, field: str, value: object, reason: str, source: str | None = None):
        self.field = field
        self.value = value
        self.reason = reason
        self.source = source
        where = f"{source}: " if source else ""
        super().__init__(f"{where}field '{field}' = {value!r}: {reason}")


class InfeasibleCaseError(CaseError):
    """The case asks for something the train cannot do (e.g. a planned time below the minimum)."""
