"""The scenario library shipped with the project (docs/scenarios.md, "The library").

`rules/`: one scenario per rule row of docs/rules.md (but 20, see
docs/scenarios.md), each asserting the referee's decision and the ball's spot. `behaviour/`: the paper's strategies at
work, each with the pass rate measured over seeds and the `min_pass` set from it.
"""

from pathlib import Path

LIBRARY = Path(__file__).resolve().parent
RULES = LIBRARY / "rules"
BEHAVIOUR = LIBRARY / "behaviour"
