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

from benchmarks.experiments.browser import _match, analyse_bare, analyse_tutorial

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
