"""The spin thread: where a node's subscription callbacks run, and why they hand their work over.

ROS 2 runs a subscription's callback on whatever thread spins the node's
executor.  In this tutorial that is one :class:`SpinThread` per node, never
the main thread: the main thread owns the model and the view, and a
callback that touched them would race with it.  So a callback checks the
message and hands what it needs over, with ``call_later`` (Choreonoid's
``callLater``; :mod:`tutorial.core.call_later`), to the main thread.
"""

from __future__ import annotations

import os
import threading
import weakref

SPIN_POLL = 0.1  # s: how often the spin thread checks whether it should stop

EXECUTOR_VARIABLE = "RTT_EXECUTOR"  # "single" (the default) or "events"
_spun_nodes: weakref.WeakSet = weakref.WeakSet()  # nodes given to a SpinThread, see SpinThread


def make_executor(context):
    """The executor a :class:`SpinThread` uses: rclpy's ``SingleThreadedExecutor``, chosen on purpose.

    It is the executor ``rclpy.spin()`` uses, so a learner's own nodes run
    their callbacks the way this tutorial's do.  rclpy's ``EventsExecutor``
    dispatches from C++ and measured faster here (the book's Benchmarks page,
    "What each figure compares": the 1 kHz rounds run it too), but in Jazzy
    it is experimental: it refuses guard conditions, and its ``shutdown()``
    and ``create_task()`` hang when called from another thread while it
    spins (``SpinThread`` never does that).  It is not kept out for losing
    messages: reading one stream at the same time, the two executors missed
    about the same messages (``python -m benchmarks.delivery``; what it
    found is in ``benchmarks/RESULTS.md``, *Tried, measured, not kept*).
    ``RTT_EXECUTOR=events`` selects it, for measuring.

    Args:
        context: the ``rclpy.context.Context`` of the node(s) to spin.

    Raises:
        ValueError: ``RTT_EXECUTOR`` is neither ``single`` nor ``events``.
    """
    choice = os.environ.get(EXECUTOR_VARIABLE, "single")
    if choice not in ("single", "events"):
        raise ValueError(f"{EXECUTOR_VARIABLE}={choice!r}: use 'single' or 'events'")
    if choice == "events":
        from rclpy.experimental import EventsExecutor

        return EventsExecutor(context=context)
    from rclpy.executors import SingleThreadedExecutor

    return SingleThreadedExecutor(context=context)


class SpinThread:
    """Spins one node's callbacks on a background thread.

    This is the analog of roscpp's ``AsyncSpinner``, which the original
    tutorial relied on: subscription callbacks run on *this* thread, never on
    the main thread or the simulation thread.  That is why a callback may not
    touch state owned by another thread, and why Step 1 uses a lock and
    Step 3 uses :func:`tutorial.core.call_later.call_later`.

    The thread calls ``spin_once`` until :meth:`stop` sets its stop flag, so
    stopping never calls into the executor from another thread and takes at
    most ``SPIN_POLL`` s.  If the ROS context is shut down first, the thread
    ends too.

    Args:
        node: the ``rclpy.node.Node`` whose callbacks to run.
        hand_over_to: the :class:`tutorial.core.hand_over.HandOverLoop` its
            callbacks post to, if any: after each callback the thread steps
            aside (:meth:`~tutorial.core.hand_over.HandOverLoop.yield_to_owner`,
            at most 1 ms) so the main thread runs the posted work before the
            executor's own bookkeeping holds the interpreter lock (speed only).

    Raises:
        RuntimeError: the node was already given to a SpinThread (one per node
            in its life: moved to a second ``EventsExecutor``, a node missed the
            messages of its first moments there, a silent loss).

    ``start`` and ``stop`` are called from the thread that owns the node
    (normally the main thread).  An exception raised by a callback ends the
    spinning; it is kept in :attr:`error` for the owner to report.
    """

    def __init__(self, node, hand_over_to=None):
        self.node = node
        self._hand_over_to = hand_over_to
        # One thread, one executor: callbacks of this node never run in
        # parallel with each other, only in parallel with the other threads.
        if node in _spun_nodes:
            raise RuntimeError(
                f"node {node.get_fully_qualified_name()} was already spun by a SpinThread; "
                "create a new node to spin it again"
            )
        self.executor = make_executor(node.context)
        _spun_nodes.add(node)
        self.executor.add_node(node)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._spin, name="ros-spin", daemon=True)
        self.error: BaseException | None = None

    def _spin(self) -> None:
        from rclpy.executors import ExternalShutdownException

        try:
            while not self._stop.is_set():
                self.executor.spin_once(timeout_sec=SPIN_POLL)
                if self._hand_over_to is not None:
                    self._hand_over_to.yield_to_owner()
        except ExternalShutdownException:
            pass
        except BaseException as exc:  # noqa: BLE001 - kept for the owner to report
            self.error = exc

    def start(self) -> SpinThread:
        """Start spinning on the background thread; returns self."""
        self._thread.start()
        return self

    def stop(self, timeout: float = 2.0) -> bool:
        """Stop spinning and wait for the thread (at most ``timeout`` s); True when it ended.

        Afterwards the node is removed from the executor and the executor is
        shut down (its guard conditions and threads released), so the node
        may be destroyed.
        """
        self._stop.set()
        if self._thread.ident is not None:
            self._thread.join(timeout)
        ended = not self._thread.is_alive()
        if ended:
            # Safe only now: the spinning thread has ended, nothing else uses the executor.
            self.executor.remove_node(self.node)
            self.executor.shutdown(timeout_sec=0)
        return ended
