"""The wire: message types (messages.py), the key table with each link's sender,
receivers and schedule (keys.py), and the contract document generated from both
(contract.py renders README.md). The bottom layer: it imports nothing of arena
but itself, and everything may import it."""
