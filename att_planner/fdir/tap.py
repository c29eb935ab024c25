"""What the nodes publish, routed to a fault monitor (no ROS): the in-process closed loop's tap.

:class:`MonitorTap` takes ``(topic, t, message)`` as :attr:`att_planner.tools.closed_loop.ClosedLoop.tap`
hands them (the mirror types of :mod:`att_msgs_py.types`) and feeds a
:class:`~.monitor.FaultMonitor`: each command's dipole; each wheel speed sample with the motor torques
last commanded and the friction the controller expects at those speeds; each gyro sample (and the time-driven detectors
at its stamp); the magnetometer; each star tracker message's arrival and attitude; each estimate (its health and
covariance, and the innovations the estimator computed since the last one); each controller status's
attitude error. A node does the same from its subscriptions.
"""
from __future__ import annotations

import math

import numpy as np

from att_msgs_py import topics
from att_msgs_py.types import FaultStatus
from att_planner.fdir.monitor import FaultMonitor


class MonitorTap:
    """A ``tap(topic, t, message)`` feeding ``monitor``; ``estimator``: whose innovations to take
    (None: none); ``friction``: the expected drive friction at relative speeds (None: none);
    ``chain``: a tap called after (a recorder's)."""

    def __init__(self, monitor: FaultMonitor, estimator=None, friction=None, chain=None):
        self.monitor, self.estimator, self.friction, self.chain = monitor, estimator, friction, chain
        self.torques = np.zeros(monitor.spacecraft.n_wheels)     # the motor torques in force
        self.omega_BN_B: np.ndarray | None = None               # the latest estimated body rate
        self.reports: list[FaultStatus] = []

    def __call__(self, topic: str, t: float, m) -> None:
        mon, out = self.monitor, self.reports
        if topic == topics.COMMAND:
            self.torques = np.asarray(m.wheel_torques, float)
            out += mon.on_dipole(t, m.dipole)
        elif topic == topics.WHEEL_SPEEDS:
            friction = None if self.friction is None else self.friction(np.asarray(m.speeds, float))
            out += mon.on_wheels(m.t, m.speeds, self.torques, friction, self.omega_BN_B)
        elif topic == topics.IMU:
            out += mon.on_gyro(m.t, m.omega)
            out += mon.tick(m.t)
        elif topic == topics.MAGNETOMETER:
            out += mon.on_magnetometer(m.t, m.field)
        elif topic == topics.STAR_TRACKER:
            mon.on_tracker(m.name, m.t)
            out += mon.on_star_tracker(m.t, m.name, m.q, bool(m.valid))
        elif topic == topics.ESTIMATE:
            self.omega_BN_B = np.asarray(m.omega, float)
            if self.estimator is not None:
                out += mon.on_innovations(self.estimator.take_innovations())
            out += mon.on_estimate(m.t, m.health, m.attitude_covariance, m.gyro_bias, m.bias_covariance)
        elif topic == topics.CONTROLLER_STATUS:
            out += mon.on_control(t, float(m.attitude_error), math.nan)
        if self.chain is not None:
            self.chain(topic, t, m)
