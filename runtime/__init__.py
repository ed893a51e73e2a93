"""How processes talk and keep time: seeds, zenoh
sessions and transports, link emulation, deterministic lockstep, the `Node`
base class and the recorder's tap. Knows nothing of soccer rules, physics or
strategies. May import `arena.config` and `arena.schemas` only; everything above may import it."""
