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
    # Never early: the first a period after it was asked for, each next a period after the one before (a
    # busy machine may make them late, which is not checked).
    assert ticks[0] - start >= 0.01 - 1e-4, ticks[0] - start
    assert all(b - a >= 0.01 - 1e-4 for a, b in zip(ticks, ticks[1:])), [b - a for a, b in zip(ticks, ticks[1:])]


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
