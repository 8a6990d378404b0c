"""The publish -> pixel benchmark's arithmetic (benchmarks.experiments.browser), on records made up here.

The experiment itself needs Chromium and minutes (``make bench``); what it
computes from its records is checked here: a page message is joined to the
command it carries by CRC-32, in order, a state is counted once, at the
first render after it arrived, and the page's clock is turned into the
monotonic one by the page's own offset.
"""

from __future__ import annotations

import zlib

import pytest

from benchmarks.experiments.browser import (
    _match,
    analyse_bare,
    analyse_tutorial,
    bare_commands,
    bare_samples,
    publisher_rate_parameter,
    since_frame_ms,
)

MS = 1_000_000  # ns


def test_match_joins_each_page_message_to_the_next_sent_one_with_its_crc():
    sent = [1, 2, 3, 2, 4]
    page = [[0.0, 2], [0.0, 3], [0.0, 2], [0.0, 9], [0.0, 4]]
    assert _match(page, sent) == [(0, 1), (1, 2), (2, 3), (4, 4)]


def _run(offset_ns: int) -> dict:
    """One body, three states 20 ms apart, each stage a different, known time (ms)."""
    sim_ns, wall_ns, applied, tape, msgs, renders = [], [], [], [], [], []
    for k in range(3):
        stamp = k * 20 * MS
        published = 1000 * MS + stamp
        sim_ns.append(stamp)
        wall_ns.append(published)
        arrived, done, sent = published + 1 * MS, published + 2 * MS, published + 4 * MS
        applied.append([stamp, arrived, done])
        data = f"state {k}".encode()
        tape.append([sent, "set_transform", "/meshcat/rtt/Tank/CHASSIS", data.hex(), "Tank", stamp])
        page_received = sent + 8 * MS
        msgs.append([(page_received + offset_ns) / MS, zlib.crc32(data)])
        renders.append((page_received + 3 * MS + offset_ns) / MS)
    rafs = [(1000 * MS + i * 16 * MS + offset_ns) / MS for i in range(10)]
    page = {"msgs": msgs, "renders": renders, "render_ms": [1.0] * 3, "rafs": rafs, "offset_ns": offset_ns}
    return {
        "sim": {"sim_ns": sim_ns, "wall_ns": wall_ns},
        "views": {"Tank": {"applied": applied}},
        "tape": tape,
        "page": page,
    }


@pytest.mark.parametrize("offset_ns", [0, 1_763_000_000_000 * MS])
def test_stages_add_up_whatever_the_page_clock(offset_ns):
    out = analyse_tutorial(_run(offset_ns), warmup=0.0)
    assert out["states_drawn"] == 2  # the third state is after the simulation's last step: left out
    for key, ms in (
        ("publish_to_callback", 1.0),
        ("callback_to_applied", 1.0),
        ("applied_to_sent", 2.0),
        ("sent_to_page", 8.0),
        ("page_to_drawn", 3.0),
        ("publish_to_drawn", 15.0),
    ):
        assert out[key]["p50"] == pytest.approx(ms, abs=1e-3), key


@pytest.mark.parametrize("offset_ns", [0, 1_763_000_000_000 * MS])
def test_where_each_measured_send_lands_in_the_page_frame(offset_ns):
    # frames every 16 ms from 1000 ms; the two measured states are sent at 1004 and 1024 ms
    out = analyse_tutorial(_run(offset_ns), warmup=0.0)
    assert out["send_phase_ms"]["p50"] == pytest.approx(6.0, abs=1e-3)
    assert out["send_phase_ms"]["max"] == pytest.approx(8.0, abs=1e-3)


def test_a_send_on_a_frame_lands_at_its_start_and_without_frames_nowhere():
    assert since_frame_ms([26 * MS], [10.0, 26.0, 42.0], offset_ns=0)["max"] == 0.0
    assert since_frame_ms([26 * MS], [], offset_ns=0)["n"] == 0


def test_a_send_before_the_first_frame_has_no_place_in_a_frame():
    rafs = [10.0, 26.0, 42.0]  # page ms; the page's clock 2 ms ahead of the monotonic one
    out = since_frame_ms([5 * MS, 9 * MS, 30 * MS], rafs, offset_ns=2 * MS)
    assert out["n"] == 2  # 5 ms is before the first frame (8 ms monotonic)
    assert out["p50"] == pytest.approx((1.0 + 6.0) / 2, abs=1e-3)


def test_a_state_sent_twice_counts_once():
    run = _run(0)
    run["tape"].insert(1, list(run["tape"][0]))
    run["page"]["msgs"].insert(1, list(run["page"]["msgs"][0]))
    assert analyse_tutorial(run, warmup=0.0)["states_drawn"] == 2


def test_bare_page_send_to_drawn():
    run = _run(5 * MS)
    sent = [(c[0], zlib.crc32(bytes.fromhex(c[3]))) for c in run["tape"]]
    out = analyse_bare(run["page"], sent, warmup=0.0)
    assert out["sent_to_page"]["p50"] == pytest.approx(8.0, abs=1e-3)
    assert out["sent_to_drawn"]["p50"] == pytest.approx(11.0, abs=1e-3)
    # sent at 1004, 1024 and 1044 ms against frames every 16 ms from 1000 ms (the page's clock 5 ms ahead)
    assert out["send_phase_ms"]["n"] == 3
    assert out["send_phase_ms"]["p50"] == pytest.approx(8.0, abs=1e-3)
    assert out["send_phase_ms"]["max"] == pytest.approx(12.0, abs=1e-3)


def _batched(run: dict) -> dict:
    """The same run with its three states sent as one set_transforms frame each, of two bodies (Tank, Tank2)."""
    from tutorial.view.meshcat_batch import pack_batch

    # Tank2's states arrive 0.5 ms later than Tank's and are applied 0.5 ms later: its stages differ.
    run["views"]["Tank2"] = {
        "applied": [[stamp, a + MS // 2, d + MS // 2] for stamp, a, d in run["views"]["Tank"]["applied"]]
    }
    tape, msgs = [], []
    for k, (record, msg) in enumerate(zip(run["tape"], run["page"]["msgs"])):
        matrix = [float(k)] * 16
        data = pack_batch(
            [
                {"type": "set_transform", "path": "/meshcat/rtt/Tank/CHASSIS", "matrix": matrix},
                {"type": "set_transform", "path": "/meshcat/rtt/Tank/TURRET_Y", "matrix": matrix},
                {"type": "set_transform", "path": "/meshcat/rtt/Tank2/CHASSIS", "matrix": matrix},
            ]
        )
        tape.append([record[0], "set_transforms", "", data.hex(), ["Tank", "Tank2"], [record[5], record[5]]])
        msgs.append([msg[0], zlib.crc32(data)])
    run["tape"], run["page"]["msgs"] = tape, msgs
    return run


def test_one_page_message_of_a_frame_counts_every_state_in_it():
    out = analyse_tutorial(_batched(_run(0)), warmup=0.0)
    assert out["states_drawn"] == 4  # two bodies, each with two states inside the run
    assert out["publish_to_drawn"]["p50"] == pytest.approx(15.0, abs=1e-3)  # one message: drawn together
    # each body's own moments, not the first body's for all: Tank 1.0 ms to its callback, Tank2 1.5 ms
    assert out["publish_to_callback"]["max"] == pytest.approx(1.5, abs=1e-3)
    assert out["publish_to_callback"]["p50"] == pytest.approx(1.25, abs=1e-3)
    assert out["applied_to_sent"]["p50"] == pytest.approx(1.75, abs=1e-3)


def test_the_bare_replay_sends_a_frame_as_meshcats_own_single_commands():
    import umsgpack

    tape = _batched(_run(0))["tape"]
    bare = bare_commands([[0, "set_object", "/meshcat/rtt/static/geom0", "c0", None, None], *tape])
    assert bare[0][1] == "set_object"
    singles = bare[1:]
    assert len(singles) == 3 * 3 and {c[1] for c in singles} == {"set_transform"}
    assert [c[0] for c in singles[:3]] == [tape[0][0]] * 3  # a frame's commands leave at the frame's moment
    first = umsgpack.unpackb(bytes.fromhex(singles[0][3]))
    assert first == {"type": "set_transform", "path": "/meshcat/rtt/Tank/CHASSIS", "matrix": [0.0] * 16}
    assert singles[0][2] == "/meshcat/rtt/Tank/CHASSIS"


def test_page_cost_reads_only_the_page_main_threads_slices_of_a_trace():
    from benchmarks.experiments.page_cost import SLICES, main_thread_ms

    main, gpu = (1, 10), (2, 20)

    def slice_(where, name, dur_us, ph="X"):
        return {"pid": where[0], "tid": where[1], "ph": ph, "name": name, "dur": dur_us}

    trace = {
        "traceEvents": [
            {"pid": 1, "tid": 10, "ph": "M", "name": "thread_name", "args": {"name": "CrRendererMain"}},
            {"pid": 2, "tid": 20, "ph": "M", "name": "thread_name", "args": {"name": "CrGpuMain"}},
            slice_(main, "ProxyMain::BeginMainFrame", 10_000),
            slice_(main, "ProxyMain::BeginMainFrame", 12_000),
            slice_(main, "GLES2::ReadPixels", 7_000),
            slice_(main, "GLES2::ReadPixels", 8_000),
            slice_(gpu, "GLES2::ReadPixels", 50_000),  # another thread: not the page's wait
            slice_(main, "GLES2::ReadPixels", 90_000, ph="B"),  # not a complete event: no duration to add
            slice_(main, "RunTask", 1_000),  # not one of the slices reported
        ]
    }
    got = main_thread_ms(trace)
    assert set(got) == set(SLICES)
    assert got["main frame"] == {"n": 2, "mean_ms": 11.0}
    assert got["waiting for the GPU process (ReadPixels)"] == {"n": 2, "mean_ms": 7.5}
    assert got["animation-frame callbacks (meshcat's render)"] == {"n": 0, "mean_ms": None}
    assert main_thread_ms({}) == {label: {"n": 0, "mean_ms": None} for label in SLICES}


def test_a_cases_publisher_rate_is_a_ros_double_and_slides_below_the_view_rate():
    # 1 kHz as "1000" is an integer parameter, which rtt-run refuses for a double: the run would not start
    assert publisher_rate_parameter(1000.0) == "RttJointStatePublisher.rate:=1000.0"
    slid = float(publisher_rate_parameter(50.0).split(":=")[1])
    assert 49.8 < slid < 50.0  # every 25th state one 1 ms step later: the states slide through the page's frame


def _widget_round(latencies_ms: list[float], fps: float) -> dict:
    """A made-up round of :func:`benchmarks.experiments.widget.widget_samples`."""
    ns = [x * MS for x in latencies_ms]
    return {
        "handed_to_drawn": ns,
        "sent_to_page": ns,
        "page_to_drawn": ns,
        "send_phase": ns,
        "frames_per_s": fps,
        "messages_per_s": 50.0,
        "states_handed": len(ns),
        "states_drawn": len(ns),
        "dropped": 0,
        "page": {"software": True},
    }


def test_the_widget_figures_pool_every_rounds_samples_and_keep_the_slowest_rate():
    from benchmarks.experiments.widget import summarise_page, summarise_widget

    rounds = [_widget_round([10.0] * 99 + [40.0], 60.0), _widget_round([10.0] * 100, 55.0)]
    out = summarise_widget(rounds)
    assert out["handed_to_drawn"]["n"] == 200
    assert out["handed_to_drawn"]["max"] == pytest.approx(40.0)
    # the one slow state of 200 lies past the pooled p99: it is the max, not a percentile
    assert out["handed_to_drawn"]["p99"] < 11.0
    assert out["frames_per_s"] == 55.0 and out["frames_per_s_rounds"] == [60.0, 55.0]
    assert out["states_drawn"] == 200

    run = _run(5 * MS)
    sent = [(c[0], zlib.crc32(bytes.fromhex(c[3]))) for c in run["tape"]]
    one = bare_samples(run["page"], sent, warmup=0.0)
    page = summarise_page([one, one])
    assert page["sent_to_drawn"]["n"] == 2 * len(one["sent_to_drawn"])
    assert page["sent_to_drawn"]["p50"] == pytest.approx(analyse_bare(run["page"], sent, 0.0)["sent_to_drawn"]["p50"])


def test_the_simulation_speed_target_times_the_controllers_it_names():
    """Step 1's controller and Step 2's publisher, as the target (and the scale projects) have them: what
    project/step2.yaml runs, and nothing else."""
    from benchmarks.paths import ROOT
    from tutorial.core.project import load_project

    names = [c.name for m in load_project(ROOT / "project/step2.yaml").models for c in m.controllers]
    assert names == ["RttTankController", "RttJointStatePublisher"]
