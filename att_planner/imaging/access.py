"""Access windows: when each imaging site sees the spacecraft high enough in its sky.

A site is *accessible* at time t when the spacecraft stands at least the instrument's minimum
elevation above the site's horizon (bsk-rl's imaging condition: the target's elevation angle seen
from the site), ``sin e ≥ sin e_min`` with ``sin e`` the one formula of
:func:`att_planner.guidance.ground_arrival.elevation_sines` (spacecraft position from the scenario's orbit,
GCRS→ITRS from its epoch's Earth rotation table, sites on WGS-84).

Computed for all sites at once:

1. a coarse grid of ``step_s`` over the horizon, the sites × times matrix of ``sin e`` in chunks of
   sites (two matrix products each);
2. each sign change of ``sin e − sin e_min`` between two samples is an edge, refined by bisection to
   ``tolerance_s``; the reported edges are the bracket ends inside the window (the site is accessible
   at both), each within ``tolerance_s`` of the true edge;
3. a pass that may peak above the threshold between samples without any sample above it (a grazing
   pass shorter than the step): each local maximum of the samples within :data:`GRAZING_MARGIN` of the
   threshold is searched for its peak (golden section over the two neighbouring steps); a peak above
   the threshold gives a window whose edges are bisected as in 2.

A window open at the horizon's start (end) starts (ends) there. A strip's access is its first
point's (the site's latitude and longitude).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from att_planner.guidance.ground_arrival import MIN_ELEVATION_DEG, elevation_sines
from att_planner.imaging.sites import SiteSet

COARSE_STEP_S = 10.0          # s between the coarse samples
TOLERANCE_S = 0.1             # s, the edges' bisection
GRAZING_MARGIN = math.radians(10.0)   # rad below the threshold a sampled peak is searched
SITE_CHUNK = 256              # sites per block of the sites × times matrix
_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


@dataclass(frozen=True)
class AccessWindows:
    """Access windows of a site set over ``[t0_s, t1_s]`` (s past the epoch), sorted by opening:
    window k is site ``site[k]`` from ``open_s[k]`` to ``close_s[k]``."""

    n_sites: int
    t0_s: float
    t1_s: float
    min_elevation_rad: float
    site: np.ndarray
    open_s: np.ndarray
    close_s: np.ndarray

    def __len__(self) -> int:
        return len(self.site)

    def per_site(self) -> np.ndarray:
        """The number of windows of each site, (N,)."""
        return np.bincount(self.site, minlength=self.n_sites)

    def accessible(self) -> np.ndarray:
        """Whether each site has at least one window, (N,)."""
        return self.per_site() > 0


class SkyGeometry:
    """The spacecraft's ITRS position over time from ``environment`` (orbit and Earth rotation) and
    the sites' positions and ups: the inputs of :func:`elevation_sines`."""

    def __init__(self, environment, sites: SiteSet):
        self.orbit, self.field = environment.orbit, environment.field
        self.sites_itrs, self.up_itrs = sites.r_itrs(), sites.up_itrs()

    def r_itrs(self, t) -> np.ndarray:
        t = np.atleast_1d(np.asarray(t, float))
        r = np.asarray(self.orbit.position(t), float).reshape(-1, 3)
        return np.einsum("kij,kj->ki", self.field.itrs_rotation(t), r)

    def grid(self, t: np.ndarray, sites: slice) -> np.ndarray:
        """``sin e`` of the sites ``sites`` at times ``t``, (n, K)."""
        return elevation_sines(self.r_itrs(t), self.sites_itrs[sites], self.up_itrs[sites])

    def pairs(self, site: np.ndarray, t: np.ndarray) -> np.ndarray:
        """``sin e`` of site ``site[k]`` at time ``t[k]``, (M,)."""
        if not len(site):
            return np.zeros(0)
        return elevation_sines(self.r_itrs(t), self.sites_itrs[site], self.up_itrs[site], pairs=True)


def _bisect(geo: SkyGeometry, site, inside, outside, threshold: float, tolerance: float):
    """Edges between ``inside`` (accessible) and ``outside`` times of each ``site``, bisected until
    the bracket is at most ``tolerance``; the inside ends."""
    inside, outside = np.array(inside, float), np.array(outside, float)
    while len(inside) and np.max(np.abs(outside - inside)) > tolerance:
        mid = 0.5 * (inside + outside)
        up = geo.pairs(site, mid) >= threshold
        inside, outside = np.where(up, mid, inside), np.where(up, outside, mid)
    return inside


def _peaks(geo: SkyGeometry, site, lo, hi, tolerance: float):
    """Golden-section search of the elevation's peak of each ``site`` within ``[lo, hi]``: (time, sin e)."""
    a, b = np.array(lo, float), np.array(hi, float)
    c, d = b - _GOLDEN * (b - a), a + _GOLDEN * (b - a)
    fc, fd = geo.pairs(site, c), geo.pairs(site, d)
    while len(a) and np.max(b - a) > tolerance:
        left = fc > fd                                   # the peak lies in [a, d]
        a, b = np.where(left, a, c), np.where(left, d, b)
        x = np.where(left, b - _GOLDEN * (b - a), a + _GOLDEN * (b - a))
        fx = geo.pairs(site, x)
        c, d, fc, fd = (np.where(left, x, d), np.where(left, c, x), np.where(left, fx, fd), np.where(left, fc, fx))
    t = 0.5 * (a + b)
    return t, geo.pairs(site, t)


def access_windows(environment, sites: SiteSet, t0_s: float, t1_s: float,
                   min_elevation_deg: float = MIN_ELEVATION_DEG, step_s: float = COARSE_STEP_S,
                   tolerance_s: float = TOLERANCE_S) -> AccessWindows:
    """Every access window of ``sites`` over ``[t0_s, t1_s]`` seen from the spacecraft of
    ``environment`` (:class:`att_sim.models.world.Environment`) (module docstring)."""
    if not (math.isfinite(t0_s) and math.isfinite(t1_s) and t1_s > t0_s):
        raise ValueError(f"a horizon t0_s < t1_s of finite times, got [{t0_s}, {t1_s}]")
    if not (0.0 < step_s and 0.0 < tolerance_s < step_s):
        raise ValueError(f"0 < tolerance_s < step_s, got tolerance_s {tolerance_s}, step_s {step_s}")
    if not 0.0 <= min_elevation_deg < 90.0:
        raise ValueError(f"min_elevation_deg in [0, 90), got {min_elevation_deg}")
    geo = SkyGeometry(environment, sites)
    threshold = math.sin(math.radians(min_elevation_deg))
    margin = math.sin(max(0.0, math.radians(min_elevation_deg) - GRAZING_MARGIN))
    n = int(math.ceil((t1_s - t0_s) / step_s))
    t = np.minimum(t0_s + step_s * np.arange(n + 1), t1_s)
    r = geo.r_itrs(t)
    opens, closes, near = [], [], []          # (site, inside time, outside time) / (site, k)
    for start in range(0, len(sites), SITE_CHUNK):
        block = slice(start, min(start + SITE_CHUNK, len(sites)))
        sines = elevation_sines(r, geo.sites_itrs[block], geo.up_itrs[block])
        up = sines >= threshold
        i, k = np.nonzero(~up[:, :-1] & up[:, 1:])               # rises between k and k + 1
        opens.append((i + start, t[k + 1], t[k]))
        i, k = np.nonzero(up[:, :-1] & ~up[:, 1:])               # sets between k and k + 1
        closes.append((i + start, t[k], t[k + 1]))
        i = np.nonzero(up[:, 0])[0]                               # open at the start
        opens.append((i + start, np.full(len(i), t[0]), np.full(len(i), t[0])))
        i = np.nonzero(up[:, -1])[0]                              # open at the end
        closes.append((i + start, np.full(len(i), t[-1]), np.full(len(i), t[-1])))
        mid = sines[:, 1:-1]
        peak = (mid >= sines[:, :-2]) & (mid > sines[:, 2:]) & (mid < threshold) & (mid >= margin)
        i, k = np.nonzero(peak)
        near.append((i + start, k + 1))
    site_o = np.concatenate([o[0] for o in opens]).astype(int)
    open_s = _bisect(geo, site_o, np.concatenate([o[1] for o in opens]), np.concatenate([o[2] for o in opens]),
                     threshold, tolerance_s)
    site_c = np.concatenate([c[0] for c in closes]).astype(int)
    close_s = _bisect(geo, site_c, np.concatenate([c[1] for c in closes]), np.concatenate([c[2] for c in closes]),
                      threshold, tolerance_s)
    # windows from sampled edges: the k-th opening of a site pairs with its k-th closing
    o_order, c_order = np.lexsort((open_s, site_o)), np.lexsort((close_s, site_c))
    if len(o_order) != len(c_order) or np.any(site_o[o_order] != site_c[c_order]):   # each site's edges alternate
        raise RuntimeError("access edges that do not pair into windows")
    site, w_open, w_close = site_o[o_order], open_s[o_order], close_s[c_order]
    # grazing passes between samples
    g_site = np.concatenate([g[0] for g in near]).astype(int)
    g_k = np.concatenate([g[1] for g in near]).astype(int)
    if len(g_site):
        t_peak, s_peak = _peaks(geo, g_site, t[g_k - 1], t[g_k + 1], tolerance_s / 4)
        hit = s_peak >= threshold
        g_site, g_k, t_peak = g_site[hit], g_k[hit], t_peak[hit]
        g_open = _bisect(geo, g_site, t_peak, t[g_k - 1], threshold, tolerance_s)
        g_close = _bisect(geo, g_site, t_peak, t[g_k + 1], threshold, tolerance_s)
        site, w_open, w_close = (np.concatenate([site, g_site]), np.concatenate([w_open, g_open]),
                                 np.concatenate([w_close, g_close]))
    order = np.lexsort((site, w_open))
    return AccessWindows(len(sites), float(t0_s), float(t1_s), math.radians(min_elevation_deg),
                         site[order], w_open[order], w_close[order])
