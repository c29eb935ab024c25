"""``att-config``: check, describe and show the configuration files a user writes.

- ``att-config check FILE...``: every file validated against the schema of its kind (by its name —
  ``NAME.params.yaml``, ``NAME.demo.yaml`` — or folder — ``missions/``, ``targets/``, ``campaigns/``,
  ``spacecraft/``, ``scenarios/``, ``faults/`` — else by its keys; or ``--kind``), and the names it refers to (a
  scenario's spacecraft, a mission's target list, a target list's or campaign's scenario) resolved; a
  parameter file's sections checked against the nodes' parameter tables. Exit 0 when every file is
  valid; else 2, after printing every problem of every file, one per line: ``file:line: field.path:
  expected ...; found ...``.
- ``att-config schema [KIND] [--out DIR]``: the JSON Schema of a kind (without KIND: of every kind, by
  name), or ``DIR/KIND.schema.json`` files, for editors: a YAML file whose first line is
  ``# yaml-language-server: $schema=<path or URL>`` is completed and checked as it is typed (the
  shipped schemas are under ``config/schemas/``).
- ``att-config show SCENARIO``: the resolved scenario (a name as ``-p scenario:=NAME`` takes it, or a
  path), one line per value, with where the value came from across its files (the scenario, its
  spacecraft, its parameter and demo files): ``file:line`` or ``default``. A file
  whose only problems are old key names is shown under the new names (with a note to migrate it).
- ``att-config migrate FILE...``: each old key name written under its new name, in place (comments
  and layout kept); the file is then checked.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from datetime import datetime
from pathlib import Path

from pydantic import BaseModel, TypeAdapter

from att_planner.fdir import table as fault_table
from att_planner.mission import schema as mission_schema
from att_planner.mission import targets as target_lists
from att_planner.tools.node_parameters import NODE_PARAMETERS, declared
from att_sim.models import config_files as cf
from att_sim.models import config_schema as cs
from att_sim.models import scenario as scen
from att_sim.truth import campaign_schema


# kind -> (model or a function of the data choosing it, the type whose JSON Schema describes the kind)
def scenario_model(data: dict) -> type[BaseModel]:
    """A scenario file's model: a self-contained one (``/**: ros__parameters:``) or one naming its spacecraft."""
    return cs.ScenarioFile if "/**" in data or "spacecraft" not in data else cs.ScenarioSky


KINDS = {
    "scenario": (scenario_model, cs.ScenarioSky),
    "spacecraft": (cs.SpacecraftFile, cs.SpacecraftFile),
    "demo": (cs.DemoFile, cs.DemoFile),
    "mission": (mission_schema.Mission, mission_schema.Mission),
    "targets": (mission_schema.target_list_model, mission_schema.TargetList),
    "campaign": (campaign_schema.CampaignFile, campaign_schema.CampaignFile),
    "parameters": (cs.ParametersFile, cs.ParametersFile),
    "faults": (fault_table.FaultTable, fault_table.FaultTable),
}
FOLDERS = {"missions": "mission", "targets": "targets", "campaigns": "campaign", "spacecraft": "spacecraft",
           "scenarios": "scenario", "faults": "faults"}


def kind_of(path: Path, data: dict) -> str:
    """The kind of a file: by its folder, else by its keys."""
    if path.name.endswith(scen.PARAMS_SUFFIX):
        return "parameters"
    if path.name.endswith(scen.DEMO_SUFFIX):
        return "demo"
    if path.parent.name in FOLDERS:
        return FOLDERS[path.parent.name]
    if "/**" in data:
        return "scenario"
    if "campaign" in data:
        return "campaign"
    if "faults" in data:
        return "faults"
    if "kind" in data:
        return "targets"
    if "targets" in data:
        return "mission"
    if "demo" in data:
        return "demo"
    if "inertia_kg_m2" in data or "inertia" in data:
        return "spacecraft"
    return "parameters"


def _known(names: list[str]) -> str:
    return ", ".join(names) or "none"


def _reference(loaded: cf.Loaded, kind: str) -> list[cf.Problem]:
    """The names a file refers to, resolved: a problem for each that names no file."""
    model, name = loaded.model, str(loaded.path)
    refs = []
    if kind == "mission":
        refs.append((("targets",), model.targets, "targets", "target list"))
    elif kind == "targets":
        refs.append((("scenario",), model.scenario, "", "scenario"))
    elif kind == "campaign":
        refs.append((("campaign", "scenario"), model.campaign.scenario, "", "scenario"))
    elif kind == "scenario" and isinstance(model, cs.ScenarioSky):
        try:                                  # the spacecraft named and the scenario resolved across its files
            scen.read(loaded.path)
        except cf.ConfigFileError as err:
            return err.problems
        except KeyError as err:
            return [cf.Problem(name, loaded.lines.get(("spacecraft",)), "spacecraft", "the name of a spacecraft",
                               f"'{model.spacecraft}', {err.args[0]}")]
    elif kind == "parameters":
        return _parameter_problems(loaded)
    out = []
    for path, ref, folder, what in refs:
        try:
            target_lists.config_file(folder, ref, what) if folder else scen.find(ref)
        except KeyError as err:
            out.append(cf.Problem(name, loaded.lines.get(path), cf.field_path(path), f"the name of a {what}",
                                  f"'{ref}', which names none ({err.args[0].split('(')[-1].rstrip(')')})"))
    return out


def _parameter_problems(loaded: cf.Loaded) -> list[cf.Problem]:
    """Each node section of a parameter file checked against that node's parameter table
    (:meth:`att_msgs_py.parameters.ParameterTable.problems`): undeclared names, wrong types, values out
    of range. A section of no suite node is refused."""
    out, name = [], str(loaded.path)
    for node, section in loaded.data.items():
        params = section.get("ros__parameters", {}) if isinstance(section, dict) else {}
        if node not in NODE_PARAMETERS:
            out.append(cf.Problem(name, loaded.lines.get((node,)), node, f"a section of one of the nodes "
                                  f"{', '.join(NODE_PARAMETERS)}", f"the section '{node}'"))
            continue
        for key, value in params.items():            # one parameter at a time: each problem on its line
            for err in declared(node).problems({key: value}, allowed=("use_sim_time",)):
                path = (node, "ros__parameters", key)
                out.append(cf.Problem(name, loaded.lines.get(path), cf.field_path(path),
                                      f"a valid {node} parameter [{err.code.name}]", err.message))
    return out


def check_file(path: Path, kind: str | None = None) -> tuple[str | None, list[cf.Problem]]:
    """The kind of file ``path`` and every problem of it (none: valid)."""
    try:
        data, lines = cf.read_yaml(path)
        kind = kind or kind_of(path, data)
        loaded = cf.Loaded(path, cf.validate(path, KINDS[kind][0], data, lines), data, lines)
    except cf.ConfigFileError as err:
        return kind, err.problems
    return kind, _reference(loaded, kind)


def schema(kind: str | None = None) -> dict:
    """The JSON Schema of ``kind`` (None: of every kind, by name)."""
    if kind is None:
        return {k: schema(k) for k in KINDS}
    if kind == "parameters":                  # each node's section typed by that node's parameter table
        out = {"type": "object", "additionalProperties": False, "title": "parameters",
               "description": "a ROS 2 parameter file: one ros__parameters mapping per node",
               "properties": {node: {"type": "object", "additionalProperties": False, "required": ["ros__parameters"],
                                     "properties": {"ros__parameters": declared(node).json_schema()}}
                              for node in NODE_PARAMETERS}}
        out = _finite_defaults(out)
    else:
        out = _finite_defaults(TypeAdapter(KINDS[kind][1]).json_schema(by_alias=True))
    out.setdefault("title", kind)
    out["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    return out


def schema_text(kind: str) -> str:
    """The JSON Schema of ``kind`` as the text of its file (``config/schemas/KIND.schema.json``)."""
    return json.dumps(schema(kind), indent=2, allow_nan=False) + "\n"


def _finite_defaults(node):
    """A JSON Schema without the defaults JSON cannot write (``.inf``: the descriptions say "no limit")."""
    if isinstance(node, dict):
        return {k: _finite_defaults(v) for k, v in node.items()
                if not (k == "default" and isinstance(v, float) and not math.isfinite(v))}
    if isinstance(node, list):
        return [_finite_defaults(v) for v in node]
    return node


def _shown(value) -> str:
    if isinstance(value, float) and math.isinf(value):
        return ".inf" if value > 0 else "-.inf"
    if isinstance(value, datetime):
        return value.isoformat()
    if isinstance(value, BaseModel):
        return json.dumps(value.model_dump(mode="json", by_alias=True))
    return json.dumps(value, default=str)


def leaves(value, path: tuple = ()):
    """(field path, value) of every leaf of a model: sub-models and lists of mappings walked."""
    if isinstance(value, BaseModel):
        for name, info in type(value).model_fields.items():
            yield from leaves(getattr(value, name), (*path, info.alias or name))
        for key, extra in (value.__pydantic_extra__ or {}).items():
            yield from leaves(extra, (*path, key))
    elif isinstance(value, dict) and value:
        for key, item in value.items():
            yield from leaves(item, (*path, key))
    elif isinstance(value, list) and any(isinstance(x, (BaseModel, dict)) for x in value):
        for i, item in enumerate(value):
            yield from leaves(item, (*path, i))
    else:
        yield path, value


def show(loaded: cf.Loaded) -> list[str]:
    """One line per value of a loaded file: ``field.path = value  (file:line)`` or ``(default)``."""
    out = []
    for path, value in leaves(loaded.model):
        line = loaded.lines.get(path)
        out.append(f"{cf.field_path(path)} = {_shown(value)}  ({f'{loaded.path}:{line}' if line else 'default'})")
    return out


def _check(args) -> int:
    bad = 0
    for name in args.files:
        kind, problems = check_file(Path(name), args.kind)
        for p in problems:
            print(p)
        print(f"{name}: {'ok' if not problems else f'{len(problems)} problem(s)'} ({kind or 'unknown kind'})",
              file=sys.stderr)
        bad += bool(problems)
    return 2 if bad else 0


def show_files(files: scen.Files) -> list[str]:
    """One line per value of a scenario resolved across its files (:func:`att_sim.models.scenario.read`):
    ``field.path = value  (file:line)`` or ``(default)``; then each node's parameter from its file."""
    out = []
    for path, value in leaves(files.shared):
        where = files.lines.get(path)
        out.append(f"{cf.field_path(path)} = {_shown(value)}  ({f'{where[0]}:{where[1]}' if where else 'default'})")
    for source in (files.params_path, files.demo_path):
        if source is not None:
            data, lines = cf.read_yaml(source)
            for path, value in leaves(data):
                out.append(f"{cf.field_path(path)} = {_shown(value)}  ({source}:{lines.get(path)})")
    return out


def _show(args) -> int:
    try:
        path = scen.find(args.scenario)
    except KeyError as err:
        print(f"att-config: {err.args[0]}", file=sys.stderr)
        return 2
    try:
        data = cf.read_yaml(path, aliases=True)[0]
        if scenario_model(data) is cs.ScenarioFile:
            print("\n".join(show(_loaded_renamed(path))))
        else:
            print("\n".join(show_files(scen.read(path))))
    except cf.ConfigFileError as err:
        print(err.message)
        return 2
    return 0


def _loaded_renamed(path: Path) -> cf.Loaded:
    """The scenario at ``path``; a file whose only problems are old key names read under the new names
    (the file itself left as it is, a note on stderr)."""
    try:
        return cf.load_file(path, cs.ScenarioFile)
    except cf.ConfigFileError as err:
        if not all(p.rename for p in err.problems):
            raise
        print(f"att-config: {path} uses {len(err.problems)} old key name(s) (att-config migrate {path} renames "
              f"them); shown under the new names", file=sys.stderr)
        data, lines = cf.parse_yaml(cf.renamed_text(path.read_text(encoding="utf-8"), err.problems), str(path))
        return cf.Loaded(path, cf.validate(path, cs.ScenarioFile, data, lines), data, lines)


def _migrate(args) -> int:
    status = 0
    for name in args.files:
        path = Path(name)
        kind, problems = check_file(path, args.kind)
        renames = [p for p in problems if p.rename]
        if renames:
            path.write_text(cf.renamed_text(path.read_text(encoding="utf-8"), renames), encoding="utf-8")
            print(f"{name}: {len(renames)} key(s) renamed", file=sys.stderr)
        for p in check_file(path, kind)[1]:
            print(p)
            status = 2
    return status


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="att-config", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    check = sub.add_parser("check", help="validate files; exit 2 printing every problem")
    check.add_argument("files", nargs="+", metavar="FILE")
    check.add_argument("--kind", choices=sorted(KINDS), help="the kind of every file (default: from its folder "
                                                              "or keys)")
    kinds = sub.add_parser("schema", help="print the JSON Schema of a kind of file")
    kinds.add_argument("kind", nargs="?", choices=sorted(KINDS), metavar="KIND",
                       help=f"one of {', '.join(KINDS)} (default: every kind)")
    kinds.add_argument("--out", metavar="DIR", help="write KIND.schema.json (every kind without KIND) into DIR")
    shown = sub.add_parser("show", help="print a scenario resolved, with where each value came from")
    shown.add_argument("scenario", metavar="SCENARIO", help="a scenario name or a path to its file")
    migrate = sub.add_parser("migrate", help="write old key names under their new names, in place")
    migrate.add_argument("files", nargs="+", metavar="FILE")
    migrate.add_argument("--kind", choices=sorted(KINDS))
    args = parser.parse_args(argv)
    if args.command == "check":
        return _check(args)
    if args.command == "schema":
        if args.out:
            for kind in [args.kind] if args.kind else KINDS:
                path = Path(args.out) / f"{kind}.schema.json"
                path.write_text(schema_text(kind), encoding="utf-8")
                print(path)
            return 0
        print(json.dumps(schema(args.kind), indent=2, allow_nan=False))
        return 0
    if args.command == "show":
        return _show(args)
    return _migrate(args)


if __name__ == "__main__":
    sys.exit(main())
