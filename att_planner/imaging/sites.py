"""Imaging sites with priorities: seeded uniform sets and CSV files.

A target list is given as a spec (``att-bench aeos --targets``):

* ``uniform:N``: N sites uniform on the sphere from a seed (``numpy.random.default_rng(seed)``):
  latitude ``asin(u)`` with ``u`` uniform in [−1, 1) (equal area), longitude uniform in
  [−180, 180) deg, priority uniform in [0, 1) (bsk-rl's uniform targets);
* a path to a CSV file (UTF-8, a header row) with the columns ``name, latitude_deg, longitude_deg,
  priority`` and optionally ``altitude_m`` and the strip's end ``end_latitude_deg,
  end_longitude_deg`` (both or neither).

Each row is validated by :class:`ImagingSite`, the ground site of the mission target lists
(:class:`att_planner.mission.schema.Site`: the name, latitude, longitude and altitude ranges written
once there) with a priority and an optional strip end. A bad file is refused with a
:class:`~att_sim.models.config_files.ConfigFileError` (``INVALID_CONFIG``) listing every problem
as ``file:line: column: expected ...; found ...``: a missing or unknown column, an empty or
non-numeric value, NaN, a latitude out of range, a name given twice, a file that is not UTF-8 or
over :data:`MAX_CSV_BYTES`, more than :data:`MAX_SITES` rows.
"""
from __future__ import annotations

import csv
import dataclasses
import io
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pydantic import ValidationError, model_validator
from pydantic.fields import FieldInfo

from att_msgs_py.errors import ConfigError, ErrorCode, clip
from att_planner.guidance.laws import geodetic_to_itrs
from att_planner.mission import ground, schema
from att_sim.models import config_files
from att_sim.models.config_base import number

MAX_SITES = 100_000            # sites of one list
MAX_CSV_BYTES = 20_000_000     # bytes of a CSV target list (100 000 rows of ~200 characters)
UNIFORM = "uniform:"

# CSV column -> ImagingSite field
COLUMNS = {"name": "name", "latitude_deg": "lat_deg", "longitude_deg": "lon_deg", "altitude_m": "alt_m",
           "priority": "priority", "end_latitude_deg": "end_lat_deg", "end_longitude_deg": "end_lon_deg"}
REQUIRED = ("name", "latitude_deg", "longitude_deg", "priority")
FIELD_COLUMN = {v: k for k, v in COLUMNS.items()}


class ImagingSite(schema.Site):
    """A ground site to image: a mission target list's site with a priority and an optional strip end
    (the strip runs from the site to the end point)."""

    dwell_s: float = FieldInfo.merge_field_infos(schema.Site.model_fields["dwell_s"], default=0.0)
    priority: float = number(1.0, ge=0.0, le=1e6, unit="", meaning="the value of an image of the site")
    end_lat_deg: float | None = FieldInfo.merge_field_infos(schema.Site.model_fields["lat_deg"], default=None)
    end_lon_deg: float | None = FieldInfo.merge_field_infos(schema.Site.model_fields["lon_deg"], default=None)

    @model_validator(mode="after")
    def _site_or_strip(self):          # in place of the mission site's: a row's dwell and scan come from the study
        if (self.end_lat_deg is None) != (self.end_lon_deg is None):
            raise ValueError("both end_latitude_deg and end_longitude_deg (a strip's end) or neither")
        return self


@dataclass(frozen=True)
class SiteSet:
    """N imaging sites as arrays (the access computation's input) with their validated rows."""

    source: str                    # the spec or file they came from
    sites: tuple[ImagingSite, ...]

    def __len__(self) -> int:
        return len(self.sites)

    @property
    def names(self) -> list[str]:
        return [s.name for s in self.sites]

    @property
    def latitude_rad(self) -> np.ndarray:
        return np.radians([s.lat_deg for s in self.sites])

    @property
    def longitude_rad(self) -> np.ndarray:
        return np.radians([s.lon_deg for s in self.sites])

    @property
    def priority(self) -> np.ndarray:
        return np.array([s.priority for s in self.sites], float)

    def r_itrs(self) -> np.ndarray:
        """Each site's ITRS position on WGS-84 (m), (N, 3)."""
        return np.array([geodetic_to_itrs(math.radians(s.lat_deg), math.radians(s.lon_deg), s.alt_m)
                         for s in self.sites]).reshape(-1, 3)

    def up_itrs(self) -> np.ndarray:
        """Each site's geodetic up (ITRS unit vector), (N, 3)."""
        return ground.geodetic_up(self.latitude_rad, self.longitude_rad).reshape(-1, 3)


def uniform(n: int, seed: int) -> SiteSet:
    """``n`` sites uniform on the sphere from ``seed`` (module docstring), named ``site0000``..."""
    if not (isinstance(n, int) and 1 <= n <= MAX_SITES):
        raise ConfigError(ErrorCode.INVALID_OPTION, f"uniform target count: expected an integer in 1..{MAX_SITES}; "
                                                   f"found {clip(repr(n), 40)}")
    rng = np.random.default_rng(seed)
    lat = np.degrees(np.arcsin(rng.uniform(-1.0, 1.0, n)))
    lon = rng.uniform(-180.0, 180.0, n)
    priority = rng.uniform(0.0, 1.0, n)
    width = len(str(n - 1))
    return SiteSet(f"{UNIFORM}{n}", tuple(
        ImagingSite(name=f"site{k:0{max(4, width)}d}", lat_deg=float(a), lon_deg=float(b), priority=float(p))
        for k, (a, b, p) in enumerate(zip(lat, lon, priority))))


def from_spec(spec: str, seed: int = 0) -> SiteSet:
    """``uniform:N`` (seeded) or a CSV file's path (:func:`read_csv`)."""
    if not isinstance(spec, str) or not spec:
        raise ConfigError(ErrorCode.INVALID_OPTION, "targets: expected 'uniform:N' or a CSV file; found nothing")
    if spec.startswith(UNIFORM):
        count = spec[len(UNIFORM):]
        if not (count.isascii() and count.isdigit()):
            raise ConfigError(ErrorCode.INVALID_OPTION, f"targets: expected 'uniform:N' with N an integer in "
                                                       f"1..{MAX_SITES}; found {clip(repr(spec), 80)}")
        return uniform(int(count), seed)
    return read_csv(Path(spec))


def _number(text: str) -> float | str:
    """A CSV cell as a float when it reads as one (the model refuses the rest, NaN included)."""
    try:
        return float(text)
    except ValueError:
        return text


def _text(path: Path) -> str:
    """The file's text: readable, at most :data:`MAX_CSV_BYTES`, UTF-8, no NUL (ConfigFileError)."""
    name = str(path)

    def refuse(line, expected, found):
        return config_files.ConfigFileError([config_files.Problem(name, line, "", expected, found)])

    try:
        size = path.stat().st_size
        if size > MAX_CSV_BYTES:
            raise refuse(None, f"a file of at most {MAX_CSV_BYTES} bytes", f"{size} bytes")
        with open(path, "rb") as fh:
            raw = fh.read(MAX_CSV_BYTES + 1)
    except OSError as exc:
        raise refuse(None, "a readable CSV file", exc.strerror or type(exc).__name__) from None
    if len(raw) > MAX_CSV_BYTES:
        raise refuse(None, f"a file of at most {MAX_CSV_BYTES} bytes", "more")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise refuse(raw[: exc.start].count(b"\n") + 1, "UTF-8 text",
                     f"the byte 0x{raw[exc.start]:02x} at offset {exc.start}") from None
    if "\x00" in text:
        raise refuse(text[: text.index("\x00")].count("\n") + 1, "text", "a NUL character")
    return text


def _header_problems(name: str, header: list[str]) -> list:
    problems = []
    unknown = [h for h in header if h not in COLUMNS]
    missing = [c for c in REQUIRED if c not in header]
    repeated = sorted({h for h in header if header.count(h) > 1})
    if unknown:
        problems.append(config_files.Problem(name, 1, clip(unknown[0], 80), f"a column of {', '.join(COLUMNS)}",
                                             f"unknown column(s) {clip(', '.join(unknown), 120)}"))
    if missing:
        problems.append(config_files.Problem(name, 1, missing[0], f"the columns {', '.join(REQUIRED)}",
                                             f"no column(s) {', '.join(missing)}"))
    if repeated:
        problems.append(config_files.Problem(name, 1, clip(repeated[0], 80), "each column once",
                                             f"column(s) {clip(', '.join(repeated), 120)} repeated"))
    return problems


def _row(name: str, line: int, header: list[str], row: list[str]) -> ImagingSite | list:
    """One row as a site, or its problems."""
    if len(row) != len(header):
        return [config_files.Problem(name, line, "", f"{len(header)} cells (the header's)", f"{len(row)} cells")]
    data = {}
    for column, cell in zip(header, row):
        cell = cell.strip()
        if cell == "" and column not in REQUIRED:
            continue
        data[COLUMNS[column]] = cell if column == "name" else _number(cell)
    try:
        return ImagingSite.model_validate(data)
    except ValidationError as exc:
        lines = {(): line, **{(k,): line for k in data}}
        return [dataclasses.replace(p, field=FIELD_COLUMN.get(p.field, p.field))
                for p in config_files.problems_of(exc, ImagingSite, data, lines, name)]


def read_csv(path: Path) -> SiteSet:
    """The sites of the CSV file ``path`` (module docstring); ConfigFileError with every problem."""
    name = str(path)
    reader = csv.reader(io.StringIO(_text(path), newline=""))
    try:
        header = next(reader, None)
    except csv.Error as exc:
        raise config_files.ConfigFileError([config_files.Problem(name, 1, "", "a CSV header row", str(exc))]) from None
    if header is None:
        raise config_files.ConfigFileError([config_files.Problem(
            name, None, "", "a CSV header row (name, latitude_deg, longitude_deg, priority)", "an empty file")])
    header = [h.strip() for h in header]
    problems = _header_problems(name, header)
    if problems:
        raise config_files.ConfigFileError(problems)
    sites, seen, rows = [], {}, 0
    try:
        for row in reader:
            line = reader.line_num
            if not any(cell.strip() for cell in row):
                continue
            rows += 1
            if rows > MAX_SITES:
                problems.append(config_files.Problem(name, line, "", f"at most {MAX_SITES} rows", "more"))
                break
            site = _row(name, line, header, row)
            if isinstance(site, list):
                problems += site
            elif site.name in seen:
                problems.append(config_files.Problem(name, line, "name", "distinct names",
                                                     f"{clip(repr(site.name), 80)}, also on line {seen[site.name]}"))
            else:
                seen[site.name] = line
                sites.append(site)
    except csv.Error as exc:
        problems.append(config_files.Problem(name, reader.line_num, "", "CSV rows", clip(str(exc), 120)))
    if problems:
        raise config_files.ConfigFileError(problems)
    if not sites:
        raise config_files.ConfigFileError([config_files.Problem(name, None, "", "at least one site row", "none")])
    return SiteSet(name, tuple(sites))
