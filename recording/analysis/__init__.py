"""The one analysis of a match's World/Referee streams, used by `arena review`
(from an MCAP recording), `arena facts` and the tournament-style round robin
(from matches played in process, experiments/facts.py), and the tests.

* `facts.py`: `measure`, the match facts (rules: ball outside, stalls,
  stuck ball; team play: shots, saves, blocks, fouls, robots stuck by the
  fence, contact and overlap between robots);
* `review.py`: `analyse`, the review of a recording (score, goals, restarts,
  possession, distances, links, timing) with the facts of the same streams;
* `geometry.py`: footprints and line crossings;
* `worldstates.py`: `score`, the accuracy of the worldstates real base
  stations sent through the RefBox bridge, against the ground truth.

Part of recording/: it may import `arena.runtime` and `arena.schemas`.
"""

from arena.recording.analysis.facts import MatchFacts, TeamFacts, measure
from arena.recording.analysis.review import NEEDED, analyse, spread

__all__ = ["NEEDED", "MatchFacts", "TeamFacts", "analyse", "measure", "spread"]
