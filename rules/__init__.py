"""The laws of the game: the referee box, a pure `process(state, change)`
state machine that turns ball events into MSL RefBox commands
(referee_box.py), and where each set piece puts the ball and the robots
(setpieces.py, with `Restarts`, which carries the referee's commands out on
the field), and the MSL RefBox's own wire as pure functions: the protocol
(refbox_protocol.py) and following a real RefBox's commands (refbox_follow.py).
Pure: no socket, no thread, no clock; the RefBox's sockets and threads are
`arena.refbox`. May import `arena.runtime` and `arena.schemas`; imported by
strategies, refbox, processes and the packages above.

The referee's vocabulary (command and stage names as `Literal` types, the set
pieces, `other_team`) is defined once in `arena.schemas.vocabulary`, because
the wire types in schemas/ check it on decode and schemas/ imports nothing
above it; it is re-exported here for rule code.
"""

from arena.schemas.vocabulary import (
    REF_COMMANDS,
    RESTARTS,
    SET_PIECES,
    STAGES,
    RefCommandName,
    SetPieceName,
    StageName,
    other_team,
)

__all__ = [
    "REF_COMMANDS",
    "RESTARTS",
    "SET_PIECES",
    "STAGES",
    "RefCommandName",
    "SetPieceName",
    "StageName",
    "other_team",
]
