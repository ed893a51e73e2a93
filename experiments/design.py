"""The experiment file (docs/experiments.md): a base match (or a scenario, through the loader
the command line hands in: scenarios/experiment.py), factors over any configuration
field by its dotted path, a design (grid, seeded random, Latin hypercube), seeds, opponents
and responses; `load(path)` checks every key and builds every cell's `MatchConfig` before a
match is played.

Loading only parses TOML (`tomllib`) and checks values: it never runs code. Anything wrong
(an unknown key, a path no configuration has, a value of the wrong type, a non-finite number,
a file too large or not a regular file) is a `ConfigError` of one line that names the key.

A factor's path is spelled as in a match configuration file (`arena config --print`):
`home`, `half_time`, `links.preset`, `links.wifi.latency_ms`, `rules.setpiece_distance`,
`timing.perception_latency`, `params.a.<name>` (`params.*.<name>`: both teams, a parameter of the model
every strategy shares). It is set on the configuration's dictionary
(`MatchConfig.to_dict()`) before `MatchConfig.from_dict` validates it, so a field added to
`MatchConfig` is a factor without a change here; a dictionary-valued field (`link_overrides`,
`params`) takes new keys as deep as its type nests.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import os
import stat
import tomllib
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from arena.config import ConfigError, MatchConfig
from arena.runtime import matchfile

MAX_FILE_BYTES = 1 << 20  # an experiment or base file larger than 1 MiB is refused unread
MAX_LEVELS = 1000  # levels of one factor
MAX_MATCHES = 100_000  # matches of one experiment
MAX_SAMPLES = 10_000  # cells of a random or Latin hypercube design
MAX_SEEDS = 10_000
TOP_KEYS = ("name", "base", "scenario", "factors", "design", "seeds", "first_seed", "opponents", "responses", "engine")
DESIGNS = ("grid", "random", "lhs")
ENGINES = ("inprocess", "processes")
# Fields an experiment does not vary: the seeds are its own, the rest is deployment (arena match's flags).
NOT_FACTORS = ("seed", "realtime", "external", "tap", "live", "pace", "refbox", "scenario")
SWAP = {"a": "b", "b": "a"}  # a team's settings on the swapped match
MATCH_RESPONSES = ("points", "goal_diff", "win", "draw", "loss", "goals_for", "goals_against")
FACTS_RESPONSES = ("shots", "on_target", "saves", "blocks")  # the `arena facts` measures: the match is watched
COVERAGE = "coverage_r"  # coverage_r0 .. coverage_r5: metres each robot of the team covered
PASS = "pass"  # a scenario base's: 1 if the run passed, 0 if not
SCENARIO_SUFFIX = ".scenario.toml"


@dataclass(frozen=True)
class Factor:
    path: str  # as the file spells it: links.wifi.latency_ms
    levels: tuple = ()  # a list of levels, or
    uniform: tuple[float, float] | None = None  # a float range, or
    integers: tuple[int, int] | None = None  # an integer range (both ends included)

    @property
    def is_range(self) -> bool:
        return not self.levels

    @property
    def column(self) -> str:
        return self.path


@dataclass
class Experiment:
    path: str
    name: str
    base: MatchConfig
    factors: list[Factor]
    design: str
    samples: int
    design_seed: int
    seeds: list[int]
    opponents: list[str]  # empty: the base's (or the cell's) away
    responses: list[str]
    engine: str
    cells: list[dict[str, Any]] = field(default_factory=list)  # path -> value, per cell
    configs: list[MatchConfig] = field(default_factory=list)  # per cell, seed 0
    scenario: Any = None  # a scenario base (scenarios/experiment.py ScenarioBase), or None: a match

    @property
    def needs_facts(self) -> bool:
        return any(r in FACTS_RESPONSES for r in self.responses)

    def matches(self) -> list[dict]:
        """Every match: cell, opponent, seed, ends; `team` is the side the cell's own strategy plays."""
        out = []
        if self.scenario is not None:  # a scenario fixes its sides: one run per cell and seed
            for c, cfg in enumerate(self.configs):
                out += [
                    {"id": f"c{c:03d}-s{s}", "cell": c, "opponent": cfg.away, "seed": s, "team": "a"}
                    for s in self.seeds
                ]
            return out
        for c, cfg in enumerate(self.configs):
            for opp in self.opponents or [cfg.away]:
                if opp == cfg.home and self.opponents:
                    continue  # against itself: both ends are the one match
                for s in self.seeds:
                    for team in ("a", "b"):
                        out.append(
                            {
                                "id": f"c{c:03d}-{short_id(opp)}-s{s}-{team}",
                                "cell": c,
                                "opponent": opp,
                                "seed": s,
                                "team": team,
                            }
                        )
        return out

    def match_config(self, m: dict) -> MatchConfig:
        """The configuration of one match of `matches()`: the cell's, with its seed and ends. With the
        ends swapped, the team settings (`params.a`, `params.b`) swap too: they follow the strategy."""
        if self.scenario is not None:  # the scenario's draws are the seed's
            return self.scenario.match(self.cells[m["cell"]], m["seed"])
        cfg = self.configs[m["cell"]]
        mine = cfg.home
        if m["team"] == "a":
            return cfg.replace(seed=m["seed"], home=mine, away=m["opponent"])
        params = {SWAP[team]: dict(values) for team, values in cfg.params.items()}
        return cfg.replace(seed=m["seed"], home=m["opponent"], away=mine, params=params)


def short_id(name: str) -> str:
    from arena.experiments.fixtures import file_safe

    return file_safe(name)


# ------------------------------------------------------------------- reading
def read_toml(path: str, what: str) -> dict:
    """A TOML file a user hands over: a regular file of at most 1 MiB, parsed, never executed."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except OSError as exc:
        raise ConfigError(f"cannot read {what} {path}: {exc.strerror}") from None
    st = os.fstat(fd)
    if not stat.S_ISREG(st.st_mode):
        os.close(fd)
        raise ConfigError(f"{what} {path} is not a regular file")
    with os.fdopen(fd, "rb") as fh:
        if st.st_size > MAX_FILE_BYTES:
            raise ConfigError(f"{what} {path} is {st.st_size} bytes; at most {MAX_FILE_BYTES} are read")
        raw = fh.read(MAX_FILE_BYTES + 1)
    try:
        data = tomllib.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise ConfigError(f"{what} {path} is not valid TOML: {exc}") from None
    _check_finite(data, path)
    return data


def _check_finite(value: Any, where: str, key: str = "") -> None:
    if isinstance(value, float) and not math.isfinite(value):
        raise ConfigError(f"{where}: {key}: {value} is not a finite number")
    if isinstance(value, dict):
        for k, v in value.items():
            _check_finite(v, where, f"{key}.{k}" if key else str(k))
    elif isinstance(value, list):
        for v in value:
            _check_finite(v, where, key)


def load(path: str, scenarios: Callable[[str, str], Any] | None = None) -> Experiment:
    """Read, check and expand an experiment file; every cell's configuration is validated here.

    `scenarios(file, name)`: a scenario file as the base (scenarios/experiment.py `base`, which the
    command line hands in: this room does not import the scenarios above it)."""
    data = read_toml(path, "experiment file")
    for key in data:
        if key not in TOP_KEYS:
            raise ConfigError(f"{path}: unknown key {key!r} (known: {', '.join(TOP_KEYS)})")
    scenario = _scenario_base(data, path, scenarios)
    base = scenario.match({}, 0) if scenario is not None else _base(data.get("base", {}), path)
    factors = [_factor(p, spec, path) for p, spec in _table(data, "factors", path).items()]
    design = _table(data, "design", path)
    for key in design:
        if key not in ("kind", "samples", "seed"):
            raise ConfigError(f"{path}: unknown key design.{key} (known: kind, samples, seed)")
    kind = design.get("kind", "grid")
    if kind not in DESIGNS:
        raise ConfigError(f"{path}: design.kind must be one of {', '.join(DESIGNS)}, got {kind!r}")
    samples = _int(design.get("samples", 0 if kind == "grid" else 10), "design.samples", path, 0, MAX_SAMPLES)
    if kind == "grid" and "samples" in design:
        raise ConfigError(f"{path}: design.samples is for kind random or lhs; a grid plays every combination")
    if kind != "grid" and samples < 1:
        raise ConfigError(f"{path}: design.samples must be 1..{MAX_SAMPLES}")
    n_seeds = _int(data.get("seeds", 4), "seeds", path, 1, MAX_SEEDS)
    first = _int(data.get("first_seed", 0), "first_seed", path, 0, 2**62)
    engine = data.get("engine", "inprocess")
    if engine not in ENGINES:
        raise ConfigError(f"{path}: engine must be one of {', '.join(ENGINES)}, got {engine!r}")
    exp = Experiment(
        path=path,
        name=_str(data.get("name", Path(path).stem), "name", path),
        base=base,
        factors=factors,
        design=kind,
        samples=samples,
        design_seed=_int(design.get("seed", 0), "design.seed", path, 0, 2**63 - 1),
        seeds=list(range(first, first + n_seeds)),
        opponents=[_strategy(o, "opponents", path) for o in _list(data, "opponents", path)],
        responses=_responses(data, path, base.robots, scenario is not None),
        engine=engine,
        scenario=scenario,
    )
    if scenario is not None:
        _check_scenario_factors(exp, path)
    exp.cells = cells(exp)
    exp.configs = [_cell(exp, cell, f"{path}: cell {i}") for i, cell in enumerate(exp.cells)]
    _check_params(exp, path)
    total = len(exp.matches())
    if total == 0:
        raise ConfigError(f"{path}: no match to play (every opponent is the cell's own strategy)")
    if total > MAX_MATCHES:
        raise ConfigError(f"{path}: {total} matches; an experiment plays at most {MAX_MATCHES}")
    return exp


def _scenario_base(data: dict, path: str, scenarios: Callable[[str, str], Any] | None) -> Any:
    """`base = "x.scenario.toml"` (and `scenario = "name"` if the file has several): the scenario base."""
    value = data.get("base")
    if not (isinstance(value, str) and value.endswith(SCENARIO_SUFFIX)):
        if "scenario" in data:
            raise ConfigError(
                f"{path}: scenario: names a scenario of a base scenario file (base = 'x{SCENARIO_SUFFIX}')"
            )
        return None
    name = _str(data["scenario"], "scenario", path) if "scenario" in data else ""
    if scenarios is None:
        raise ConfigError(f"{path}: base: a scenario file is a base for arena experiment run")
    try:
        return scenarios(str(Path(path).parent / value), name)
    except ConfigError as exc:
        raise ConfigError(f"{path}: {exc}") from None


def _check_scenario_factors(exp: Experiment, path: str) -> None:
    if exp.opponents:
        raise ConfigError(f"{path}: opponents: a scenario fixes its sides; vary home or away as factors")
    for f in exp.factors:
        why = exp.scenario.check_factor(f.path)
        if why:
            raise ConfigError(f"{path}: factors.{f.path}: not over a scenario: {why}")


def _cell(exp: Experiment, cell: dict[str, Any], where: str) -> MatchConfig:
    """A cell's configuration at seed 0: the base's with the cell's values, or the scenario's."""
    if exp.scenario is None:
        return cell_config(exp.base, cell, where)
    try:
        return exp.scenario.match(cell, 0)
    except ConfigError as exc:
        raise ConfigError(f"{where}: {exc}") from None


def _check_params(exp: Experiment, path: str) -> None:
    """Every strategy parameter a cell sets is one its strategy declares, of its type and range (on
    each side it plays, against each opponent): said before a match is played, naming the cell."""
    from arena.strategies import registry

    seen = set()
    for m in exp.matches():
        key = (m["cell"], m["opponent"], m["team"])
        if key in seen or not exp.configs[m["cell"]].params:
            continue
        seen.add(key)
        try:
            registry.check_params(exp.match_config(m))
        except ConfigError as exc:
            raise ConfigError(f"{path}: cell {m['cell']} ({exp.cells[m['cell']]}): {exc}") from None


def _table(data: dict, key: str, path: str) -> dict:
    value = data.get(key, {})
    if not isinstance(value, dict):
        raise ConfigError(f"{path}: {key} must be a table ([{key}])")
    return value


def _list(data: dict, key: str, path: str) -> list:
    value = data.get(key, [])
    if not isinstance(value, list):
        raise ConfigError(f'{path}: {key} must be a list, e.g. {key} = ["AD", "BS"]')
    return value


def _int(value: Any, key: str, path: str, lo: int, hi: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
        raise ConfigError(f"{path}: {key} must be an integer {lo}..{hi}, got {value!r}")
    return value


def _str(value: Any, key: str, path: str) -> str:
    if not isinstance(value, str) or not value or len(value) > 200:
        raise ConfigError(f"{path}: {key} must be a non-empty string, got {value!r}")
    return value


def _strategy(value: Any, key: str, path: str) -> str:
    from arena.strategies import registry

    try:
        return registry.resolve_name(_str(value, key, path))
    except ConfigError as exc:
        raise ConfigError(f"{path}: {key}: {exc}") from None


def _responses(data: dict, path: str, robots: int, scenario: bool) -> list[str]:
    """The responses asked for; a scenario base's are its pass and team a's score (default: pass)."""
    if scenario:
        known = [PASS, *MATCH_RESPONSES]
        given = _list(data, "responses", path) or [PASS]
    else:
        known = [*MATCH_RESPONSES, *FACTS_RESPONSES, *(f"{COVERAGE}{n}" for n in range(6))]
        given = _list(data, "responses", path) or list(MATCH_RESPONSES)
    for r in given:
        if r not in known:
            what = "over a scenario base " if scenario else "" if r != PASS else "(pass is a scenario base's) "
            raise ConfigError(f"{path}: unknown response {r!r} {what}(known: {', '.join(known)})")
        if r.startswith(COVERAGE) and int(r[len(COVERAGE) :]) >= robots:
            raise ConfigError(f"{path}: response {r}: the teams have {robots} robots (0..{robots - 1})")
    return list(dict.fromkeys(given))


def _base(value: Any, path: str) -> MatchConfig:
    """`base`: an inline match configuration, or the path of a match configuration file."""
    if isinstance(value, str):
        where = str(Path(path).parent / value)
        data = read_toml(where, "base")
    elif isinstance(value, dict):
        where, data = f"{path}: base", value
    else:
        raise ConfigError(f"{path}: base must be a table of match configuration keys or a file's path")
    if "seed" in data:
        raise ConfigError(f"{where}: seed: the seeds are the experiment's (seeds, first_seed)")
    cfg = matchfile.from_data(matchfile.to_dict(data, where), where)
    return cfg.replace(home=_strategy(cfg.home, "home", where), away=_strategy(cfg.away, "away", where))


# ------------------------------------------------------------------- factors
def _factor(path_text: str, spec: Any, where: str) -> Factor:
    _resolve(path_text, tree_of(MatchConfig()), where)  # a path no configuration has fails here
    if isinstance(spec, list):
        if not 1 <= len(spec) <= MAX_LEVELS:
            raise ConfigError(f"{where}: factors.{path_text}: give 1..{MAX_LEVELS} levels")
        for v in spec:
            if not isinstance(v, str | int | float | bool):
                raise ConfigError(f"{where}: factors.{path_text}: a level is a number, a string or a boolean")
        return Factor(path_text, levels=tuple(spec))
    if isinstance(spec, dict) and len(spec) == 1:
        ((kind, ends),) = spec.items()
        ok = isinstance(ends, list) and len(ends) == 2
        if kind == "uniform" and ok and all(isinstance(e, int | float) and not isinstance(e, bool) for e in ends):
            if ends[0] < ends[1]:
                return Factor(path_text, uniform=(float(ends[0]), float(ends[1])))
        if kind == "int" and ok and all(isinstance(e, int) and not isinstance(e, bool) for e in ends):
            if ends[0] <= ends[1]:
                return Factor(path_text, integers=(ends[0], ends[1]))
    raise ConfigError(
        f"{where}: factors.{path_text}: give levels [a, b, ...], {{uniform = [low, high]}} or {{int = [low, high]}}"
    )


def _resolve(path_text: str, tree: dict, where: str) -> tuple[list[str], bool]:
    """The dictionary path of a file path, and whether its last key may be new (a dict field's)."""
    parts = path_text.split(".")
    if parts[0] == "links":
        parts = ["link"] if parts[1:] == ["preset"] else ["link_overrides", *parts[1:]]
    top = parts[0]
    fields = {f.name: f for f in dataclasses.fields(MatchConfig)}
    if top not in fields or top in NOT_FACTORS or not all(parts):
        raise ConfigError(f"{where}: factors.{path_text}: no such configuration field to vary")
    open_depth = str(fields[top].type).count("dict[")  # link_overrides, params: dict[str, dict[str, ...]]
    if open_depth:
        if len(parts) != 1 + open_depth:
            raise ConfigError(f"{where}: factors.{path_text}: give {top} and {open_depth} keys below it")
        return parts, True
    node: Any = tree
    for p in parts:
        if not isinstance(node, dict) or p not in node:
            raise ConfigError(f"{where}: factors.{path_text}: no such configuration field to vary")
        node = node[p]
    if isinstance(node, dict | list):
        raise ConfigError(f"{where}: factors.{path_text}: a table; vary one of its keys")
    return parts, False


def set_path(tree: dict, path_text: str, value: Any, where: str) -> None:
    """Set `path_text` (as the file spells it) to `value` in a `MatchConfig.to_dict()` tree, type-checked."""
    parts, is_open = _resolve(path_text, tree, where)
    if parts[0] == "params" and parts[1] == "*":  # the model's: both teams
        for team in ("a", "b"):
            set_path(tree, f"params.{team}.{parts[2]}", value, where)
        return
    node = tree
    for p in parts[:-1]:
        node = node.setdefault(p, {})
    old = node.get(parts[-1])
    name = f"{where}: {path_text} = {value!r}"
    if parts[0] in ("home", "away"):
        value = _strategy(value, path_text, where)
    elif is_open:
        if not isinstance(value, int | float | str | bool):
            raise ConfigError(f"{name}: give a number, a string or a boolean")
    elif isinstance(old, bool) != isinstance(value, bool):
        raise ConfigError(f"{name}: give {'true or false' if isinstance(old, bool) else 'a number or a string'}")
    elif isinstance(old, int) and not isinstance(old, bool) and not isinstance(value, int):
        raise ConfigError(f"{name}: give an integer")
    elif isinstance(old, float):
        if not isinstance(value, int | float):
            raise ConfigError(f"{name}: give a number")
        value = float(value)
    elif isinstance(old, str) and not isinstance(value, str):
        raise ConfigError(f"{name}: give a string")
    node[parts[-1]] = value


def tree_of(cfg: MatchConfig) -> dict:
    """Every field of `cfg` as builtins. `cfg.to_dict()` of a configuration built by `from_dict` leaves
    out the fields its input did not name (msgspec reads the instance's own attributes)."""
    import msgspec

    return msgspec.to_builtins(dataclasses.asdict(cfg))


def cell_config(base: MatchConfig, cell: dict[str, Any], where: str) -> MatchConfig:
    """The base with the cell's values set; validated as a match configuration file is."""
    tree = tree_of(base)
    for path_text, value in cell.items():
        set_path(tree, path_text, value, where)
    return matchfile.from_data(tree, where)


# -------------------------------------------------------------------- design
def cells(exp: Experiment) -> list[dict[str, Any]]:
    """The design's cells, each {path: value}; a random or Latin hypercube design from its seed."""
    import numpy as np

    if not exp.factors:
        return [{}]
    if exp.design == "grid":
        ranged = [f.path for f in exp.factors if f.is_range]
        if ranged:
            raise ConfigError(f"{exp.path}: factors {', '.join(ranged)}: a range needs design.kind random or lhs")
        combos = list(itertools.product(*(f.levels for f in exp.factors)))
        if len(combos) > MAX_MATCHES:
            raise ConfigError(f"{exp.path}: {len(combos)} cells; an experiment plays at most {MAX_MATCHES} matches")
        return [dict(zip((f.path for f in exp.factors), combo)) for combo in combos]
    rng = np.random.default_rng(exp.design_seed)
    n = exp.samples
    columns = {}
    for f in exp.factors:
        if exp.design == "lhs":  # one draw in each of n equal strata, the strata shuffled per factor
            u = (rng.permutation(n) + rng.random(n)) / n
        else:
            u = rng.random(n)
        columns[f.path] = [_at(f, float(x)) for x in u]
    return [{p: columns[p][i] for p in columns} for i in range(n)]


def _at(f: Factor, u: float) -> Any:
    """The factor's value at quantile u in [0, 1)."""
    if f.uniform is not None:
        lo, hi = f.uniform
        return float(f"{lo + u * (hi - lo):.6g}")
    if f.integers is not None:
        lo, hi = f.integers
        return min(hi, lo + int(u * (hi - lo + 1)))
    return f.levels[min(len(f.levels) - 1, int(u * len(f.levels)))]
