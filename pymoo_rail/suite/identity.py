"""What fixes an instance's identity: checksums of canonical definitions, and the HV reference margin."""

from __future__ import annotations

import hashlib
import json

import numpy as np

DIGITS = 12
"""Significant digits of the floats of a definition: the last bits of a simulated number (a window's
end from the flat-out run, a front's vertex) may differ between machines; 12 digits do not."""

HV_MARGIN = 0.1
"""A family instance's hypervolume reference point lies this share of the front's range beyond its nadir."""


def as_text(values) -> list[str]:
    """Floats (a number or an array) as text with :data:`DIGITS` significant digits."""
    return [f"{float(v):.{DIGITS}g}" for v in np.ravel(values)]


def checksum_of(definition: dict) -> str:
    """SHA-256 (hex) of a definition as sorted, compact JSON."""
    text = json.dumps(definition, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode("utf-8")).hexdigest()
