"""A class on one server: ``make hub``'s configuration gives each learner's robots to that learner alone.

Two learners log in through the hub and start their servers; each server's
environment carries the learner's own ROS domain, and what each learner's
kernel starts (the Step 2 simulation, a joystick) lives in that domain: A's
joystick drives A's tank and not B's, and neither sees the other's nodes.
Both run as this machine's one Unix user (the trial's spawner), where Fast
DDS's shared memory would carry data between them if their domains met.
Then a learner logs in through the hub's form in a Chromium context of
their own and runs a notebook with Step 2's live view, which draws (both
learners, each in a context of their own, in make test-more).
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from conftest import ROOT

sys.path.insert(0, str(ROOT / "course"))

from domains import LEARNER_DOMAINS, DomainBook, DomainError, running_hub  # noqa: E402
from hub import (  # noqa: E402
    PASSWORD,
    SUBMIT,
    Hub,
    KernelDied,
    Learner,
    grading_leaves_out_the_forgery,
    open_live_notebook,
    require_live_view_draws,
    submit_as,
)

from netns import net, on  # noqa: E402,F401 - net: the network tier's fixture

# Two domains of the upper block (215-232), picked per test session: the test sessions' own are 1-100.
_FIRST = 215 + (os.getpid() % 9) * 2
DOMAINS = (_FIRST, _FIRST + 1)

# What a learner's kernel runs: the Step 2 simulation (and with a joystick, its demo) for a few seconds,
# then the summary of where the tank ended and which nodes this learner's graph held meanwhile.
DRIVE_S = 5  # s of simulated time a learner's drive lasts (the joystick 4 s of it), and the undriven run
DRIVE = """
import json, os, subprocess, sys, time
import rclpy
venv = os.path.dirname(sys.executable)
sim = subprocess.Popen([os.path.join(venv, "rtt-run"), "{root}/project/step2.yaml", "--headless", "--json",
                        "--duration", "{drive_s}"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
joy = subprocess.Popen([os.path.join(venv, "rtt-joy"), "--demo", "--duration", "4"],
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) if {with_joy} else None
rclpy.init()
node = rclpy.create_node("graph_look")
seen = set()
deadline = time.monotonic() + 4
while time.monotonic() < deadline:
    rclpy.spin_once(node, timeout_sec=0.2)
    seen.update(n for n, _ in node.get_node_names_and_namespaces())
node.destroy_node(); rclpy.shutdown()
out, _ = sim.communicate(timeout=120)
if joy: joy.wait(60)
lines = [json.loads(l) for l in out.splitlines() if l.startswith("{{")]
summary = [l for l in lines if l.get("event") == "summary"][-1]
warnings = [l for l in lines if l.get("event") == "warning"]
print(json.dumps({{"domain": os.environ.get("ROS_DOMAIN_ID"), "nodes": sorted(seen),
                  "root": summary["bodies"]["Tank"]["root_position"], "warnings": warnings}}))
"""


TEACHER_PASSWORD = "the-teachers-own-password-of-32-characters"


@pytest.fixture
def hub(tmp_path):
    teacher = {"RTT_HUB_TEACHER": "teacher", "RTT_HUB_TEACHER_PASSWORD": TEACHER_PASSWORD}
    h = Hub(tmp_path / "hub", ["learner-a", "learner-b", "learner-c"], DOMAINS, teacher)  # two domains, three learners
    yield h
    h.close()
    assert h.cgroups_left == [], "a learner's server stopped without removing its cgroups (course/limits.py)"


# A learner's cell that asks for 8 GiB, every page touched, stopping itself there (a limit must stop it sooner:
# a missing limit fails the test, it does not take the machine down).
MEMORY_HOG = """
import numpy as np
held = [np.ones(256 * 2**20, dtype=np.uint8) for _ in range(32)]
print(f"held {len(held) / 4:.2f} GiB")
del held
"""


def run_drive(learner: Learner, with_joy: bool) -> dict:
    out = learner.run(DRIVE.format(root=ROOT, with_joy=with_joy, drive_s=DRIVE_S), timeout=180)
    return json.loads(out.strip().splitlines()[-1])


@pytest.mark.cross_process
@pytest.mark.parametrize(
    "in_browsers",
    [
        pytest.param(("learner-a",), id="one-browser"),
        # make test: A's live view and A's rtt-run page in a browser, B kept off A's page by the proxy (the API's
        # 403s below); the more tier has each learner in a browser of their own, both views drawing at once
        pytest.param(("learner-a", "learner-b"), id="two-browsers", marks=pytest.mark.more),
    ],
)
def test_each_learners_robots_are_their_own(hub, in_browsers):
    a, b = Learner(hub, "learner-a"), Learner(hub, "learner-b")
    for learner in (a, b):
        assert learner.log_in().status_code == 302, hub.log()[-2000:]
    # both ask at once, as a class does (the hub answers a request when its server is up, or after 10 s)
    with ThreadPoolExecutor(2) as pool:
        list(pool.map(Learner.request_server, (a, b)))
    for learner in (a, b):
        learner.start_server()
    env_a = json.loads(a.run("import os, json; print(json.dumps(dict(os.environ)))"))
    env_b = json.loads(b.run("import os, json; print(json.dumps(dict(os.environ)))"))
    assert {env_a["ROS_DOMAIN_ID"], env_b["ROS_DOMAIN_ID"]} == {str(d) for d in DOMAINS}
    assert env_a["RTT_ASSIGNED_ROS_DOMAIN_ID"] == env_a["ROS_DOMAIN_ID"]
    assert env_a["ROS_AUTOMATIC_DISCOVERY_RANGE"] == env_b["ROS_AUTOMATIC_DISCOVERY_RANGE"] == "LOCALHOST"
    assert env_a["RTT_FRAME_RATE"] == "20"  # a class's server: live views at 20 frames/s (the Benchmarks page)
    assert env_a["RTT_REALTIME_SLICE_MS"] == "10"  # ... and its simulations wake up every 10 ms, not every step
    book = json.loads((hub_state(hub) / "ros_domains.json").read_text())
    assert book == {"learner-a": int(env_a["ROS_DOMAIN_ID"]), "learner-b": int(env_b["ROS_DOMAIN_ID"])}
    given = hub_state(hub) / "homes" / "learner-a" / "notebooks" / "01_step1_tank_controller.ipynb"
    assert given.is_file()
    assert "Worked solution to Exercise" not in given.read_text()  # held back, as in the graded assignments
    # A terminal of the learner's JupyterLab runs the notebooks' "Outside Jupyter" commands: the rtt-* programs
    # on its PATH, the learner's domain, their own copy of project/ in the home folder it opens in.
    said = a.terminal("command -v rtt-run; echo domain=$ROS_DOMAIN_ID; ls project/step1.yaml; echo en''d.", "end.\r")
    assert "/rtt-run\r" in said and f"domain={env_a['ROS_DOMAIN_ID']}\r" in said, said
    assert "project/step1.yaml\r" in said and "No such file" not in said, said
    both_submit_under_their_own_names(hub, [a, b])
    # The teacher's account sees the learners' servers on the hub's admin page; a learner is refused it, and the
    # shared password is no teacher's.
    teacher = Learner(hub, "teacher")
    assert teacher.log_in().status_code != 302 and teacher.log_in(TEACHER_PASSWORD).status_code == 302
    users = teacher.http.get(f"{hub.url}/hub/api/users", headers={"X-XSRFToken": teacher._xsrf()}, timeout=30)
    servers = {u["name"]: bool(u["servers"]) for u in users.json()}
    assert servers["learner-a"] and servers["learner-b"] and not servers["teacher"], servers
    assert a.http.get(f"{hub.url}/hub/admin", timeout=30).status_code == 403

    # A third learner finds no domain left: told why, given no server, and A and B run on undisturbed.
    c = Learner(hub, "learner-c")
    c.log_in()
    refused = c.request_server()  # the hub's API: 503, the server cannot be had, with the reason
    assert refused.status_code == 503 and "no ROS domain left for learner-c" in refused.text, refused.text
    with pytest.raises(RuntimeError):
        c.start_server(timeout=30)
    assert "no ROS domain left for learner-c" in hub.log()
    assert "no ROS domain left for learner-c" in c.server_error(), c.server_error()  # on the learner's page
    page = c.http.get(f"{hub.url}/hub/spawn-pending/learner-c", timeout=30).text  # the page a browser shows
    assert "no ROS domain left for learner-c" in page and "Unhandled error" not in page, page[-2000:]

    # Both drive at once: B's kernel runs its drive while A's runs in a thread of this test.
    import threading

    results, errors = {}, []

    def drive(name, learner, with_joy):
        try:
            results[name] = run_drive(learner, with_joy)
        except BaseException as exc:  # noqa: BLE001 - collected and asserted below
            errors.append(exc)

    threads = [
        threading.Thread(target=drive, args=("a", a, True)),
        threading.Thread(target=drive, args=("b", b, False)),
    ]
    for t in threads:
        t.start()
    for t in threads:
        t.join(240)
    assert not errors, errors
    ra, rb = results["a"], results["b"]
    rest = undriven_root()
    moved_a = sum((x - y) ** 2 for x, y in zip(ra["root"], rest)) ** 0.5
    moved_b = sum((x - y) ** 2 for x, y in zip(rb["root"], rest)) ** 0.5
    assert moved_a > 0.2, ra  # A's joystick drove A's tank
    assert moved_b < 0.001, rb  # ... and not B's
    assert "rtt_joy" in ra["nodes"] and "rtt_joy" not in rb["nodes"], (ra["nodes"], rb["nodes"])
    assert rb["nodes"].count("rtt") == 1 and ra["nodes"].count("rtt") == 1
    assert ra["warnings"] == [] and rb["warnings"] == []  # no "2 nodes are named /rtt"

    # B's kernel asks for 8 GiB: the memory limit of B's server (course/limits.py) stops that kernel alone.
    if os.geteuid() == 0:  # the limits need root (cgroups); a trial without root has none
        assert "learner learner-b: at most 2.0 GiB, 500 processes, an equal share of the CPU" in hub.log()
        with pytest.raises(KernelDied):
            b.run(MEMORY_HOG, timeout=120)
        said = b.run("from tutorial.notebook.session import init_ros\ninit_ros()")  # the first cell, run again
        assert "more than its memory limit (2.0 GiB)" in said, said
        assert a.run("print(40 + 2)").strip() == "42"  # A's kernel and server never noticed

    # rtt-run's own meshcat page, started from A's terminal as the notebooks' "Outside Jupyter" sections say:
    # its line names the page on the hub's address, through A's Jupyter (jupyter-server-proxy).
    said = a.terminal(
        "nohup rtt-run project/step3.yaml --duration 120 --ros-args -r __node:=rtt_viewer > rtt-run.log 2>&1 & "
        "echo pid=$!; until grep -q 'in a browser' rtt-run.log; do sleep 0.2; done; cat rtt-run.log; echo en''d.",
        "end.\r",
        timeout=90,
    )
    page = re.search(r"JupyterHub's address followed by (/user/learner-a/proxy/(\d+)/static/) in a browser", said)
    pid = re.search(r"pid=(\d+)", said)
    assert page and pid, said
    try:
        # B's own Jupyter does not proxy A's page (course/own_ports.py), by any of its routes; A's does.
        port = page.group(2)
        routes = [f"proxy/{port}/static/", f"proxy/absolute/{port}/static/", f"proxy/localhost:{port}/static/",
                  f"proxy/127.0.0.1:{port}/static/"]  # fmt: skip
        for learner, route, status in [*((b, route, 403) for route in routes), (a, routes[0], 200)]:
            r = learner.api("GET", route)
            assert r.status_code == status, (learner.name, route, r.status_code, r.text[:300])
        # A learner in a browser (each in one of their own, two-browsers): logged in through the hub's form, a
        # notebook that starts Step 2 with its live view; each view gets its scene over its own notebook's
        # connection and draws.
        live_views_draw(hub, list(in_browsers), rtt_run_page=("learner-a", page.group(1)))
    finally:
        a.terminal(f"kill {pid.group(1)}; echo en''d.", "end.\r")


# What a learner's kernel runs to hand in an assignment: nbgrader's own commands, in their home, with the
# configuration the hub gives their server (the course and its exchange).
def both_submit_under_their_own_names(hub: Hub, learners: list[Learner]) -> None:
    """Each learner fetches and submits a released assignment: the exchange holds one submission per learner,
    named after the hub's learner (the trial's learners share one Unix user, whose name nbgrader would use)."""
    import nbformat

    course = hub_state(hub) / "exchange" / "ros-tank-tutorial"
    made = course.lstat()  # by the hub before any learner could (a learner's would stop grading)
    assert (made.st_uid, made.st_mode & 0o7777) == (os.geteuid(), 0o755)
    (course / "outbound" / "hello").mkdir(parents=True)
    (course / "inbound").mkdir(mode=0o733)  # as nbgrader's release makes it: learners write, only the teacher lists
    (course / "inbound").chmod(0o733)  # past the umask
    nbformat.write(nbformat.v4.new_notebook(), course / "outbound" / "hello" / "hello.ipynb")
    with ThreadPoolExecutor(len(learners)) as pool:  # at once, as a class hands in
        said = list(pool.map(lambda learner: learner.run(SUBMIT, timeout=180), learners))
    assert all(s.strip().endswith("submitted") for s in said), said
    handed_in = sorted(p.name.split("+")[0] for p in (course / "inbound").iterdir())
    assert handed_in == sorted(learner.name for learner in learners), handed_in


def live_views_draw(hub: Hub, names: list[str], rtt_run_page: tuple[str, str]) -> None:
    """In one Chromium, a context (cookies) per learner of ``names``: log in, run a live view, see it draw; and
    the page of a learner's ``rtt-run`` (``(learner, path on the hub)``) draws for that learner, and for no
    other of ``names`` (with one name: the caller holds the others off by the hub's API)."""
    from playwright.sync_api import expect, sync_playwright

    from tests.jupyterlab import CHROMIUM, CHROMIUM_FLAGS
    from tests.lab_browser import step2_notebook

    for name in names:
        step2_notebook(hub_state(hub) / "homes" / name / "live.ipynb")
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_FLAGS)
        try:
            pages = {name: open_live_notebook(browser, hub.url, name) for name in names}
            # A learner's Nbgrader menu: their assignments, and none of the teacher's tools (no formgrader)
            page = pages[names[-1]]
            page.locator(".lm-MenuBar-itemLabel", has_text="Nbgrader").click()
            menu = page.locator(".lm-Menu-itemLabel")
            expect(menu.filter(has_text="Assignment List")).to_have_count(1)
            assert menu.filter(has_text="Formgrader").count() == 0, menu.all_inner_texts()
            page.keyboard.press("Escape")
            assert page.locator(".jp-Toolbar-item", has_text="Validate").count() == 0, "a Validate button is shown"
            for name, page in pages.items():
                require_live_view_draws(page, name)
            owner, path = rtt_run_page
            page = pages[owner]
            page.goto(hub.url + path)
            # meshcat's page, its WebSocket found under the proxy's path (tutorial/view/meshcat_page.py): the tank
            page.wait_for_function(
                "window.viewer && Object.keys(viewer.scene_tree.find(['meshcat', 'rtt', 'Tank', 'CHASSIS']).children)"
                ".length > 0",
                timeout=60_000,
            )
            for name in set(pages) - {owner}:  # the hub lets no other learner through to it
                other = pages[name]
                other.goto(hub.url + path)
                assert other.evaluate("typeof window.viewer") == "undefined", f"{name} opened {owner}'s page"
        finally:
            browser.close()


def hub_state(hub: Hub):
    return hub.log_path.parent


def undriven_root() -> list[float]:
    """Where the Step 2 tank's root ends after DRIVE_S s with no joystick (run here, in the test's own domain)."""
    import subprocess

    rtt_run = os.path.join(os.path.dirname(sys.executable), "rtt-run")
    out = subprocess.run(
        [rtt_run, str(ROOT / "project" / "step2.yaml"), "--headless", "--json", "--fast", "--duration", str(DRIVE_S)],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    ).stdout
    [summary] = [json.loads(line) for line in out.splitlines() if '"event": "summary"' in line]
    return summary["bodies"]["Tank"]["root_position"]


@pytest.mark.unit
def test_a_learner_the_book_cannot_hold_is_told_why_and_no_one_else_is_disturbed(tmp_path):
    book = DomainBook(tmp_path / "d.json", domains=(7, 8))
    assert book.domain_for("ada") == 7 and book.domain_for("grace") == 8
    assert book.domain_for("ada") == 7  # kept across restarts
    with pytest.raises(DomainError, match=r"no ROS domain left for linus: .* its 2 domains .* several servers"):
        book.domain_for("linus")
    with pytest.raises(DomainError, match="cannot be given a ROS domain"):
        book.domain_for("Robert'); DROP")
    assert book.read() == {"ada": 7, "grace": 8}  # the refusals changed nothing
    assert DomainBook(tmp_path / "d.json", domains=(7, 8), per_learner_network=True).domain_for("linus") == 7
    (tmp_path / "bad.json").write_text("[1, 2]")
    with pytest.raises(DomainError, match="not a book of ROS domains"):
        DomainBook(tmp_path / "bad.json").domain_for("ada")


@pytest.mark.slow
@pytest.mark.cross_process
@pytest.mark.skipif(not os.environ.get("RTT_TEST_JUPYTERHUB"), reason="RTT_TEST_JUPYTERHUB names no other JupyterHub")
def test_a_hub_of_the_charts_jupyterhub_version_serves_this_learners_server(tmp_path):
    """Zero to JupyterHub's chart runs its own JupyterHub (5.5 for chart 4.x); the image's learner server is the
    lock's: a learner logs in through that hub, runs code, and their live view draws in a browser (the OAuth
    that JupyterHub warns a version mismatch may break).  RTT_TEST_JUPYTERHUB: that hub's ``jupyterhub``
    (book/course.md says how to install it: the tests fetch nothing)."""
    import subprocess

    from playwright.sync_api import sync_playwright

    from tests.jupyterlab import CHROMIUM, CHROMIUM_FLAGS
    from tests.lab_browser import step2_notebook

    other = os.environ["RTT_TEST_JUPYTERHUB"]
    version = subprocess.run([other, "--version"], capture_output=True, text=True, check=True).stdout.strip()
    hub = Hub(tmp_path / "hub", ["learner-a"], DOMAINS[:1], jupyterhub=other)
    try:
        a = Learner(hub, "learner-a")
        assert a.log_in().status_code == 302, hub.log()[-2000:]
        a.start_server()
        ours = a.run("import jupyterhub\nprint(jupyterhub.__version__)").strip()
        print(f"hub {version}, learner's server {ours}")
        assert version.split(".")[0] != ours.split(".")[0], "not another major version: nothing tested"
        step2_notebook(tmp_path / "live.ipynb")
        content = json.loads((tmp_path / "live.ipynb").read_text())
        r = a.api("PUT", "api/contents/live.ipynb", json={"type": "notebook", "format": "json", "content": content})
        assert r.status_code in (200, 201), r.text[:500]
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_FLAGS)
            try:
                require_live_view_draws(open_live_notebook(browser, hub.url, "learner-a"), "learner-a")
            finally:
                browser.close()
    finally:
        hub.close()


@pytest.mark.slow  # make test-hub: make test keeps the hub's one real case, which checks the folder the hub made
@pytest.mark.cross_process
@pytest.mark.skipif(os.geteuid() != 0, reason="a folder of another user's needs root")
def test_a_hub_whose_course_folder_in_the_exchange_a_learner_made_first_does_not_start(tmp_path):
    """A learner who made the course's folder in the exchange before the hub did would own it, and grading
    would refuse the whole course (course/submissions.py): the hub makes it first, or says what to do."""
    taken = tmp_path / "exchange" / "ros-tank-tutorial"
    taken.mkdir(parents=True)
    os.chown(taken, 4242, 4242)  # a learner's uid
    with pytest.raises(RuntimeError, match=r"ros-tank-tutorial is not the hub's \(a link, or someone") as refused:
        Hub(tmp_path, ["learner-a"], DOMAINS, timeout=30).close()  # (closed, should it start: the test fails)
    assert "Move it away" in str(refused.value)  # without it, the hub makes its own (both_submit_under_...)


@pytest.mark.unit
def test_the_domains_a_server_has():
    assert len(LEARNER_DOMAINS) == 119 and 0 not in LEARNER_DOMAINS
    assert max(LEARNER_DOMAINS) == 232 and 102 not in LEARNER_DOMAINS
    # Fast DDS's ports of domain d start at 7400 + 250 d: below Linux's ephemeral range (32768-60999), or
    # above it and below 65536 (ROS 2's documentation, "The ROS_DOMAIN_ID").
    for d in LEARNER_DOMAINS:
        base = 7400 + 250 * d
        assert base + 11 < 32768 or (base > 60999 and base + 11 <= 65535), d  # participant 0 fits


@pytest.mark.unit
def test_a_learner_who_changed_their_domain_is_warned():
    from tutorial.ros.env import assigned_domain_warning

    assert assigned_domain_warning({"RTT_ASSIGNED_ROS_DOMAIN_ID": "12", "ROS_DOMAIN_ID": "12"}) is None
    assert assigned_domain_warning({"ROS_DOMAIN_ID": "5"}) is None  # no hub, no assignment
    text = assigned_domain_warning({"RTT_ASSIGNED_ROS_DOMAIN_ID": "12", "ROS_DOMAIN_ID": "5"})
    assert "gave you ROS domain 12" in text and "ROS_DOMAIN_ID is 5" in text
    assert "gave you ROS domain 12" in assigned_domain_warning({"RTT_ASSIGNED_ROS_DOMAIN_ID": "12"})


@pytest.mark.cross_process
def test_a_domain_changed_by_hand_after_the_first_cell_is_warned_at_init_ros():
    """rclpy.shutdown(), another learner's domain, init_ros(): said (it was checked at import only)."""
    import subprocess
    import sys

    script = (
        "import os, rclpy\n"
        "from tutorial.notebook.session import init_ros\n"
        "init_ros(); rclpy.shutdown()\n"
        "os.environ['ROS_DOMAIN_ID'] = '13'\n"
        "init_ros(); rclpy.shutdown()\n"
    )
    env = dict(os.environ, RTT_ASSIGNED_ROS_DOMAIN_ID=os.environ["ROS_DOMAIN_ID"])
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60, env=env)
    assert done.returncode == 0, done.stderr
    assert done.stderr.count("WARNING: ROS_DOMAIN_ID is 13, but this server gave you") == 1, done.stderr


@pytest.mark.slow  # make test-hub: make test keeps the hub's one real case (two learners, their own domains)
@pytest.mark.network
def test_with_a_network_namespace_each_learners_may_share_a_domain(procs, net):  # noqa: F811 - the fixture
    """Containers or pods: each learner's server in a network namespace of its own, the same ROS domain.

    Both simulations are named /rtt in one domain; each learner's nodes find each other over their own
    loopback (localhost discovery, as the hub sets it), never the other's, though the hosts are linked.
    """
    a, b = net["robot"], net["operator"]
    learner = {"ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}  # what the hub gives every learner's server
    sim_args = ("tutorial.tools.rtt_run", str(ROOT / "project" / "step2.yaml"), "--headless", "--json")
    sim_a = on(procs, a, *sim_args, "--duration", "10", **learner)
    sim_b = on(procs, b, *sim_args, "--duration", "10", **learner)
    joy_a = on(procs, a, "tutorial.tools.rtt_joy", "--demo", "--duration", "6", **learner)
    assert sim_a.wait(90) == 0 and sim_b.wait(90) == 0, (sim_a.err, sim_b.err)
    joy_a.wait(60)
    summary_a, summary_b = sim_a.summary(), sim_b.summary()
    assert summary_a["controllers"]["RttTankController"]["joy_received"] > 10  # A's joystick drove A's tank
    assert summary_b["controllers"]["RttTankController"]["joy_received"] == 0  # ... and nothing reached B's
    assert sim_a.records("warning") == [] and sim_b.records("warning") == []  # neither saw the other /rtt


# ---- learners as Unix users (The Littlest JupyterHub's way): slow (an environment to build), `make test-hub` ----


@pytest.fixture(scope="module")
def shared_environment(tmp_path_factory):
    """The project's environment on Debian's Python, in a folder every user can read (root's own Python cannot)."""
    import shutil
    import stat
    import subprocess

    system_python = shutil.which("python3", path="/usr/bin")
    if os.geteuid() != 0 or not system_python:
        pytest.skip("learners as Unix users need root (to make them) and Debian's /usr/bin/python3")
    for parent in [ROOT, *ROOT.parents]:
        if not parent.stat().st_mode & stat.S_IXOTH:
            pytest.skip(f"other users cannot enter {parent}, where the project is")
    folder = tmp_path_factory.mktemp("learners_env")
    for parent in [folder, *folder.parents]:
        os.chmod(parent, parent.stat().st_mode | stat.S_IXOTH | stat.S_IROTH)
    env = dict(os.environ, UV_PROJECT_ENVIRONMENT=str(folder / "venv"))
    uv = os.path.join(os.path.dirname(sys.executable), "uv")
    subprocess.run(
        [uv, "sync", "--locked", "--inexact", "--all-extras", "--python", system_python, "--quiet"],
        cwd=ROOT,
        env=env,
        check=True,
        timeout=600,
    )
    return folder / "venv" / "bin" / "python"


@pytest.fixture
def unix_learners():
    """Two Unix users of this machine, removed afterwards with everything they ran and owned."""
    import subprocess

    names = [f"rttl{os.getpid() % 100000}{x}" for x in "ab"]
    for name in names:
        subprocess.run(["useradd", "--create-home", "--shell", "/bin/bash", name], check=True, timeout=30)
    try:
        yield names
    finally:
        for name in names:
            subprocess.run(["pkill", "-KILL", "-u", name], timeout=30, check=False)
            subprocess.run(["userdel", "--remove", name], capture_output=True, timeout=30, check=False)


@pytest.mark.slow
@pytest.mark.cross_process
def test_learners_as_unix_users_have_their_own_robots(tmp_path, shared_environment, unix_learners):
    import stat

    # A hub whose state the learners cannot reach (their Jupyter configuration, nbgrader's exchange) refuses
    # to start, rather than start their servers without them.
    users = {"RTT_HUB_SPAWNER": "users", "RTT_HUB_PYTHON": str(shared_environment)}
    said = rf"cannot reach their Jupyter configuration .* other users cannot enter or read {tmp_path}\."
    with pytest.raises(RuntimeError, match=said):
        Hub(tmp_path / "closed", unix_learners, DOMAINS, extra_env=users)
    tmp_path.chmod(tmp_path.stat().st_mode | stat.S_IXOTH)  # its parents are open: shared_environment opened them
    hub = Hub(tmp_path / "hub", unix_learners, DOMAINS, extra_env=users)
    try:
        a, b = (Learner(hub, name) for name in unix_learners)
        for learner in (a, b):
            assert learner.log_in().status_code == 302, hub.log()[-2000:]
            learner.start_server()
        import pwd

        for learner in (a, b):
            uid, home = learner.run("import os; print(os.getuid(), os.path.expanduser('~'))").split()
            entry = pwd.getpwnam(learner.name)
            assert (int(uid), home) == (entry.pw_uid, entry.pw_dir)
            for theirs in ("notebooks/02_step2_joint_state_publisher.ipynb", "project/step1.yaml", "model"):
                assert (Path(home) / theirs).stat().st_uid == entry.pw_uid, f"{learner.name}'s {theirs} is not theirs"
        # useradd made their homes others can read (UMASK 022): the hub closed each, so B cannot read A's notebooks
        peeked = b.run(f"import os; print(os.access({pwd.getpwnam(a.name).pw_dir + '/notebooks'!r}, os.R_OK))")
        assert peeked.strip() == "False", "a learner can read another learner's home"
        results = {}
        for name, learner, with_joy in (("a", a, True), ("b", b, False)):  # one after the other: a slow machine
            results[name] = run_drive(learner, with_joy)
        rest = undriven_root()
        moved = {k: sum((x - y) ** 2 for x, y in zip(r["root"], rest)) ** 0.5 for k, r in results.items()}
        assert moved["a"] > 0.2 and moved["b"] < 0.001, (moved, results)
        assert results["a"]["domain"] != results["b"]["domain"]
        assert "rtt_joy" not in results["b"]["nodes"]
        # Each submits under their own name; then A hands one in under B's name, newer than B's own.  The
        # teacher's grading leaves A's out and stages B's (course/submissions.py).
        both_submit_under_their_own_names(hub, [a, b])
        assert a.run(submit_as(b.name)).strip() == "submitted"
        grading_leaves_out_the_forgery(tmp_path / "teacher", hub_state(hub) / "exchange", a.name, b.name)
    finally:
        hub.close()


# ---- each learner's server in cgroups of its own (course/limits.py) ----


def running(pid: int) -> bool:
    """Whether process ``pid`` runs (a zombie, killed and not yet reaped, does not)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False


FORKS = """
import subprocess, sys
started = []
try:
    for _ in range(200):  # stopping itself at 200
        started.append(subprocess.Popen(["sleep", "30"], stdout=subprocess.DEVNULL))
except OSError as exc:
    print(f"refused after {len(started)}: {type(exc).__name__}")
for p in started:
    p.kill()
"""


@pytest.mark.cross_process
def test_a_learners_server_and_what_it_starts_stay_in_its_cgroups_and_go_with_it(tmp_path):
    import asyncio
    import subprocess
    from types import SimpleNamespace

    from limits import LimitedSimpleLocalProcessSpawner

    if os.geteuid() != 0 or not Path("/sys/fs/cgroup/pids/cgroup.procs").exists():
        pytest.skip("the learners' limits need root and cgroup v1")
    name = f"rttlimits{os.getpid()}"
    spawner = LimitedSimpleLocalProcessSpawner(
        user=SimpleNamespace(name=name), home_dir_template=str(tmp_path / "{username}"), mem_limit="256M", pids_limit=40
    )
    groups = spawner.cgroups()
    try:
        # A "server" that starts a process in a session of its own (as a kernel is), then the forks.
        kernel = "import subprocess, sys; subprocess.Popen(['sleep', '60'], start_new_session=True, stdout=-3)"
        server = subprocess.Popen(
            [sys.executable, "-c", f"{kernel}; exec(sys.argv[1])", FORKS],
            preexec_fn=spawner.make_preexec_fn(name), start_new_session=True, stdout=subprocess.PIPE, text=True,
        )  # fmt: skip
        out, _ = server.communicate(timeout=60)
        assert re.fullmatch(r"refused after (\d+): BlockingIOError\n", out), out
        assert int(out.split()[2].rstrip(":")) < 40  # the pids limit, not the loop's own end, stopped it
        memory = next(g for g in groups if g.parent.name == "memory")
        assert int((memory / "memory.limit_in_bytes").read_text()) == 256 * 1024**2
        cpu = next(g for g in groups if g.parent.name == "cpu")
        assert (cpu / "cpu.shares").read_text().strip() == "1024"  # an equal share
        assert (cpu / "cpu.cfs_quota_us").read_text().strip() == "-1"  # and no cap unless cpu_limit says so
        left = (memory / "cgroup.procs").read_text().split()
        assert len(left) == 1, left  # the server is gone; what it started in a session of its own is not
        asyncio.run(spawner.remove_cgroups())
        assert not any(g.exists() for g in groups)
        assert not running(int(left[0]))
    finally:
        asyncio.run(spawner.remove_cgroups())


# What A's and B's kernels run meanwhile: Step 2 with a demo joystick for ``seconds``; the simulation's real-time
# factor, and how late the joint states came to the kernel: the gaps between them (50 per second), p99.
STEP2_WATCHED = """
import json, os, subprocess, sys, time
import numpy as np
import rclpy
from sensor_msgs.msg import JointState
venv = os.path.dirname(sys.executable)
sim = subprocess.Popen([os.path.join(venv, "rtt-run"), "{root}/project/step2.yaml", "--headless", "--json",
                        "--duration", "{seconds}"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
joy = subprocess.Popen([os.path.join(venv, "rtt-joy"), "--demo", "--duration", "{seconds}"],
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
if not rclpy.ok():
    rclpy.init()
node = rclpy.create_node("arrivals")
arrivals = []
node.create_subscription(JointState, "/Tank/joint_state", lambda m: arrivals.append(time.monotonic()), 100)
while sim.poll() is None:
    rclpy.spin_once(node, timeout_sec=0.1)
node.destroy_node()
out, _ = sim.communicate(timeout=60)
joy.wait(60)
summary = [json.loads(x) for x in out.splitlines() if x.startswith('{{"event": "summary"')][-1]
gaps = np.diff(arrivals[len(arrivals) // 10:]) * 1000  # ms, after the first tenth (start-up)
print(json.dumps({{"rtf": summary["real_time_factor"], "gap_p99_ms": float(np.percentile(gaps, 99))}}))
"""


def cpu_used(learner: str) -> int:
    """ns of CPU the learner's server and all it started have used (their cpuacct cgroup, course/limits.py)."""
    return int(Path(f"/sys/fs/cgroup/cpuacct/rtt-learner-{learner}/cpuacct.usage").read_text())


def memory_used(learner: str) -> int:
    """Bytes of memory the learner's server and all it started use, as ``podman stats`` counts a container's:
    their memory cgroup's usage less its inactive file cache (course/limits.py)."""
    cgroup = Path(f"/sys/fs/cgroup/memory/rtt-learner-{learner}")
    stat = dict(line.split() for line in (cgroup / "memory.stat").read_text().splitlines())
    return int((cgroup / "memory.usage_in_bytes").read_text()) - int(stat["total_inactive_file"])


# Learner C's misbehaviours, one at a time, each stopping itself where the issue says.
BUSY = """
import subprocess, sys
loops = [subprocess.Popen([sys.executable, "-c", "import time\\nend = time.monotonic() + {seconds}\\n"
                           "while time.monotonic() < end: pass"]) for _ in range(4)]
print("busy", [p.wait() for p in loops])
"""
FORK_BOMB = """
import subprocess
started = []
try:
    while len(started) < 2000:  # stopping itself at 2,000 processes
        started.append(subprocess.Popen(["sleep", "60"], stdout=subprocess.DEVNULL))
except OSError as exc:
    print(f"refused after {len(started)}: {type(exc).__name__}")
for p in started:
    p.kill()
    p.wait()
"""


@pytest.mark.slow
@pytest.mark.cross_process
def test_one_learner_cannot_take_the_others_down(tmp_path):
    """A and B run Step 2 with a joystick while C runs busy loops, then a memory hog, then a fork bomb."""
    import threading

    if os.geteuid() != 0:
        pytest.skip("the learners' limits need root (cgroups)")
    seconds = 15
    domains = (_FIRST, _FIRST + 1, 201 + os.getpid() % 10)  # C's from the block below 215's
    hub = Hub(tmp_path / "hub", ["learner-a", "learner-b", "learner-c"], domains)
    try:
        a, b, c = (Learner(hub, name) for name in ("learner-a", "learner-b", "learner-c"))
        for learner in (a, b, c):
            assert learner.log_in().status_code == 302, hub.log()[-2000:]
            learner.start_server()
        started = {x.name: x.server()["started"] for x in (a, b)}

        def round_with(misbehaviour: str | None) -> tuple[dict, str | Exception]:
            results, errors, said = {}, [], {}

            def watch(learner):
                try:
                    results[learner.name] = json.loads(
                        learner.run(STEP2_WATCHED.format(root=ROOT, seconds=seconds), timeout=180).splitlines()[-1]
                    )
                except BaseException as exc:  # noqa: BLE001 - collected and asserted below
                    errors.append(exc)

            def misbehave():
                try:
                    said["c"] = c.run(misbehaviour.replace("{seconds}", str(seconds - 3)), timeout=180)
                except Exception as exc:  # noqa: BLE001 - what C got is the case's result
                    said["c"] = exc

            threads = [threading.Thread(target=watch, args=(x,)) for x in (a, b)]
            if misbehaviour:
                threads.append(threading.Thread(target=misbehave))
            for t in threads:
                t.start()
            for t in threads:
                t.join(240)
            assert not errors, errors
            return results, said.get("c", "")

        before, _ = round_with(None)
        print("before", before)
        for name, misbehaviour in (("busy", BUSY), ("memory", MEMORY_HOG), ("fork bomb", FORK_BOMB)):
            used_before = cpu_used("learner-c")
            during, got = round_with(misbehaviour)
            print(name, during, repr(got)[:300])
            for learner in ("learner-a", "learner-b"):
                assert during[learner]["rtf"] >= 0.99, (name, learner, during)
                assert during[learner]["gap_p99_ms"] <= 2 * before[learner]["gap_p99_ms"], (name, before, during)
            if name == "busy":
                assert got.startswith("busy [0, 0, 0, 0]"), got
                # C got what A and B did not need (an equal share each, not a cap): more than a third of 2 cores
                cores = (cpu_used("learner-c") - used_before) / 1e9 / (seconds - 3)
                print(f"C's busy loops got {cores:.2f} cores")
                assert cores > 0.8, cores
            elif name == "memory":
                assert isinstance(got, KernelDied), got  # the limit stopped C's kernel before 8 GiB
            else:
                found = re.match(r"refused after (\d+): BlockingIOError", got)
                assert found and int(found.group(1)) < 500, got
        assert hub.proc.poll() is None
        for x in (a, b):  # A's and B's servers never restarted
            assert x.server()["started"] == started[x.name]
    finally:
        hub.close()
    assert hub.cgroups_left == []


def refused_page_says_why(browser, hub_url: str, name: str) -> None:
    """``name`` logs in with a browser while no domain is left: their page says why, and gives no server."""
    page = browser.new_context().new_page()
    page.goto(hub_url + "/hub/login")
    page.fill("input[name=username]", name)
    page.fill("input[name=password]", PASSWORD)
    page.click("input[type=submit], button[type=submit]")
    page.get_by_text(f"no ROS domain left for {name}: this server gives each learner one of its 1 domains").wait_for(
        timeout=60_000
    )  # JupyterHub's spawn page, from the pre-spawn hook's refusal (course/jupyterhub_config.py)
    shown = page.inner_text("body")
    assert "Unhandled error" not in shown and "/user/" not in page.url, (page.url, shown[-2000:])
    page.context.close()


@pytest.mark.slow
@pytest.mark.cross_process
def test_a_learner_who_left_is_culled_and_finds_their_work_again(tmp_path):
    """C closes their page on a simulation and its live view: the run pauses, C's server costs next to
    nothing, the hub's idle culler stops it and all it ran, and C comes back to their work, told why."""
    import time

    from playwright.sync_api import sync_playwright

    from tests.jupyterlab import CHROMIUM, CHROMIUM_FLAGS
    from tests.lab_browser import step2_notebook

    idle = 75  # s: the test's timeout (a class's: an hour); past the 30 s a run shown in no page takes to pause
    hub = Hub(
        tmp_path / "hub",
        ["learner-c", "learner-d"],
        DOMAINS[:1],  # C takes the one domain: D is refused
        extra_env={"RTT_HUB_IDLE_TIMEOUT": str(idle), "RTT_HUB_ACTIVITY_INTERVAL": "5"},
    )
    try:
        c = Learner(hub, "learner-c")
        assert c.log_in().status_code == 302, hub.log()[-2000:]
        c.start_server()
        said = c.run(
            "import os, subprocess\n"
            "open(os.path.expanduser('~/my_notes.txt'), 'w').write('mine')\n"
            "left = subprocess.Popen(['sleep', '600'])  # a program C leaves running\n"
            "print(os.environ['ROS_DOMAIN_ID'], left.pid)"
        )
        domain, program = said.split()
        path = tmp_path / "live.ipynb"
        step2_notebook(path)
        r = c.api("PUT", "api/contents/live.ipynb", json={"type": "notebook", "format": "json",
                                                          "content": json.loads(path.read_text())})  # fmt: skip
        assert r.status_code in (200, 201), r.text[:500]
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_FLAGS)
            try:
                page = open_live_notebook(browser, hub.url, "learner-c")
                require_live_view_draws(page, "learner-c")
                # the same work as a learner's container's figure in make test-containers (book/course.md)
                print(f"C's server, Step 2 and its live view running: memory {memory_used('learner-c') / 1e6:.0f} MB")
                refused_page_says_why(browser, hub.url, "learner-d")
                page.context.close()  # C leaves: the simulation and its view run on in C's kernel
            finally:
                browser.close()
        left = time.monotonic()
        # Within 60 s of the page closing, C's server (kernel, Jupyter server, all C started) costs <= 0.02 cores:
        # measured over the 20 s before that deadline, the run having paused 30 s after the page went.
        time.sleep(40)  # waiting for the pause's 30 s to pass: a duration under test, not a synchronisation
        used, since = cpu_used("learner-c"), time.monotonic()
        time.sleep(20)  # the measuring window
        cores = (cpu_used("learner-c") - used) / 1e9 / (time.monotonic() - since)
        print(f"C's server {time.monotonic() - left:.0f} s after C's page closed: {cores:.4f} cores")
        assert cores <= 0.02, cores
        while c.server() and time.monotonic() - left < idle + 60:  # the culler's timeout, its period, slack
            time.sleep(1)  # polling the hub's record of C's server, within the deadline
        assert not c.server(), f"C's server still runs {time.monotonic() - left:.0f} s after C left"
        waited = time.monotonic() - left
        assert waited >= idle - 10, waited  # not before the timeout (less the activity interval's lag)
        assert "idle-culler" in hub.log() and "learner-c" in hub.log()
        assert not running(int(program)), "the program C left running outlived C's server"
        # C comes back: their notebooks, their file and their domain are there.
        c.kernel_id = None  # that kernel went with the server
        c.start_server()
        again = c.run(
            "import os\nprint(os.environ['ROS_DOMAIN_ID'], open(os.path.expanduser('~/my_notes.txt')).read(), "
            "os.path.exists(os.path.expanduser('~/notebooks/03_step3_viewer.ipynb')))"
        )
        assert again.split() == [domain, "mine", "True"], again
        # ... and their first init_ros() says why their runs are gone, once
        told = c.run("from tutorial.notebook.session import init_ros\ninit_ros()")
        assert re.fullmatch(
            r"Note: your last server was stopped at [-0-9]+ [:0-9]+ UTC after (\d+) s without use \(this class "
            rf"stops a server after {idle} s\), with every simulation, joystick and view it ran\. .*\n",
            told,
        ), told
        assert int(re.search(r"after (\d+) s without", told).group(1)) >= idle, told
        c.kernel_id = None
        assert c.run("from tutorial.notebook.session import init_ros\ninit_ros()") == ""  # a new kernel: not again
    finally:
        hub.close()
    assert hub.cgroups_left == []


@pytest.mark.unit
def test_a_server_stopped_idle_is_told_once_in_its_next_server(tmp_path, monkeypatch):
    """The hub writes down a stop after the timeout without use, and only such a stop; the next server is told
    once, whichever of its kernels asks first."""
    import asyncio
    import datetime
    import logging
    from types import SimpleNamespace

    from idle_stops import VARIABLE, IdleStops, remembering_last_use

    from tutorial.notebook.session import idle_stop_note

    def spawner(name, idle_s):
        last = datetime.datetime.now(datetime.UTC).replace(tzinfo=None) - datetime.timedelta(seconds=idle_s)
        return SimpleNamespace(
            user=SimpleNamespace(name=name), last_use_before_stop=last, environment={}, log=logging.getLogger("test")
        )

    class Stopped:  # a spawner whose last use the hub sets to "now" as it stops, as JupyterHub does
        orm_spawner = SimpleNamespace(last_activity="before")

        async def stop(self, now=False):
            self.orm_spawner.last_activity = "now"

    kept = remembering_last_use(Stopped)()
    asyncio.run(kept.stop())
    assert kept.last_use_before_stop == "before" and type(kept).__name__ == "Stopped"

    stops = IdleStops(tmp_path / "idle-stops.json", timeout_s=3600)
    stops.after_stop(spawner("a", 3599))  # stopped by hand before the timeout: nothing to tell
    stops.after_stop(spawner("b", 3700))
    stops.after_stop(SimpleNamespace())  # it stopped by itself: the hub never asked it to
    nobody, a, b = spawner("c", 0), spawner("a", 0), spawner("b", 0)
    for each in (nobody, a, b):
        stops.before_spawn(each)
    assert nobody.environment == a.environment == {}
    when, idle_s, timeout_s = b.environment[VARIABLE].split()
    assert 3700 <= int(idle_s) <= 3760 and timeout_s == "3600", b.environment
    again = spawner("b", 0)
    stops.before_spawn(again)  # told in the environment once: the next server after is not
    assert again.environment == {}

    seen = tmp_path / "home" / "idle-stop"
    monkeypatch.setenv(VARIABLE, b.environment[VARIABLE])
    said = idle_stop_note(seen)
    assert said.startswith(f"Note: your last server was stopped at {when[:10]} {when[11:19]} UTC after 62 min ")
    assert "(this class stops a server after 60 min)" in said, said
    assert idle_stop_note(seen) == ""  # the server's next kernel
    monkeypatch.setenv(VARIABLE, "2026-11-26T21:40:00Z 90 60")  # a later stop is told, in seconds when short
    assert "after 90 s without use (this class stops a server after 60 s)" in idle_stop_note(seen)
    for bad in ("", "soon", "2026-11-26T21:40:00Z many 60", "a b c d"):
        monkeypatch.setenv(VARIABLE, bad)
        assert idle_stop_note(seen) == "", bad


@pytest.mark.unit
def test_a_kernel_stopped_at_the_memory_limit_is_told_once(tmp_path, monkeypatch):
    from tutorial.notebook.session import memory_limit_note

    root, seen = tmp_path / "memory", tmp_path / "told"
    root.mkdir()
    monkeypatch.setenv("MEM_LIMIT", str(2 * 1024**3))
    (root / "memory.oom_control").write_text("oom_kill_disable 0\nunder_oom 0\noom_kill 0\n")
    assert memory_limit_note(root, seen) == ""  # nothing stopped
    (root / "memory.oom_control").write_text("oom_kill_disable 0\nunder_oom 0\noom_kill 1\n")
    assert "more than its memory limit (2.0 GiB)" in memory_limit_note(root, seen)
    assert memory_limit_note(root, seen) == ""  # the next kernel is not told again
    (root / "memory.oom_control").write_text("oom_kill_disable 0\nunder_oom 0\noom_kill 2\n")
    assert "more than its memory limit" in memory_limit_note(root, seen)  # a second stop is


def test_a_second_hub_on_the_same_state_folder_is_refused_while_the_first_runs(tmp_path):
    """A second make hub would stop the first one's proxy: the state folder's pid file names a running hub."""
    assert running_hub(tmp_path) is None  # no pid file
    (tmp_path / "jupyterhub.pid").write_text("not a pid")
    assert running_hub(tmp_path) is None
    hub = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)", str(tmp_path / "bin" / "jupyterhub")])
    other = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)", "jupyterhub-singleuser"])
    try:
        (tmp_path / "jupyterhub.pid").write_text(str(other.pid))  # a learner's server, not a hub
        assert running_hub(tmp_path) is None
        (tmp_path / "jupyterhub.pid").write_text(f"{hub.pid}\n")
        assert running_hub(tmp_path) == hub.pid
    finally:
        for p in (hub, other):
            p.kill()
            p.wait(10)
    assert running_hub(tmp_path) is None  # the hub it names is gone: a stale pid file


def test_a_learners_home_is_made_theirs_alone(tmp_path):
    """Learners as Unix users: useradd makes homes others can read (UMASK 022); the hub closes each one."""
    from learner_home import close_home

    home = tmp_path / "home"
    home.mkdir(mode=0o755)
    os.chmod(home, 0o755)
    assert close_home(home) and home.stat().st_mode & 0o777 == 0o700
    assert not close_home(home) and home.stat().st_mode & 0o777 == 0o700  # closed already: left as it is
    os.chmod(home, 0o750)
    assert close_home(home) and home.stat().st_mode & 0o777 == 0o700
