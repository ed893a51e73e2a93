"""The laws of the game: the referee box, a pure `process(state, change)`
state machine that turns ball events into MSL RefBox commands
(referee_box.py), and where each set piece puts the ball and the robots
(setpieces.py), and the MSL RefBox's own wire, so real base stations can
join a match: the protocol (refbox_protocol.py) and the bridge's TCP server
(refbox_server.py). May import `arena.runtime` and `arena.schemas`; imported by
strategies, processes and tools."""
