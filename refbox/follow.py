"""A real RefBox, followed over TCP; and our own base stations as the bridge's clients.

`Follower` (`arena match --refbox-follow HOST:PORT`, docs/refbox.md): our
referee connects to the official MSL RefBox as a base station would
(`RefboxClient`, refbox/client.py) and applies each command it receives with
the pure transition `follow` (rules/refbox_follow.py) instead of deciding.
`ViaRefbox` (`--via-refbox`): a base station's referee view from the bridge
(refbox/server.py) over TCP, and its world model sent back as worldstates.
"""

from __future__ import annotations

import json
import logging

from arena.config import RefboxTeam
from arena.refbox.client import RefboxClient
from arena.rules import refbox_protocol as rp
from arena.rules.refbox_follow import end_of_match, follow


class Follower:
    """Our referee box, driven by a real RefBox instead of its own rules: `step` has the
    signature of `RefereeBox.step`, so the referee process just calls the one it was given."""

    def __init__(self, box, log: logging.Logger, endpoint: str = "", source: str = ""):
        self.box = box  # a RefereeBox: its state, counts and summary stay the match's record
        self.params = box.rules.cfg.refbox
        host, port = rp.parse_endpoint(endpoint or self.params.follow)
        self.endpoint = f"{host}:{port}"
        self.client = RefboxClient(host, port, log, source=source, name="follow")
        self.ball = (0.0, 0.0)
        self.applied = 0
        self.ignored: dict[str, int] = {}
        self.log = log

    def step(self, tick: int, events) -> list:
        for ev in events:  # where the engine last saw the ball: the spot of the next set piece
            self.ball = (ev.x, ev.y)
        out = []
        for cmd in self.client.drain():
            st, cmds, why = follow(self.box.state, tick, cmd, self.ball, self.box.rules, self.params)
            if why:
                self.ignored[why] = self.ignored.get(why, 0) + 1
                self.log.warning("refbox: ignored %s", why)
                continue
            self.box.state = st
            self.applied += 1
            out.extend(cmds)
        end = end_of_match(self.box.state, tick, self.box.rules)
        if end is not None:
            self.box.state, cmds = end
            out.extend(cmds)
        self.box.counts.update(c.name for c in out)
        if tick >= self.box.rules.total_ticks:
            self.client.close()
        return out

    def summary(self) -> dict[str, object]:
        return {
            "endpoint": self.endpoint,
            "connected": self.client.connected.is_set(),  # ever, during the match
            "applied": self.applied,
            "ignored": dict(sorted(self.ignored.items())),
            "errors": len(self.client.errors),
        }


# ------------------------------------------------------------- --via-refbox
VIA_SOURCE = {"a": "127.0.1.1", "b": "127.0.2.1"}  # our base stations' source addresses on loopback
VIA_TEAMS = tuple(
    RefboxTeam(address=ip.rsplit(".", 1)[0] + ".*", name=f"arena {t}", side=t) for t, ip in VIA_SOURCE.items()
)


def via_endpoint(listen: str) -> tuple[str, str]:
    """(endpoint, source address) for our own base station of team `a`/`b` to reach the bridge
    on this machine; the bridge tells the two apart by source address, as the RefBox does."""
    host, port = rp.parse_endpoint(listen)
    if host in ("0.0.0.0", "") or host.startswith("127."):
        return f"tcp/127.0.0.1:{port}", "loopback"
    return f"tcp/{host}:{port}", ""


class ViaRefbox:
    """`--via-refbox`: a base station's referee view from the bridge over TCP, and its
    world model sent back as MSL worldstates (docs/refbox.md)."""

    def __init__(self, cfg, team: str, log: logging.Logger):
        from arena.rules.referee_box import RefereeBox

        endpoint, source = via_endpoint(cfg.refbox.listen)
        self.team = team
        self.dt = cfg.timing.dt
        self.follower = Follower(RefereeBox(cfg), log, endpoint, VIA_SOURCE[team] if source else "")
        self.sent = 0

    def referee(self, k: int, reports: dict):
        """The referee frame of tick k as the commands that came over TCP make it."""
        for r in reports.values():
            if r.ball.visible:
                self.follower.ball = (r.ball.x, r.ball.y)
        return self.follower.box.frame(k, self.follower.step(k, []))

    def send_worldstate(self, k: int, latest: dict) -> None:
        """The newest report of each robot as one worldstate, ageMs from its tick."""
        if not latest:
            return
        oldest = min(r.tick for r in latest.values())
        balls = [r.ball for r in latest.values() if r.ball.visible]
        seen = [(o.x, o.y) for r in latest.values() for o in r.robots if o.team != self.team]
        doc = {
            "type": "worldstate",
            "teamName": f"arena {self.team}",
            "intention": "",
            "ageMs": round((k - oldest) * self.dt * 1000.0),
            "robots": [
                {
                    "id": n,
                    "pose": [r.pose.x, r.pose.y, r.pose.theta],
                    "ballEngaged": int(r.has_ball),
                    "intention": r.role,
                }
                for n, r in sorted(latest.items())
            ],
            "balls": [{"position": [b.x, b.y, 0.0], "confidence": 1.0} for b in balls[:1]],
            "obstacles": [{"position": [x, y], "radius": 0.25, "confidence": 1.0} for x, y in seen],
        }
        if self.follower.client.send(json.dumps(doc, separators=(",", ":")).encode() + b"\0"):
            self.sent += 1

    def close(self) -> None:
        self.follower.client.close()
