"""att-mission's map fixes (``sensor_msgs/NavSatFix``): a point on the Earth is a fix, a boresight
that misses the Earth (NaN) is NO_FIX at 0, 0, never a NaN a map would choke on."""
import math

import pytest

from att_msgs_py import convert


@pytest.mark.parametrize("lat, lon, alt, fixed", [(28.63, -106.09, 1440.0, True), (math.nan, 12.0, 0.0, False),
                                                  (10.0, math.nan, 0.0, False), (-89.0, 179.9, 797e3, True)])
def test_a_fix_is_a_point_or_no_fix(lat, lon, alt, fixed):
    from sensor_msgs.msg import NavSatFix, NavSatStatus

    from att_planner.tools.mission import fix_msg

    msg = fix_msg(convert.time_msg(12.5), "boresight", lat, lon, alt)
    assert isinstance(msg, NavSatFix) and msg.header.frame_id == "boresight"
    assert msg.header.stamp.sec == 12 and msg.header.stamp.nanosec == 500_000_000
    assert msg.status.status == (NavSatStatus.STATUS_FIX if fixed else NavSatStatus.STATUS_NO_FIX)
    values = (msg.latitude, msg.longitude, msg.altitude)
    assert values == ((lat, lon, alt) if fixed else (0.0, 0.0, 0.0))
    assert all(math.isfinite(v) for v in values)
