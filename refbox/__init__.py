"""The MSL RefBox protocol's sockets and threads, so real base stations and a real RefBox can
join a match: the bridge's TCP server (server.py), a base station's client (client.py), and
following a real RefBox or reaching the bridge as our own base stations (follow.py).

The protocol itself (encoding, framing, validation) and following a RefBox's commands are pure
and stay in `arena.rules` (refbox_protocol.py, refbox_follow.py). May import `arena.rules`,
`arena.runtime` and `arena.schemas`; imported by processes, tools and the command line.
"""
