"""Exponential atmosphere: Vallado, *Fundamentals of Astrodynamics and Applications*, 4th ed. (2013),
Table 8-4 (CIRA-72 below 50 km, U.S. Standard Atmosphere 1976 to 1000 km)::

    ρ(h) = ρ_0 exp(−(h − h_0) / H)      for h_0 ≤ h < next h_0,

with the base altitude ``h_0``, nominal density ``ρ_0`` and scale height ``H`` of the band holding
``h``; the last band (1000 km) continues above 1000 km. Static and mean-solar: no diurnal bulge,
no solar or geomagnetic activity (real densities in LEO vary by a factor of ~10 over a solar
cycle), and the bands join with small steps. ``altitude`` is the caller's: the suite uses
``|r| − R_E`` (spherical Earth, equatorial radius).
"""
from __future__ import annotations

import bisect
import math

import numpy as np

# Vallado (2013) Table 8-4: base altitude (km), nominal density (kg/m³), scale height (km)
VALLADO_TABLE_8_4 = np.array([
    (0.0, 1.225, 7.249), (25.0, 3.899e-2, 6.349), (30.0, 1.774e-2, 6.682), (40.0, 3.972e-3, 7.554),
    (50.0, 1.057e-3, 8.382), (60.0, 3.206e-4, 7.714), (70.0, 8.770e-5, 6.549), (80.0, 1.905e-5, 5.799),
    (90.0, 3.396e-6, 5.382), (100.0, 5.297e-7, 5.877), (110.0, 9.661e-8, 7.263), (120.0, 2.438e-8, 9.473),
    (130.0, 8.484e-9, 12.636), (140.0, 3.845e-9, 16.149), (150.0, 2.070e-9, 22.523), (180.0, 5.464e-10, 29.740),
    (200.0, 2.789e-10, 37.105), (250.0, 7.248e-11, 45.546), (300.0, 2.418e-11, 53.628),
    (350.0, 9.518e-12, 53.298), (400.0, 3.725e-12, 58.515), (450.0, 1.585e-12, 60.828),
    (500.0, 6.967e-13, 63.822), (600.0, 1.454e-13, 71.835), (700.0, 3.614e-14, 88.667),
    (800.0, 1.170e-14, 124.64), (900.0, 5.245e-15, 181.05), (1000.0, 3.019e-15, 268.00),
])
_BASE = VALLADO_TABLE_8_4[:, 0] * 1e3          # m
_RHO0 = VALLADO_TABLE_8_4[:, 1]                # kg/m³
_SCALE = VALLADO_TABLE_8_4[:, 2] * 1e3         # m
_BANDS = (_BASE.tolist(), _RHO0.tolist(), _SCALE.tolist())


def density(altitude_m) -> np.ndarray | float:
    """Mass density (kg/m³) at geometric altitude(s) ``altitude_m`` (m, ≥ 0), same shape."""
    if isinstance(altitude_m, float | int) and not isinstance(altitude_m, bool):
        h = float(altitude_m)                  # one altitude: the simulator's per-stage path
        if h >= 0.0:
            i = bisect.bisect_right(_BANDS[0], h) - 1
            return _BANDS[1][i] * math.exp(-(h - _BANDS[0][i]) / _BANDS[2][i])
    h = np.asarray(altitude_m, float)
    if not np.all(h >= 0.0):                   # NaN fails too
        raise ValueError(f"altitude must be at least 0 m (Vallado Table 8-4 starts at sea level), "
                         f"got {np.min(h) if h.size else h} m")
    i = np.searchsorted(_BASE, h, side="right") - 1
    rho = _RHO0[i] * np.exp(-(h - _BASE[i]) / _SCALE[i])
    return float(rho) if rho.ndim == 0 else rho
