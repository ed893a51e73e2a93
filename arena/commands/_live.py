"""`arena match`'s configuration from all its flags (`full_config`), with
`--live [PORT]`, `--pace X`, `--live-host`: a Foxglove viewer, and in lockstep
a paced, pausable engine."""

from __future__ import annotations

import argparse

from arena.config import ConfigError, MatchConfig


def full_config(args: argparse.Namespace) -> tuple[MatchConfig, str]:
    """The match `arena match` plays, and the absolute path of its recording ("" for none)."""
    from arena.commands._match_flags import match_config
    from arena.commands._refbox_flags import refbox_params

    missing = [f for f, v in (("--home", args.home), ("--away", args.away)) if v is None]
    if missing and not args.config_file:
        raise ConfigError(f"the following arguments are required: {', '.join(missing)} (or give them in --config FILE)")
    record = ""
    if args.record:  # match.run imports zenoh, ssl and the credentials: not for a match without a file
        from arena.match.run import record_path

        record = record_path(args.record, fresh=True)
    cfg = match_config(
        args, realtime=args.realtime, external=args.external, tap=bool(record), refbox=refbox_params(args)
    )
    cfg = live_config(cfg, args.live, args.pace, args.live_host)
    if args.match:
        from arena.schemas.keys import check_match_id

        try:
            check_match_id(args.match)
        except ValueError as exc:
            raise ConfigError(str(exc)) from None
    if args.startup_timeout is not None or cfg.external:
        import dataclasses

        timeout = args.startup_timeout if args.startup_timeout is not None else 600.0
        cfg = cfg.replace(timing=dataclasses.replace(cfg.timing, startup_timeout=timeout))
    return cfg, record


def add_live_flags(m: argparse.ArgumentParser) -> None:
    m.add_argument(
        "--live",
        nargs="?",
        type=int,
        const=8765,
        metavar="PORT",
        help="start a viewer: the Foxglove app connects to ws://127.0.0.1:PORT (8765; 0: a free port, "
        "printed); in lockstep the "
        "viewer's parameters pause, step and pace the match",
    )
    m.add_argument(
        "--pace",
        type=float,
        metavar="X",
        help="with --live in lockstep: X simulated seconds per wall second (1.0 = real time, the default "
        "with --live; 0 = as fast as it goes). It only waits: the result is the same",
    )
    m.add_argument("--live-host", default="127.0.0.1", metavar="HOST", help="with --live: the address to serve on")


def live_config(cfg: MatchConfig, live: int | None, pace: float | None, host: str = "127.0.0.1") -> MatchConfig:
    """`--live [PORT]` and `--pace X`: a viewer, and in lockstep a paced, pausable engine."""
    if live is None:
        if pace is not None:
            raise ConfigError("--pace needs --live")
        return cfg
    import dataclasses
    import socket

    if pace is not None and cfg.realtime:
        raise ConfigError("--pace applies to lockstep; --realtime already plays at the wall clock's speed")
    pace = 0.0 if cfg.realtime else (1.0 if pace is None else pace)
    if 0 <= live <= 65535:
        # A port in use would stop the viewer after every other process had started: say so now.
        # Port 0 is a free port chosen here, so the address printed is the one to connect to.
        with socket.socket() as s:
            s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            try:
                s.bind((host, live))
            except OSError as exc:
                raise ConfigError(f"--live {live}: cannot serve on {host}:{live}: {exc.strerror}") from None
            live = s.getsockname()[1]
    timing = cfg.timing
    if not cfg.realtime:
        # Everybody waits while the viewer pauses the engine: a pause is not a failure.
        timing = dataclasses.replace(timing, wait_timeout=max(timing.wait_timeout, 3600.0))
    return cfg.replace(live=live, pace=pace, timing=timing)
