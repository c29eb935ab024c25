"""Test ephemerides: the interface :class:`att_planner.zones.FittedZones` reads of
:class:`att_sim.models.ephemeris.Ephemeris`, from closed-form motions instead of DE421."""
import numpy as np

from att_sim.models import rotations as rot

C = np.sqrt(0.5)
RATE = np.deg2rad(0.25)          # rad/s: the Sun descends along the 45° meridian


class DescendingEphemeris:
    """An ephemeris whose Sun starts at azimuth 45°, elevation 52° and turns down its meridian at RATE
    (the interface :class:`att_planner.zones.FittedZones` reads; Moon and Earth unused)."""

    d0 = rot.dcm_NB(rot.from_axis_angle([-C, C, 0.0], -np.deg2rad(52.0))) @ np.array([C, C, 0.0])

    def sun_direction(self, t):
        t = np.asarray(t, float)
        turn = rot.from_axis_angle(np.broadcast_to([-C, C, 0.0], t.shape + (3,)), RATE * t)
        return rot.dcm_NB(turn) @ self.d0

    moon_direction = sun_direction

    def nadir(self, t):
        return np.broadcast_to([0.0, 0.0, -1.0], np.shape(t) + (3,))

    def earth_angular_radius(self, t):
        return np.full(np.shape(t), 0.5)
