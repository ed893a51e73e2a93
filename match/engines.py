"""The `Engine` protocol and its two engines; `play` and `engine`, the entry points."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, ClassVar, Protocol

import msgspec

if TYPE_CHECKING:
    from arena.config import MatchConfig, ProcessId
    from arena.match.inprocess import Stepped
    from arena.match.result import MatchResult

ENGINES = ("processes", "inprocess")


class Engine(Protocol):
    """Plays one match of a `MatchConfig` to its end and returns its result.

    `record`: write the match to this new MCAP file ("" for none); `watch`: keys (relative, e.g.
    "world", "referee") whose payloads the result keeps in `frames`, in the order they were put.
    A match that cannot be played to the end raises `MatchError` (its message says why)."""

    name: str

    def play(self, cfg: MatchConfig, *, record: str = "", watch: tuple[str, ...] = ()) -> MatchResult: ...


class InProcess(msgspec.Struct, frozen=True):
    """Every node of the match on this thread, driven cooperatively (lockstep only)."""

    name: ClassVar[str] = "inprocess"
    last: bool = False  # the process ends with its match (`arena match`): what it leaves is not collected

    def play(self, cfg: MatchConfig, *, record: str = "", watch: tuple[str, ...] = ()) -> MatchResult:
        from arena.match import inprocess

        return inprocess.play_match(cfg, record=record, watch=watch, last=self.last)

    def stepped(
        self,
        cfg: MatchConfig,
        *,
        watch: tuple[str, ...] = (),
        only: tuple[ProcessId, ...] | None = None,
        match: str = "inprocess",
    ) -> Stepped:
        """The match built and not yet played, for a caller that drives it (match/inprocess.py `Stepped`)."""
        from arena.match.inprocess import Stepped

        return Stepped(cfg, watch=watch, only=only, match=match)


class Processes(msgspec.Struct, frozen=True):
    """Every process its own OS process over zenoh, supervised (match/launcher.py `play_match`
    says what each option does). `watch` is read back from the recording (a temporary one if no
    `record` is given)."""

    name: ClassVar[str] = "processes"
    match: str | None = None
    listen: str | None = None
    progress: bool = False
    log_dir: str | None = None
    announce: Callable[[str], None] | None = None
    strict: bool = False
    live_host: str = "127.0.0.1"
    secure: bool | None = None
    credentials: str | None = None

    def play(self, cfg: MatchConfig, *, record: str = "", watch: tuple[str, ...] = ()) -> MatchResult:
        if not watch:
            return self._play(cfg, record)
        import tempfile
        from pathlib import Path

        from arena.recording.reader import load

        with tempfile.TemporaryDirectory(prefix="arena-match-") as tmp:
            path = record or str(Path(tmp) / "match.mcap")
            result = self._play(cfg, path)
            rec = load(path, keep=set(watch))
            result.frames = {name: list(rec.payloads(name)) for name in watch}
        if not record:
            result.recording = None  # the temporary file is gone; the match was not asked to record
        return result

    def _play(self, cfg: MatchConfig, record: str) -> MatchResult:
        from arena.match import launcher

        return launcher.play_match(
            cfg,
            match=self.match,
            listen=self.listen,
            progress=self.progress,
            log_dir=self.log_dir,
            announce=self.announce,
            strict=self.strict,
            live_host=self.live_host,
            secure=self.secure,
            credentials=self.credentials,
            record=record,
        )


def engine(name: str, **options) -> Engine:
    """The engine called `name` ("processes" or "inprocess"); `options`: the processes engine's
    (`Processes`' fields), e.g. `engine("processes", strict=True)`."""
    if name == "inprocess":
        if options:
            raise TypeError(f"the in-process engine takes no options, got {', '.join(sorted(options))}")
        return InProcess()
    if name == "processes":
        return Processes(**options)
    raise ValueError(f"no engine {name!r} (one of {', '.join(ENGINES)})")


def play(
    cfg: MatchConfig, *, engine: str | Engine = "inprocess", record: str = "", watch: tuple[str, ...] = ()
) -> MatchResult:
    """Play the match `cfg` on `engine` (a name, or an `Engine` with its options) to its end."""
    played_by = _engine(engine) if isinstance(engine, str) else engine
    return played_by.play(cfg, record=record, watch=watch)


_engine = engine
