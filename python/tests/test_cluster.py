"""A Ray cluster of two nodes on one machine: a head and a second node, each its own
`ray start` (own CPU, own object store), on loopback only, with Ray's token authentication
on (as `ray start` turns it on when ~/.ray/auth_token exists). The render is bit-identical
across both; SIGKILLing the second node's raylet and workers mid-render changes nothing; a
driver killed mid-render resumes from its checkpoint to the same bits; a node that joins
mid-render gets work. docs/distributed.md, "Faults", says what each case stands for.

The tests share one cluster and run in file order (the second node is killed in the third
and a new one joins in the fourth)."""

import json
import os
import pathlib
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import uuid

import numpy as np
import pytest

import glint
from conftest import ROOT, cornell, cornell_dict

ray = pytest.importorskip("ray", reason="ray is not installed: the multi-node cluster tests need it")
import glint.distributed as gd  # noqa: E402
from glint.distributed import _worker  # noqa: E402

RAY = pathlib.Path(sys.executable).with_name("ray")
#: The node each process belongs to, by a variable in its environment (inherited by the
#: raylet's workers): how the tests find a node's processes, and only this cluster's.
NODE_VARIABLE = "GLINT_TEST_NODE"


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


#: `ray start` for a worker node on loopback. RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER=0 keeps
#: 127.0.0.1 as the node's address (Ray 2.60 otherwise puts the host's address in its place,
#: and its servers then listen on every interface), but `ray start` also refuses to start a
#: worker node under it. This runs Ray's own `ray start` with that refusal lifted and
#: 127.0.0.1 kept; its raylet and workers see the variable and stay on loopback.
WORKER_NODE_START = """
import sys
import ray._private.ray_constants as constants
import ray._private.services as services
from ray.scripts.scripts import main
constants.ENABLE_RAY_CLUSTER = True
services.resolve_ip_for_localhost = lambda host: host
sys.argv = ["ray"] + sys.argv[1:]
main()
"""


def node_env(tag: str, head: bool) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in ("RAY_ADDRESS", "RAY_AUTH_MODE")}
    if not head:
        # `ray start --head` turns token authentication on when ~/.ray/auth_token exists,
        # but a worker node given --address does not, and the head would refuse it.
        env["RAY_AUTH_MODE"] = "token"
    env.update(
        {
            NODE_VARIABLE: tag,
            "RAY_USAGE_STATS_ENABLED": "0",
            "RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER": "0",
            # A dead node is noticed in about two seconds, not thirty.
            "RAY_health_check_period_ms": "500",
            "RAY_health_check_timeout_ms": "500",
            "RAY_health_check_failure_threshold": "3",
        }
    )
    return env


def node_pids(tag: str) -> list:
    """Live processes of the node ``tag`` (raylet, workers, agents; the GCS on the head)."""
    found = []
    needle = f"{NODE_VARIABLE}={tag}".encode()
    for pid in os.listdir("/proc"):
        if not pid.isdigit() or int(pid) == os.getpid():
            continue
        try:
            with open(f"/proc/{pid}/environ", "rb") as f:
                if needle in f.read().split(b"\0"):
                    with open(f"/proc/{pid}/stat", "rb") as s:
                        if s.read().rsplit(b")", 1)[1].split()[0] != b"Z":
                            found.append(int(pid))
        except (OSError, IndexError):
            pass
    return found


def kill_node(tag: str) -> list:
    """SIGKILLs every process of the node, by process id, until none is left."""
    killed = []
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        pids = node_pids(tag)
        if not pids:
            return killed
        for pid in pids:
            try:
                os.kill(pid, signal.SIGKILL)
                killed.append(pid)
            except ProcessLookupError:
                pass
        time.sleep(0.1)
    raise AssertionError(f"processes of node {tag} still alive: {node_pids(tag)}")


class Cluster:
    def __init__(self):
        self.run = uuid.uuid4().hex[:8]
        # Short: Ray's socket paths must fit 107 bytes.
        self.temp = tempfile.mkdtemp(prefix="glint-ray-", dir="/tmp")
        self.port = free_port()
        self.address = f"127.0.0.1:{self.port}"
        self.nodes = []

    def start(self, name: str, head: bool = False) -> str:
        tag = f"{self.run}-{name}"
        args = ["start", "--node-ip-address=127.0.0.1", "--num-cpus=1", "--object-store-memory=100000000",
                f"--dashboard-agent-listen-port={free_port()}", f"--metrics-export-port={free_port()}",
                f"--runtime-env-agent-port={free_port()}", f"--dashboard-agent-grpc-port={free_port()}",
                "--disable-usage-stats"]
        if head:
            args = [str(RAY)] + args + ["--head", f"--port={self.port}", f"--temp-dir={self.temp}",
                                        "--include-dashboard=false"]
        else:
            args = [sys.executable, "-c", WORKER_NODE_START] + args + [f"--address={self.address}"]
        p = subprocess.run(args, env=node_env(tag, head), capture_output=True, text=True, timeout=120)
        assert p.returncode == 0, p.stdout + p.stderr
        self.nodes.append(tag)
        return tag

    def stop(self):
        for tag in reversed(self.nodes):
            kill_node(tag)
        shutil.rmtree(self.temp, ignore_errors=True)


def wait_for_cpus(n: int, timeout: float = 60) -> None:
    """Waits until the cluster (ray is connected) counts ``n`` CPUs."""
    deadline = time.monotonic() + timeout
    while ray.cluster_resources().get("CPU", 0) != n:
        assert time.monotonic() < deadline, f"the cluster has {ray.cluster_resources().get('CPU')} CPUs, not {n}"
        time.sleep(0.2)


@pytest.fixture(scope="module")
def cluster():
    if not sys.platform.startswith("linux"):
        pytest.skip("the cluster tests find a node's processes through /proc")
    token = pathlib.Path.home() / ".ray" / "auth_token"
    if not token.exists():
        # What Ray's own ray.init() does for a local cluster: make the token file.
        subprocess.run([str(RAY), "get-auth-token", "--generate"], check=True, capture_output=True)
    c = Cluster()
    with pytest.MonkeyPatch.context() as m:
        # The driver (this process) on loopback too, as RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER=0
        # in its environment would put it (Ray reads the variable when it is imported).
        m.setenv("RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER", "0")
        m.setattr(ray._private.ray_constants, "ENABLE_RAY_CLUSTER", False)
        try:
            c.head = c.start("head", head=True)
            c.second = c.start("second")
            yield c
        finally:
            if ray.is_initialized():
                ray.shutdown()
            c.stop()


def listening(pids) -> list:
    """The local addresses the processes listen on (TCP), from /proc/net/tcp{,6}."""
    inodes = set()
    for pid in pids:
        try:
            for fd in os.listdir(f"/proc/{pid}/fd"):
                link = os.readlink(f"/proc/{pid}/fd/{fd}")
                if link.startswith("socket:["):
                    inodes.add(link[8:-1])
        except OSError:
            pass
    found = []
    for table, v6 in (("/proc/net/tcp", False), ("/proc/net/tcp6", True)):
        with open(table) as f:
            for line in f.readlines()[1:]:
                cols = line.split()
                if cols[3] == "0A" and cols[9] in inodes:  # LISTEN
                    found.append(decode_address(cols[1], v6))
    return found


def decode_address(text: str, v6: bool) -> str:
    host, port = text.split(":")
    raw = bytes.fromhex(host)
    if v6:
        words = [raw[i:i + 4][::-1] for i in range(0, 16, 4)]
        ip = socket.inet_ntop(socket.AF_INET6, b"".join(words))
    else:
        ip = socket.inet_ntop(socket.AF_INET, raw[::-1])
    return f"{ip}:{int(port, 16)}"


def same_bits(a: np.ndarray, b: np.ndarray) -> None:
    assert a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


def recording_task(flags: pathlib.Path, hold=None):
    """The worker's task (``_worker.render_block``), which also leaves a file naming the node
    and process that ran it; ``hold(flags)`` (if given) runs first and may wait."""

    def task(key, pack_box, spp, seed, aovs, threads, region, passes):
        from glint.distributed import _worker

        node = os.environ.get(NODE_VARIABLE, "?").rsplit("-", 1)[-1]
        (flags / f"ran-{node}-{os.getpid()}-{region[0]}-{region[1]}-{passes[0]}").touch()
        if hold is not None:
            hold(flags, node)
        return _worker.render_block(key, pack_box, spp, seed, aovs, threads, region, passes)

    return task


def head_waits_for(node_name: str):
    """A ``hold`` for ``recording_task``: the head's first task leaves ``head-held`` and waits
    (at most two minutes) until a task has run on ``node_name``."""

    def hold(flags, node):
        if node == "head" and not any(flags.glob("head-held")):
            (flags / "head-held").touch()
            deadline = time.monotonic() + 120
            while not any(flags.glob(f"ran-{node_name}-*")) and time.monotonic() < deadline:
                time.sleep(0.05)

    return hold


def nodes_that_ran(flags: pathlib.Path) -> set:
    return {m.name.split("-")[1] for m in flags.glob("ran-*")}


def test_a_render_across_two_nodes_on_loopback_is_bit_identical(cluster, tmp_path, monkeypatch):
    # The head's first task waits until a task has run on the second node (at most two
    # minutes): the tasks are small, and on a busy machine the head could otherwise finish
    # them all before the second node's worker has started (seen once under load).
    local = glint.render(cornell(48), spp=8, seed=4)

    monkeypatch.setattr(_worker, "render_block", recording_task(tmp_path, head_waits_for("second")))
    ray.init(address=gd._address(cluster.address), logging_level="WARNING")
    try:
        wait_for_cpus(2)
        r = gd.render(cornell(48), spp=8, seed=4, tile=16, passes_per_task=2)
    finally:
        ray.shutdown()
    same_bits(r.image, local.image)
    assert nodes_that_ran(tmp_path) == {"head", "second"}
    # Every server of both nodes listens on loopback only.
    addresses = listening(node_pids(cluster.head) + node_pids(cluster.second))
    assert addresses and all(a.startswith(("127.", "::ffff:127.", "::1:")) for a in addresses), addresses


DRIVER = """
import sys, time, pathlib
import glint.distributed as gd
from glint.distributed import _worker
flags = pathlib.Path(sys.argv[4])

def task(key, pack_box, spp, seed, aovs, threads, region, passes):
    from glint.distributed import _worker
    if tuple(region[:2]) == (0, 0) and passes[0] == 0:
        # The first task never ends: the render is certainly unfinished when the driver dies.
        while not (flags / "release").exists():
            time.sleep(0.05)
    return _worker.render_block(key, pack_box, spp, seed, aovs, threads, region, passes)

_worker.render_block = task
gd.render(sys.argv[1], spp=6, seed=9, tile=8, passes_per_task=2, address=sys.argv[2], checkpoint=sys.argv[3],
          checkpoint_every=0.1)
"""


def test_a_driver_killed_mid_render_resumes_from_its_checkpoint(cluster, cli, tmp_path):
    # The driver is a process of its own, started as a user would (no RAY_AUTH_MODE: it
    # must find the token itself), and SIGKILLed once its checkpoint holds some blocks.
    d = cornell_dict(24)
    scene = tmp_path / "scene.json"
    d["shapes"] = [dict(s, file=str(ROOT / "scenes" / s["file"])) if "file" in s else s for s in d["shapes"]]
    scene.write_text(json.dumps(d))
    ck = tmp_path / "render.film"
    env = {k: v for k, v in os.environ.items() if k not in ("RAY_AUTH_MODE", "RAY_ADDRESS")}
    env.update(RAY_USAGE_STATS_ENABLED="0", RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER="0")
    log = tmp_path / "driver.log"
    with open(log, "w") as err:
        driver = subprocess.Popen([sys.executable, "-c", DRIVER, str(scene), cluster.address, str(ck), str(tmp_path)],
                                  env=env, stderr=err)
    try:
        deadline = time.monotonic() + 120
        while not ck.exists():
            assert driver.poll() is None, f"the driver ended early: {log.read_text()}"
            assert time.monotonic() < deadline, "no checkpoint written"
            time.sleep(0.05)
        driver.send_signal(signal.SIGKILL)
        driver.wait()
    finally:
        (tmp_path / "release").touch()  # the held task's worker ends
        if driver.poll() is None:
            driver.kill()
            driver.wait()
    local = tmp_path / "local.pfm"
    subprocess.run([str(cli), "render", str(scene), "-o", str(local), "--spp", "6", "--seed", "9", "--quiet"],
                   check=True)
    out = tmp_path / "resumed.pfm"
    ray.init(address=gd._address(cluster.address), logging_level="WARNING")
    try:
        r = gd.render(scene, spp=6, seed=9, tile=8, passes_per_task=2, out=out, resume=ck)
    finally:
        ray.shutdown()
    assert 0 < r.stats["tasks"] < 27  # only what the checkpoint lacked
    assert out.read_bytes() == local.read_bytes()


def test_the_second_node_killed_mid_render_changes_nothing(cluster, tmp_path, monkeypatch):
    # Its first task waits until the node is killed, raylet and workers, by process id: the
    # node is certainly at work when it dies. Its tasks run again on the head.
    local = glint.render(cornell(48), spp=8, seed=5)
    killed: list = []

    def hold(flags, node):
        if node == "second":
            deadline = time.monotonic() + 120
            while time.monotonic() < deadline:
                time.sleep(0.05)

    def killer():
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and not any(tmp_path.glob("ran-second-*")):
            time.sleep(0.02)
        killed.extend(kill_node(cluster.second))

    monkeypatch.setattr(_worker, "render_block", recording_task(tmp_path, hold))
    ray.init(address=gd._address(cluster.address), logging_level="WARNING")
    try:
        wait_for_cpus(2)
        t = threading.Thread(target=killer, daemon=True)
        t.start()
        r = gd.render(cornell(48), spp=8, seed=5, tile=16, passes_per_task=2)
        t.join()
    finally:
        ray.shutdown()
    assert killed and not node_pids(cluster.second)
    same_bits(r.image, local.image)
    assert r.stats["tasks"] == 9 * 4


def test_a_node_that_joins_mid_render_gets_work(cluster, tmp_path, monkeypatch):
    # The head's first task waits until a task has run on the new node (at most two
    # minutes): the render is certainly under way when the node joins.
    assert not node_pids(cluster.second)
    local = glint.render(cornell(32), spp=8, seed=6)

    started = threading.Event()

    def join():
        while not any(tmp_path.glob("head-held")):
            time.sleep(0.05)
        cluster.start("joined")
        started.set()

    monkeypatch.setattr(_worker, "render_block", recording_task(tmp_path, head_waits_for("joined")))
    ray.init(address=gd._address(cluster.address), logging_level="WARNING")
    try:
        wait_for_cpus(1)
        t = threading.Thread(target=join, daemon=True)
        t.start()
        r = gd.render(cornell(32), spp=8, seed=6, tile=16, passes_per_task=2)
        t.join()
    finally:
        ray.shutdown()
    assert started.is_set() and "joined" in nodes_that_ran(tmp_path)
    same_bits(r.image, local.image)
