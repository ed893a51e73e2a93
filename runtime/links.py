"""Link emulation: latency, jitter and Gilbert-Elliott bursty loss, seeded per link.

Every inbound link of a process gets a `LinkEmulator` with its own RNG
(derived from the master seed and the link's name). For each frame, in the
order the sender sent them, it decides: drop, or deliver after a delay.

Delay model: ``latency_ms + Exp(mean=jitter_ms)``, a shifted exponential, the
usual right-skewed shape of Wi-Fi latency (most frames near the base, a tail of
late ones).

Loss model: Gilbert-Elliott, a two-state Markov chain stepped once per frame.
In state Good a frame is lost with `loss_good`, in Bad with `loss_bad`;
`p_gb` is P(Good -> Bad) and `p_bg` is P(Bad -> Good) per frame. The
stationary loss rate is ``pi_G * loss_good + pi_B * loss_bad`` with
``pi_B = p_gb / (p_gb + p_bg)``; the mean burst (Bad sojourn) is 1/p_bg frames.

In lockstep mode a delay is rounded *up* to the receiver's next tick, and every
link has at least its lockstep lag (see runtime/lockstep.py): a 3 ms Wi-Fi delay
therefore arrives one 20 ms tick later.

Link classes: `sensor` (engine <-> robot: sensors and actuators), `wifi`
(robot <-> base station), `wired` (referee, engine events, field spec).
"""

from __future__ import annotations

import dataclasses
import random
from dataclasses import dataclass

from arena.config import ConfigError

LINK_CLASSES = ("sensor", "wifi", "wired")


@dataclass(frozen=True)
class LinkModel:
    latency_ms: float = 0.0  # [ms] base one-way latency
    jitter_ms: float = 0.0  # [ms] mean of the exponential extra delay
    p_gb: float = 0.0  # [1/frame] Gilbert-Elliott P(Good -> Bad)
    p_bg: float = 1.0  # [1/frame] Gilbert-Elliott P(Bad -> Good)
    loss_good: float = 0.0  # [-] loss probability in Good
    loss_bad: float = 0.0  # [-] loss probability in Bad

    def stationary_loss(self) -> float:
        total = self.p_gb + self.p_bg
        pi_bad = self.p_gb / total if total > 0 else 0.0
        return (1.0 - pi_bad) * self.loss_good + pi_bad * self.loss_bad

    def mean_delay_ms(self) -> float:
        return self.latency_ms + self.jitter_ms

    def is_ideal(self) -> bool:
        return self.latency_ms == 0 and self.jitter_ms == 0 and self.stationary_loss() == 0

    def validate(self, where: str) -> None:
        for name in ("p_gb", "p_bg", "loss_good", "loss_bad"):
            v = getattr(self, name)
            if not 0.0 <= v <= 1.0:
                raise ConfigError(f"link {where}: {name} must be in [0, 1], got {v}")
        for name in ("latency_ms", "jitter_ms"):
            v = getattr(self, name)
            if not 0.0 <= v <= 10_000.0:
                raise ConfigError(f"link {where}: {name} must be in [0, 10000] ms, got {v}")


IDEAL = LinkModel()
_WIRED = LinkModel(latency_ms=0.3, jitter_ms=0.1)

# preset -> link class -> model. Engine <-> robot stands for the robot's own
# sensors and actuators, ideal in every preset; override it to study them.
PRESETS: dict[str, dict[str, LinkModel]] = {
    "ideal": {"sensor": IDEAL, "wifi": IDEAL, "wired": IDEAL},
    "lan": {
        "sensor": IDEAL,
        "wifi": LinkModel(latency_ms=0.5, jitter_ms=0.2, p_gb=0.0005, p_bg=0.5, loss_good=0.0, loss_bad=0.5),
        "wired": _WIRED,
    },
    # A good venue Wi-Fi: a few ms, a tail, ~1 % bursty loss.
    "wifi": {
        "sensor": IDEAL,
        "wifi": LinkModel(latency_ms=3.0, jitter_ms=4.0, p_gb=0.01, p_bg=0.25, loss_good=0.002, loss_bad=0.25),
        "wired": _WIRED,
    },
    # A crowded competition hall: tens of ms, long tail, ~10 % loss in bursts.
    "congested-wifi": {
        "sensor": IDEAL,
        "wifi": LinkModel(latency_ms=15.0, jitter_ms=25.0, p_gb=0.04, p_bg=0.25, loss_good=0.01, loss_bad=0.6),
        "wired": _WIRED,
    },
}


def resolve(preset: str, overrides: dict[str, dict[str, float]] | None = None) -> dict[str, LinkModel]:
    """The models per link class for `preset` with per-parameter overrides applied."""
    if preset not in PRESETS:
        raise ConfigError(f"unknown link preset {preset!r}; choose one of: {', '.join(PRESETS)}")
    models = dict(PRESETS[preset])
    fields = {f.name for f in dataclasses.fields(LinkModel)}
    for cls, params in (overrides or {}).items():
        if cls not in LINK_CLASSES:
            raise ConfigError(f"unknown link class {cls!r}; choose one of: {', '.join(LINK_CLASSES)}")
        bad = set(params) - fields
        if bad:
            raise ConfigError(f"unknown link parameter {sorted(bad)[0]!r}; choose one of: {', '.join(sorted(fields))}")
        models[cls] = dataclasses.replace(models[cls], **{k: float(v) for k, v in params.items()})
    for cls, model in models.items():
        model.validate(cls)
    return models


def parse_override(text: str) -> tuple[str, str, float]:
    """`wifi.latency_ms=12` -> ("wifi", "latency_ms", 12.0)."""
    try:
        lhs, value = text.split("=", 1)
        cls, param = lhs.strip().split(".", 1)
        return cls.strip(), param.strip(), float(value)
    except ValueError:
        raise ConfigError(f"bad link override {text!r}: use CLASS.PARAM=VALUE, e.g. wifi.latency_ms=12") from None


def parse_overrides(texts) -> dict[str, dict[str, float]]:
    """Every `--link-param CLASS.PARAM=V` as {class: {param: value}}, the later one winning."""
    out: dict[str, dict[str, float]] = {}
    for text in texts:
        cls, param, value = parse_override(text)
        out.setdefault(cls, {})[param] = value
    return out


class LinkEmulator:
    """Decides, frame by frame and in send order, whether a frame is dropped and how late it is."""

    __slots__ = ("model", "_rng", "_bad", "frames", "dropped", "delays_ms", "_ideal", "_changes", "on_time")

    def __init__(self, model: LinkModel, rng: random.Random, changes: tuple[tuple[int, LinkModel], ...] = ()):
        """`changes`: (tick, model) in tick order: a scenario's link steps (`scheduled`), for frames sent from then on."""
        self.model = model
        self._changes = list(changes)
        self._rng = rng
        self._bad = False
        self._ideal = model.is_ideal()
        # Ideal now and for good: `decide` only counts the frame and says 0.0 (its receiver does
        # that itself, without the call, and counts it only in real time, where the count is read:
        # runtime/lockstep.py `Inbound._accept_one`, `counted`).
        self.on_time = self._ideal and not self._changes
        self.frames = 0  # frames decided, and a real-time receiver's on an ideal link (`Inbound._accept_one`)
        self.dropped = 0
        self.delays_ms: list[float] = []  # drawn delays of delivered frames (non-ideal links)

    def decide(self, tick: int = -1) -> float | None:
        """Delay in ms for the next frame (sent at `tick`), or None if it is lost."""
        if self._changes and tick >= self._changes[0][0]:
            self.model = self._changes.pop(0)[1]
            self._ideal = self.model.is_ideal()
            self.on_time = self._ideal and not self._changes
        self.frames += 1
        if self._ideal:
            return 0.0  # no delay statistics to keep: every delay is 0
        m = self.model
        r = self._rng.random
        # Step the Gilbert-Elliott chain, then draw loss in the new state.
        if self._bad:
            if r() < m.p_bg:
                self._bad = False
        elif r() < m.p_gb:
            self._bad = True
        if r() < (m.loss_bad if self._bad else m.loss_good):
            self.dropped += 1
            return None
        delay = m.latency_ms + (self._rng.expovariate(1.0 / m.jitter_ms) if m.jitter_ms > 0 else 0.0)
        self.delays_ms.append(delay)
        return delay


def scheduled(cfg, link_class: str) -> tuple[tuple[int, LinkModel], ...]:
    """A scenario's link changes for `link_class` (`SetLink` steps of `cfg.scenario`), as (tick, model)."""
    from arena.schemas.messages import SetLink

    out = []
    for step in cfg.scenario.steps:
        for a in step.actions:
            if isinstance(a, SetLink) and step.at >= 0:
                out.append((step.at, resolve(a.preset, a.overrides)[link_class]))
    return tuple(sorted(out, key=lambda c: c[0]))
