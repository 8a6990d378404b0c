"""The learner image (course/containers/Containerfile) with podman, and the class on containers: `make test-containers`.

The image is built first (``make image``: warm, from the uv cache).  Then, in it: Step 2 at real time, with
no network but its own loopback; Steps 1 to 5 without any OpenGL library, and the camera saying what to
install; two containers in one ROS domain, apart each in its own network namespace and together with the
host's network and shared memory; and ``make hub-containers`` (DockerSpawner through podman's API) with two
learners logged in through the hub, each driving their own tank and drawing their own live view in a
Chromium context of their own.  Every container, network and volume a test makes is removed, also on
failure, and IP forwarding is put back as it was (netavark turns it on).  Root only (podman here needs it).
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from conftest import ROOT

sys.path.insert(0, str(Path(__file__).parent))
from hub import (  # noqa: E402
    PASSWORD,
    SUBMIT,
    Learner,
    free_port_block,
    grading_leaves_out_the_forgery,
    open_live_notebook,
    require_live_view_draws,
    submit_as,
)

pytestmark = [pytest.mark.slow, pytest.mark.cross_process]

IMAGE = "localhost/ros-tank-tutorial:learner"
CONF = ROOT / "course" / "containers" / "containers.conf"
DOMAIN = os.environ["ROS_DOMAIN_ID"]  # this test session's own (tests/conftest.py)
LIBRARIES = ["/usr/lib/x86_64-linux-gnu/libEGL.so.1", "/usr/lib/x86_64-linux-gnu/libOpenGL.so.0"]


def podman(*args: str, timeout: float = 120, check: bool = True) -> subprocess.CompletedProcess:
    env = dict(os.environ, CONTAINERS_CONF=str(CONF))
    return subprocess.run(["podman", *args], capture_output=True, text=True, timeout=timeout, env=env, check=check)


def run_in_image(*command: str, options: tuple[str, ...] = ("--network", "none"), timeout: float = 120):
    """``command`` in a throwaway container of the image, in this session's ROS domain."""
    domain = ("-e", f"ROS_DOMAIN_ID={DOMAIN}")
    return podman("run", "--rm", *options, *domain, IMAGE, *command, timeout=timeout, check=False)


@pytest.fixture(scope="module", autouse=True)
def image():
    """The image, built (or found up to date) by ``make image``; IP forwarding put back afterwards."""
    if os.geteuid() != 0 or not shutil.which("podman"):
        pytest.skip("the learner image needs root and podman (make test-containers installs it)")
    forward = Path("/proc/sys/net/ipv4/ip_forward").read_text()
    try:
        started = time.monotonic()
        subprocess.run(["make", "image"], cwd=ROOT, check=True, timeout=1800, capture_output=True)
        print(f"make image: {time.monotonic() - started:.0f} s")
        size = json.loads(podman("image", "inspect", IMAGE).stdout)[0]["Size"]
        print(f"the learner image: {size / 1e9:.2f} GB")
        yield
    finally:
        Path("/proc/sys/net/ipv4/ip_forward").write_text(forward)


def summary(out: str) -> dict:
    return [json.loads(line) for line in out.splitlines() if line.startswith('{"event": "summary"')][-1]


def test_step_2_runs_in_the_image_at_real_time():
    r = run_in_image("rtt-run", "/opt/rtt/project/step2.yaml", "--headless", "--json", "--duration", "5")
    assert r.returncode == 0, r.stderr[-2000:]
    assert summary(r.stdout)["real_time_factor"] >= 0.99, r.stdout[-1000:]


def test_without_opengl_libraries_steps_1_to_5_run_and_the_camera_says_what_to_install():
    from tutorial import NO_OPENGL

    hide = tuple(x for lib in LIBRARIES for x in ("-v", f"/dev/null:{lib}:ro"))
    for step in ("step1", "step2", "step3", "step4", "step5"):
        r = run_in_image(
            "rtt-run", f"/opt/rtt/project/{step}.yaml", "--headless", "--json", "--duration", "1",
            options=("--network", "none", *hide),
        )  # fmt: skip
        assert r.returncode == 0, (step, r.stderr[-2000:])
        said = summary(r.stdout)  # steps 3 and 5 are viewers: they simulate nothing
        assert said.get("simulated_time", 1.0) == 1.0 and said["controllers"], (step, said)
    r = run_in_image(
        "rtt-run", "/opt/rtt/project/step6.yaml", "--headless", "--duration", "1", options=("--network", "none", *hide)
    )
    assert r.returncode == 1, r.stdout + r.stderr
    assert r.stderr.strip().splitlines()[0].endswith(NO_OPENGL), r.stderr


# What the second container runs: the node names it finds in its ROS domain within 8 s.
LOOK = (
    "import time, rclpy\nrclpy.init()\nnode = rclpy.create_node('look')\nseen = set()\n"
    "end = time.monotonic() + 8\n"
    "while time.monotonic() < end:\n"
    "    rclpy.spin_once(node, timeout_sec=0.2)\n"
    "    seen.update(n for n, _ in node.get_node_names_and_namespaces())\n"
    "print(sorted(seen))\n"
)


@pytest.mark.parametrize(
    "options, sees",
    [(("--network", "none"), False), (("--network", "host", "--ipc", "host"), True)],
    ids=["own-network-namespaces", "host-network-and-ipc"],
)
def test_two_containers_in_one_domain(options, sees):
    name = f"rtt-sim-{os.getpid()}"
    podman(
        "run", "--detach", "--rm", "--name", name, *options, "-e", f"ROS_DOMAIN_ID={DOMAIN}", IMAGE,
        "rtt-run", "/opt/rtt/project/step2.yaml", "--headless", "--duration", "30",
    )  # fmt: skip
    try:
        r = run_in_image("python", "-c", LOOK, options=options)
        assert r.returncode == 0, r.stderr[-2000:]
        assert ("'rtt'" in r.stdout) is sees, r.stdout
    finally:
        podman("rm", "--force", "--time", "0", name, check=False)


# ---- the class on containers: make hub-containers ----

DRIVE = """
import json, os, subprocess, time
import rclpy
sim = subprocess.Popen(["rtt-run", "/opt/rtt/project/step2.yaml", "--headless", "--json", "--duration", "7"],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
joy = subprocess.Popen(["rtt-joy", "--demo", "--duration", "5"], stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL) if {with_joy} else None
out, _ = sim.communicate(timeout=120)
if joy: joy.wait(60)
summary = [json.loads(x) for x in out.splitlines() if x.startswith('{{"event": "summary"')][-1]
print(json.dumps({{"domain": os.environ.get("ROS_DOMAIN_ID"), "rtf": summary["real_time_factor"],
                  "root": summary["bodies"]["Tank"]["root_position"]}}))
"""


# A demo joystick started from the learner's kernel, left running while the test watches the views.
JOY_IN_THE_BACKGROUND = """
import subprocess
subprocess.Popen(["rtt-joy", "--demo", "--duration", "20"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
print("driving")
"""


@contextlib.contextmanager
def hub_on_containers(tmp_path: Path, learners: list[str]):
    """``make hub-containers``'s script on a free port, a network of this test's own and a state folder of its
    own; stopped afterwards with all it made (the learners' home volumes too)."""
    port = free_port_block()
    network = f"rtt-test-{os.getpid()}"
    env = dict(
        os.environ,
        RTT_HUB_URL=f"http://127.0.0.1:{port}",
        RTT_HUB_STATE=str(tmp_path / "hub"),
        RTT_HUB_LEARNERS=",".join(learners),
        RTT_HUB_PASSWORD=PASSWORD,
        RTT_HUB_CONTAINER_NETWORK=network,
        RTT_HUB_CONTAINER_DOMAIN=DOMAIN,
    )
    log = open(tmp_path / "hub.log", "w")  # noqa: SIM115 - closed below
    proc = subprocess.Popen(
        ["bash", str(ROOT / "scripts" / "hub-containers.sh")], cwd=ROOT, env=env, stdout=log,
        stderr=subprocess.STDOUT, start_new_session=True,
    )  # fmt: skip
    hub = type("HubOnContainers", (), {"url": f"http://127.0.0.1:{port}", "port": port, "log": tmp_path / "hub.log"})
    try:
        import requests

        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            assert proc.poll() is None, (tmp_path / "hub.log").read_text()[-3000:]
            with contextlib.suppress(requests.ConnectionError):
                if requests.get(hub.url + "/hub/login", timeout=2).status_code == 200:
                    break
            time.sleep(0.5)  # polling the hub's page, within the deadline
        else:
            raise RuntimeError("the hub on containers did not answer: " + (tmp_path / "hub.log").read_text()[-3000:])
        yield hub
    finally:
        os.killpg(proc.pid, signal.SIGINT)  # as Ctrl-C in its terminal: the hub stops the learners' containers
        try:
            proc.wait(90)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(10)
        log.close()
        left = podman("ps", "--all", "--format", "{{.Names}}").stdout.split()
        for name in left:
            if name.startswith(("jupyter-learner", f"{network}-keeper")):
                podman("rm", "--force", "--time", "0", name, check=False)
        podman("network", "rm", "--force", network, check=False)
        for volume in podman("volume", "ls", "--format", "{{.Name}}").stdout.split():
            if volume.startswith("rtt-home-learner"):
                podman("volume", "rm", "--force", volume, check=False)
        assert not [n for n in left if n.startswith("jupyter-learner")], f"the hub left containers: {left}"


def home_volume_of(name: str) -> Path:
    """Where this machine keeps the home volume of the running container of the hub's learner ``name``."""
    for container in podman("ps", "--format", "{{.Names}}").stdout.split():
        info = json.loads(podman("inspect", container).stdout)[0]
        if f"JUPYTERHUB_USER={name}" in info["Config"]["Env"]:
            return Path(next(m["Source"] for m in info["Mounts"] if m["Destination"] == "/home/jovyan"))
    raise AssertionError(f"no running container of {name}")


def learners_own_their_files(learners: list[Learner], course: Path) -> None:
    """Each learner's container runs as jovyan (1000) inside, and as a uid of that learner's alone on this
    machine (a user namespace each: course/jupyterhub_containers_config.py): their home volume's files and
    their folder of the exchange are that uid's, not uid 1000's, and not the other learner's."""
    owners = {}
    for learner in learners:
        assert learner.run("import os\nprint(os.getuid(), os.getgid())").strip() == "1000 1000"
        home = home_volume_of(learner.name)
        owners_there = {(p.lstat().st_uid, p.lstat().st_gid) for p in [home, *home.rglob("*")]}
        folder = (course / "inbound-by-learner" / learner.name).lstat()
        inbound = folder.st_uid
        assert owners_there == {(inbound, inbound)} == {(folder.st_uid, folder.st_gid)}, (learner.name, owners_there)
        owners[learner.name] = inbound
    print(f"this machine's uids for the learners' jovyan: {owners}")
    assert len(set(owners.values())) == len(learners) and all(uid >= 1 << 24 for uid in owners.values()), owners


def test_a_class_on_containers(tmp_path):
    import nbformat
    from playwright.sync_api import sync_playwright

    from tests.jupyterlab import CHROMIUM, CHROMIUM_FLAGS
    from tests.lab_browser import changed, moving, step2_notebook, wait_for

    names = ["learner-a", "learner-b"]
    with hub_on_containers(tmp_path, names) as hub:
        learners = [Learner(hub, name) for name in names]
        for learner in learners:
            assert learner.log_in().status_code == 302, hub.log.read_text()[-2000:]
            started = time.monotonic()
            learner.start_server(timeout=180)
            print(f"{learner.name}'s container answered through the hub in {time.monotonic() - started:.1f} s")
        learners_own_their_files(learners, tmp_path / "hub" / "exchange" / "ros-tank-tutorial")
        # Both drive at once, in the same ROS domain, each in a container of their own: A's joystick drives
        # A's tank only.
        results, errors = {}, []

        def drive(learner, with_joy):
            try:
                out = learner.run(DRIVE.format(with_joy=with_joy), timeout=180)
                results[learner.name] = json.loads(out.strip().splitlines()[-1])
            except BaseException as exc:  # noqa: BLE001 - collected and asserted below
                errors.append(exc)

        threads = [threading.Thread(target=drive, args=(x, x.name == "learner-a")) for x in learners]
        for t in threads:
            t.start()
        for t in threads:
            t.join(240)
        assert not errors, errors
        a, b = results["learner-a"], results["learner-b"]
        assert a["domain"] == b["domain"] == DOMAIN
        moved = {k: sum(x * x for x in r["root"][:2]) ** 0.5 for k, r in results.items()}
        assert moved["learner-a"] > 0.2 and moved["learner-b"] < 0.001, results
        assert a["rtf"] >= 0.99 and b["rtf"] >= 0.99, results
        # nbgrader's exchange: each fetches and submits; A also submits under B's name.  B's container sees only
        # B's submissions; grading gathers each one's own and refuses A's forgery (course/container_exchange.py).
        exchange = tmp_path / "hub" / "exchange" / "ros-tank-tutorial"
        (exchange / "outbound" / "hello").mkdir(parents=True, exist_ok=True)
        nbformat.write(nbformat.v4.new_notebook(), exchange / "outbound" / "hello" / "hello.ipynb")
        (exchange / "outbound" / "hello").chmod(0o755)
        for learner in learners:
            assert learner.run(SUBMIT, timeout=180).strip() == "submitted"
        a, b = learners
        assert a.run(submit_as(b.name)).strip() == "submitted"
        seen_by_b = b.run(
            f"import os\nprint(sorted(n.split('+')[0] for n in os.listdir({str(exchange / 'inbound')!r})))"
        )
        assert seen_by_b.strip() == "['learner-b']", seen_by_b
        grading_leaves_out_the_forgery(tmp_path / "teacher", exchange.parent, "learner-a", "learner-b")
        stats = json.loads(podman("stats", "--no-stream", "--format", "json").stdout or "[]")
        for s in stats:
            if s.get("name", "").startswith("jupyter-learner"):
                print(f"{s['name']}: memory {s.get('mem_usage', '?')}")
        # Each learner in a browser context of their own: a notebook of Step 2 with its live view, put in
        # their home through their server's API, draws.
        for learner in learners:
            path = tmp_path / f"{learner.name}.ipynb"
            step2_notebook(path)
            content = json.loads(path.read_text())
            r = learner.api("PUT", "api/contents/live.ipynb", json={"type": "notebook", "format": "json",
                                                                    "content": content})  # fmt: skip
            assert r.status_code in (200, 201), r.text[:500]
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_FLAGS)
            try:
                pages = {}
                for name in names:
                    pages[name] = open_live_notebook(browser, hub.url, name)
                    require_live_view_draws(pages[name], name)
                stats = json.loads(podman("stats", "--no-stream", "--format", "json").stdout or "[]")
                for s in stats:  # the same work as make test-hub's figure for a learner's server (book/course.md)
                    if s.get("name", "").startswith("jupyter-learner"):
                        print(f"{s['name']}, Step 2 and its live view running: memory {s.get('mem_usage', '?')}")
                # A's demo joystick, in A's container: A's view shows A's tank driving; B's tank stands still.
                assert a.run(JOY_IN_THE_BACKGROUND).strip() == "driving"
                moved = wait_for(pages["learner-a"], lambda: moving(pages["learner-a"]), "A's view moving", 30)
                still = changed(pages["learner-b"])
                print(f"pixels changed in 1 s: A's view {moved}, B's view {still}")
                assert still < 200, still
            finally:
                browser.close()
        log = hub.log.read_text()
        assert re.search(r"Hub API listening on http://10\.\d+\.\d+\.1:", log), log[-2000:]
