"""The LEO observatory's datasheets (config/spacecraft/leo_observatory.yaml): the noise the detectors'
fault-free runs are drawn with."""
from __future__ import annotations

from pathlib import Path

import pytest

from att_sim.models import config_files
from att_sim.models.config_schema import SpacecraftFile

LEO = Path(__file__).resolve().parents[3] / "config" / "spacecraft" / "leo_observatory.yaml"


@pytest.fixture(scope="session")
def leo() -> SpacecraftFile:
    return config_files.load_file(LEO, SpacecraftFile).model
