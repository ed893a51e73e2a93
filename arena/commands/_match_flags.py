"""The flags that describe one match (`--home`, `--away`, `--half-time`, links, ...)
and the one place that turns them into a `MatchConfig`."""

from __future__ import annotations

import argparse
import dataclasses

from arena.commands._common import seconds
from arena.config import MAX_HALF_TIME, MatchConfig, ProcessId

# The match flags' defaults where a command gives none of its own: the match's (config/__init__.py).
MATCH_DEFAULTS = {k: getattr(MatchConfig(), k) for k in ("seed", "home", "away", "robots", "half_time", "link")}


def add_match_flags(
    p: argparse.ArgumentParser,
    required: bool = False,
    seed: bool = True,
    *,
    teams: bool = True,
    config: bool = False,
    defaults: dict | None = None,
) -> None:
    """The match flags on `p`. `seed=False`: the command's --seed is its own (a tournament's);
    `teams=False`: no --home/--away (a tournament's --strategies); `config`: also --config FILE.toml;
    `defaults`: the command's own defaults of `MATCH_DEFAULTS`' keys, e.g. {"half_time": 60.0}, under
    a --config file's values and the flags (`match_config`)."""
    d = {**MATCH_DEFAULTS, **(defaults or {})}
    # Flags default to None: the command's default, or --config FILE's value, applies (match_config).
    p.set_defaults(match_defaults=defaults or {})
    if config:
        p.add_argument(
            "--config",
            dest="config_file",
            metavar="FILE.toml",
            help="the match's configuration: field, robot, rules, timing, links (arena config --print writes one); "
            "flags given here win",
        )
    if teams:
        own = defaults or {}
        home, away = (f" ({own[k]})" if k in own else "" for k in ("home", "away"))
        p.add_argument(
            "--home", required=required, metavar="STRATEGY", help=f"team a's strategy (name or BS/BD/AS/AD){home}"
        )
        p.add_argument("--away", required=required, metavar="STRATEGY", help=f"team b's strategy{away}")
    p.add_argument(
        "--robots", type=int, default=None, metavar="N", help=f"robots per team, goalkeeper included ({d['robots']})"
    )
    p.add_argument(
        "--half-time",
        type=seconds,
        default=None,
        metavar="SECONDS",
        help=f"simulated half length [s], at most {MAX_HALF_TIME:g} ({d['half_time']:g})",
    )
    if seed:
        p.add_argument("--seed", type=int, default=None, metavar="N", help=f"master seed ({d['seed']})")
    p.add_argument("--link", default=None, metavar="PRESET", help=f"ideal | lan | wifi | congested-wifi ({d['link']})")
    p.add_argument(
        "--link-param",
        action="append",
        default=[],
        metavar="CLASS.PARAM=V",
        help="override one link parameter, e.g. wifi.latency_ms=12 (repeatable)",
    )
    if teams:  # a command without --home/--away sets a strategy's parameters its own way (tournament)
        p.add_argument(
            "--param",
            action="append",
            default=[],
            metavar="TEAM.NAME=V",
            help="set one of team a's or b's strategy parameters, e.g. a.kick_speed=7.0 (repeatable; "
            "arena strategies --params NAME lists them)",
        )
    p.add_argument(
        "--perception-latency",
        type=int,
        default=None,
        metavar="TICKS",
        help="a robot at tick k sees the sense of tick k - TICKS (the model; changes digests), e.g. "
        "--perception-latency 0 for robots that see the present (default: timing.perception_latency, 3 = 60 ms)",
    )
    p.add_argument(
        "--batch",
        type=int,
        default=None,
        metavar="N",
        help="sense/cmd frames per message, 1..perception latency; 0 = as many as it allows, one in process (a "
        "transport detail: digests are the same for every N), e.g. --batch 1 for one frame per message (0)",
    )


class _AllowPickle(argparse.Action):
    """`--allow-pickle`: from the moment it is parsed, this process and every process it starts load
    pickle policy files (ARENA_ALLOW_PICKLE=1)."""

    def __call__(self, parser, namespace, values, option_string=None):
        from arena.strategies.policy_file import allow_pickle

        allow_pickle()
        setattr(namespace, self.dest, True)


def allow_pickle_flag(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--allow-pickle",
        action=_AllowPickle,
        nargs=0,
        default=False,
        help="load pickle policy files (policy:FILE.pkl): loading a pickle RUNS ANY CODE IT HOLDS, so only for "
        "files you trust; an ONNX policy file needs no flag (docs/learning.md)",
    )


def match_config(
    args: argparse.Namespace, realtime: bool = False, external=(), tap: bool = False, refbox=None, seed: bool = True
) -> MatchConfig:
    """The one place flags become a `MatchConfig`: the match flags a command has (`--home`, `--away`,
    `--robots`, `--half-time`, `--seed`, `--link`, `--link-param`, `--param`, `--perception-latency`, `--batch`,
    `--config FILE`) over the file's values, over the command's own defaults (`add_match_flags`) or the
    match's, every range checked by `MatchConfig.validate`, the strategy parameters by the strategies'
    declarations (`registry.check_params`).
    A command that plays many matches gets the one they share (`seed=False`: its --seed is not a match's)."""
    from arena.runtime.links import parse_overrides, resolve
    from arena.strategies import registry

    def given(name: str):
        return getattr(args, name, None)

    overrides = parse_overrides(given("link_param") or ())
    own = dict(given("match_defaults") or {})  # the command's own defaults, under the file's values
    if not seed:
        own.pop("seed", None)
    base = MatchConfig(**own)
    if given("config_file"):
        from arena.runtime import matchfile

        base = matchfile.load(args.config_file, under=own)
    link = given("link") if given("link") is not None else base.link
    if given("link") is None:  # the file's overrides, then the flags' on top
        merged = {cls: dict(ps) for cls, ps in base.link_overrides.items()}
        for cls, ps in overrides.items():
            merged.setdefault(cls, {}).update(ps)
        overrides = merged
    resolve(link, overrides)  # validates preset, classes and values
    params = {team: dict(values) for team, values in base.params.items()}  # the file's, then the flags'
    for text in given("param") or ():
        team, name, value = registry.parse_param(text)
        params.setdefault(team, {})[name] = value
    timing = base.timing
    if given("perception_latency") is not None:
        timing = dataclasses.replace(timing, perception_latency=args.perception_latency)
    if given("batch") is not None:
        timing = dataclasses.replace(timing, batch=args.batch)
    cfg = base.replace(
        timing=timing,
        seed=args.seed if seed and given("seed") is not None else base.seed,
        home=registry.resolve_name(given("home") or base.home),
        away=registry.resolve_name(given("away") or base.away),
        robots=given("robots") if given("robots") is not None else base.robots,
        half_time=given("half_time") if given("half_time") is not None else base.half_time,
        link=link,
        link_overrides=overrides,
        params=params,
        realtime=realtime,
        tap=tap,
        **({"refbox": refbox} if refbox is not None else {}),
        external=tuple(
            ProcessId.parse(e).short if ProcessId.parse(e).kind == "robot" else str(ProcessId.parse(e))
            for e in external
        ),
    )
    cfg.validate()
    return registry.check_params(cfg)
