"""`arena tournament --ray [ADDRESS]`: every fixture one Ray task, the tables on the driver.

Ray is imported only here, and only when `--ray` is given. Each task gets the
fixture's `MatchConfig` itself and plays it on a worker node as a local job
does: on the processes engine a `python -m arena.match` process group
(match/child.py) with its own zenoh router (a unix socket in a private
temp dir), so matches never hear each other, on one node or many. The task
returns the match's `MatchResult`; the driver writes the result atomically to
`<out>/matches/<id>.json` as it arrives (so `--resume` works), feeds the
progress bar from `ray.wait`, and on Ctrl-C or SIGTERM ends the Ray job
(Ray kills the job's workers, and each match dies with its worker by
PR_SET_PDEATHSIG) and keeps what is finished.

Two kinds of failure, two mechanisms:
- a match that fails (non-zero exit, no JSON, time-out, a version mismatch)
  is played once more by the driver, as locally, possibly on another node;
- a worker or node that dies mid-task is a system failure: Ray itself runs the
  task again on a live node (`max_retries`), and the driver still gets exactly
  one result per fixture, so nothing is counted twice.

A worker whose soccer-arena differs from the driver's (version, git revision
or the hash of its source files) refuses to play and says which two differ.
"""

from __future__ import annotations

import contextlib
import ctypes
import hashlib
import importlib.metadata
import json
import signal
import socket
import subprocess
import threading
import time
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING

from arena.config import ConfigError
from arena.runtime.version import PACKAGES

if TYPE_CHECKING:
    from arena.experiments.tournament import TournamentOptions

# CPUs a match needs, by engine: the distributed engine runs ~11 processes
# that keep about two cores busy; the in-process engine is one thread.
TASK_CPUS = {"processes": 2.0, "inprocess": 1.0}
SYSTEM_RETRIES = 3  # worker or node deaths Ray absorbs per task (not match failures)
# A local instance's workers run at nice 0, as local jobs do. Ray's default
# (15) lets every other process on the machine starve the matches: on the
# shared 2-core development host it made --ray 1.2-1.9x slower than --jobs 2.
LOCAL_SYSTEM_CONFIG = {"worker_niceness": 0}
INSTALL_HINT = "--ray needs Ray: pip install 'soccer-arena[cluster]'"


# ------------------------------------------------------------------ address
def parse_address(text: str | None) -> str | None:
    """None or "" (--ray alone): start a local instance; "auto": the cluster on this node; "HOST:PORT": that head."""
    if not text:
        return None
    if text == "auto":
        return text
    host, sep, port = text.rpartition(":")
    if not sep or not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise ConfigError(f"--ray {text!r}: give auto or HOST:PORT of a Ray head node (e.g. 10.0.0.5:6379)")
    return text


def parse_runtime_env(text: str | None) -> dict | None:
    """--ray-runtime-env: a JSON object, handed to ray.init as the job's runtime_env."""
    if text is None:
        return None
    try:
        env = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ConfigError(f"--ray-runtime-env: not JSON ({exc.msg} at character {exc.pos})") from None
    if not isinstance(env, dict):
        raise ConfigError('--ray-runtime-env: give a JSON object, e.g. {"pip": ["soccer-arena==0.1.0"]}')
    return env


def probe(address: str, timeout: float = 5.0) -> None:
    """Fail fast if nothing listens at HOST:PORT (ray.init would retry for over a minute)."""
    host, _, port = address.rpartition(":")
    try:
        with socket.create_connection((host.strip("[]"), int(port)), timeout=timeout):
            pass
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise ConfigError(
            f"--ray {address}: no Ray cluster there ({reason}); start one with `ray start --head --port {port}`"
        ) from None


def preflight(opts: TournamentOptions) -> None:
    """A ConfigError now for what `connect` would refuse later: no Ray, a bad address or runtime env."""
    import importlib.util

    if importlib.util.find_spec("ray") is None:
        raise ConfigError(INSTALL_HINT)
    address = parse_address(opts.ray)
    parse_runtime_env(opts.ray_runtime_env)
    if address not in (None, "auto"):
        probe(address)


def connect(address: str | None, local_cpus: float, runtime_env: dict | None = None):
    """ray.init for the driver; a one-line ConfigError on any failure."""
    try:
        import ray
    except ImportError:
        raise ConfigError(INSTALL_HINT) from None
    if address not in (None, "auto"):
        probe(address)
    kw = {"logging_level": "ERROR", "log_to_driver": False, "include_dashboard": False}
    if runtime_env is not None:
        kw["runtime_env"] = runtime_env
    try:
        if address is None:
            ray.init(address="local", num_cpus=local_cpus, _system_config=LOCAL_SYSTEM_CONFIG, **kw)
        else:
            ray.init(address=address, **kw)
    except (ConnectionError, RuntimeError, ValueError, TimeoutError) as exc:
        first = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
        raise ConfigError(f"--ray {address or ''}: cannot join the cluster: {first}".replace("  ", " ")) from None
    return ray


# -------------------------------------------------------------- fingerprint
_FINGERPRINT: dict | None = None


def fingerprint() -> dict:
    """This process's soccer-arena: version, git revision (if a checkout) and a hash of its sources."""
    global _FINGERPRINT
    if _FINGERPRINT is None:
        import arena

        try:
            version = importlib.metadata.version("soccer-arena")
        except importlib.metadata.PackageNotFoundError:
            version = "not installed"
        root = Path(arena.__file__).resolve().parent.parent
        try:
            rev = subprocess.run(
                ["git", "-C", str(root), "rev-parse", "--short=12", "HEAD"],
                capture_output=True,
                text=True,
                timeout=10,
            ).stdout.strip()
        except (OSError, subprocess.TimeoutExpired):
            rev = ""
        _FINGERPRINT = {"version": version, "git": rev or "none", "source": source_hash()}
    return _FINGERPRINT


def source_hash() -> str:
    """BLAKE2b of every .py file of the `arena` package that this process imports, by module path."""
    import importlib.util

    h = hashlib.blake2b(digest_size=8)
    for name in ("arena", *(f"arena.{p}" for p in PACKAGES)):
        spec = importlib.util.find_spec(name)  # found, not imported: arena.learn needs its extra to import
        for base in map(Path, spec.submodule_search_locations if spec else []):
            for f in sorted(base.rglob("*.py")):
                h.update(f"{name}/{f.relative_to(base)}".encode())
                h.update(f.read_bytes())
    return h.hexdigest()


def describe(fp: dict) -> str:
    return f"soccer-arena {fp['version']} (git {fp['git']}, source {fp['source']})"


# ---------------------------------------------------------------- the task
def _die_with_parent() -> None:
    with contextlib.suppress(OSError):
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG


def play_on_worker(job: dict, driver: dict) -> dict:
    """Body of the Ray task: check the version, play one match, return what the driver needs.

    `job` is {"config": MatchConfig, "engine": name, "timeout": s}. The distributed engine plays
    in a process group of its own (`python -m arena.match` under this worker's interpreter, handed
    the configuration); the in-process engine plays in this worker process itself: Ray reuses its
    workers, so it imports once.
    """
    import ray

    node = ray.get_runtime_context().get_node_id()[:12]
    mine = fingerprint()
    if mine != driver:
        return {
            "rc": -1,
            "node": node,
            "reason": f"version mismatch on node {node}: the worker has {describe(mine)}, "
            f"the driver has {describe(driver)}; install the same soccer-arena on every node or use a runtime_env",
        }
    t0 = time.monotonic()
    if job["engine"] == "inprocess":
        from arena.match import play

        try:
            m = play(job["config"])
        except Exception as exc:  # a failed match is a result for the driver, never a crashed task
            return {"rc": 1, "node": node, "reason": f"{type(exc).__name__}: {exc}".splitlines()[0]}
        m.summaries = {}  # the driver reads the result's own fields
        return {"rc": 0, "match": m, "wall": time.monotonic() - t0, "node": node}
    from arena.match import child

    proc, given = child.start(
        job["config"], job["engine"], stderr=subprocess.PIPE, start_new_session=True, preexec_fn=_die_with_parent
    )
    reason = ""
    try:
        out, err = proc.communicate(input=given, timeout=job["timeout"])
    except subprocess.TimeoutExpired:
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate()
        reason = f"timed out after {job['timeout']:g} s"
    got = {"rc": proc.returncode, "err": err, "reason": reason, "wall": time.monotonic() - t0, "node": node}
    if proc.returncode == 0 and not reason:
        try:
            got["match"] = child.decode(out)
        except ValueError as exc:
            got["reason"] = str(exc)
    return got


# ------------------------------------------------------------------ driver
def task_cpus(engine: str) -> float:
    return TASK_CPUS.get(engine or "processes", 2.0)


def play(opts: TournamentOptions, runner, todo: list, on_result) -> bool:
    """Play `todo` on the cluster; call on_result(Result) as each arrives. Returns interrupted.

    After the last result Ray shuts down in the background (about 1.3 s: it
    stops its processes one by one), while the caller writes its report;
    `closed()` waits for it. On Ctrl-C or an error it shuts down at once.
    """
    global _CLOSING
    closed()
    # Ray's driver prints cluster events ("Raylet is terminated ...") to
    # sys.stdout, which is for the tournament's --json: they go to a log,
    # until Ray has shut down.
    stack = contextlib.ExitStack()
    log = stack.enter_context(open(runner.logs_dir / "ray-driver.log", "a"))
    stack.enter_context(contextlib.redirect_stdout(log))
    try:
        ray, interrupted = _play(opts, runner, todo, on_result)
    except BaseException:
        stack.close()
        raise
    if interrupted:
        _shutdown(ray)
        stack.close()
        return True
    t = threading.Thread(target=_shutdown, args=(ray,), name="ray-shutdown")
    t.start()
    _CLOSING = (t, stack)
    return False


_CLOSING: tuple[threading.Thread, contextlib.ExitStack] | None = None


def closed() -> None:
    """Wait until the Ray shut-down that `play` began is over (a no-op if none is under way)."""
    global _CLOSING
    if _CLOSING is not None:
        t, stack = _CLOSING
        _CLOSING = None
        t.join()
        stack.close()


def _shutdown(ray) -> None:
    with contextlib.suppress(Exception):
        ray.shutdown()


def _play(opts: TournamentOptions, runner, todo: list, on_result):
    """(ray, interrupted); Ray is shut down here only if this raises."""
    from arena.experiments import tournament as T
    from arena.experiments.matches import default_jobs

    cpus = task_cpus(opts.engine)
    jobs = opts.jobs or default_jobs()
    address = parse_address(opts.ray)
    ray = connect(address, jobs * cpus, parse_runtime_env(opts.ray_runtime_env))
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, T._interrupt)  # ray.init put in its own, which exits at once
    try:
        remote = ray.remote(play_on_worker).options(num_cpus=cpus, max_retries=SYSTEM_RETRIES, retry_exceptions=False)
        driver = fingerprint()
        timeout = 120.0 + 2.0 * opts.base.half_time
        # An existing cluster decides how many run at once; --jobs caps it if given.
        cap = jobs if address is None or opts.jobs else len(todo)
        queue = list(todo)
        inflight: dict = {}  # ref -> (fixture, attempt)

        def submit(fx, attempt: int) -> None:
            job = {"config": runner.match_config(fx), "engine": runner.engine, "timeout": timeout}
            inflight[remote.remote(job, driver)] = (fx, attempt)

        try:
            while queue and len(inflight) < cap:
                submit(queue.pop(0), 1)
            while inflight:
                ready, _ = ray.wait(list(inflight), num_returns=1, timeout=0.2)
                for ref in ready:
                    fx, attempt = inflight.pop(ref)
                    try:
                        got = ray.get(ref)
                    except Exception as exc:  # the task itself failed (retries used up)
                        got = {"rc": -1, "reason": f"task failed: {str(exc).strip().splitlines()[-1][:300]}"}
                    r = finish(runner, fx, attempt, got)
                    if r is None:
                        submit(fx, attempt + 1)
                        continue
                    on_result(r)
                    if queue:
                        submit(queue.pop(0), 1)
        except KeyboardInterrupt:
            # No ray.cancel: Ray 2.60's driver aborts ("Tried to complete task
            # that was not pending") when a force-cancelled task's reply is
            # already on its way. Disconnecting the driver (ray.shutdown, in
            # play) ends the job, Ray kills the job's workers, and each match
            # dies with its worker (PR_SET_PDEATHSIG).
            return ray, True
        return ray, False
    except BaseException:
        _shutdown(ray)
        raise


def finish(runner, fx, attempt: int, got: dict):
    """The Result of one attempt, written to --out; None if the match is to be played again."""
    from arena.experiments.fixtures import Result, void_reason, write_atomic

    log = runner.logs_dir / f"{fx.id}.log"
    reason = got.get("reason", "")
    where = f"[cluster] attempt {attempt} played on node {got['node']}\n" if "node" in got else ""
    write_atomic(log, (got.get("err") or "") + (f"{reason}\n" if reason else "") + where)
    if got["rc"] == 0 and not reason:
        m = got["match"]
        reason = void_reason(m)
        if not reason:
            r = Result.played(fx, m, attempt, got["wall"], m.engine)
            write_atomic(runner.matches_dir / f"{fx.id}.json", json.dumps(asdict(r)))
            return r
    if not reason:
        tail = (got.get("err") or "").strip().splitlines()
        reason = tail[-1] if tail else f"exit code {got['rc']}"
    if attempt < 2:
        return None
    r = Result.failed(fx, reason, attempt, runner.engine)
    write_atomic(runner.matches_dir / f"{fx.id}.json", json.dumps(asdict(r)))
    return r
