"""Geomagnetic field: IGRF-14 to degree 13, or the tilted dipole of :mod:`att_sim.models.environment`.

IGRF-14 (IAGA Working Group V-MOD, *International Geomagnetic Reference Field, 14th generation*, 2024,
doi:10.5281/zenodo.14012302; the form of Alken et al., *Earth Planets Space* 73, 49, 2021, §2).
The potential, in geocentric spherical coordinates (r, colatitude θ, east longitude φ) of the ITRS::

    V = a Σ_{n=1}^{13} Σ_{m=0}^{n} (a/r)^{n+1} [g_n^m(y) cos mφ + h_n^m(y) sin mφ] P_n^m(cos θ),

``a = 6371.2 km``, ``B = −∇V``: ``B_r = Σ (n+1)(a/r)^{n+2} A P``, ``B_θ = −Σ (a/r)^{n+2} A dP/dθ``,
``B_φ = −(1/sin θ) Σ (a/r)^{n+2} m (h cos mφ − g sin mφ) P`` with ``A = g cos mφ + h sin mφ``.
``P_n^m`` are the Schmidt semi-normalised associated Legendre functions (Winch et al., *Geophys. J.
Int.* 160, 487, 2005), by the recursions
``P_n^n = sqrt((2n−1)/2n) sin θ P_{n−1}^{n−1}`` (``P_1^1 = sin θ``) and
``P_n^m = [(2n−1) cos θ P_{n−1}^m − sqrt((n−1)² − m²) P_{n−2}^m] / sqrt(n² − m²)``, differentiated
term by term for ``dP/dθ``. Coefficients: ppigrf's ``IGRF14.shc`` (1900..2025 every 5 years, and
2030 = 2025 + 5 × secular variation), read once; linear in time between the columns, so
2025–2030 is the IGRF-14 secular variation, and 2030–2035 extrapolates it as IAGA's ``igrf14syn``
does (reduced accuracy). Outside 1900–2035 the model is undefined: ``ValueError``. Near the
geographic poles ``sin θ`` is held at ≥ 1e-12 (a shift of the point by < 10 µm).

Earth rotation (GCRS → ITRS, ``r_ITRS = R(t) r_GCRS``): skyfield's ``framelib.itrs`` (IAU 2006
precession, IAU 2000A nutation, Greenwich apparent sidereal time from UT1 by the built-in ΔT table of
:func:`att_sim.models.epoch.timescale`; no polar motion: ≤ 0.5″ ≈ 15 m on the ground). It is tabulated as
``R(t) = R_3(ω t) M(t)``, with ``ω`` the rate of the Earth rotation angle and ``M`` (precession,
nutation, ΔT drift) linear between hourly nodes, computed a day at a time: interpolation error
< 1e-10 rad (checked by the tests).
:meth:`GeomagneticField.track` tabulates the inertial field along a trajectory (cubic spline, 10 s
nodes, error < 1e-3 nT in LEO) for the simulator's per-stage calls (~3 µs; a direct scalar
:meth:`GeomagneticField.field_inertial` costs ~0.1 ms).

The ``dipole`` model is :func:`att_sim.models.environment.dipole_field_components` (Bruni–Celani, Wertz
H-17) with ``|r|`` in place of the circular orbit's radius: identical on a circular orbit.
"""
from __future__ import annotations

import math
from datetime import UTC, datetime
from functools import lru_cache
from importlib import resources

import numpy as np

from att_sim.models import epoch as ep
from att_sim.models.environment import DEFAULT_DIPOLE, DipoleModel

IGRF_REFERENCE_RADIUS = 6371.2e3          # m, a
IGRF_MAX_DEGREE = 13
IGRF_YEAR_MIN, IGRF_YEAR_MAX = 1900.0, 2035.0
MIN_RADIUS = 3480e3                        # m, core–mantle boundary: the expansion is not valid inside
EARTH_ROTATION_RATE = 2.0 * math.pi * 1.00273781191135448 / 86400.0   # rad/s, d(ERA)/dt (IERS 2010 eq. 5.15)
FIELD_MODELS = ("igrf14", "dipole")
_JULIAN_YEAR = 365.25 * 86400.0
_NODE_STEP = 3600.0                        # s, Earth-rotation table
_CHUNK = 86400.0                           # s, one skyfield call per day of table
_TRACK_STEP = 10.0                         # s, field track nodes
_SIN_MIN = 1e-12

# (n, m) of the expansion, n = 1..13, m = 0..n, in the order of the kernel's loops (m outer, n inner)
_TERMS = [(n, m) for m in range(IGRF_MAX_DEGREE + 1) for n in range(max(m, 1), IGRF_MAX_DEGREE + 1)]


@lru_cache(maxsize=1)
def igrf14_coefficients() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(years (27,), g (27, K), h (27, K))`` in nT from ppigrf's ``IGRF14.shc``, columns in ``_TERMS``
    order (``h = 0`` for ``m = 0``). Read once."""
    text = (resources.files("ppigrf") / "IGRF14.shc").read_text()
    rows = [line.split() for line in text.splitlines() if line.strip() and not line.startswith("#")]
    years = np.array(rows[1], float)
    table = {(int(r[0]), int(r[1])): np.array(r[2:], float) for r in rows[2:]}
    zero = np.zeros_like(years)
    g = np.stack([table[(n, m)] for n, m in _TERMS], -1)
    h = np.stack([table[(n, -m)] if m else zero for n, m in _TERMS], -1)
    return years, g, h


@lru_cache(maxsize=1)
def _intervals() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per 5-year interval: start year, ``[g, h]`` at its start and their rate per year (26, 2K)."""
    years, g, h = igrf14_coefficients()
    gh = np.concatenate([g, h], -1)
    return years[:-1], gh[:-1], np.diff(gh, axis=0) / np.diff(years)[:, None]


@lru_cache(maxsize=1)
def _recursion_constants() -> list[tuple]:
    """Per term: ``(n, m, sectoral, c1, c2)``; sectoral terms use ``c1 = sqrt((2n−1)/2n)`` (1 for n = 1)."""
    out = []
    for n, m in _TERMS:
        if n == m:
            out.append((n, m, True, 1.0 if n == 1 else math.sqrt((2 * n - 1) / (2 * n)), 0.0))
        else:
            d = math.sqrt(n * n - m * m)
            out.append((n, m, False, (2 * n - 1) / d, math.sqrt(max((n - 1) ** 2 - m * m, 0)) / d))
    return out


def _check_year(decimal_year) -> None:
    y = np.asarray(decimal_year, float)
    if not (np.all(y >= IGRF_YEAR_MIN) and np.all(y <= IGRF_YEAR_MAX)):          # NaN fails too
        raise ValueError(f"decimal_year must be from {IGRF_YEAR_MIN:.0f} to {IGRF_YEAR_MAX:.0f} "
                         f"(IGRF-14 and its secular-variation extrapolation), got {decimal_year}")


def _coefficients(decimal_year):
    """``[g, h]`` at ``decimal_year`` as a list of 2K floats (scalar) or 2K arrays (array years)."""
    start, gh, rate = _intervals()
    y = np.asarray(decimal_year, float)
    i = np.clip(((y - IGRF_YEAR_MIN) // 5.0).astype(int), 0, len(start) - 1)
    c = gh[i] + (y - start[i])[..., None] * rate[i]
    return c.tolist() if c.ndim == 1 else list(np.moveaxis(c, -1, 0))


def _kernel(x, y, z, gh, sqrt, maximum):
    """IGRF field (nT) in ITRS Cartesian axes at ``(x, y, z)`` (m): floats or arrays alike.

    ``gh`` is :func:`_coefficients`; ``sqrt`` and ``maximum`` are math's or numpy's."""
    rho = sqrt(x * x + y * y)
    r = sqrt(rho * rho + z * z)
    ct, st = z / r, maximum(rho / r, _SIN_MIN)
    on_axis = rho == 0.0
    cp = (x + 1e-300 * on_axis) / maximum(rho, 1e-300)  # cos φ, sin φ (φ = 0 on the polar axis)
    sp = y / maximum(rho, 1e-300)
    ar = IGRF_REFERENCE_RADIUS / r
    radial = [ar ** (n + 2) for n in range(IGRF_MAX_DEGREE + 1)]
    k_half = len(_TERMS)
    b_r = b_t = b_p = 0.0
    cm, sm = 1.0, 0.0                                   # cos mφ, sin mφ
    pmm, dpmm = 1.0, 0.0                                # P_m^m, dP_m^m/dθ
    p1, dp1, p2, dp2 = 1.0, 0.0, 0.0, 0.0               # P_{n-1}^m, P_{n-2}^m: order 0 starts at P_0^0
    for k, (n, m, sectoral, c1, c2) in enumerate(_recursion_constants()):
        if sectoral:                                    # a new order m: P_m^m from P_{m-1}^{m-1}
            cm, sm = cm * cp - sm * sp, sm * cp + cm * sp
            pmm, dpmm = c1 * st * pmm, c1 * (ct * pmm + st * dpmm)
            p, dp = pmm, dpmm
            p1 = dp1 = 0.0                              # P_{m-1}^m = 0
        else:
            p, dp = c1 * ct * p1 - c2 * p2, c1 * (ct * dp1 - st * p1) - c2 * dp2
        p2, dp2, p1, dp1 = p1, dp1, p, dp
        g, h = gh[k], gh[k_half + k]
        a = radial[n] * (g * cm + h * sm)
        b_r = b_r + (n + 1) * a * p
        b_t = b_t - a * dp
        if m:
            b_p = b_p - radial[n] * m * (h * cm - g * sm) * p
    b_p = b_p / st
    b_h = b_r * st + b_t * ct
    return b_h * cp - b_p * sp, b_h * sp + b_p * cp, b_r * ct - b_t * st


def igrf_field_geocentric(r_ITRS, decimal_year) -> np.ndarray:
    """IGRF-14 field (T) in ITRS Cartesian axes at ``r_ITRS`` (..., 3) m, geocentric, at
    ``decimal_year`` (scalar, or an array broadcasting with ``r_ITRS[..., 0]``)."""
    _check_year(decimal_year)
    r = np.asarray(r_ITRS, float)
    if r.shape[-1:] != (3,):
        raise ValueError(f"r_ITRS must have a trailing axis of 3 (m), got shape {r.shape}")
    norm = np.linalg.norm(r, axis=-1)
    if not np.all(np.isfinite(norm)) or np.any(norm < MIN_RADIUS):
        raise ValueError(f"r_ITRS must be finite with a norm of at least {MIN_RADIUS / 1e3:.0f} km "
                         f"(the core radius), got a smallest norm of {np.min(norm) / 1e3:.1f} km")
    gh = _coefficients(decimal_year)
    if r.ndim == 1 and np.ndim(decimal_year) == 0:
        x, y, z = r.tolist()
        return 1e-9 * np.array(_kernel(x, y, z, gh, math.sqrt, max))
    return 1e-9 * np.stack(np.broadcast_arrays(*_kernel(r[..., 0], r[..., 1], r[..., 2], gh, np.sqrt,
                                                        np.maximum)), -1)


def decimal_year(dt: datetime) -> float:
    """``year + (dt − Jan 1) / (length of that year)``, UTC."""
    dt = dt.astimezone(UTC)
    start = datetime(dt.year, 1, 1, tzinfo=UTC)
    end = datetime(dt.year + 1, 1, 1, tzinfo=UTC)
    return dt.year + (dt - start).total_seconds() / (end - start).total_seconds()


def _r3(angle):
    """``R_3(angle)`` (frame rotation about z), stacked on the angle's shape."""
    c, s = np.cos(angle), np.sin(angle)
    z, o = np.zeros_like(c), np.ones_like(c)
    return np.stack([np.stack([c, s, z], -1), np.stack([-s, c, z], -1), np.stack([z, z, o], -1)], -2)



class _RotationTable:
    """GCRS → ITRS rotation ``R(t) = R_3(ω t) M(t)``, ``M`` linear between hourly skyfield nodes,
    tabulated a day at a time on demand."""

    def __init__(self, epoch: datetime):
        self.epoch = epoch
        self._days: dict[int, tuple[np.ndarray, list]] = {}   # day -> (M at 25 nodes (25, 3, 3), as lists)

    def _day(self, day: int) -> tuple[np.ndarray, list]:
        if day not in self._days:
            from skyfield.framelib import itrs

            t = day * _CHUNK + _NODE_STEP * np.arange(round(_CHUNK / _NODE_STEP) + 1)
            r = np.moveaxis(itrs.rotation_at(ep.skyfield_times(self.epoch, t)), -1, 0)
            m = np.einsum("kji,kjl->kil", _r3(EARTH_ROTATION_RATE * t), r)      # R_3(ωt)ᵀ R
            self._days[day] = (m, m.reshape(len(t), 9).tolist())
        return self._days[day]

    def matrix(self, t) -> np.ndarray:
        """``R(t)``, shape ``t.shape + (3, 3)``."""
        t = np.asarray(t, float)
        day = np.floor(t / _CHUNK).astype(int)
        m = np.empty(t.shape + (3, 3))
        for d in np.unique(day):
            sel = day == d
            nodes = self._day(int(d))[0]
            u = (t[sel] - d * _CHUNK) / _NODE_STEP
            j = np.minimum(u.astype(int), len(nodes) - 2)
            f = (u - j)[:, None, None]
            m[sel] = nodes[j] + f * (nodes[j + 1] - nodes[j])
        return _r3(EARTH_ROTATION_RATE * t) @ m

    def matrix_at(self, t: float) -> tuple:
        """``R(t)`` at one time as 9 floats, row-major (the per-stage path)."""
        day = math.floor(t / _CHUNK)
        nodes = self._day(day)[1]
        u = (t - day * _CHUNK) / _NODE_STEP
        j = min(int(u), len(nodes) - 2)
        f = u - j
        a, b = nodes[j], nodes[j + 1]
        m = [ai + f * (bi - ai) for ai, bi in zip(a, b)]
        c, s = math.cos(EARTH_ROTATION_RATE * t), math.sin(EARTH_ROTATION_RATE * t)
        return (c * m[0] + s * m[3], c * m[1] + s * m[4], c * m[2] + s * m[5],
                c * m[3] - s * m[0], c * m[4] - s * m[1], c * m[5] - s * m[2], m[6], m[7], m[8])


class GeomagneticField:
    """The field the spacecraft flies through, in GCRS axes at ``t`` seconds past ``epoch``.

    ``model``: ``"igrf14"`` (needs an epoch with a decimal year in 1900..2035) or ``"dipole"``
    (:class:`att_sim.models.environment.DipoleModel`, time from t = 0, the epoch is not used).
    """

    def __init__(self, model: str = "dipole", epoch: datetime | str | None = None,
                 dipole: DipoleModel = DEFAULT_DIPOLE):
        if model not in FIELD_MODELS:
            raise ValueError(f"field_model must be one of {', '.join(FIELD_MODELS)}, got {model!r}")
        self.model, self.dipole = model, dipole
        self.epoch = None if epoch is None else ep.parse_epoch(epoch)
        if model == "igrf14" and self.epoch is None:
            raise ValueError("field_model 'igrf14' needs an epoch (ISO 8601 UTC), got none")
        self.decimal_year0 = None if self.epoch is None else decimal_year(self.epoch)
        if model == "igrf14" and not IGRF_YEAR_MIN <= self.decimal_year0 <= IGRF_YEAR_MAX:
            raise ValueError(f"field_model 'igrf14' needs an epoch from {IGRF_YEAR_MIN:.0f} to "
                             f"{IGRF_YEAR_MAX:.0f}, got {ep.format_epoch(self.epoch)}")
        self._rotation = None if self.epoch is None else _RotationTable(self.epoch)

    def _need_epoch(self, what: str) -> None:
        if self.epoch is None:
            raise ValueError(f"{what} needs an epoch: this {self.model} field has none")

    def decimal_year(self, t):
        """Decimal year of ``epoch + t`` (s), advancing by Julian years (the secular variation's clock)."""
        self._need_epoch("decimal_year")
        return self.decimal_year0 + np.asarray(t, float) / _JULIAN_YEAR

    def itrs_rotation(self, t) -> np.ndarray:
        """``R(t)`` with ``r_ITRS = R r_GCRS`` (tabulated skyfield ITRS frame), shape ``t.shape + (3, 3)``."""
        self._need_epoch("itrs_rotation")
        return self._rotation.matrix(t)

    def field_inertial(self, t, r_GCRS) -> np.ndarray:
        """B (T) in GCRS axes at time(s) ``t`` (s past the epoch) and position(s) ``r_GCRS`` (..., 3) m."""
        r = np.asarray(r_GCRS, float)
        if self.model == "dipole":
            return self._dipole(t, r)
        if r.ndim == 1 and np.ndim(t) == 0:
            t = float(t)
            m = self._rotation.matrix_at(t)
            x, y, z = r.tolist()
            r_i = np.array([m[0] * x + m[1] * y + m[2] * z, m[3] * x + m[4] * y + m[5] * z,
                            m[6] * x + m[7] * y + m[8] * z])
            bx, by, bz = igrf_field_geocentric(r_i, self.decimal_year0 + t / _JULIAN_YEAR).tolist()
            return np.array([m[0] * bx + m[3] * by + m[6] * bz, m[1] * bx + m[4] * by + m[7] * bz,
                             m[2] * bx + m[5] * by + m[8] * bz])
        t = np.broadcast_to(np.asarray(t, float), r.shape[:-1])
        rot = self._rotation.matrix(t)
        b_i = igrf_field_geocentric(np.einsum("...ij,...j->...i", rot, r), self.decimal_year(t))
        return np.einsum("...ji,...j->...i", rot, b_i)

    def _dipole(self, t, r: np.ndarray) -> np.ndarray:
        """``(μ_m/|r|³)[3 (m̂ᵀr̂) r̂ − m̂]`` (environment's formula at the actual radius)."""
        if r.ndim == 1 and np.ndim(t) == 0:                            # one time: floats
            x, y, z = r.tolist()
            mx, my, mz = self.dipole.axis_at(float(t))
            norm = math.sqrt(x * x + y * y + z * z)
            x, y, z = x / norm, y / norm, z / norm
            k, proj3 = self.dipole.strength / norm**3, 3.0 * (mx * x + my * y + mz * z)
            return np.array([k * (proj3 * x - mx), k * (proj3 * y - my), k * (proj3 * z - mz)])
        norm = np.linalg.norm(r, axis=-1, keepdims=True)
        r_hat = r / norm
        m_hat = self.dipole.axis(t)
        k = self.dipole.strength / norm**3
        return k * (3.0 * np.sum(m_hat * r_hat, -1, keepdims=True) * r_hat - m_hat)

    def track(self, position, t0: float, t1: float, step: float = _TRACK_STEP) -> FieldTrack:
        """The field along a trajectory ``position(t) -> (..., 3)`` m GCRS, tabulated on ``[t0, t1]``."""
        if not (math.isfinite(t0) and math.isfinite(t1) and t1 > t0) or not step > 0.0:
            raise ValueError(f"track span must be finite with t1 > t0 and step > 0, got t0={t0}, t1={t1}, "
                             f"step={step}")
        t = np.linspace(t0, t1, max(math.ceil((t1 - t0) / step - 1e-9), 3) + 1)   # ≤ step apart
        return FieldTrack(t, self.field_inertial(t, position(t)))


class FieldTrack:
    """B (T, GCRS) along a trajectory: not-a-knot cubic spline through the field at equally spaced
    nodes ``t``. A scalar call costs a few µs (pure-Python Horner on the spline's pieces).
    ``scipy.interpolate`` is imported here, on the first track: it costs every node that imports this
    module, with or without a magnetic field, some 0.3 s of CPU at start."""

    def __init__(self, t: np.ndarray, b: np.ndarray):
        from scipy.interpolate import CubicSpline

        self.t0, self.t1 = float(t[0]), float(t[-1])
        self._spline = CubicSpline(t, b, axis=0)
        self._step = (self.t1 - self.t0) / (len(t) - 1)
        self._pieces = np.moveaxis(self._spline.c, 0, 1).reshape(len(t) - 1, 12).tolist()

    def _check(self, t) -> None:
        if not (np.all(np.asarray(t) >= self.t0) and np.all(np.asarray(t) <= self.t1)):   # NaN fails too
            raise ValueError(f"t must be within the field track's span [{self.t0}, {self.t1}] s, got {t}")

    def __call__(self, t) -> np.ndarray:
        if np.ndim(t):
            self._check(t)
            return self._spline(np.asarray(t, float))
        t = float(t)
        if not self.t0 <= t <= self.t1:
            self._check(t)
        i = min(int((t - self.t0) / self._step), len(self._pieces) - 1)
        d = t - (self.t0 + i * self._step)
        c = self._pieces[i]
        return np.array([((c[0] * d + c[3]) * d + c[6]) * d + c[9], ((c[1] * d + c[4]) * d + c[7]) * d + c[10],
                         ((c[2] * d + c[5]) * d + c[8]) * d + c[11]])
