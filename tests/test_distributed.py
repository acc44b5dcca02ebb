"""Sweeps and checks on Dask (issue 13): the same rows as the serial run, every point exactly
once when a worker dies mid-sweep, lost tasks as rows, the caller's limits in force in the
workers, Ctrl-C stops the cluster and leaves no file.

One LocalCluster (2 worker processes: the ``dask_client`` fixture) is shared by the module."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("dask.distributed")

from typer.testing import CliRunner  # noqa: E402

from obsdesign import api  # noqa: E402
from obsdesign import sweep as sw  # noqa: E402
from obsdesign.cli import app  # noqa: E402
from obsdesign.distributed import run_tasks  # noqa: E402
from obsdesign.limits import reset_limits, set_limits  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SPECS = ROOT / "specs"
SPEC = SPECS / "constrained-redesign-sec5-lyapunov.toml"
#: the fast shipped specs (the whole folder is the slow test below)
FAST = [
    SPECS / "constrained-redesign-sec5-lyapunov.toml",
    SPECS / "hernandez-garcia-example.toml",
    SPECS / "schaum-impulsive-example.toml",
    SPECS / "astolfi-stubborn-duffing.toml",
]
GRID12 = ["method.lambda=0.94:0.99:6", "method.rate_tol=[0.0001, 0.001]"]


#: a task may be on one dying worker and be retried once; the second death marks it lost
DASK_CONFIG = {"distributed.scheduler.allowed-failures": 1}


def _strip(rows: list[dict]) -> list[dict]:
    """Rows without the wall-clock columns (the only ones two runs may differ in)."""
    return [{k: v for k, v in r.items() if k not in sw.TIMING_COLUMNS} for r in rows]


@pytest.fixture(scope="module")
def serial12() -> list[dict]:
    return sw.sweep_rows(SPEC, GRID12)


def test_twelve_point_sweep_is_the_serial_table(dask_client, serial12):
    rows = sw.sweep_rows(SPEC, GRID12, client=dask_client)
    assert len(rows) == 12
    assert _strip(rows) == _strip(serial12)
    assert [r["exit_code"] for r in rows] == [1] * 4 + [0] * 8  # λ ≤ 0.95 infeasible
    assert sw.columns(rows) == sw.columns(serial12)
    # the DataFrame too (column order included)
    pd = pytest.importorskip("pandas")
    a = sw.to_frame(rows).drop(columns=list(sw.TIMING_COLUMNS), errors="ignore")
    b = sw.to_frame(serial12).drop(columns=list(sw.TIMING_COLUMNS), errors="ignore")
    pd.testing.assert_frame_equal(a, b)


def test_a_worker_killed_mid_sweep_costs_a_retry_not_a_row(dask_client, serial12):
    pids = dask_client.run(os.getpid)
    seen: list[int] = []
    killed: list[int] = []

    def on_row(row: dict) -> None:
        seen.append(row["point"])
        if not killed:
            busy = [w for w, keys in dask_client.processing().items() if keys and w in pids]
            victim = pids[busy[0]] if busy else next(iter(pids.values()))
            os.kill(victim, signal.SIGKILL)
            killed.append(victim)

    rows = sw.sweep_rows(SPEC, GRID12, client=dask_client, on_row=on_row)
    assert killed
    assert sorted(seen) == list(range(12))  # every point reported exactly once
    assert [r["point"] for r in rows] == list(range(12))
    assert _strip(rows) == _strip(serial12)
    dask_client.wait_for_workers(2, timeout=60)  # the nanny restarted it
    assert killed[0] not in dask_client.run(os.getpid).values()


def test_chunks_give_the_same_results_in_order(dask_client):
    seen: list[int] = []
    out = run_tasks(
        abs, list(range(-7, 0)), client=dask_client, chunk=3, on_result=lambda i, r: seen.append(i)
    )
    assert out == [7, 6, 5, 4, 3, 2, 1] and sorted(seen) == list(range(7))


def test_a_task_that_kills_every_worker_is_a_row_not_a_hang(dask_client):
    def die_on_3(x: int) -> int:
        if x == 3:
            os._exit(1)
        return x * x

    # chunks [0, 1, 2], [3, 4, 5]: the second dies, is run again item by item, and only
    # item 3 is lost
    out = run_tasks(
        die_on_3, list(range(6)), client=dask_client, lost=lambda x, msg: (x, msg), chunk=3
    )
    assert out[:3] == [0, 1, 4] and out[4:] == [16, 25]
    assert out[3][0] == 3 and "killed every worker" in out[3][1]
    dask_client.wait_for_workers(2, timeout=60)


def test_the_callers_limits_hold_in_the_workers(dask_client):
    grid = ["method.lambda=[0.97, 0.97" + "0" * 40 + "1]"]  # 43 digits
    old = set_limits(max_digits=40)
    try:
        serial = sw.sweep_rows(SPEC, grid)
        dist = sw.sweep_rows(SPEC, grid, client=dask_client)
    finally:
        reset_limits(old)
    assert [r["exit_code"] for r in serial] == [0, 2]
    assert "digits" in serial[1]["message"]
    assert _strip(dist) == _strip(serial)
    # and the workers are back to their own limits afterwards
    assert [r["exit_code"] for r in sw.sweep_rows(SPEC, grid, client=dask_client)] == [0, 0]


#: run in each worker by ``client.run(exec, ...)``: api.design of a spec named "slow*.toml"
#: spins in Python for 20 s (a spec that hangs), of any other the real one
_SLOW_DESIGN = """
import time
import obsdesign.api as _api
_real = getattr(_api, "_real_design", _api.design)
_api._real_design = _real
def _slow(sp, *a, **k):
    if str(getattr(sp, "file", "")).split("/")[-1].startswith("slow"):
        t0 = time.perf_counter()
        while time.perf_counter() - t0 < 20:
            time.sleep(0.01)
    return _real(sp, *a, **k)
_api.design = _slow
"""
_REAL_DESIGN = "import obsdesign.api as _api\n_api.design = _api._real_design\n"


def test_check_and_sweep_on_dask_stop_a_spec_at_the_timeout(dask_client, tmp_path: Path):
    """``--timeout`` was not applied with ``--workers`` / ``--scheduler`` (a Dask task runs in
    a worker thread, which SIGALRM does not reach): one spec that hangs held the run for as
    long as it hung (session 30). The budget is applied in the worker: an exit-3 row, the
    others kept."""
    good, slow = tmp_path / "a.toml", tmp_path / "slow.toml"
    good.write_text(SPEC.read_text())
    slow.write_text(SPEC.read_text())
    dask_client.run(exec, _SLOW_DESIGN, {})
    try:
        t0 = time.perf_counter()
        rows = api.check([good, slow], client=dask_client, timeout=1)
        took = time.perf_counter() - t0
        t0 = time.perf_counter()
        pts = sw.sweep_rows(slow, ["method.lambda=[0.97, 0.98]"], client=dask_client, timeout=1)
        took_sweep = time.perf_counter() - t0
    finally:
        dask_client.run(exec, _REAL_DESIGN, {})
    assert [r.code for r in rows] == [0, 3] and took < 15, [r.message for r in rows]
    assert "not finished within 1 s" in rows[1].message and rows[1].method == "lyapunov"
    assert [r["exit_code"] for r in pts] == [3, 3] and took_sweep < 15
    assert all("not finished within 1 s" in r["message"] for r in pts)


def _check_rows(rows: list) -> list[dict]:
    return [{k: v for k, v in r.__dict__.items() if k != "seconds"} for r in rows]


def test_check_on_dask_equals_serial_on_the_fast_specs(dask_client):
    serial = api.check(FAST)
    dist = api.check(FAST, client=dask_client)
    assert [r.spec for r in dist] == [str(f) for f in FAST]
    assert _check_rows(dist) == _check_rows(serial)
    assert all(r.code == 0 for r in dist)


def test_check_on_dask_reads_relative_paths_here_and_refuses_another_copy(
    dask_client, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A relative spec path was sent as typed, and a worker resolved it in its own working
    directory: it checked another file of that name, and an infeasible spec was "ok", exit 0
    (distributed trial, session 27). The worker gets the absolute path and the sha256 of the
    bytes read here; the row names the path as given, and equals the serial row. A copy that
    differs on the worker is refused (exit 2), not checked."""
    bad = SPEC.read_text().replace("lambda = 0.955", "lambda = 0.5")
    assert "lambda = 0.5" in bad
    (tmp_path / "s.toml").write_text(bad)
    other = tmp_path / "w"
    other.mkdir()
    (other / "s.toml").write_text(SPEC.read_text())  # a feasible spec of the same name
    monkeypatch.chdir(tmp_path)
    dask_client.run(os.chdir, str(other))  # where the workers stand
    try:
        serial = api.check([Path("s.toml")])
        dist = api.check([Path("s.toml")], client=dask_client)
    finally:
        dask_client.run(os.chdir, str(ROOT))
    assert serial[0].code == 1 and _check_rows(dist) == _check_rows(serial)
    assert dist[0].spec == "s.toml"
    item = (*api._remote_item(Path("s.toml")), None)
    (tmp_path / "s.toml").write_text(SPEC.read_text())  # the "worker's" copy differs now
    row = api.check_remote(item)
    assert row.code == 2 and "the workers must see the same files" in row.message
    assert row.spec == "s.toml"


@pytest.mark.slow
def test_cli_check_workers_2_on_specs_equals_serial():
    runner = CliRunner()
    a = runner.invoke(app, ["check", str(SPECS), "--format", "json"])
    b = runner.invoke(app, ["check", str(SPECS), "--format", "json", "--workers", "2", "-q"])
    assert a.exit_code == b.exit_code == 0, (a.stderr, b.stderr)
    import json

    ra, rb = json.loads(a.stdout), json.loads(b.stdout)
    for r in ra + rb:
        r.pop("seconds")
    assert ra == rb and len(ra) == len(list(SPECS.glob("*.toml")))


@pytest.mark.slow  # its own LocalCluster (seconds); the Ctrl-C test runs `sweep --workers 2` too
def test_cli_sweep_workers_2_writes_the_serial_table(tmp_path: Path, serial12):
    out = tmp_path / "t.jsonl"
    r = CliRunner().invoke(
        app, ["sweep", str(SPEC), *sum((["--set", g] for g in GRID12), []), "--workers", "2",
              "-o", str(out), "-q"],
    )  # fmt: skip
    assert r.exit_code == 1, r.stderr
    import json

    rows = [json.loads(x) for x in out.read_text(encoding="utf-8").splitlines()]
    assert _strip(rows) == _strip(serial12)


def test_ctrl_c_stops_the_cluster_it_started_and_writes_nothing(tmp_path: Path):
    """Ctrl-C as a terminal sends it, to the whole process group (the command and its Dask
    workers): exit 130, one line, no output file, no worker left. Each worker printed its own
    "obsdesign: interrupted" (three lines for two workers: outsider trial, session 22); the
    workers now ignore SIGINT and the command shuts them down."""
    psutil = pytest.importorskip("psutil")
    out = tmp_path / "t.csv"
    exe = Path(sys.executable).parent / "obsdesign"
    cmd = [str(exe)] if exe.exists() else [sys.executable, "-m", "obsdesign.cli"]
    p = subprocess.Popen(
        [*cmd, "sweep", str(SPEC), "--set", "method.lambda=0.96:0.99:3000", "--workers", "2",
         "-o", str(out), "-q"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
    )  # fmt: skip
    try:
        proc = psutil.Process(p.pid)
        deadline = time.monotonic() + 60
        kids: list = []
        while time.monotonic() < deadline:  # the two worker processes are up
            kids = proc.children(recursive=True)
            if sum(_is_worker(k) for k in kids) >= 2:
                break
            time.sleep(0.2)
        assert sum(_is_worker(k) for k in kids) >= 2, [_name(k) for k in kids]
        time.sleep(3)  # tasks running
        os.killpg(p.pid, signal.SIGINT)  # the whole group, as Ctrl-C in a terminal
        _, err = p.communicate(timeout=60)
    finally:
        if p.poll() is None:
            p.kill()
    assert p.returncode == 130, err
    assert err.count("interrupted") == 1, err
    assert not out.exists() and not any(tmp_path.iterdir())
    gone, alive = psutil.wait_procs(kids, timeout=20)
    assert not alive, alive


def _is_worker(proc) -> bool:
    """A Dask worker process: titled "dask worker [...]" when setproctitle takes effect, else
    (it did not under OPENBLAS_NUM_THREADS=1) the multiprocessing child that runs it."""
    name = _name(proc)
    return "dask" in name or "spawn_main" in name


def _name(proc) -> str:
    try:
        return proc.name() + " " + " ".join(proc.cmdline())
    except Exception:  # noqa: BLE001 - gone already
        return ""


@pytest.mark.slow
def test_an_existing_scheduler_runs_the_sweep_and_a_dead_address_is_bad_input(
    tmp_path: Path, serial12
):
    import json

    bindir = Path(sys.executable).parent
    sched_file = tmp_path / "scheduler.json"
    common = ["--no-dashboard"]
    sched = subprocess.Popen(
        [str(bindir / "dask"), "scheduler", "--scheduler-file", str(sched_file), "--port", "0",
         *common],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )  # fmt: skip
    worker = None
    try:
        deadline = time.monotonic() + 60
        while not sched_file.exists() and time.monotonic() < deadline:
            time.sleep(0.2)
        time.sleep(0.5)
        address = json.loads(sched_file.read_text())["address"]
        worker = subprocess.Popen(
            [str(bindir / "dask"), "worker", address, "--nworkers", "2", "--nthreads", "1",
             *common],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )  # fmt: skip
        out = tmp_path / "t.jsonl"
        args = ["sweep", str(SPEC), *sum((["--set", g] for g in GRID12), [])]
        r = CliRunner().invoke(app, [*args, "--scheduler", address, "-o", str(out), "-q"])
        assert r.exit_code == 1, r.stderr
        rows = [json.loads(x) for x in out.read_text(encoding="utf-8").splitlines()]
        assert _strip(rows) == _strip(serial12)
    finally:
        for p in (worker, sched):
            if p is not None:
                p.send_signal(signal.SIGINT)
                try:
                    p.wait(timeout=20)
                except subprocess.TimeoutExpired:
                    p.kill()
    r = CliRunner().invoke(app, [*args, "--scheduler", "tcp://127.0.0.1:9", "-q"])
    assert r.exit_code == 2 and "cannot connect" in r.stderr


def test_dask_logs_are_quiet_here_and_in_the_workers(monkeypatch: pytest.MonkeyPatch) -> None:
    """The LocalCluster obsdesign starts silences Dask's logs up to CRITICAL in the workers,
    and the client process's "distributed" logger too: a worker's heartbeat error at shutdown
    printed a 30-line traceback under `check --workers 2` (docs audit)."""
    import logging

    from obsdesign import distributed as dist

    seen: dict[str, object] = {}

    class FakeCluster:
        def __init__(self, **kw: object) -> None:
            seen.update(kw)

        def close(self) -> None:
            seen["closed"] = True

    class FakeClient:
        def __init__(self, cluster: object) -> None:
            pass

        def close(self) -> None:
            pass

    import dask.distributed as dd

    monkeypatch.setattr(dd, "LocalCluster", FakeCluster)
    monkeypatch.setattr(dd, "Client", FakeClient)
    with dist.dask_client(workers=2):
        assert logging.getLogger("distributed").level == logging.CRITICAL
    assert seen["silence_logs"] == logging.CRITICAL and seen["closed"] is True


def test_an_unknown_scheduler_scheme_is_bad_input() -> None:
    """``--scheduler junk://x`` reached distributed's "unknown address scheme" (exit 3;
    hostile-input trial, session 24): the scheme is checked first, exit 2."""
    from obsdesign.distributed import check_workers
    from obsdesign.errors import InputError

    with pytest.raises(InputError, match="schemes: tcp"):
        check_workers(None, "junk://x")
    check_workers(None, "tcp://127.0.0.1:8786")  # no connection is made here


@pytest.mark.parametrize("port", ["99999", "0", "00000", "9" * 5000])
def test_a_scheduler_port_out_of_range_is_bad_input_at_once(port: str) -> None:
    """``--scheduler tcp://127.0.0.1:99999`` waited the whole CONNECT_S probe (20 s) and then
    blamed the service (CLI review 44): a port outside 1-65535 is refused before any
    connection, naming the port; ports in range and IPv6 hosts pass."""
    from obsdesign.distributed import check_workers
    from obsdesign.errors import InputError

    with pytest.raises(InputError, match=r"port .* is outside 1-65535"):
        check_workers(None, f"tcp://127.0.0.1:{port}")
    # signs, underscores and other non-digits too (they waited the probe: CLI review 45)
    for bad in ("-1", "+99999", "9_9999", "８７８６", "x"):
        with pytest.raises(InputError, match=r"is not a number from 1 to 65535"):
            check_workers(None, f"tcp://127.0.0.1:{bad}")
    for ok in (
        "tcp://127.0.0.1:65535",
        "tls://[::1]:1",
        "tcp://host:08786",
        "inproc://x:99999",
        "tcp://[::1]",
        "tcp://host:8786/path",
    ):
        check_workers(None, ok)


def test_workers_in_a_removed_working_folder_is_bad_input(monkeypatch: pytest.MonkeyPatch) -> None:
    """``check --workers 2`` in a removed working folder was exit 3 "Nanny failed to start"
    (multiprocessing's spawn reads the working folder; re-check review 45): exit 2 saying
    so, before any process starts; a --scheduler (no local processes) is not refused."""
    from obsdesign import distributed as dist
    from obsdesign.errors import InputError

    def gone() -> str:
        raise FileNotFoundError(2, "No such file or directory")

    monkeypatch.setattr(dist.os, "getcwd", gone)
    with pytest.raises(InputError, match="the working folder no longer exists"):
        dist.check_workers(2, None)
    dist.check_workers(None, "tcp://127.0.0.1:8786")


def test_a_scheduler_address_without_a_port_is_bad_input() -> None:
    """``--scheduler tcp://`` raised distributed's ValueError "missing port number" (exit 3;
    hostile-input trial, session 24): exit 2 naming the option."""
    from obsdesign.distributed import dask_client
    from obsdesign.errors import InputError

    with pytest.raises(InputError, match="--scheduler tcp://: cannot connect"):
        with dask_client(scheduler="tcp://"):
            pass


def _tcp_service(on_connect: Any) -> tuple[Any, int]:
    """A TCP server on a free local port calling ``on_connect(socket)`` for each connection
    (in a daemon thread, until the server is closed): (server socket, port)."""
    import socket
    import threading

    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(8)

    def serve() -> None:
        while True:
            try:
                c, _ = srv.accept()
            except OSError:
                return
            on_connect(c)

    threading.Thread(target=serve, daemon=True).start()
    return srv, srv.getsockname()[1]


def test_a_tcp_service_that_is_not_dask_is_bad_input_not_a_hang(monkeypatch) -> None:
    """--scheduler at a service that accepts TCP and never answers Dask's handshake (python3 -m
    http.server) hung forever: Client's timeout bounds the connect only (distributed trial,
    session 27). Exit 2 after CONNECT_S; an HTTP-like reply (read as an exabyte frame,
    MemoryError) and a tls:// address without its setup (TypeError) are exit 2 too. No Client
    is left half-made (one interrupted while being made deadlocked the next test's
    LocalCluster from its finalizer), so no warning either."""
    import socket

    from obsdesign import distributed
    from obsdesign.errors import InputError

    monkeypatch.setattr(distributed, "CONNECT_S", 2.0)
    conns: list[socket.socket] = []
    srv, port = _tcp_service(conns.append)  # accepted, never answered
    t0 = time.monotonic()
    try:
        with pytest.raises(InputError, match="no Dask scheduler answered within 2 s"):
            run_tasks(abs, [1, 2], scheduler=f"tcp://127.0.0.1:{port}")
    finally:
        srv.close()
        for c in conns:
            c.close()
    assert time.monotonic() - t0 < 30
    with pytest.raises(InputError, match="cannot connect"):
        run_tasks(abs, [1], scheduler="tls://127.0.0.1:9")


def test_a_scheduler_without_workers_is_bad_input(monkeypatch) -> None:
    """A scheduler with no worker took the tasks and waited forever, silently (distributed
    trial, session 27): exit 2 after CONNECT_S naming the scheduler."""
    from dask.distributed import LocalCluster

    from obsdesign import distributed
    from obsdesign.errors import InputError

    monkeypatch.setattr(distributed, "CONNECT_S", 2.0)
    with LocalCluster(n_workers=0, processes=False, dashboard_address=":0") as cluster:
        with pytest.raises(InputError, match="no worker joined within 2 s"):
            run_tasks(abs, [1], scheduler=cluster.scheduler_address)


def test_a_run_whose_workers_are_all_gone_stops() -> None:
    """The last worker of an external cluster died mid-run and the run waited forever with no
    message (distributed trial, session 27): after NO_WORKERS_S without a worker it stops
    (exit 3). Shown on the loop itself with a stand-in for as_completed and the count."""
    from obsdesign import distributed
    from obsdesign.errors import SolverError

    class Never:
        def is_empty(self) -> bool:
            return False

        def next_batch(self, block: bool = True) -> list[object]:
            return []

    class Gone:
        paused = 0

        def gone_for(self) -> float:
            return distributed.NO_WORKERS_S + 1

    with pytest.raises(SolverError, match="no worker for"):
        next(distributed._arrivals(Never(), Gone()))  # type: ignore[arg-type]
    got = list(distributed._arrivals(_Ready([1, 2]), Gone()))  # type: ignore[arg-type]
    assert got == [1, 2]
    Gone.paused = 2
    with pytest.raises(SolverError, match=r"2 worker\(s\) have been paused for 60 s"):
        next(distributed._arrivals(Never(), Gone()))  # type: ignore[arg-type]


def test_paused_workers_are_no_workers() -> None:
    """Workers Dask paused (past 80 % of their memory limit) take no task, but were counted:
    check --scheduler on such a cluster waited forever with no word (Dask review 47)."""
    from obsdesign import distributed

    class Client:
        def __init__(self, states: list[str | None]) -> None:
            self.states = states

        def scheduler_info(self) -> dict:
            return {
                "workers": {
                    f"w{i}": ({} if st is None else {"status": st})
                    for i, st in enumerate(self.states)
                }
            }

    w = distributed._Workers(Client(["paused", "paused"]))
    w.gone_for()
    assert w.none_since is not None and w.paused == 2
    for states in (["paused", "running"], [None], ["init"]):
        w = distributed._Workers(Client(states))
        assert w.gone_for() == 0.0 and w.none_since is None


class _Ready:
    """as_completed's stand-in holding futures already done."""

    def __init__(self, items: list[object]) -> None:
        self.items = items

    def is_empty(self) -> bool:
        return not self.items

    def next_batch(self, block: bool = True) -> list[object]:
        out, self.items = self.items, []
        return out


def test_every_distributed_logger_is_quieted_and_lost_rows_are_one_line() -> None:
    """distributed.client has its own level (WARNING) from dask's config, so quieting the
    parent logger left ~35 lines of traceback on stderr when the scheduler was killed mid-run;
    and the lost row's message kept the error's raw newline (distributed trial, session 27)."""
    import logging

    from obsdesign import distributed

    logging.getLogger("distributed.client").setLevel(logging.WARNING)
    distributed._quiet_logs()
    assert logging.getLogger("distributed.client").level == distributed.QUIET
    assert logging.getLogger("distributed").level == distributed.QUIET
    assert logging.getLogger("asyncio").level == distributed.QUIET  # session 28
    msg = distributed._lost_message(RuntimeError("cancelled.\nClient lost the connection"))
    assert "\n" not in msg and "\\n" in msg


def test_workers_running_other_code_are_refused(monkeypatch) -> None:
    """A worker on an older checkout (same version number) gave 5 of 13 check rows that
    differ from the serial run, silently (distributed trial, session 27): a --scheduler whose
    workers report another fingerprint of the obsdesign sources is exit 2; the same code runs."""
    from dask.distributed import LocalCluster

    from obsdesign import distributed
    from obsdesign.errors import InputError

    class Fake:
        def __init__(self, fps: dict[str, str] | Exception) -> None:
            self.fps = fps

        def run(self, fn: object) -> dict[str, str]:
            if isinstance(self.fps, Exception):
                raise self.fps
            return self.fps

    mine = distributed.code_fingerprint()
    distributed._same_code(Fake({"w1": mine, "w2": mine}), "tcp://x:1")
    with pytest.raises(InputError, match="1 of 2 worker"):
        distributed._same_code(Fake({"w1": mine, "w2": "0" * 64}), "tcp://x:1")
    with pytest.raises(InputError, match="cannot report its obsdesign code"):
        distributed._same_code(Fake(AttributeError("no such function")), "tcp://x:1")
    with LocalCluster(n_workers=1, processes=False, dashboard_address=":0") as cluster:
        assert run_tasks(abs, [-1, -2], scheduler=cluster.scheduler_address) == [1, 2]


def test_results_from_a_worker_with_other_code_are_refused(monkeypatch: pytest.MonkeyPatch):
    """A worker that joined after the check at the start ran its tasks with its own code,
    silently (session 27's note): each task's results carry the worker's code fingerprint,
    and one that differs from the caller's is exit 2."""
    from dask.distributed import Client, LocalCluster, get_worker

    from obsdesign import distributed
    from obsdesign.errors import InputError

    real = distributed.code_fingerprint

    def in_worker_other() -> str:
        try:
            get_worker()
        except ValueError:
            return real()
        return "0" * 64

    with (
        LocalCluster(n_workers=1, processes=False, dashboard_address=":0") as cluster,
        Client(cluster) as c,
    ):
        assert run_tasks(abs, [-1, -2], client=c) == [1, 2]
        monkeypatch.setattr(distributed, "code_fingerprint", in_worker_other)
        with pytest.raises(InputError, match="ran other obsdesign code"):
            run_tasks(abs, [-1, -2], client=c)
    with pytest.raises(InputError, match="ran other obsdesign code"):
        distributed._own_code([1, 2], "the cluster")  # a worker older than the check


def test_a_cluster_whose_start_is_interrupted_is_closed_and_unregistered(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Ctrl-C while LocalCluster started its workers left the half-started cluster in Dask's
    registry; Dask's exit hook closed it again and printed a 29-line AssertionError traceback
    after "interrupted" (9 of 10 interrupts 1.5–2.6 s into `check --workers 2`; session 27's
    note). The interrupted cluster is closed and unregistered (1 of 10 still prints a
    spawned child's unpickling error, outside this process)."""
    import dask.distributed
    from distributed.deploy.spec import SpecCluster

    from obsdesign import distributed

    closed: list[object] = []

    class HalfStarted:
        shutdown_on_close = True
        status = None

        def __init__(self, **kw: object) -> None:
            SpecCluster._instances.add(self)
            raise KeyboardInterrupt

        def close(self, timeout: float | None = None) -> None:
            closed.append(self)
            raise AssertionError("Status.starting")  # what Dask's _close asserts

    monkeypatch.setattr(dask.distributed, "LocalCluster", HalfStarted)
    with pytest.raises(KeyboardInterrupt), distributed.dask_client(workers=1):
        pass
    assert len(closed) == 1
    assert not [c for c in SpecCluster._instances if isinstance(c, HalfStarted)]


def test_an_interrupted_cluster_is_closed_with_a_bounded_wait(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Mutation review 28: obsdesign.distributed.x__abandon__mutmut_1 (``close(timeout=None)``: an interrupted
    cluster's close could wait without end after Ctrl-C)."""
    import dask.distributed
    from distributed.deploy.spec import SpecCluster

    from obsdesign import distributed

    waits: list[object] = []

    class HalfStarted:
        def __init__(self, **kw: object) -> None:
            SpecCluster._instances.add(self)
            raise KeyboardInterrupt

        def close(self, timeout: float | None = None) -> None:
            waits.append(timeout)

    monkeypatch.setattr(dask.distributed, "LocalCluster", HalfStarted)
    with pytest.raises(KeyboardInterrupt), distributed.dask_client(workers=1):
        pass
    assert len(waits) == 1 and isinstance(waits[0], (int, float)) and 0 < waits[0] <= 60


def test_an_http_service_as_scheduler_is_named_as_not_dask() -> None:
    """A service that answers HTTP at once: Dask reads its first bytes as a frame length of
    exabytes, and the message was "cannot connect (MemoryError: Unable to allocate 3.07 EiB
    …)" (CLI trial, session 40). It now says the service does not speak Dask's protocol."""
    import socket

    from obsdesign.errors import InputError

    def http(c: socket.socket) -> None:
        with contextlib.suppress(OSError):
            c.sendall(b"HTTP/1.0 400 Bad Request\r\nServer: x\r\n\r\n" + b"x" * 64)
            c.close()

    srv, port = _tcp_service(http)
    try:
        with pytest.raises(InputError, match="cannot connect") as ei:
            run_tasks(abs, [1], scheduler=f"tcp://127.0.0.1:{port}")
    finally:
        srv.close()
    msg = ei.value.message
    assert "EiB" not in msg and "Unable to allocate" not in msg, msg


def test_a_scheduler_that_went_away_stops_the_run_with_one_message() -> None:
    """A scheduler killed mid-run made each row not done an exit-3 row of its own,
    "internal failure: FutureCancelledError … cancelled for reason: unknown" (Dask review
    47): a cancelled future stops the run, exit 3, once; other failures are rows."""
    from distributed.client import FutureCancelledError

    from obsdesign import distributed
    from obsdesign.errors import SolverError

    with pytest.raises(SolverError, match="the Dask scheduler went away"):
        distributed._scheduler_gone(FutureCancelledError("obsdesign-x-0-3", "unknown"))
    distributed._scheduler_gone(RuntimeError("a worker's own failure"))  # a row: no raise
