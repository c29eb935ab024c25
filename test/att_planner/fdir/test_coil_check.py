"""The active coil check: the controller's pattern (one coil at a time, alternating signs, only over the
dwell before a check sample), its torque fed forward so that the wheels take it off the body, the
magnetometer's read-back judging the coils (an open coil declared within 30 s and isolated; a healthy
one never, with the field drifting, a slew's rotation and the datasheet's noise; a stuck magnetometer
blaming no coil), and the fault table refusing bad check parameters with the field's path."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode
from att_planner.control.coil_check import CoilCheck, feedforward
from att_planner.fdir import table
from att_planner.fdir.coils import CoilDetector, Readback
from att_planner.fdir.monitor import FaultMonitor
from att_planner.fdir.onboard import coil_check
from att_planner.tools import config_cli
from att_sim.models import scenario as scen
from att_sim.models.config_files import ConfigFileError

NT = 1e-9
K = 20.0 * NT                     # T per A m²: the leo_pyramid magnetometer's coupling
SIGMA = math.hypot(50.0, 10.0 / math.sqrt(12.0)) * NT
M_MAX, CONTROL_S, MAG_S = 50.0, 0.05, 0.5
CHECK = CoilCheck(period_s=1.0, fraction=0.5, dwell_s=0.05, magnetometer_period_s=MAG_S)
THRESHOLD, WINDOW_S, PERSISTENCE_S = 30.0, 12.0, 2.0
S3, S23 = 0.5773502691896258, 0.816496580927726
G = np.array([[S23, 0.0, -S23, 0.0], [0.0, S23, 0.0, -S23], [S3, S3, S3, S3]])


def field(t: float, rate_rad_s: float) -> np.ndarray:
    """A LEO field in body axes turning at ``rate_rad_s`` about an axis off every body axis, with a slow
    change of magnitude (the orbit)."""
    a = rate_rad_s * t
    axis = np.array([0.3, -0.5, 0.81]) / np.linalg.norm([0.3, -0.5, 0.81])
    b0 = 3e-5 * np.array([0.8, 0.2, 0.56])
    rotated = (b0 * math.cos(a) + np.cross(axis, b0) * math.sin(a) + axis * (axis @ b0) * (1 - math.cos(a)))
    return rotated * (1.0 + 0.1 * math.sin(1.1e-3 * t))


def fly(seed, duration_s=120.0, open_at=math.inf, coil=0, rate_rad_s=2.2e-3, dumping_Am2=0.0, stuck_at=math.inf,
        reset_at=math.inf):
    """The controller's 20 Hz commands with the check (and a dumping dipole on the other steps, as the
    law commands it outside the blanking), the 2 Hz magnetometer with the datasheet's bias, noise,
    quantum and coupling to the applied dipole, coil ``coil`` open from ``open_at``, the magnetometer
    stuck from ``stuck_at``, the attitude reset (the field turned by 60 deg) at ``reset_at``; the read-back and
    its verdicts."""
    rng = np.random.default_rng(seed)
    d = Readback(K, SIGMA, THRESHOLD, WINDOW_S, PERSISTENCE_S)
    bias = rng.normal(0.0, 100.0 * NT, 3)
    applied, last, out = np.zeros(3), None, []
    for k in range(int(round(duration_s / CONTROL_S)) + 1):
        t = k * CONTROL_S
        if k % int(round(MAG_S / CONTROL_S)) == 0 and k:
            b = field(t + (5e2 if t >= reset_at else 0.0), rate_rad_s) + bias + K * applied \
                + rng.normal(0.0, 50.0 * NT, 3)
            b = np.round(b / (10.0 * NT)) * 10.0 * NT
            last = b if t < stuck_at or last is None else last
            out += d.on_field(t, last)
        m = CHECK.dipole(t, CONTROL_S, M_MAX)
        if m is None:
            blank = math.floor(t / MAG_S + 1e-9 + 1) * MAG_S <= t + CONTROL_S + 1e-9
            m = np.zeros(3) if blank else dumping_Am2 * np.array([math.sin(0.01 * t), math.cos(0.013 * t), 0.5])
        out += d.on_dipole(t, m)
        applied = m.copy()
        if t >= open_at:
            applied[coil] = 0.0
    return d, out


def test_the_pattern_pulses_one_coil_before_each_check_sample_its_sign_alternating():
    pulses = [(t, CHECK.dipole(t, CONTROL_S, M_MAX)) for t in np.arange(0.0, 12.0, CONTROL_S)]
    on = [(round(t, 6), m) for t, m in pulses if m is not None]
    assert [t for t, _ in on] == pytest.approx([k - CONTROL_S for k in range(1, 13)])
    assert all(np.count_nonzero(m) == 1 and abs(m).max() == 0.5 * M_MAX for _, m in on)
    coils = [int(np.flatnonzero(m)[0]) for _, m in on]
    signs = [float(np.sign(m.sum())) for _, m in on]
    assert coils == [(k % 3) for k in range(1, 13)]
    by_coil = {i: [s for c, s in zip(coils, signs) if c == i] for i in range(3)}
    assert all(all(a == -b for a, b in zip(s, s[1:])) for s in by_coil.values())   # each coil's sign alternates


def test_the_feedforward_takes_the_magnetic_torque_off_the_body():
    m, b = np.array([0.0, -25.0, 0.0]), np.array([2.1e-5, -0.7e-5, 1.9e-5])
    for healthy in (None, np.array([True, False, True, True])):
        A = np.linalg.pinv(G) if healthy is None else np.zeros((4, 3))
        if healthy is not None:
            A[healthy] = np.linalg.pinv(G[:, healthy])
        du = feedforward(m, b, A)
        assert -G @ du + np.cross(m, b) == pytest.approx(np.zeros(3), abs=1e-15)
        if healthy is not None:
            assert du[~healthy] == pytest.approx(0.0)


@pytest.mark.parametrize("coil,open_at", [(0, 40.3), (1, 61.7), (2, 77.1)])
def test_an_open_coil_is_declared_within_30_s_and_isolated(coil, open_at):
    _, verdicts = fly(20 + coil, open_at=open_at, coil=coil, duration_s=open_at + 40.0)
    assert [(v.component, v.index, v.detector) for v in verdicts] == [("magnetorquer", coil, "coil_torque")]
    assert open_at < verdicts[0].t <= open_at + 30.0
    assert verdicts[0].t - open_at <= 3.0 * CHECK.period_s + PERSISTENCE_S + 2.0   # its next visit, the next coil's
    assert "does not read back" in verdicts[0].evidence


@pytest.mark.parametrize("seed", range(12))
def test_healthy_coils_under_the_pattern_are_never_declared(seed):
    rate = (2.2e-3, 8.7e-3, -1.2e-2)[seed % 3]      # a hold, a 0.5 deg/s slew, a 0.7 deg/s one
    d, verdicts = fly(100 + seed, duration_s=300.0, rate_rad_s=rate, dumping_Am2=20.0 * (seed % 2))
    assert verdicts == []
    glr, _, _ = d.statistics()
    assert glr.max() < THRESHOLD / 3


@pytest.mark.parametrize("reset_at", [30.2, 31.7, 33.4])
def test_a_reset_of_the_attitude_starts_the_window_again(reset_at):
    d, _ = fly(8, reset_at=reset_at, duration_s=reset_at + 6.0)
    assert d.samples[0][0] >= reset_at
    assert fly(8, reset_at=reset_at, duration_s=60.0)[1] == []


def test_a_stuck_magnetometer_blames_no_coil():
    _, verdicts = fly(7, stuck_at=30.0, duration_s=120.0)
    assert verdicts == []


def test_a_coil_never_checked_is_not_seen():
    d = Readback(K, SIGMA, THRESHOLD, WINDOW_S, PERSISTENCE_S)
    out = []
    for k in range(1, 200):
        out += d.on_field(0.5 * k, field(0.5 * k, 2e-3))
        out += d.on_dipole(0.5 * k, np.zeros(3))
    assert out == [] and d.statistics()[0].tolist() == [0.0, 0.0, 0.0]


def test_the_shipped_table_checks_the_coils_of_the_fault_scenario():
    s = scen.load("leo_pyramid")
    check = coil_check(table.read(), s.sensors)
    assert check == CoilCheck(1.0, 0.5, 0.05, 0.5)
    monitor = FaultMonitor(table.read(), s.spacecraft, s.sensors)
    (fault_id, detector), = monitor.detectors["coils"]
    assert fault_id == "coil_open" and isinstance(detector, CoilDetector) and detector.readback is not None
    assert detector.readback.k == pytest.approx(K)


CHECK_BASE = """\
faults:
  coil_open:
    detector: coil_torque
    threshold: 30.0
    window_s: 60.0
    persistence_s: 2.0
    response: report
    check:
      period_s: 1.0
      dipole_fraction: 0.5
      dwell_s: 0.05
      window_s: 12.0
"""

# name: (text replaced, its replacement, line, field path, words of what was expected or found)
CHECK_EDITS = {
    "fraction above the limit": ("dipole_fraction: 0.5", "dipole_fraction: 1.5", 10,
                                 "faults.coil_open.check.dipole_fraction", "less than or equal to 1"),
    "fraction zero": ("dipole_fraction: 0.5", "dipole_fraction: 0", 10, "faults.coil_open.check.dipole_fraction",
                      "greater than 0"),
    "period negative": ("period_s: 1.0", "period_s: -1.0", 9, "faults.coil_open.check.period_s", "greater than 0"),
    "dwell the whole period": ("dwell_s: 0.05", "dwell_s: 1.0", 8, "faults.coil_open.check", "dwell_s below period_s"),
    "window too short": ("window_s: 12.0", "window_s: 4.0", 8, "faults.coil_open.check",
                         "window_s at least 6 period_s"),
    "unknown key": ("dwell_s: 0.05", "dwell_s: 0.05\n      duty: 0.5", 12, "faults.coil_open.check.duty",
                    "unknown key(s) duty"),
}


@pytest.mark.parametrize("name", sorted(CHECK_EDITS))
def test_the_table_refuses_bad_check_parameters_naming_the_field(name, tmp_path):
    old, new, line, where, words = CHECK_EDITS[name]
    path = tmp_path / "faults" / "check.yaml"
    path.parent.mkdir()
    path.write_text(CHECK_BASE.replace(old, new, 1))
    kind, problems = config_cli.check_file(path)
    mine = [p for p in problems if p.field == where]
    assert kind == "faults" and mine, f"{name}: " + "\n".join(map(str, problems))
    assert mine[0].line == line and words in mine[0].expected + " " + mine[0].found, str(mine[0])
    with pytest.raises(ConfigFileError) as err:
        table.read(path)
    assert err.value.code == ErrorCode.INVALID_CONFIG and str(path) in str(err.value)


def test_the_check_base_passes(tmp_path):
    path = tmp_path / "check.yaml"
    path.write_text(CHECK_BASE)
    assert config_cli.check_file(path, "faults") == ("faults", [])
    assert table.read(path).faults["coil_open"].check.window_s == 12.0



def test_the_momentum_does_not_fit_the_checks_pulses(monkeypatch):
    """The check's 0.05 s pulses span a few thousandths of the momentum's noise: the balance, whose noise
    is the LEO pyramid's, does not fit them (fitted, their tiny regressors explain part of any residual
    the balance does not model: the false alarms of the dispersed swift_demo runs before this rule)."""
    from att_planner.fdir.coils import momentum_noise

    J, I_W = np.diag([3000.0, 4500.0, 6000.0]), 0.2
    sigma = momentum_noise(J, G, I_W, math.radians(0.005) / 60.0, 20.0, 0.01)
    d = CoilDetector(J, G, I_W, sigma, THRESHOLD, 60.0, PERSISTENCE_S)

    def fitted(*_):
        raise AssertionError("the pulses were fitted")

    monkeypatch.setattr(d, "ratios", fitted)
    rng = np.random.default_rng(5)
    out = []
    for k in range(1, int(90.0 / CONTROL_S)):
        t = k * CONTROL_S
        out += d.on_field(t, field(t, 2.2e-3))
        out += d.on_wheels(t, rng.normal(0.0, 0.01, 4))
        out += d.on_gyro(t, rng.normal(0.0, math.radians(0.005) / 60.0 * math.sqrt(20.0), 3))
        m = CHECK.dipole(t, CONTROL_S, M_MAX)
        out += d.on_dipole(t, np.zeros(3) if m is None else m)
    assert out == [] and d.samples[-1][0] - d.samples[0][0] > 59.0
