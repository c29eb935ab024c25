"""An open magnetorquer coil from the momentum balance: the GLR against an independent least-squares
recomputation, the open coil isolated while the coils are commanded, nothing from a coil never
commanded, no verdict in fault-free windows drawn with the LEO pyramid's gyro and tachometer noise."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_planner.fdir.coils import CoilDetector, momentum_noise

S3 = 0.5773502691896258
S23 = 0.816496580927726
G = np.array([[S23, 0.0, -S23, 0.0], [0.0, S23, 0.0, -S23], [S3, S3, S3, S3]])   # the leo_pyramid wheels
J = np.diag([3000.0, 4500.0, 6000.0])
I_W, SIGMA_NU = 0.2, 0.01                       # kg m², rad/s
ARW, GYRO_HZ = math.radians(0.005) / 60.0, 20.0  # rad/sqrt(s), Hz
THRESHOLD = 30.0


def detector(window_s=60.0):
    return CoilDetector(J, G, I_W, momentum_noise(J, G, I_W, ARW, GYRO_HZ, SIGMA_NU), THRESHOLD, window_s, 2.0)


def fly(seed, duration_s=160.0, open_at=math.inf, coil=1, amplitude_Am2=50.0, disturbance_Nm=(2e-3, -1e-3, 3e-3)):
    """A body held still by its wheels (their momentum takes every torque), the field turning at twice
    the orbit rate, the coils commanded sinusoids of ``amplitude_Am2`` (each applied over the next gyro
    interval), coil ``coil`` open from ``open_at``; the detector and its verdicts."""
    rng = np.random.default_rng(seed)
    d, H, m_applied, out, dt = detector(), np.zeros(3), np.zeros(3), [], 1.0 / GYRO_HZ
    for k in range(int(round(duration_s / dt))):
        t = (k + 1) * dt
        B = 3e-5 * np.array([math.cos(2e-3 * t), math.sin(2e-3 * t), 0.3])
        m_actual = m_applied.copy()
        if t >= open_at:
            m_actual[coil] = 0.0
        H = H + (np.cross(m_actual, B) + np.asarray(disturbance_Nm)) * dt
        out += d.on_field(t, B)
        out += d.on_wheels(t, np.linalg.lstsq(I_W * G, H, rcond=None)[0] + rng.normal(0.0, SIGMA_NU, 4))
        out += d.on_gyro(t, rng.normal(0.0, ARW * math.sqrt(GYRO_HZ), 3))
        m_applied = amplitude_Am2 * np.array([math.sin(0.21 * t), math.sin(0.13 * t + 1.0), math.cos(0.17 * t)])
        out += d.on_dipole(t, m_applied)
    return d, out


def test_the_noise_is_the_gyro_on_the_inertia_and_the_tachometers_through_the_axes():
    sigma = momentum_noise(J, G, I_W, ARW, GYRO_HZ, SIGMA_NU)
    wheels = I_W * SIGMA_NU * np.sqrt([2 * S23**2, 2 * S23**2, 4 * S3**2])
    assert sigma == pytest.approx(np.hypot(np.diag(J) * ARW * math.sqrt(GYRO_HZ), wheels), rel=1e-12)


def test_the_glr_is_the_least_squares_fit_of_each_hypothesis():
    d, _ = fly(3, duration_s=100.0, open_at=40.0)
    glr = d.ratios()
    t = np.array([x[0] for x in d.samples])
    y = np.array([x[1] + x[2] for x in d.samples])
    C = np.array([x[3] for x in d.samples])
    y, C, tau = (y[1:] - y[0]) / d.sigma_H, (C[1:] - C[0]) / d.sigma_H, t[1:] - t[0]
    base = np.column_stack([np.ones_like(tau), tau])

    def rss(r):
        return sum(float(np.sum(np.linalg.lstsq(base, r[:, k], rcond=None)[1])) for k in range(3))

    healthy = y - C.sum(axis=1)
    step = max(int(round(2.0 * (len(tau) - 1) / (tau[-1] - tau[0]))), 1)
    for i in range(3):
        best = max(rss(healthy) - rss(healthy + np.where((np.arange(len(tau)) >= j)[:, None], C[:, i] - C[j, i], 0.0))
                   for j in range(0, len(tau) - 1, step))
        assert glr[i] == pytest.approx(best, rel=1e-6, abs=1e-6)
    assert int(np.argmax(glr)) == 1 and glr[1] > THRESHOLD


@pytest.mark.parametrize("coil", [1, 2])
def test_an_open_coil_is_isolated_while_the_coils_are_commanded(coil):
    _, verdicts = fly(10 + coil, open_at=100.0, coil=coil)
    assert [(v.component, v.index, v.detector) for v in verdicts] == [("magnetorquer", coil, "coil_torque")]
    assert 100.0 < verdicts[0].t <= 145.0 and "GLR" in verdicts[0].evidence


def test_healthy_coils_and_a_coil_never_commanded_give_no_verdict():
    d, verdicts = fly(21)
    assert verdicts == [] and np.all(d.ratios() < THRESHOLD)
    d, verdicts = fly(22, open_at=100.0, amplitude_Am2=0.0)
    assert verdicts == [] and np.all(d.ratios() == 0.0)        # never commanded: not seen at all


def test_a_noise_that_is_not_positive_is_refused():
    with pytest.raises(ValueError, match="sigma_H_Nms"):
        CoilDetector(J, G, I_W, [1e-3, 0.0, 1e-3], THRESHOLD, 60.0, 2.0)
