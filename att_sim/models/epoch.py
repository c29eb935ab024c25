"""Epoch and time scales of the real sky.

An epoch is a timezone-aware :class:`datetime` in UTC; sim time ``t`` is SI seconds past it. Text is
ISO 8601 (``datetime.fromisoformat``, Python ≥ 3.11: ``Z`` or a ``±HH:MM`` offset; naive text is
refused because it would silently mean local time). The span is that of the JPL DE421 ephemeris
shipped by ``skyfield-data`` (1899-07-29 .. 2053-10-09) rounded inwards to 1900 .. 2050.

TT/UTC: skyfield's built-in leap-second and ΔT tables (``load.timescale(builtin=True)``; Rhodes,
*Skyfield* documentation, "Dates and Time"), so nothing is downloaded. ``epoch + t`` is formed on the
TT scale (``tt_jd(whole, fraction + t/86400)``), which counts SI seconds, so a leap second inside
``[epoch, epoch + t]`` is handled: UTC labels of later times shift by it, physical time does not.
"""
from __future__ import annotations

from datetime import UTC, datetime
from functools import lru_cache

import numpy as np

EPOCH_MIN = datetime(1900, 1, 1, tzinfo=UTC)
EPOCH_MAX = datetime(2050, 1, 1, tzinfo=UTC)


def parse_epoch(value, field: str = "epoch") -> datetime:
    """ISO 8601 text with ``Z`` or an offset, or an aware ``datetime``, as a UTC ``datetime`` in
    ``[EPOCH_MIN, EPOCH_MAX]``; anything else is a ``ValueError`` naming ``field``."""
    span = f"an ISO 8601 UTC time ('Z' or an offset) from {format_epoch(EPOCH_MIN)} to {format_epoch(EPOCH_MAX)}"
    if isinstance(value, str):
        try:
            dt = datetime.fromisoformat(value.strip())
        except ValueError:
            raise ValueError(f"{field} must be {span}, got {value!r}") from None
    elif isinstance(value, datetime):
        dt = value
    else:
        raise ValueError(f"{field} must be {span}, got {type(value).__name__} {value!r}")
    if dt.tzinfo is None or dt.utcoffset() is None:
        raise ValueError(f"{field} must carry 'Z' or a UTC offset (naive times are refused), got {value!r}")
    dt = dt.astimezone(UTC)
    if not EPOCH_MIN <= dt <= EPOCH_MAX:
        raise ValueError(f"{field} must be {span}, got {format_epoch(dt)}")
    return dt


def format_epoch(dt: datetime) -> str:
    """``YYYY-MM-DDTHH:MM:SS.ffffffZ`` of an aware ``datetime`` (converted to UTC)."""
    if dt.tzinfo is None or dt.utcoffset() is None:
        raise ValueError(f"epoch must be timezone-aware, got naive {dt!r}")
    return dt.astimezone(UTC).strftime("%Y-%m-%dT%H:%M:%S.%fZ")


@lru_cache(maxsize=1)
def timescale():
    """skyfield ``Timescale`` with its built-in leap-second and ΔT tables (no download), cached."""
    from skyfield.api import load

    return load.timescale(builtin=True)


def skyfield_times(epoch: datetime, t=0.0):
    """skyfield ``Time`` of ``epoch + t`` SI seconds (``t`` a scalar or an array)."""
    ts = timescale()
    t0 = ts.from_datetime(parse_epoch(epoch))
    return ts.tt_jd(t0.whole, t0.tt_fraction + np.asarray(t, float) / 86400.0)
