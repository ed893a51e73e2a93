"""Team play: the `Strategy` plugin API (base.py), the paper's four strategies
(iris.py) and the simple ones, roles, skills, the team world model, the
registry of built-ins and entry-point plugins, and the conformance suite.
May import `arena.navigation`, `arena.rules`, `arena.runtime` and
`arena.schemas`; imported by processes and the packages above."""
