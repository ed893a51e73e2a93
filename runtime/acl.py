"""Access control of a secure match, generated from the key table.

`schemas.keys.routes()` says, for every concrete key, who sends it and who
receives it. From that alone, each principal (one per process, plus the
read-only `viewer`) gets a zenoh `access_control` policy, matched on its
`transport/auth/usrpwd` user name, default permission deny:

* `put` (ingress) only on the keys it sends, its own `summary/<p>` and `tap/<p>`; `declare_subscriber`
  (ingress) only on the keys it receives and its own `ack/<p>` (the recorder: `tap/**`, `summary/**`);
* `put` (egress) only on the keys it may read, so the router never forwards
  a frame to a principal that may not read it; subscriber declarations
  (egress) on the whole match, so a sender learns of every matching
  subscriber, wildcards included (who listens is no secret);
* its own liveliness token `alive/<p>`, and reading `alive/**` and the
  collector's token (the start barrier and dead-peer detection);
* querying the engine's `config` queryable (the engine: serving it), and the
  router for its identity (`claim/<p>`, with its token `claim/<p>/*`);
* the robots' `report`s and the base stations' `order`s are also served
  (`SERVED`): their senders answer the viewer's queries with the last frame;
* the viewer: reading `world`, `referee`, `field`, `engine/events` and the
  teams' `report`s and `order`s (the live viewer draws what each robot and
  base station believes), and the live viewer's `control` (pause, step,
  pace) to the engine;
* the `operator`: putting `operator` frames (teleports, referee overrides),
  which only the engine and the referee may read, and nobody else may put.

The router (hosted by `arena match` / `arena run router`) enforces it for every process,
since in a secure match every process is a client of it (runtime/credentials.py says why).
"""

from __future__ import annotations

from arena.schemas.keys import (
    ACK,
    ALIVE,
    CLAIM,
    COLLECTOR,
    CONFIG,
    CONTROL,
    KEY_BY_NAME,
    OPERATOR,
    OPERATOR_PRINCIPAL,
    REFUSED,
    SERVED,
    SPOOFING,
    SUMMARY,
    TAP,
    VIEWER,
    WAITING,
    routes,
)

# The summary collector of a standalone router's match (`arena up`): not a process of the match.
COLLECTOR_PRINCIPAL = "collector"


def user_of(principal: str) -> str:
    """The zenoh user name (and credentials file stem) of a principal: `robot/b/1` -> `robot-b-1`."""
    return principal.replace("/", "-")


def permissions(principal: str, prefix: str, robots: int) -> dict[str, list[str]]:
    """Key expressions per (message, flow) for one principal; `prefix` is `arena/<match>/`."""
    table = routes(robots)
    sends = [prefix + rel for rel, sender, _ in table if sender == principal]
    receives = [prefix + rel for rel, _, receivers in table if principal in receivers]
    own_out = [f"{prefix}{x}/{principal}" for x in (SUMMARY, TAP, REFUSED)]
    own_in = [f"{prefix}{ACK}/{principal}"]
    if principal == "recorder":
        own_in += [f"{prefix}{TAP}/**", f"{prefix}{SUMMARY}/**"]
    writes = sends + own_out
    # The referee's state is public (a RefBox broadcasts it to every team): any principal may
    # read it; a process started by hand (`arena run`) prints the final score from it.
    reads = list(dict.fromkeys([*receives, *own_in, prefix + KEY_BY_NAME["referee"].rel()]))
    barrier = [f"{prefix}{ALIVE}/**", f"{prefix}{COLLECTOR}", f"{prefix}{WAITING}/**"]
    config = [f"{prefix}{CONFIG}", prefix + KEY_BY_NAME["field"].rel()]  # both served by the engine
    perms = {
        "put/ingress": writes,
        # Who subscribes is no secret (the key table is public), and a sender
        # must learn of wildcard subscribers (the recorder's `tap/**`) too.
        "declare_subscriber/egress": [f"{prefix}**"],
        "declare_subscriber/ingress": reads,
        "put/egress": reads,
        "liveliness_token/ingress": [
            f"{prefix}{ALIVE}/{principal}",
            f"{prefix}{WAITING}/{principal}/*",
            f"{prefix}{SPOOFING}/{user_of(principal)}/**",
        ],
        "liveliness_token/egress": barrier,
        "declare_liveliness_subscriber/ingress": barrier,
        "liveliness_query/ingress": barrier,
        "query/ingress": config,
        "reply/egress": config,
        "declare_queryable/egress": config,
    }
    control = [f"{prefix}{CONTROL}"]  # the live viewer's pause/step/pace, to the engine
    # The keys of SERVED: their sender answers the viewer's queries with its last frame.
    served = [prefix + rel for rel, sender, _ in table if sender == principal and _served(rel)]
    if served:
        perms["declare_queryable/ingress"] = served
        perms["reply/ingress"] = served
        perms["query/egress"] = served
    if principal == "engine":
        perms.update({"declare_queryable/ingress": config, "reply/ingress": config, "query/egress": config})
        perms["declare_subscriber/ingress"] = [*reads, *control]
        perms["put/egress"] = [*reads, *control]
        perms["query/ingress"] = [*config, *control]
        perms["reply/egress"] = [*config, *control]
    operator = [f"{prefix}{OPERATOR}"]  # a live session's teleports and overrides: the operator's alone
    if principal in ("engine", "referee"):
        perms["declare_subscriber/ingress"] = [*perms["declare_subscriber/ingress"], *operator]
        perms["put/egress"] = [*perms["put/egress"], *operator]
    if principal == OPERATOR_PRINCIPAL:  # puts its frames and reads the score; not a process: no alive token
        perms["put/ingress"] = operator
        perms["liveliness_token/ingress"] = []
    if principal == COLLECTOR_PRINCIPAL:
        perms["declare_subscriber/ingress"] = perms["put/egress"] = [f"{prefix}{SUMMARY}/**", *reads]
        perms["put/ingress"] = [f"{prefix}{ACK}/**"]
        perms["liveliness_token/ingress"] = [f"{prefix}{COLLECTOR}"]
    if principal == VIEWER:
        perms["put/ingress"] = [*writes, *control]
        perms.update({"declare_queryable/ingress": control, "reply/ingress": control, "query/egress": control})
        asked = [prefix + rel for rel, _, receivers in table if VIEWER in receivers and _served(rel)]
        perms["query/ingress"] = [*config, *asked]
        perms["reply/egress"] = [*config, *asked]
        perms["declare_queryable/egress"] = [*config, *asked]
    claim = f"{prefix}{CLAIM}/{principal}"  # its identity, asked of the router (match/claims.py)
    for what, key in (("liveliness_token/ingress", f"{claim}/*"), ("query/ingress", claim), ("reply/egress", claim)):
        perms[what] = [*perms[what], key]
    return {k: v for k, v in perms.items() if v}


def _served(rel: str) -> bool:
    """Is the key `rel` (relative to arena/<m>/) one of `SERVED`'s?"""
    return any(rel.startswith(KEY_BY_NAME[name].pattern.split("<")[0]) for name in SERVED)


def principals(processes: list[str]) -> list[str]:
    """The principals of a match: its processes (`MatchConfig.processes()`), the viewer and the operator."""
    return [*processes, *(p for p in (VIEWER, OPERATOR_PRINCIPAL) if p not in processes)]


def access_control(prefix: str, robots: int, processes: list[str]) -> dict:
    """The router's `access_control` section (zenoh 1.x format), default deny."""
    rules: list[dict] = []
    subjects: list[dict] = []
    policies: list[dict] = []
    for p in principals(processes):
        user = user_of(p)
        ids = []
        for what, key_exprs in permissions(p, prefix, robots).items():
            message, flow = what.split("/")
            rid = f"{user}:{message}:{flow}"
            rules.append(
                {"id": rid, "messages": [message], "flows": [flow], "permission": "allow", "key_exprs": key_exprs}
            )
            ids.append(rid)
        subjects.append({"id": user, "usernames": [user]})
        policies.append({"id": f"{user}:policy", "rules": ids, "subjects": [user]})
    return {
        "enabled": True,
        "default_permission": "deny",
        "rules": rules,
        "subjects": subjects,
        "policies": policies,
    }
