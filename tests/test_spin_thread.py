"""The spin thread: callbacks run on it, and it stops cleanly however it is asked to."""

import threading

import pytest
from std_msgs.msg import String

from tutorial.ros.spin import SPIN_POLL, SpinThread, make_executor

from conftest import wait_until


def test_the_executor_is_the_single_threaded_executor_unless_switched(node, monkeypatch):
    from rclpy.executors import SingleThreadedExecutor

    monkeypatch.delenv("RTT_EXECUTOR", raising=False)
    assert isinstance(make_executor(node.context), SingleThreadedExecutor)
    monkeypatch.setenv("RTT_EXECUTOR", "events")
    assert type(make_executor(node.context)).__name__ == "EventsExecutor"
    monkeypatch.setenv("RTT_EXECUTOR", "fast")
    with pytest.raises(ValueError, match="RTT_EXECUTOR"):
        make_executor(node.context)


def test_callbacks_run_on_the_spin_thread_and_stop_ends_it(node):
    threads = []
    node.create_subscription(String, "/spin_thread_test", lambda msg: threads.append(threading.get_ident()), 10)
    pub = node.create_publisher(String, "/spin_thread_test", 10)
    spin = SpinThread(node).start()
    try:
        assert wait_until(lambda: pub.get_subscription_count() > 0, timeout=10)
        for _ in range(5):
            pub.publish(String(data="x"))
        assert wait_until(lambda: len(threads) == 5, timeout=10), threads
        assert set(threads) == {spin._thread.ident} and spin._thread.ident != threading.get_ident()
        # A subscription added while spinning is served too (the executor is woken from this thread).
        later = []
        node.create_subscription(String, "/spin_thread_test", lambda msg: later.append(msg.data), 10)
        assert wait_until(lambda: pub.get_subscription_count() > 1, timeout=10)
        pub.publish(String(data="y"))
        assert wait_until(lambda: later == ["y"], timeout=10), later
    finally:
        assert spin.stop(timeout=10 * SPIN_POLL + 2.0)
    assert spin.error is None
    # One spin thread per node in its life: a second one is refused, not silently lossy.
    with pytest.raises(RuntimeError, match="already spun"):
        SpinThread(node)


@pytest.mark.ros
def test_a_ros_shutdown_ends_the_spin_thread():
    import rclpy

    context = rclpy.Context()
    rclpy.init(context=context)
    node = rclpy.create_node("spin_thread_shutdown", context=context)
    spin = SpinThread(node).start()
    rclpy.try_shutdown(context=context)
    assert wait_until(lambda: not spin._thread.is_alive(), timeout=10)
    assert spin.error is None
    spin.stop()
    node.destroy_node()


def test_an_exception_in_a_callback_is_kept_for_the_owner(node):
    def broken(msg):
        raise ValueError("broken callback")

    node.create_subscription(String, "/spin_thread_broken", broken, 10)
    pub = node.create_publisher(String, "/spin_thread_broken", 10)
    spin = SpinThread(node).start()
    try:
        assert wait_until(lambda: pub.get_subscription_count() > 0, timeout=10)
        pub.publish(String(data="x"))
        assert wait_until(lambda: spin.error is not None, timeout=10)
        assert isinstance(spin.error, ValueError)
    finally:
        assert spin.stop()


def test_after_a_callback_the_spin_thread_steps_aside_for_the_owner(node):
    from tutorial.core.hand_over import HandOverLoop

    loop = HandOverLoop()  # owned by this thread, which runs it below
    ran = []
    node.create_subscription(
        String, "/spin_thread_hand_over", lambda msg: loop.call_later(ran.append, msg.data, key=msg.data), 10
    )
    pub = node.create_publisher(String, "/spin_thread_hand_over", 10)
    stepped_aside, spun = [], []
    real_yield = loop.yield_to_owner
    loop.yield_to_owner = lambda: stepped_aside.append(real_yield())  # a spy: called after every spin_once
    spin = SpinThread(node, hand_over_to=loop)
    real_spin_once = spin.executor.spin_once
    spin.executor.spin_once = lambda timeout_sec: spun.append(real_spin_once(timeout_sec=timeout_sec))
    spin.start()
    try:
        assert wait_until(lambda: pub.get_subscription_count() > 0, timeout=10)
        for i in range(5):
            pub.publish(String(data=str(i)))
            assert loop.run_until(lambda: len(ran) == i + 1, timeout=10), ran  # noqa: B023 - called in this iteration
    finally:
        assert spin.stop(timeout=10 * SPIN_POLL + 2.0)
    assert spin.error is None
    assert ran == ["0", "1", "2", "3", "4"]
    # After every turn of the executor the spin thread stepped aside (the spy), and at least once it waited
    # until this thread, waiting in run_once, took the work (the others found nothing to wait for).
    assert len(stepped_aside) == len(spun) >= 5, (len(stepped_aside), len(spun))
    assert loop.yields >= 1 and loop.yields == sum(stepped_aside), (loop.yields, loop.yield_timeouts, stepped_aside)
