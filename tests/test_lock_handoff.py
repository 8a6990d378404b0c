"""Step 1's lesson: the Joy callback and control() share the newest message under one lock."""

import threading
from types import SimpleNamespace

from tutorial.controllers.tank_controller import RttTankController


def test_control_always_sees_one_whole_message_under_concurrent_callbacks():
    controller = RttTankController()
    errors: list[BaseException] = []
    stop = threading.Event()
    torn = []

    def publisher(offset: int) -> None:
        try:
            k = offset
            while not stop.is_set():
                # every value of message k is k: a torn read would mix two k's
                controller.on_joy(SimpleNamespace(axes=[float(k)] * 8, buttons=[k] * 8))
                k += 4
        except BaseException as exc:  # noqa: BLE001
            errors.append(exc)

    def control_loop() -> None:
        try:
            for _ in range(20000):
                _count, axes, buttons = controller.take_input()
                if axes and (set(axes) != {float(buttons[0])} or set(buttons) != {buttons[0]}):
                    torn.append((axes, buttons))
        except BaseException as exc:  # noqa: BLE001
            errors.append(exc)

    threads = [threading.Thread(target=publisher, args=(i,)) for i in range(4)]
    reader = threading.Thread(target=control_loop)
    for t in threads:
        t.start()
    reader.start()
    reader.join(60)
    stop.set()
    for t in threads:
        t.join(10)
    assert not reader.is_alive() and not any(t.is_alive() for t in threads)
    assert errors == []
    assert torn == []
    assert controller.summary()["joy_received"] > 0


class PausedBetweenTheWrites(RttTankController):
    """The Step 1 controller, its callback made to pause between its two writes when ``pause`` is set.

    ``on_joy`` stores the axes, then the buttons (``self._axes, self._buttons = ...``): the buttons'
    store here first says it has been reached (``between``), then waits for ``reader_done``, at most
    ``PAUSE`` s.  Python's interpreter lock almost never switches threads there on its own; this makes
    the other thread run exactly there, every time: notebook 01's "forced race".
    """

    PAUSE = 0.5  # s: how long the writer waits, between its writes, for a reader that is not locked out

    @property
    def _buttons(self):
        return self.__dict__.get("_stored_buttons", ())

    @_buttons.setter
    def _buttons(self, value):
        pause = self.__dict__.get("pause")
        if pause is not None:
            pause["between"].set()
            pause["reader_done"].wait(self.PAUSE)
        self.__dict__["_stored_buttons"] = value


def test_a_read_forced_between_the_callbacks_two_writes_still_sees_one_whole_message():
    controller = PausedBetweenTheWrites()
    controller.on_joy(SimpleNamespace(axes=[1.0] * 8, buttons=[1] * 8))  # message 1, whole
    controller.pause = {"between": threading.Event(), "reader_done": threading.Event()}
    errors: list[BaseException] = []
    read = []

    def writer():
        try:
            controller.on_joy(SimpleNamespace(axes=[2.0] * 8, buttons=[2] * 8))  # message 2: pauses between
        except BaseException as exc:  # noqa: BLE001 - collected and asserted below
            errors.append(exc)

    def reader():
        try:
            read.append(controller.take_input())  # with the lock: waits until message 2 is whole
        except BaseException as exc:  # noqa: BLE001
            errors.append(exc)
        finally:
            controller.pause["reader_done"].set()

    w = threading.Thread(target=writer)
    w.start()
    assert controller.pause["between"].wait(10), "the callback never reached its second write"
    r = threading.Thread(target=reader)
    r.start()
    r.join(10)
    w.join(10)
    assert not w.is_alive() and not r.is_alive() and not errors, errors
    [(count, axes, buttons)] = read
    assert set(axes) == {float(b) for b in buttons}, f"a torn read: axes {axes} with buttons {buttons}"
    assert (count, axes[0]) == (2, 2.0)  # the reader waited for message 2, whole
