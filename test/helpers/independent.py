"""An INDEPENDENT check of a benchmark's plans: nothing of the suite, only numpy and skyfield.

:func:`integrate` flies a plan's torque samples from rest with its own RK4 of the rigid body
(J ω̇ = T − ω × Jω, q̇ = ½ q ⊗ [ω, 0]; Euler's equations, Wie, *Space Vehicle Dynamics and Control*,
2008, §5.2), the samples held (``zoh``) or interpolated linearly (``linear``, at each RK4 stage's
time), on Python floats. :func:`margins` gives each zone's margin against the true sky: the
spacecraft from the JSON's TLE through skyfield's ``EarthSatellite`` (SGP4, TEME → GCRS), the Sun and
Moon from the ``de421.bsp`` of skyfield-data (geometric, light time ignored: ≤ 0.006° in these
cases), the Earth limb as asin(R_E/|r|) + margin about −r̂ (R_E = 6378.137 km, WGS-84); fixed cones
and inertial zones from their directions.
"""
from __future__ import annotations

from datetime import datetime
from functools import lru_cache
from importlib.resources import files

import numpy as np

R_EARTH = 6378.137e3          # m, WGS-84 equatorial radius
SUBSTEPS = 4                  # RK4 steps per knot interval


def dcm(q):
    """Body-to-inertial rotation matrices of unit quaternions q (K, 4) = (x, y, z, w)."""
    x, y, z, w = np.moveaxis(np.asarray(q, float), -1, 0)
    return np.stack([np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
                     np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
                     np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1)], -2)


def integrate(J, t, torque, q0, interpolation="zoh", substeps=SUBSTEPS, dense=False):
    """The rigid body from rest at ``q0`` under the torque samples; the states (x, y, z, w, ωx, ωy, ωz)
    at the knots ``t`` (``dense``: ``(times, states)`` after every RK4 step)."""
    J = [list(map(float, row)) for row in J]
    Ji = np.linalg.inv(np.array(J)).tolist()
    torque = [[float(v) for v in row] for row in torque]

    def f(x, u):
        qx, qy, qz, qw, wx, wy, wz = x
        h = [J[i][0] * wx + J[i][1] * wy + J[i][2] * wz for i in range(3)]
        r = (u[0] - (wy * h[2] - wz * h[1]), u[1] - (wz * h[0] - wx * h[2]), u[2] - (wx * h[1] - wy * h[0]))
        return (0.5 * (qw * wx + qy * wz - qz * wy), 0.5 * (qw * wy + qz * wx - qx * wz),
                0.5 * (qw * wz + qx * wy - qy * wx), -0.5 * (qx * wx + qy * wy + qz * wz),
                *(Ji[i][0] * r[0] + Ji[i][1] * r[1] + Ji[i][2] * r[2] for i in range(3)))

    def axpy(x, a, k):
        return [xi + a * ki for xi, ki in zip(x, k)]

    x = [float(v) for v in q0] + [0.0, 0.0, 0.0]
    knots, times, states = [list(x)], [float(t[0])], [list(x)]
    for k in range(len(t) - 1):
        h = (t[k + 1] - t[k]) / substeps
        a, b = torque[k], torque[k + 1] if interpolation == "linear" else torque[k]
        for i in range(substeps):
            u0, um, u1 = ([ai + (bi - ai) * (i + f) / substeps for ai, bi in zip(a, b)] for f in (0.0, 0.5, 1.0))
            k1 = f(x, u0)
            k2 = f(axpy(x, 0.5 * h, k1), um)
            k3 = f(axpy(x, 0.5 * h, k2), um)
            k4 = f(axpy(x, h, k3), u1)
            x = [xi + h / 6.0 * (p + 2 * q + 2 * r + s) for xi, p, q, r, s in zip(x, k1, k2, k3, k4)]
            n = sum(v * v for v in x[:4]) ** 0.5
            x[:4] = [v / n for v in x[:4]]
            times.append(t[k] + (i + 1) * h)
            states.append(list(x))
        knots.append(list(x))
    return (np.array(times), np.array(states)) if dense else np.array(knots)


def attitude_error(q, q_goal) -> float:
    """Angle (rad) between two attitudes (q and −q alike)."""
    return 2.0 * float(np.arccos(min(1.0, abs(float(np.asarray(q) @ np.asarray(q_goal))))))


@lru_cache(maxsize=1)
def _skyfield():
    """skyfield's built-in time scale and the packaged DE421, opened offline once."""
    from skyfield.api import load, load_file

    return load.timescale(builtin=True), load_file(str(files("skyfield_data") / "data" / "de421.bsp"))


def sky(payload, t):
    """(sun, moon, nadir) unit vectors from the spacecraft, (K, 3) each, and asin(R_E/|r|) (K,)."""
    from skyfield.api import EarthSatellite

    ts, eph = _skyfield()
    e = datetime.fromisoformat(payload["epoch"].replace("Z", "+00:00"))
    # UTC seconds = SI seconds: no leap second within a maneuver of these cases
    tt = ts.utc(e.year, e.month, e.day, e.hour, e.minute, e.second + e.microsecond * 1e-6 + np.asarray(t))
    r = EarthSatellite(*payload["tle"], ts=ts).at(tt).position.m.T
    earth = eph["earth"].at(tt).position.m.T

    def unit(v):
        return v / np.linalg.norm(v, axis=1, keepdims=True)
    sun = unit(eph["sun"].at(tt).position.m.T - earth - r)
    moon = unit(eph["moon"].at(tt).position.m.T - earth - r)
    return {"sun": sun, "moon": moon, "earth_limb": unit(-r)}, np.arcsin(R_EARTH / np.linalg.norm(r, axis=1))


def margins(payload, t, q):
    """Per-zone margins (rad, ≥ 0 clear) of attitudes q (K, 4) at times t (K,): the payload's
    ``cones`` (keep-out cones of its ``sensor_axis``) and ``zones`` (against the true sky)."""
    out = {}
    for c in payload.get("cones", []):
        b = dcm(q) @ np.asarray(payload["sensor_axis"], float)
        gamma = np.arccos(np.clip(b @ np.asarray(c["direction"], float) / np.linalg.norm(b, axis=1), -1.0, 1.0))
        out[c["name"]] = gamma - c["half_angle"]
    moving = [z for z in payload.get("zones", []) if z["body"] != "inertial"]
    axes, limb = sky(payload, t) if moving else ({}, None)
    for z in payload.get("zones", []):
        b = dcm(q) @ np.asarray(z["sensor_axis"], float)
        if z["body"] == "inertial":
            a, half = np.broadcast_to(np.asarray(z["direction"], float), b.shape), z["half_angle"]
        elif z["body"] == "earth_limb":
            a, half = axes["earth_limb"], limb + z["margin"]
        else:
            a, half = axes[z["body"]], z["half_angle"]
        gamma = np.arccos(np.clip(np.sum(a * b, axis=1) / np.linalg.norm(b, axis=1), -1.0, 1.0))
        out[z["name"]] = half - gamma if z["keep_in"] else gamma - half
    return out
