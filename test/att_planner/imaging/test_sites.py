"""Imaging site lists: the seeded uniform set and a CSV file."""
from __future__ import annotations

import numpy as np
import pytest

from att_msgs_py.errors import ConfigError, ErrorCode
from att_planner.imaging import sites
from att_planner.mission import ground


def test_uniform_sites_are_seeded_and_cover_the_sphere_by_area():
    a, b, c = sites.uniform(3000, 0), sites.uniform(3000, 0), sites.uniform(3000, 1)
    assert a == b and a.names != [] and a.sites != c.sites
    assert len(set(a.names)) == 3000
    # equal area: sin(latitude) uniform in [-1, 1] (mean 0, variance 1/3), E|latitude| = π/2 − 1
    z = np.sin(a.latitude_rad)
    assert abs(z.mean()) < 0.05 and abs(z.var() - 1 / 3) < 0.03
    assert abs(np.abs(a.latitude_rad).mean() - (np.pi / 2 - 1)) < 0.02
    assert np.all((a.priority >= 0) & (a.priority < 1)) and abs(a.priority.mean() - 0.5) < 0.03
    assert np.allclose(np.linalg.norm(a.up_itrs(), axis=1), 1.0)
    assert np.allclose(a.up_itrs()[0], ground.geodetic_up(a.latitude_rad[0], a.longitude_rad[0]))


def test_a_csv_file_gives_its_sites_with_strips(tmp_path):
    path = tmp_path / "t.csv"
    path.write_text("name,latitude_deg,longitude_deg,priority,end_latitude_deg,end_longitude_deg\n"
                    "toulouse,43.6,1.44,0.8,,\n\nstrip,10,20,2,10.5,20.1\n")
    s = sites.from_spec(str(path))
    assert s.names == ["toulouse", "strip"] and s.priority.tolist() == [0.8, 2.0]
    assert s.sites[0].end_lat_deg is None and s.sites[1].end_lon_deg == 20.1 and s.sites[0].dwell_s == 0.0


@pytest.mark.parametrize("spec", ["uniform:0", "uniform:-3", "uniform:1e3", "uniform:", "uniform:100001", ""])
def test_a_bad_uniform_spec_is_refused(spec):
    with pytest.raises(ConfigError) as err:
        sites.from_spec(spec)
    assert err.value.code == ErrorCode.INVALID_OPTION and "uniform" in err.value.message or spec == ""
