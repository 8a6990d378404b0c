"""call_later: any thread posts, the owner thread runs, the newest state wins."""

import threading

from tutorial.core.call_later import LazyCaller, MainLoop, WrongThreadError
from tutorial.core.hand_over import HandOverLoop


def test_posted_calls_run_on_the_owner_thread_in_order():
    loop = MainLoop()
    ran = []
    t = threading.Thread(target=lambda: [loop.call_later(ran.append, i, key=i) for i in range(3)])
    t.start()
    t.join(10)
    assert ran == []  # posting never runs anything
    assert loop.process_pending() == 3
    assert ran == [0, 1, 2]


def test_same_function_coalesces_newest_arguments_win():
    loop = MainLoop()
    seen = []

    def update(state):
        seen.append(state)

    for k in range(100):
        loop.call_later(update, k)
    assert loop.pending() == 1
    loop.process_pending()
    assert seen == [99]
    assert (loop.posted, loop.coalesced, loop.executed) == (100, 99, 1)


def test_lazy_caller_coalesces():
    loop = MainLoop()
    seen = []
    lazy = LazyCaller(loop, seen.append)
    lazy(1)
    lazy(2)
    loop.process_pending()
    lazy(3)
    loop.process_pending()
    assert seen == [2, 3]


def test_only_the_owner_may_run_posted_calls():
    loop = MainLoop()
    errors = []

    def other():
        try:
            loop.process_pending()
        except WrongThreadError as exc:
            errors.append(exc)

    t = threading.Thread(target=other)
    t.start()
    t.join(10)
    assert len(errors) == 1


def test_an_error_in_a_call_does_not_stop_the_loop(capsys):
    loop = MainLoop()
    ran = []
    loop.call_later(lambda: 1 / 0, key="bad")
    loop.call_later(ran.append, "after", key="good")
    loop.process_pending()
    assert ran == ["after"]
    assert len(loop.errors) == 1 and "ZeroDivisionError" in loop.errors[0]


def test_no_backlog_under_a_flood_from_many_threads():
    """Four threads post 20,000 states; the owner sees each thread's states in order and the queue never grows."""
    loop = MainLoop()
    errors: list[BaseException] = []
    seen: dict[int, list[int]] = {i: [] for i in range(4)}
    max_pending = 0

    def update(thread_id, k):
        seen[thread_id].append(k)

    def flood(thread_id):
        try:
            for k in range(5000):
                loop.call_later(update, thread_id, k, key=thread_id)
        except BaseException as exc:  # noqa: BLE001
            errors.append(exc)

    threads = [threading.Thread(target=flood, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    while any(t.is_alive() for t in threads):
        max_pending = max(max_pending, loop.pending())
        loop.run_once(0.001)
    for t in threads:
        t.join(10)
    loop.process_pending()
    assert errors == []
    assert max_pending <= 4  # one pending call per key, never a queue of states
    for states in seen.values():
        assert states == sorted(states)  # never an older state after a newer one
        assert states[-1] == 4999  # the newest state always arrives
    assert loop.posted == 20000 and loop.executed + loop.coalesced == 20000


def test_run_until_has_a_deadline():
    loop = MainLoop()
    assert loop.run_until(lambda: False, timeout=0.05) is False
    loop.call_later(lambda: None)
    assert loop.run_until(lambda: loop.executed == 1, timeout=5.0)


def test_call_every_runs_on_schedule():
    import time

    loop = MainLoop()
    ticks = []
    start = time.monotonic()
    loop.call_every(0.01, lambda: ticks.append(time.monotonic()))
    loop.run_until(lambda: len(ticks) >= 3, timeout=5.0)
    assert len(ticks) >= 3
    # Never early: tick k (from 0) is due k + 1 periods after it was asked for, on a fixed-rate schedule, so
    # one late tick does not push the next ones back.  A busy machine may make them late, which is not checked.
    since = [t - start for t in ticks]
    assert all(t >= (k + 1) * 0.01 for k, t in enumerate(since)), since


def test_wake_on_the_owner_thread_takes_no_lock():
    """Ctrl-C's handler wakes the loop on the owner thread, maybe inside Event.wait with the event's lock held.

    Before the fix, wake() called Event.set() there and waited forever for a
    lock its own thread held (a viewer hung on Ctrl-C this way).
    """
    import time

    errors, finished, waited = [], threading.Event(), []

    def owner():
        try:
            loop = MainLoop()
            with loop._wakeup._cond:  # the state a signal handler can interrupt run_once in
                loop.wake()
            t0 = time.monotonic()
            loop.run_once(5.0)  # the wake is not lost: it returns without waiting its timeout
            waited.append(time.monotonic() - t0)
        except Exception as exc:  # noqa: BLE001 - asserted below
            errors.append(exc)
        finally:
            finished.set()

    threading.Thread(target=owner, daemon=True).start()
    assert finished.wait(10), "wake() on the owner thread blocked on the event's own lock"
    assert errors == []
    assert waited[0] < 2.5


def test_wake_from_another_thread_ends_a_wait():
    import time

    loop = MainLoop()
    t = threading.Timer(0.2, loop.wake)
    t.start()
    t0 = time.monotonic()
    loop.run_once(10.0)
    assert time.monotonic() - t0 < 5.0
    t.join(10)


def test_yield_to_owner_returns_once_the_waiting_owner_took_the_work():
    from conftest import wait_until

    loop = HandOverLoop()
    ran, results, errors = [], [], []
    stop = threading.Event()

    def poster():
        try:
            for i in range(5):
                assert wait_until(lambda: loop.owner_waiting, timeout=10)
                loop.call_later(ran.append, i)
                taken = loop.yield_to_owner(timeout=10.0)
                # Taken or not (the owner may have been quicker than this thread's check),
                # the work has left the queue by the time yield_to_owner returns.
                results.append((taken, loop.pending()))
        except Exception as exc:  # noqa: BLE001 - collected and asserted on
            errors.append(exc)
        finally:
            stop.set()
            loop.wake()

    t = threading.Thread(target=poster)
    t.start()
    while not stop.is_set():  # the owner: waits long in run_once, so the post finds it waiting
        loop.run_once(10.0)
    t.join(10)
    assert errors == []
    assert ran == [0, 1, 2, 3, 4]
    assert [pending for _, pending in results] == [0] * 5
    assert any(taken for taken, _ in results), results
    assert loop.yields == sum(taken for taken, _ in results) and loop.yield_timeouts == 0


def test_yield_to_owner_does_not_wait_for_an_owner_that_is_not_waiting():
    loop = HandOverLoop()
    results = []

    def poster():
        loop.call_later(print, "never run here")
        results.append(loop.yield_to_owner(timeout=10.0))  # the owner is not in run_once

    t = threading.Thread(target=poster)
    t.start()
    t.join(10)
    assert not t.is_alive()
    assert results == [False]
    assert loop.yield_to_owner() is False  # the owner never waits for itself
    assert (loop.yields, loop.yield_timeouts) == (0, 0)
    assert loop.pending() == 1  # nothing was lost: the owner runs it when it comes


def test_yield_to_owner_gives_up_after_its_timeout():
    loop = HandOverLoop()
    loop._owner_waiting = True  # as if the owner were waiting but never scheduled (a busy machine)
    results = []

    def poster():
        loop.call_later(len, "")
        results.append(loop.yield_to_owner(timeout=0.05))

    t = threading.Thread(target=poster)
    t.start()
    t.join(10)
    assert results == [False]
    assert (loop.yields, loop.yield_timeouts) == (0, 1)
    assert loop.process_pending() == 1


def test_two_lazy_callers_of_one_function_do_not_replace_each_other_and_pass_keywords():
    """Each LazyCaller coalesces its own calls only (its key is itself), keywords included."""
    loop = MainLoop()
    seen = []

    def show(body, q=None):
        seen.append((body, q))

    tank, arm = LazyCaller(loop, show), LazyCaller(loop, show)
    tank("Tank", q=0.1)
    arm("Arm", q=0.2)
    tank("Tank", q=0.3)  # replaces the tank's pending call, not the arm's
    assert loop.pending() == 2 and loop.max_pending == 2
    loop.process_pending()
    assert seen == [("Tank", 0.3), ("Arm", 0.2)]  # the tank keeps its place in the queue
    loop.call_later(show, "x", key=None)  # key None: the function is the key
    loop.call_later(show, "y")
    assert loop.pending() == 1 and loop.max_pending == 2
    loop.call_later(seen.append, "z")  # another function: another key
    assert loop.pending() == 2


def test_a_new_loop_has_counted_nothing_and_is_not_woken():
    loop = MainLoop()
    assert (loop.posted, loop.coalesced, loop.executed, loop.max_pending, loop.errors) == (0, 0, 0, 0, [])
    import time

    start = time.monotonic()
    assert loop.run_once(0.05) == 0  # nothing posted, no wake asked: it waits its timeout
    assert time.monotonic() - start >= 0.045


def test_only_the_owner_may_run_posted_calls_and_the_error_says_how_to_post():
    loop = MainLoop()
    errors = []
    t = threading.Thread(target=lambda: errors.append(_raised(loop.run_once, 0.0)))
    t.start()
    t.join(10)
    assert str(errors[0]) == (
        "MainLoop: only its owner thread may run posted calls; other threads must use call_later()"
    )


def _raised(func, *args):
    try:
        func(*args)
    except WrongThreadError as exc:
        return exc
    return None


def test_a_failing_call_is_printed_by_name_and_at_most_100_errors_are_kept(capsys):
    loop = MainLoop()

    def broken_callback(state, scale=1.0):
        raise ValueError(f"bad state {state} x{scale}")

    for k in range(101):
        loop.call_later(broken_callback, k, key=k, scale=2.0)
    loop.process_pending()
    printed = capsys.readouterr().out
    assert printed.count("[call_later] error in test_a_failing_call_is_printed_by_name_and_at_most_100") == 101
    assert "broken_callback:\nTraceback" in printed and "ValueError: bad state 100 x2.0" in printed
    assert len(loop.errors) == 100 and "bad state 99 x2.0" in loop.errors[-1]  # the 101st is printed, not kept
    loop.call_later(functools_partial_failing(), key="q")
    loop.process_pending()
    assert "[call_later] error in functools.partial(" in capsys.readouterr().out  # no __qualname__: its repr


def functools_partial_failing():
    import functools

    return functools.partial(int, "not a number")


def test_run_until_gives_up_exactly_at_its_deadline_not_a_poll_later():
    import time

    loop = MainLoop()
    start = time.monotonic()
    assert loop.run_until(lambda: False, timeout=0.3, poll=0.5) is False
    assert 0.28 <= time.monotonic() - start < 0.45  # the last wait is cut to what is left


def test_a_timer_that_is_due_runs_at_once_and_is_not_waited_for():
    import time

    loop = MainLoop()
    ticks = []
    loop.call_every(0.02, lambda: ticks.append(time.monotonic()))
    start = time.monotonic()
    loop.run_once(5.0)  # would wait 5 s, but the timer is due in 0.02 s: the wait ends then
    assert ticks and time.monotonic() - start < 1.0
    assert ticks[0] - start >= 0.019


def test_a_loop_owned_by_another_thread_refuses_this_one_saying_how_to_post():
    other = threading.Thread(target=lambda: None)
    other.start()
    other.join(10)
    loop = MainLoop(owner=other)
    try:
        loop.process_pending()
    except WrongThreadError as exc:
        assert str(exc) == "MainLoop: only its owner thread may run posted calls; other threads must use call_later()"
    else:
        raise AssertionError("the loop ran its calls on a thread that does not own it")


class FlushCounting:
    """Stands in for ``sys.stdout``: counts flushes, so an error shows in a notebook at once."""

    def __init__(self):
        self.text, self.flushes = "", 0

    def write(self, text):
        self.text += text

    def flush(self):
        self.flushes += 1


def test_an_error_in_a_call_is_flushed_at_once(monkeypatch):
    import sys

    out = FlushCounting()
    monkeypatch.setattr(sys, "stdout", out)
    loop = MainLoop()
    loop.call_later(int, "not a number")
    loop.process_pending()
    assert "[call_later] error in int:" in out.text and out.flushes >= 1


class FakeClock:
    """Stands in for the module ``time`` of call_later: time moves only when the loop waits."""

    def __init__(self, now=100.0):
        self.now = now

    def monotonic(self):
        return self.now


class FakeClockLoop(MainLoop):
    """A MainLoop whose waits move the fake clock by what they would wait, and are recorded."""

    def __init__(self, clock):
        super().__init__()
        self.clock, self.waits = clock, []

    def _wait(self, timeout):
        self.waits.append(timeout)
        self.clock.now += timeout


def test_a_timer_runs_exactly_when_due_and_not_a_moment_before(monkeypatch):
    from tutorial.core import call_later

    clock = FakeClock()
    monkeypatch.setattr(call_later, "time", clock)
    loop, ticks = MainLoop(), []
    loop.call_every(1.0, lambda: ticks.append(clock.now))
    clock.now = 100.5
    loop.process_pending()
    assert ticks == []  # half a period: not yet
    clock.now = 101.0
    loop.process_pending()
    assert ticks == [101.0]  # due at 101.0 s exactly: runs
    clock.now = 101.75
    loop.process_pending()
    assert ticks == [101.0]


def test_run_until_polls_every_10_ms_by_default_and_stops_at_its_deadline_exactly(monkeypatch):
    from tutorial.core import call_later

    clock = FakeClock()
    monkeypatch.setattr(call_later, "time", clock)
    loop = FakeClockLoop(clock)
    assert loop.run_until(lambda: False, timeout=1.0, poll=0.25) is False
    assert loop.waits == [0.25] * 4 and clock.now == 101.0  # nothing left at the deadline: no wait of 0 s more
    loop = FakeClockLoop(clock)
    assert loop.run_until(lambda: False, timeout=0.5) is False
    assert loop.waits[0] == 0.01
