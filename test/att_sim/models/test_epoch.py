"""Epoch parsing, range and skyfield times (att_sim.models.epoch)."""
from datetime import UTC, datetime, timedelta, timezone

import numpy as np
import pytest

from att_sim.models import epoch as ep


@pytest.mark.parametrize("text, expected", [
    ("2026-12-21T00:00:00Z", datetime(2026, 12, 21, tzinfo=UTC)),
    ("2026-12-21T01:30:00+01:30", datetime(2026, 12, 21, tzinfo=UTC)),
    ("2026-12-20T19:00:00.250-05:00", datetime(2026, 12, 21, 0, 0, 0, 250000, tzinfo=UTC)),
    ("1900-01-01T00:00:00Z", ep.EPOCH_MIN),
    ("2050-01-01T00:00:00Z", ep.EPOCH_MAX),
])
def test_parse_good_text_to_utc(text, expected):
    dt = ep.parse_epoch(text)
    assert dt == expected and dt.utcoffset() == timedelta(0)


def test_parse_datetime_and_format_round_trip():
    dt = datetime(2026, 12, 21, 3, 4, 5, 678901, tzinfo=timezone(timedelta(hours=2)))
    assert ep.format_epoch(dt) == "2026-12-21T01:04:05.678901Z"
    assert ep.parse_epoch(ep.format_epoch(dt)) == dt
    assert ep.parse_epoch(dt) == dt


@pytest.mark.parametrize("value, words", [
    ("2026-12-21T00:00:00", "naive"),                 # no zone: refused, not taken as local time
    ("2026-12-21", "naive"),
    ("21/12/2026 00:00Z", "ISO 8601"),
    ("", "ISO 8601"),
    ("2026-12-21T24:01:00Z", "ISO 8601"),
    ("1899-12-31T23:59:59Z", "1900-01-01"),           # before DE421's span as used
    ("2050-01-01T00:00:01Z", "2050-01-01"),
    (1798761600, "int"),
    (None, "NoneType"),
    (datetime(2026, 12, 21), "naive"),
])
def test_parse_bad_input_names_the_field(value, words):
    with pytest.raises(ValueError, match="epoch") as err:
        ep.parse_epoch(value)
    assert words in str(err.value)


def test_custom_field_name_and_naive_format_refused():
    with pytest.raises(ValueError, match="^request.epoch"):
        ep.parse_epoch("2026-12-21T00:00:00", field="request.epoch")
    with pytest.raises(ValueError, match="aware"):
        ep.format_epoch(datetime(2026, 12, 21))


def test_timescale_cached_and_times_count_si_seconds():
    assert ep.timescale() is ep.timescale()
    t = ep.skyfield_times("2026-12-21T00:00:00Z", np.array([0.0, 86400.0, 0.5]))
    utc = t.utc_datetime()
    assert utc[0] == datetime(2026, 12, 21, tzinfo=UTC)
    assert utc[1] == datetime(2026, 12, 22, tzinfo=UTC)
    assert abs((utc[2] - utc[0]).total_seconds() - 0.5) < 1e-5
    # TT − UTC = 32.184 s + 37 leap seconds since 2017
    assert (t.tt[0] - t.tai[0]) * 86400 == pytest.approx(32.184, abs=1e-4)
    assert (t.tai[0] - ep.timescale().utc(2026, 12, 21).tai) * 86400 == pytest.approx(0.0, abs=1e-5)
    # across the 2016-12-31 leap second: 1 s of SI time more than the UTC labels say
    t2 = ep.skyfield_times("2016-12-31T23:59:00Z", 121.0)
    assert t2.utc_datetime() == datetime(2017, 1, 1, 0, 1, tzinfo=UTC)
